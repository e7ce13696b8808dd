"""A success rate from many of the model's verdicts and a few simulated trials: prediction-powered
inference (A. N. Angelopoulos, S. Bates, C. Fannjiang, M. I. Jordan, T. Zrnic, "Prediction-powered
inference", Science 382, 2023), for a verdict and an outcome that are both land-or-miss.

With f the model's verdict on a world (1: it lands) and Y the simulator's, the rate is

    r = P(Y = 1) = pi a + (1 - pi) b,   pi = P(f = 1),  a = P(Y = 1 | f = 1),  b = P(Y = 1 | f = 0).

The predictions, N model-only worlds, carry pi; the trials, each with its own world's verdict,
correct the model within each verdict (a from the trials the model said land, b from those it said
miss: the rectifier E[Y - f] = (1 - pi) b - pi (1 - a), split by the verdict). Each of pi, a and
b gets an exact Clopper-Pearson interval (pi at PI_SHARE of the error rate, a and b at half the
rest each), and r's interval is the
range of pi a + (1 - pi) b over them (its ends at the intervals' corners: it is linear in each),
so it holds r with at least the stated confidence whatever the model's quality, for any number of
trials: a model that is often wrong only widens it, and a verdict no trial had leaves its part of
r anywhere in [0, 1]. The estimate is pi's sample share times the trials' rates within each
verdict (the trials' own rate where the model gave them one verdict only).

The CLT interval of PPI and PPI++ (the `ppi-python` package's `ppi_mean_ci`) is narrower, and
holds its level as n grows; with 100 trials of a plan that lands 99% of the time it does not
(benchmarks/predict.py measures both).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, Tuple

import numpy as np

from stablepush.errors import SettingError
from stablepush.evaluation.prediction import Verdicts, agreement

# The share of the error rate pi's interval takes; a and b share the rest. The predictions are many
# (pi's interval is narrow at any level), the trials few.
PI_SHARE = 0.1
METHOD = "prediction-powered, stratified by the model's verdict, exact (Clopper-Pearson) bounds"


@dataclass(frozen=True)
class PredictedRate:
    """A success rate estimated from `predictions` model-only verdicts and `trials` simulated
    trials with their own worlds' verdicts: its `estimate` and interval [`low`, `high`] at
    `confidence`; `predicted_rate`, the share of the predictions that land (pi); `agreement`, the
    model's verdicts against the trials' outcomes (prediction.agreement)."""

    estimate: float
    low: float
    high: float
    confidence: float
    predictions: int
    predicted_rate: float
    trials: int
    agreement: Dict[str, int]

    def as_dict(self) -> dict:
        return {"method": METHOD, "estimate": self.estimate, "interval": [self.low, self.high],
                "confidence": self.confidence, "predictions": self.predictions,
                "predicted_rate": self.predicted_rate, "trials": self.trials, "agreement": dict(self.agreement)}

    def describe(self) -> str:
        a = self.agreement
        agreed = a["lands_landed"] + a["misses_missed"]
        return (f"with {self.predictions:,} model-only worlds ({self.predicted_rate:.2%} predicted to land): "
                f"{self.estimate:.1%} ({self.confidence:.0%} CI {self.low:.1%}-{self.high:.1%}); the model agreed "
                f"with {agreed} of the {self.trials} trials (said lands: {a['lands_landed']} landed, "
                f"{a['lands_missed']} missed; said misses: {a['misses_landed']} landed, {a['misses_missed']} missed)")


def clopper_pearson(successes: int, n: int, alpha: float) -> Tuple[float, float]:
    """The exact two-sided interval of a binomial rate at error rate `alpha`; (0, 1) for n = 0."""
    from scipy.stats import beta

    low = 0.0 if successes == 0 else float(beta.ppf(alpha / 2, successes, n - successes + 1))
    high = 1.0 if successes == n else float(beta.ppf(1 - alpha / 2, successes + 1, n - successes))
    return low, high


def prediction_powered_rate(landed: Verdicts, predicted: Verdicts, predicted_unlabelled: Verdicts,
                            confidence: float = 0.95) -> PredictedRate:
    """The success rate from the trials' outcomes `landed`, the model's verdicts on the same trials'
    worlds `predicted`, and its verdicts on model-only worlds `predicted_unlabelled` (module
    docstring). SettingError for a confidence outside (0, 1), ValueError for trials and verdicts
    of different lengths."""
    if not 0.0 < confidence < 1.0:
        raise SettingError("confidence", f"must lie strictly between 0 and 1, got {confidence!r:.40}")
    y, f = np.asarray(landed, bool), np.asarray(predicted, bool)
    unlabelled = np.asarray(predicted_unlabelled, bool)
    if y.shape != f.shape or y.ndim != 1:
        raise ValueError(f"one verdict per trial: {y.shape} outcomes, {f.shape} verdicts")
    if unlabelled.size == 0:
        raise ValueError("no model-only world to predict the rate from")
    alpha = 1.0 - confidence
    pi_hat = float(unlabelled.mean())
    pi = clopper_pearson(int(unlabelled.sum()), unlabelled.size, PI_SHARE * alpha)
    within = (1.0 - PI_SHARE) / 2 * alpha
    a = clopper_pearson(int(np.sum(y & f)), int(f.sum()), within)
    b = clopper_pearson(int(np.sum(y & ~f)), int((~f).sum()), within)
    ends = [p * ra + (1.0 - p) * rb for p in pi for ra in a for rb in b]
    if f.all() or not f.any():  # one verdict on every trial: their rate stands for both verdicts'
        estimate = float(y.mean()) if y.size else pi_hat
    else:
        estimate = pi_hat * float(y[f].mean()) + (1.0 - pi_hat) * float(y[~f].mean())
    return PredictedRate(estimate=estimate, low=max(0.0, min(ends)), high=min(1.0, max(ends)), confidence=confidence,
                         predictions=int(unlabelled.size), predicted_rate=pi_hat, trials=int(y.size),
                         agreement=agreement(f, y))
