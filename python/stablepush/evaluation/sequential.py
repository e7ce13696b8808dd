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
`undecided`; default_cap() is the cap a study takes when none is given, one the test decides
within at every rate but those near the middle of the indifference zone.

With the model's verdicts (`evaluate --predict`), PredictionPoweredTest answers the same question
with the same error rates, by betting on the trials' outcomes with the model's verdict on each
trial's world as a control variate (its docstring has the equation).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from stablepush.errors import SettingError
from stablepush.evaluation.ppi import PI_SHARE, clopper_pearson
from stablepush.evaluation.prediction import Verdicts

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
                raise SettingError(name, f"must lie strictly between {low:g} and {high:g}, got {value!r:.40}")
        if self.target - self.indifference <= 0.0:
            raise SettingError("target", f"must lie strictly between {self.indifference:g} and 1 (the test weighs "
                                         f"the target against a rate {self.indifference:g} below it, its "
                                         f"indifference zone), got {self.target:g}")

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

    def ratio(self, successes: int, trials: int) -> float:
        """The log likelihood ratio after `trials` trials of which `successes` landed."""
        win, loss = self.steps
        return successes * win + (trials - successes) * loss

    def decide(self, successes: int, trials: int) -> Optional[str]:
        """`above`, `below`, or None (go on) after `trials` trials of which `successes` landed; valid
        only when asked after every trial in the order they were run (the rule decide() is)."""
        ratio = self.ratio(successes, trials)
        low, high = self.bounds
        return "above" if ratio >= high else "below" if ratio <= low else None

    def to_decide(self, successes: int, trials: int, verdict: str) -> int:
        """How many more trials in a row, all landings (`above`) or all misses (`below`), decide
        `verdict` after `trials` trials of which `successes` landed: the fewest a decision takes
        from here (0 once it is decided so)."""
        win, loss = self.steps
        low, high = self.bounds
        ratio = self.ratio(successes, trials)
        k = max(0, math.ceil((high - ratio) / win if verdict == "above" else (ratio - low) / -loss))
        land = verdict == "above"
        # decide() is the rule: the estimate is moved to where it first says `verdict`, whatever the rounding
        while k > 0 and self.decide(successes + land * (k - 1), trials + k - 1) == verdict:
            k -= 1
        while self.decide(successes + land * k, trials + k) != verdict:
            k += 1
        return k

    def state(self, successes: int, trials: int) -> str:
        """The test after `trials` trials of which `successes` landed, in words for a progress
        line: its log likelihood ratio between its bounds and the fewest trials that decide it
        either way, or its decision."""
        verdict = self.decide(successes, trials)
        ratio = self.ratio(successes, trials)
        if verdict is not None:
            return f"decided {verdict} (log LR {ratio:+.2f})"
        low, high = self.bounds
        return (f"log LR {ratio:+.2f} in ({low:+.2f}, {high:+.2f}): {self.to_decide(successes, trials, 'above')} "
                f"more landings decide above, {self.to_decide(successes, trials, 'below')} misses below")

    def default_cap(self) -> int:
        """The trials a study runs at most when the caller names no cap: the most trials the test
        is expected to take at any success rate (Wald's approximation, the overshoot of the bounds
        neglected), and never fewer than a plan that lands every time needs.

        With w = log(p1 / p0) and l = log((1 - p1) / (1 - p0)) a landing's and a miss's step
        (`steps`) and b < 0 < a the bounds (`bounds`), a trial's step Z has the mean
        E_p[Z] = p w + (1 - p) l at a success rate p, and Wald's identity E[L_N] = E[N] E[Z] gives
        the expected trials E_p[N] = E_p[L_N] / E_p[Z]. They are most where E_p[Z] = 0, at
        p* = -l / (w - l) in the indifference zone: there the test ends at a with probability
        -b / (a - b), so E[L_N^2] = -a b, and Wald's second identity E[L_N^2] = E[N] E[Z^2], with
        E_p*[Z^2] = p* w^2 + (1 - p*) l^2 = -w l, gives

            max_p E_p[N] = (a / w) (b / l),

        the trials that all land to reach a times those that all miss to reach b. For a target of
        0.99, an indifference of 0.01 and a confidence of 0.95 that is 295.1 x 4.32 = 1276 trials
        (every landing: 296). A cap of the expected count at p* leaves some studies near p*
        undecided, where either answer would do; at p1 and p0 (the edges of the zone) the test
        decides within it in most studies, and outside the zone in nearly all
        (tests/test_sequential.py; docs/evaluate.md)."""
        win, loss = self.steps
        low, high = self.bounds
        return max(self.to_decide(0, 0, "above"), math.ceil((high / win) * (low / loss)))

    def cap_warning(self, cap: int) -> Optional[str]:
        """Why a study capped at `cap` trials cannot decide `above` whatever its trials, or None."""
        needed = self.to_decide(0, 0, "above")
        if cap >= needed:
            return None
        return (f"the test cannot decide above within {cap} trials: a plan that lands every time needs {needed} "
                f"(the default cap is {self.default_cap()})")

    def log_ratios(self, outcomes: Verdicts) -> np.ndarray:
        """The log likelihood ratio after each of `outcomes` (landed or not), in order."""
        win, loss = self.steps
        return np.cumsum(np.where(np.asarray(outcomes, bool), win, loss))

    def first_decision(self, outcomes: Sequence[bool]) -> Tuple[str, int]:
        """The test run over `outcomes` in order: its verdict and the trials it took (all of them,
        `undecided`, when neither bound was reached)."""
        ratio = self.log_ratios(outcomes)
        low, high = self.bounds
        crossed = np.flatnonzero((ratio >= high) | (ratio <= low))
        if crossed.size == 0:
            return "undecided", len(ratio)
        k = int(crossed[0])
        return ("above" if ratio[k] >= high else "below"), k + 1

    def as_dict(self) -> dict:
        return {"target": self.target, "confidence": self.confidence, "indifference": self.indifference,
                "method": "Wald's SPRT"}


