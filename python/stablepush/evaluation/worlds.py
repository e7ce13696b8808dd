"""The worlds of an evaluation: trial i of a batch with seed S runs in a world drawn from
numpy's generator seeded with (S, i) alone, so a trial's world, and so its outcome, is the same
whichever worker runs it, in whatever order.

A world multiplies the task's pad mu, pusher mu, grip force and mass by factors drawn uniformly
within +-FRACTION (`Spreads.vary`), places each feature off by up to (mm, deg) in x, z and theta
(uniform), and seeds the tracker's noise. `robust_task` widens a task's uncertainty box to hold
those multipliers, for a plan every push of which is stable in every such world.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Dict, Mapping, Optional, Sequence, Tuple

import numpy as np

from stablepush.errors import SettingError
from stablepush.task.model import MAX_ANGLE, MAX_COORDINATE, UNCERTAIN, Task
from stablepush.units import as_pair

VARY_KEYS = tuple(UNCERTAIN)  # pad_mu, pusher_mu, grip_force, mass: the keys of a task's uncertainty box
MAX_FRACTION = 0.9  # a spread of +-90% at most: every multiplier stays positive (the box's own limit)
# The spreads of a study that names none (Spreads.for_task), for a task without an uncertainty
# box: friction known to 10%, the grip to 5%, the mass to 2% (a scale), and fixtures placed to
# 0.2 mm and 0.2 deg (a dial gauge and a square). docs/evaluate.md, "The worlds".
DEFAULT_VARY = {"pad_mu": 0.1, "pusher_mu": 0.1, "grip_force": 0.05, "mass": 0.02}
DEFAULT_FEATURE_ERROR = (0.2, 0.2)  # mm, deg
# The most a feature may be off, or the tracker's noise (mm, deg): the task file's bounds on coordinates
# and angles (`--feature-error 0.9 1e308` overflowed numpy's uniform draw: an internal error).
SPREAD_LIMITS = (MAX_COORDINATE, MAX_ANGLE)


@dataclass(frozen=True)
class Spreads:
    """How far the worlds of a batch may differ from the task: `vary` maps VARY_KEYS to a fraction
    (a multiplier within 1 +- fraction); `feature_error` (mm, deg) bounds each feature's offset;
    `tracker_noise` (mm, deg) is the tracker's standard deviation."""

    vary: Dict[str, float] = field(default_factory=dict)
    feature_error: Tuple[float, float] = (0.0, 0.0)
    tracker_noise: Tuple[float, float] = (0.0, 0.0)

    def __post_init__(self):
        # -0.0 passes the range checks but makes numpy's uniform(0, -0) refuse "high - low < 0": every
        # spread is taken as the non-negative number it is (x + 0.0 is 0.0 for -0.0, x for any other).
        if not isinstance(self.vary, Mapping):
            raise TypeError(f"vary must be a mapping of {', '.join(VARY_KEYS)} to fractions, got "
                            f"{type(self.vary).__name__}")
        object.__setattr__(self, "vary", {key: fraction + 0.0 for key, fraction in dict(self.vary).items()})
        for name in ("feature_error", "tracker_noise"):
            object.__setattr__(self, name, tuple(v + 0.0 for v in getattr(self, name)))
        for key, fraction in self.vary.items():
            if key not in VARY_KEYS:
                raise SettingError("vary", f"unknown key {key!r} (one of {', '.join(VARY_KEYS)})")
            if not 0.0 <= fraction <= MAX_FRACTION:
                raise SettingError("vary", f"{key} must be a fraction from 0 to {MAX_FRACTION:g}, got {fraction:g}")
        for name, pair in (("feature_error", self.feature_error), ("tracker_noise", self.tracker_noise)):
            if len(pair) != 2 or not all(0.0 <= v <= most for v, most in zip(pair, SPREAD_LIMITS)):  # nan fails too
                raise SettingError(name, f"must be 2 numbers, not negative, at most {SPREAD_LIMITS[0]:g} mm and "
                                         f"{SPREAD_LIMITS[1]:g} deg (the task file's bounds on coordinates and "
                                         f"angles), got {tuple(pair)}")

    @classmethod
    def for_task(cls, task: Task, vary: Optional[Dict[str, float]] = None,
                 feature_error: Optional[Sequence[float]] = None,
                 tracker_noise: Sequence[float] = (0.0, 0.0)) -> "Spreads":
        """The spreads of a study of `task`: `vary` when given ({} varies nothing), else the task's
        uncertainty box when it has one, else DEFAULT_VARY; `feature_error` when given, else
        DEFAULT_FEATURE_ERROR when `vary` was not given either (a study that names no spread gets
        a lab's), else none."""
        if vary is None:
            vary = {k: v for k, v in task.uncertainty.items() if v > 0.0} or dict(DEFAULT_VARY)
            feature_error = DEFAULT_FEATURE_ERROR if feature_error is None else feature_error
        return cls(vary=dict(vary), feature_error=as_pair(feature_error or (0.0, 0.0)),
                   tracker_noise=as_pair(tracker_noise))  # Spreads checks each is two

    @property
    def one_world(self) -> bool:
        """Whether every world is the model's own: nothing varies, the features are in place and the
        tracker is exact, so every trial runs the same world (a study of one)."""
        return not any(self.vary.values()) and not any(self.feature_error) and not any(self.tracker_noise)

    def trials_to_run(self, requested: int) -> int:
        """How many of `requested` trials a study of these spreads runs: one for one world, where
        every trial would run the same world, else all."""
        return 1 if self.one_world else requested

    def describe(self) -> str:
        """The worlds in words: each spread, or the model's own world when nothing varies."""
        if self.one_world:
            return "one world, the model's own (nothing varies)"
        parts = [f"{key} +-{fraction:.0%}" for key, fraction in self.vary.items() if fraction]
        if any(self.feature_error):
            parts.append(f"features off by up to {self.feature_error[0]:g} mm, {self.feature_error[1]:g} deg")
        if any(self.tracker_noise):
            parts.append(f"tracker noise {self.tracker_noise[0]:g} mm, {self.tracker_noise[1]:g} deg")
        return ", ".join(parts)


