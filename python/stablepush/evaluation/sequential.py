"""A sequential decision on "does the plan land at least `target` of the time?": Wald's sequential
probability ratio test (A. Wald, "Sequential tests of statistical hypotheses", Ann. Math. Statist.
16(2), 1945) with Ville's bounds, valid however early it stops (anytime-valid).

The test weighs "the success rate is `target`" (p1) against "it is `target` - `indifference`"
(p0) trial by trial. After s successes and f failures the log likelihood ratio is

    L = s log(p1 / p0) + f log((1 - p1) / (1 - p0))

and the test decides `above` once L >= log(1 / alpha), `below` once L <= log(beta), with
alpha = beta = 1 - confidence; until then it goes on. Under a rate p <= p0, exp(L) is a
nonnegative supermartingale of mean at most 1, so by Ville's inequality the test ever says `above`
with probability at most alpha; likewise exp(-L) under p >= p1 bounds `below` by beta (Wald's own
bounds, log((1 - beta) / alpha), are a little looser: about alpha / (1 - beta)). Between p0 and p1
lies the indifference zone, where either answer may come. A study capped before either bound is
`undecided`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

VERDICTS = ("above", "below", "undecided")


@dataclass(frozen=True)
class SequentialTest:
    """Whether a success rate is at least `target` (a fraction in (0, 1)), with error rates at most
    1 - `confidence` on each side, rates within `indifference` below the target (fraction) left to
    either answer. ValueError naming the setting when one is out of its range."""

    target: float
    confidence: float = 0.95
    indifference: float = 0.01

    def __post_init__(self) -> None:
        for name, value, low, high in (("target", self.target, 0.0, 1.0), ("confidence", self.confidence, 0.5, 1.0),
                                       ("indifference", self.indifference, 0.0, 1.0)):
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not low < value < high:
                raise ValueError(f"{name} must lie strictly between {low:g} and {high:g}, got {value!r:.40}")
        if self.target - self.indifference <= 0.0:
            raise ValueError(f"indifference {self.indifference:g} must be less than the target {self.target:g}")

    @property
    def steps(self) -> Tuple[float, float]:
        """What a success and a failure add to the log likelihood ratio."""
        p1, p0 = self.target, self.target - self.indifference
        return math.log(p1 / p0), math.log((1.0 - p1) / (1.0 - p0))

    @property
    def bounds(self) -> Tuple[float, float]:
        """The log likelihood ratios at which the test decides `below` and `above` (Ville's)."""
        alpha = beta = 1.0 - self.confidence
        return math.log(beta), math.log(1.0 / alpha)

    def decide(self, successes: int, trials: int) -> Optional[str]:
        """`above`, `below`, or None (go on) after `trials` trials of which `successes` landed; valid
        only when asked after every trial in the order they were run (the rule decide() is)."""
        win, loss = self.steps
        ratio = successes * win + (trials - successes) * loss
        low, high = self.bounds
        return "above" if ratio >= high else "below" if ratio <= low else None

    def first_decision(self, outcomes: Sequence[bool]) -> Tuple[str, int]:
        """The test run over `outcomes` in order: its verdict and the trials it took (all of them,
        `undecided`, when neither bound was reached)."""
        win, loss = self.steps
        ratio = np.cumsum(np.where(np.asarray(outcomes, bool), win, loss))
        low, high = self.bounds
        crossed = np.flatnonzero((ratio >= high) | (ratio <= low))
        if crossed.size == 0:
            return "undecided", len(ratio)
        k = int(crossed[0])
        return ("above" if ratio[k] >= high else "below"), k + 1

    def as_dict(self) -> dict:
        return {"target": self.target, "confidence": self.confidence, "indifference": self.indifference,
                "method": "Wald's SPRT"}
