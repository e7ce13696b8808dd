"""What is known of the friction coefficients after some probes: a posterior on a grid.

The unknowns are the pads' mu and each pusher's mu. A push by pusher i is stable or not as a
function of the pads' mu and pusher i's alone (the stable-push test, docs/model.md section 2), so
every observation's likelihood is a table over that pair, and the posterior is a product of one
table per pusher:

    p(mu_pad, mu_1, ..., mu_k | outcomes) ~ prod_i L_i(mu_pad, mu_i)

with a uniform prior on each axis' grid. The marginals then need only sums over each table,
which keeps a grid of every unknown at once exact and cheap. An observation is taken as right
with probability 1 - `error_rate`: an outcome the simulator or the tracker gets wrong near the
boundary of stability lowers the odds of the worlds it excludes instead of excluding them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import List, Sequence, Tuple

import numpy as np

from stablepush.calibration.settings import DEFAULT_LEVEL


@dataclass(frozen=True)
class Interval:
    """An unknown's estimate (`value`, the posterior mean) and its credible interval [`low`,
    `high`], in the quantity's own units (mu: none)."""

    value: float
    low: float
    high: float

    def as_dict(self) -> dict:
        return {"value": self.value, "low": self.low, "high": self.high}

    @property
    def half_width(self) -> float:
        """The larger distance from the estimate to an end of the interval."""
        return max(self.high - self.value, self.value - self.low)


class Belief:
    """The posterior over the pads' mu (`pad_axis`, its grid) and each pusher's mu (`pusher_axes`,
    one grid each, all of the same size as the pads')."""

    def __init__(self, pad_axis: Sequence[float], pusher_axes: Sequence[Sequence[float]]):
        self.pad_axis = np.asarray(pad_axis, float)
        self.pusher_axes = [np.asarray(axis, float) for axis in pusher_axes]
        if any(axis.shape != self.pad_axis.shape for axis in self.pusher_axes):
            raise ValueError("every pusher's grid has as many values as the pads'")
        n = len(self.pad_axis)
        self.log_tables = [np.zeros((n, n)) for _ in self.pusher_axes]  # [pad index, pusher index]
        self.observations = 0

    def observe(self, pusher: int, chance: np.ndarray, stuck: bool) -> None:
        """Take one outcome of a push by `pusher` that sticks with probability `chance` (a table over
        [pad value, pusher value]: stick_chance): the pusher stuck (`stuck`) or slipped."""
        p = np.clip(np.asarray(chance, float), 1e-12, 1.0 - 1e-12)
        self.log_tables[pusher] += np.log(p) if stuck else np.log1p(-p)
        self.observations += 1

    def _sums(self) -> List[np.ndarray]:
        """Per pusher, log sum over its own axis of its table: a function of the pads' mu."""
        return [_logsumexp(table, axis=1) for table in self.log_tables]

    def pad_log_marginal(self) -> np.ndarray:
        return _normalised(np.sum(self._sums(), axis=0) if self.log_tables else np.zeros(len(self.pad_axis)))

    def pair_weights(self, pusher: int) -> np.ndarray:
        """The posterior's mass on each (pad value, pusher value) of `pusher`, the other pushers
        summed out: how likely each cell of that pusher's table is (sums to 1)."""
        sums = self._sums()
        others = np.sum([s for i, s in enumerate(sums) if i != pusher], axis=0) if len(sums) > 1 else 0.0
        log = self.log_tables[pusher] + np.asarray(others)[..., None] if len(sums) > 1 else self.log_tables[pusher]
        return np.exp(_normalised(log))

    def pusher_log_marginal(self, pusher: int) -> np.ndarray:
        return np.log(np.maximum(self.pair_weights(pusher).sum(axis=0), 1e-300))

    def pad_interval(self, level: float = DEFAULT_LEVEL) -> Interval:
        return _interval(self.pad_axis, np.exp(self.pad_log_marginal()), level)

    def pusher_interval(self, pusher: int, level: float = DEFAULT_LEVEL) -> Interval:
        return _interval(self.pusher_axes[pusher], np.exp(self.pusher_log_marginal(pusher)), level)

    def informative(self, pusher: int) -> bool:
        """Whether any observation has moved this pusher's own marginal from flat (beyond rounding)."""
        marginal = np.exp(self.pusher_log_marginal(pusher))
        return bool(np.ptp(marginal) > 1e-6 * marginal.max())