@dataclass(frozen=True)
class TrialWorld:
    """One trial's world: the multipliers under VARY_KEYS' names, each feature's offset (pusher ->
    (dx mm, dz mm, dtheta deg)), and the tracker's seed."""

    trial: int
    multipliers: Dict[str, float]
    feature_offsets: Dict[str, Tuple[float, float, float]]
    tracker_seed: int

    def as_dict(self) -> dict:
        return {**self.multipliers, "feature_offsets": {k: list(v) for k, v in self.feature_offsets.items()}}


def draw_world(seed: int, trial: int, spreads: Spreads, pushers: Sequence[str]) -> TrialWorld:
    """Trial `trial`'s world: a function of (seed, trial) and the spreads alone."""
    rng = np.random.default_rng([seed, trial])
    multipliers = {key: float(1.0 + rng.uniform(-spreads.vary.get(key, 0.0), spreads.vary.get(key, 0.0)))
                   for key in VARY_KEYS}
    mm, deg = spreads.feature_error
    offsets = {name: (float(rng.uniform(-mm, mm)), float(rng.uniform(-mm, mm)), float(rng.uniform(-deg, deg)))
               for name in pushers}
    return TrialWorld(trial=trial, multipliers=multipliers, feature_offsets=offsets,
                      tracker_seed=int(rng.integers(2**31)))


def robust_task(task: Task, spreads: Spreads) -> Task:
    """The task whose `uncertainty` box holds every multiplier the spreads draw: each key the
    larger of the task's fraction and the spread's. A plan of it has every push stable at the box's
    corners, and so in every world of the batch up to the features' offsets and the tracker's noise,
    which the box does not describe (docs/model.md section 7). SettingError when the spreads vary
    nothing: there is no box to widen the task's to."""
    if not any(spreads.vary.values()):
        raise SettingError("vary", "a robust plan needs spreads to widen the box to (vary, or the defaults it takes "
                                   "without)")
    box = {key: max(task.uncertainty.get(key, 0.0), spreads.vary.get(key, 0.0)) for key in VARY_KEYS}
    return dataclasses.replace(task, uncertainty={key: value for key, value in box.items() if value > 0.0})