# The prediction-powered test's constants (PredictionPoweredTest), chosen once from the reasoning in
# its docstring and the synthetic studies of benchmarks/predict.py's `decision` mode, not per case.
# The largest bet as a share of the one that could lose all the wealth on one trial (Waudby-Smith
# and Ramdas's truncation c; they use 1/2 to 3/4 for means anywhere in [0, 1]): near 99% a trial
# rarely goes against the bet, and a bet this bold reaches the all-landings floor of the binomial
# test within about a tenth of it, while one trial against it costs log(1 / (1 - c)) = 2.3 in log wealth.
MAX_BET_SHARE = 0.9
# The weight, in trials, of the prior of the bets' plug-in mean and variance of Z (aGRAPA's running
# estimates): the middle of the indifference zone, with a binomial variance there. One trial's
# weight: the first bet is about half the largest, and the trials take over at once.
PRIOR_TRIALS = 1.0
# The weight, in trials, of the prior of each of the model's two verdicts' landing rates (a and b,
# whose difference is the control variate's weight lambda): the trials' own rate, so that a model
# is trusted only as far as trials under both its verdicts show (the model of the tables' rows is
# pessimistic: most worlds it calls misses land; benchmarks/results/predict_rows.md).
VERDICT_PRIOR_TRIALS = 1.0
# The share of the wealth held in Wald's likelihood ratio (SequentialTest's) rather than in the bets.
# The bets are bold: they decide far above the target sooner than Wald, but near the indifference
# zone, with a model that is not exact, they leave many studies undecided where Wald's ratio (the
# most powerful between the two rates it weighs) decides; a mixture of the two is itself a wealth
# (a nonnegative supermartingale of mean 1 under each hypothesis), and either decides it, each
# paying log(1 / its share) for the other's place (benchmarks/results/predict_decision.md).
WALD_WEIGHT = 0.5