def stick_chance(margins: np.ndarray, error_rate: float, boundary: float) -> np.ndarray:
    """The chance that a push sticks in each world of a table, from its margin there [N]: the
    stable-push test's verdict blurred over `boundary` N about its boundary (a probit; 0: a step),
    then wrong with probability `error_rate` (an outcome the simulator or a tracker gets wrong)."""
    margins = np.asarray(margins, float)
    if boundary > 0.0:
        sure = 0.5 * (1.0 + np.vectorize(math.erf)(margins / (boundary * math.sqrt(2.0))))
    else:
        sure = (margins > 0.0).astype(float)
    return error_rate + (1.0 - 2.0 * error_rate) * sure


def split(weights: np.ndarray, chance: np.ndarray) -> float:
    """The posterior's chance that a push sticks: its stick chance averaged over the posterior."""
    return float(np.sum(weights * chance))


def expected_information(weights: np.ndarray, chance: np.ndarray) -> float:
    """The bits one observation of a push is expected to tell (the mutual information of its
    outcome and the world): the outcome's entropy less its entropy in each world, averaged (a push
    the posterior is sure of, or whose outcome is a coin toss in every world, tells nothing)."""
    return _entropy(split(weights, chance)) - float(np.sum(weights * _entropies(chance)))


def _entropies(p: np.ndarray) -> np.ndarray:
    p = np.clip(np.asarray(p, float), 1e-12, 1.0 - 1e-12)
    return -(p * np.log2(p) + (1.0 - p) * np.log2(1.0 - p))


def _entropy(p: float) -> float:
    return 0.0 if p <= 0.0 or p >= 1.0 else -(p * math.log2(p) + (1.0 - p) * math.log2(1.0 - p))


def _interval(axis: np.ndarray, mass: np.ndarray, level: float) -> Interval:
    """The posterior mean and the central `level` interval of a grid's mass, each end widened by
    half a grid step (the grid's own resolution)."""
    mass = mass / mass.sum()
    cdf = np.cumsum(mass)
    tail = (1.0 - level) / 2.0
    lo_i = int(np.searchsorted(cdf, tail, side="left"))
    hi_i = int(np.searchsorted(cdf, 1.0 - tail, side="left"))
    step = float(axis[1] - axis[0]) if len(axis) > 1 else 0.0
    lo = max(float(axis[0]), float(axis[min(lo_i, len(axis) - 1)]) - step / 2)
    hi = min(float(axis[-1]), float(axis[min(hi_i, len(axis) - 1)]) + step / 2)
    return Interval(value=float(np.sum(axis * mass)), low=lo, high=hi)


def _logsumexp(values: np.ndarray, axis: int) -> np.ndarray:
    top = np.max(values, axis=axis, keepdims=True)
    return np.squeeze(top, axis=axis) + np.log(np.sum(np.exp(values - top), axis=axis))


def _normalised(log: np.ndarray) -> np.ndarray:
    flat = log.reshape(-1)
    return log - _logsumexp(flat, axis=0)


def grid(nominal: float, spread: float, size: int) -> Tuple[float, ...]:
    """`size` values evenly from nominal (1 - spread) to nominal (1 + spread); a frictionless
    nominal (0) spans 0 to `spread`, as mu itself."""
    low, high = (nominal * (1.0 - spread), nominal * (1.0 + spread)) if nominal > 0.0 else (0.0, spread)
    return tuple(float(v) for v in np.linspace(max(low, 0.0), high, size))
