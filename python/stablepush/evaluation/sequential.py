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
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from stablepush.errors import SettingError

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