@dataclass(frozen=True)
class PredictionPoweredTest:
    """Whether a success rate r is at least `target`, from trials that each carry the simulator's
    outcome Y (1: landed) and the model's verdict F on the same trial's world (1: predicted to
    land), and the model's verdicts on `predictions` model-only worlds of the same spreads, of which
    `predicted_landings` land: a test by betting (I. Waudby-Smith, A. Ramdas, "Estimating means of
    bounded random variables by betting", JRSS-B 86(1), 2024) on the trials' outcomes with the
    model's verdict as a control variate (as PPI++: A. N. Angelopoulos, J. C. Duchi, T. Zrnic,
    "PPI++: efficient prediction-powered inference", 2023), anytime-valid as SequentialTest.

    With pi = P(F = 1) and pi_hat = predicted_landings / predictions its share in the model-only
    worlds (drawn apart from the trials'), trial t gives

        Z_t = Y_t - lambda_t (F_t - pi_hat),   E[Z_t | past] = r - lambda_t (pi - pi_hat),

    lambda_t in [0, 1] predictable (from the trials before t only). For two verdicts the variance
    of Z is least at lambda = Cov(Y, F) / Var(F) = a - b, a = P(Y = 1 | F = 1) and
    b = P(Y = 1 | F = 0): lambda_t is a_hat - b_hat (VERDICT_PRIOR_TRIALS), clipped to [0, 1]; an exact
    model gives lambda -> 1 and Z -> pi_hat (a miss it foresaw costs nothing), an uninformative
    one lambda -> 0 and Z = Y. pi's Clopper-Pearson interval [pi_low, pi_high] at error delta =
    PI_SHARE alpha (ppi.py) holds pi with probability at least 1 - delta. With p0 = target -
    indifference and p1 = target, on that event

        H0 (r <= p0):  E[Z_t | past] <= m_t  = p0 + lambda_t (pi_hat - pi_low),
        H1 (r >= p1):  E[Z_t | past] >= m'_t = p1 - lambda_t (pi_high - pi_hat),

    so the wealths

        K_t  = prod_{s <= t} (1 + b_s (Z_s - m_s)),   K'_t = prod_{s <= t} (1 + b'_s (m'_s - Z_s)),

    with predictable bets b_s in [0, c / (m_s - min Z_s)] and b'_s in [0, c / (max Z_s - m'_s)]
    (min Z = -lambda (1 - pi_hat), max Z = 1 + lambda pi_hat; c = MAX_BET_SHARE < 1 keeps every
    factor at least 1 - c > 0), are nonnegative supermartingales of mean at most 1 under H0 and
    under H1. By Ville's inequality K ever reaches 1 / (alpha - delta) with probability at most
    alpha - delta, so the test that decides `above` once K_t >= 1 / (alpha - delta) errs under
    H0 with probability at most alpha, however early it stops; likewise `below` once
    K'_t >= 1 / (beta - delta), at most beta under H1 (alpha = beta = 1 - confidence). The
    model's quality does not enter the error rates, only how soon the test decides. The bets are
    aGRAPA's plug-in (Waudby-Smith and Ramdas, section 5.3), b = (mu_hat - m) / (sigma2_hat +
    (mu_hat - m)^2) and b' with m' - mu_hat, from the running mean and variance of the Z before t
    with a prior of PRIOR_TRIALS trials at the indifference zone's middle, truncated to the range.

    The test holds WALD_WEIGHT of its wealth in Wald's likelihood ratio exp(L_t) (SequentialTest;
    a nonnegative martingale of mean 1 under p0, its inverse under p1, whatever the model) and the
    rest in the bets, and decides by the mixture: a mixture of wealths is a wealth, so the error
    rates hold as above, and it decides about as soon as the better of the two, each paying
    log(1 / its share) in log wealth.

    What it cannot beat: a trial that lands moves log K by at most log((Z - min Z) / (m - min Z)),
    about log(1 / p0), so near a target of 0.99 (p0 = 0.98) `above` takes at least about 150
    trials however good the model (the binomial floor: 0.98^n <= alpha); Wald's test needs 296.
    The model helps where trials miss: a miss it foresaw is no evidence against the plan."""

    target: float
    predictions: int
    predicted_landings: int
    confidence: float = 0.95
    indifference: float = 0.01

    def __post_init__(self) -> None:
        SequentialTest(self.target, self.confidence, self.indifference)  # the same settings, refused by name
        n = self.predictions
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise SettingError("predictions", f"must be a whole number of at least 1, got {n!r:.40}")
        k = self.predicted_landings
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k <= n:
            raise SettingError("predicted_landings", f"must be a whole number from 0 to {n}, got {k!r:.40}")

    @classmethod
    def of(cls, test: SequentialTest, predicted: Verdicts) -> "PredictionPoweredTest":
        """`test`'s settings with the model's verdicts `predicted` on the model-only worlds."""
        verdicts = np.asarray(predicted, bool)
        return cls(test.target, int(verdicts.size), int(verdicts.sum()), test.confidence, test.indifference)

    @property
    def predicted_rate(self) -> float:
        """pi_hat: the share of the model-only worlds predicted to land."""
        return self.predicted_landings / self.predictions

    @property
    def pi_error(self) -> float:
        """delta: the share of each error rate that pi's interval may miss by."""
        return PI_SHARE * (1.0 - self.confidence)

    @property
    def bounds(self) -> Tuple[float, float]:
        """The log wealths at which the test decides `below` (of K') and `above` (of K)."""
        level = math.log(1.0 / (1.0 - self.confidence - self.pi_error))
        return level, level

    def log_wealth(self, landed: Verdicts, predicted: Verdicts) -> Tuple[np.ndarray, np.ndarray]:
        """The log wealths the test decides by after each trial (`above`'s, `below`'s): the bets'
        (betting_log_wealth) mixed with Wald's likelihood ratio, WALD_WEIGHT of it,
        log((1 - w) K_t + w exp(L_t)) and log((1 - w) K'_t + w exp(-L_t))."""
        above, below = self.betting_log_wealth(landed, predicted)
        ratio = SequentialTest(self.target, self.confidence, self.indifference).log_ratios(landed)
        bet, lr = math.log(1.0 - WALD_WEIGHT), math.log(WALD_WEIGHT)
        return np.logaddexp(bet + above, lr + ratio), np.logaddexp(bet + below, lr - ratio)

    def betting_log_wealth(self, landed: Verdicts, predicted: Verdicts) -> Tuple[np.ndarray, np.ndarray]:
        """log K_t (`above`'s) and log K'_t (`below`'s) after each trial, with the trials' outcomes
        `landed` and the model's verdicts on their worlds `predicted`, in the order they were run.
        ValueError for sequences of different lengths."""
        y, f = np.asarray(landed, bool).astype(float), np.asarray(predicted, bool).astype(float)
        if y.shape != f.shape or y.ndim != 1:
            raise ValueError(f"one verdict per trial: {y.shape} outcomes, {f.shape} verdicts")
        p1 = self.target
        p0 = p1 - self.indifference
        pi_hat = self.predicted_rate
        pi_low, pi_high = clopper_pearson(self.predicted_landings, self.predictions, self.pi_error)
        # Everything at trial t from the trials before it (predictable): counts shifted by one.
        def before(x: np.ndarray) -> np.ndarray:
            return np.concatenate(([0.0], np.cumsum(x)[:-1]))
        seen = np.arange(y.size, dtype=float)
        said_lands, landed_said_lands, landed_said_misses = before(f), before(y * f), before(y * (1.0 - f))
        # Each verdict's landing rate shrunk toward the trials' own (itself from Jeffreys's prior): until
        # trials under both verdicts say otherwise the model is taken to tell nothing (lambda near 0).
        pooled = (before(y) + 0.5) / (seen + 1.0)
        a = (landed_said_lands + VERDICT_PRIOR_TRIALS * pooled) / (said_lands + VERDICT_PRIOR_TRIALS)
        b = (landed_said_misses + VERDICT_PRIOR_TRIALS * pooled) / (seen - said_lands + VERDICT_PRIOR_TRIALS)
        lam = np.clip(a - b, 0.0, 1.0)
        z = y - lam * (f - pi_hat)
        m_above = p0 + lam * (pi_hat - pi_low)
        m_below = p1 - lam * (pi_high - pi_hat)
        middle = (p0 + p1) / 2.0
        count = PRIOR_TRIALS + seen
        mean = (PRIOR_TRIALS * middle + before(z)) / count
        second = (PRIOR_TRIALS * (middle * (1.0 - middle) + middle ** 2) + before(z * z)) / count
        variance = np.maximum(second - mean ** 2, 1e-12)
        least, most = -lam * (1.0 - pi_hat), 1.0 + lam * pi_hat
        up, down = mean - m_above, m_below - mean
        bet_above = np.clip(up / (variance + up ** 2), 0.0, MAX_BET_SHARE / (m_above - least))
        bet_below = np.clip(down / (variance + down ** 2), 0.0, MAX_BET_SHARE / (most - m_below))
        return np.cumsum(np.log1p(bet_above * (z - m_above))), np.cumsum(np.log1p(bet_below * (m_below - z)))

    def first_decision(self, landed: Verdicts, predicted: Verdicts) -> Tuple[str, int]:
        """The test run over the trials in order: its verdict and the trials it took (all of them,
        `undecided`, when neither wealth reached its bound)."""
        above, below = self.log_wealth(landed, predicted)
        low, high = self.bounds
        crossed = np.flatnonzero((above >= high) | (below >= low))
        if crossed.size == 0:
            return "undecided", len(above)
        k = int(crossed[0])
        return ("above" if above[k] >= high else "below"), k + 1

    def decide(self, landed: Verdicts, predicted: Verdicts) -> Optional[str]:
        """`above`, `below`, or None (go on) after the trials so far (first_decision's verdict on
        them, asked after every trial in the order they were run)."""
        verdict, _ = self.first_decision(landed, predicted)
        return None if verdict == "undecided" else verdict

    def state(self, landed: Verdicts, predicted: Verdicts) -> str:
        """The test after the trials so far, in words for a progress line: its two log wealths
        against their bounds, or its decision."""
        verdict, _ = self.first_decision(landed, predicted)
        above, below = self.log_wealth(landed, predicted)
        low, high = self.bounds
        now = (float(above[-1]), float(below[-1])) if above.size else (0.0, 0.0)
        if verdict != "undecided":
            return f"decided {verdict} (log wealth above {now[0]:+.2f}, below {now[1]:+.2f})"
        return f"log wealth above {now[0]:+.2f} of {high:.2f}, below {now[1]:+.2f} of {low:.2f}"

    def default_cap(self) -> int:
        """The Wald test's of the same settings (SequentialTest.default_cap): the new test decides
        within it wherever that one does, in the studies of benchmarks/predict.py's `decision`."""
        return SequentialTest(self.target, self.confidence, self.indifference).default_cap()

    def as_dict(self) -> dict:
        return {"target": self.target, "confidence": self.confidence, "indifference": self.indifference,
                "method": PP_METHOD, "predictions": self.predictions, "predicted_rate": self.predicted_rate}


PP_METHOD = "prediction-powered test by betting"
