"""The model's verdict on a world: a plan re-checked in the stable-push model of that world, in
microseconds where a simulated trial takes a second.

A world (worlds.TrialWorld) scales the task's pad mu, pusher mu, grip force and mass. In its model
the plan is predicted to land when

- every push is a stable push (docs/model.md section 3: the pusher sticks, the object slides in
  the pads) in that world: the object then follows the plan, pose for pose;
- the pads hold the object at the plan's end when the last feature lets go (`hold_ratio` >= 1 in
  that world; not asked when the task's run ends on its feature), else it moves on release;
- the plan's end lies within the success tolerance of the goal (open loop; the closed loop corrects
  its end to it).

What the model does not see: the features' offsets and the tracker's noise, the arm's tracking,
and, closed loop, a correction after a push that slipped (predicted a miss, where the closed loop
may still land). How often this verdict and the simulator's agree is measured, not assumed
(`Prediction.agreement`; docs/evaluate.md, "Odds from predictions"); the intervals that use it
(ppi.py) are valid whatever that agreement is.

Speed: a world's model is the task's model with the pads and the mass scaled
(StablePushModel.in_world, the pushers' cones shared); the cones of the pushers' scaled mu come from
one model per pusher-mu multiplier, rounded down to PUSHER_MU_QUANTUM (a cone at most that share
narrower than the world's: a conservative verdict).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from stablepush.evaluation.worlds import VARY_KEYS, Spreads, TrialWorld
from stablepush.plan.plan import Plan
from stablepush.pose import Tolerance
from stablepush.task.model import UNCERTAIN, Task
from stablepush.units import pose_to_si

PUSHER_MU_QUANTUM = 1e-3  # the pushers' mu multiplier is rounded down to a multiple of this
# The model-only worlds' generator is seeded with (seed, this), a trial's with (seed, trial) and
# trial < batch.MAX_TRIALS: no prediction's world is one of the trials'.
FIRST_PREDICTED_WORLD = 1_000_000
CAUSES = ("push_slips", "moved_on_release", "off_goal")


@dataclass(frozen=True)
class Prediction:
    """The model's verdict on one world: `lands`, else the `cause` (CAUSES) and, for a push that
    is not stable there, its index in the plan's waypoints (`push`); `least_margin` [N], the least
    margin of the plan's pushes in that world (negative: some push is not stable)."""

    lands: bool
    least_margin: float
    cause: Optional[str] = None
    push: Optional[int] = None

    def as_dict(self) -> dict:
        return {"lands": self.lands, "cause": self.cause, "push": self.push, "least_margin": self.least_margin}


class PlanInWorlds:
    """A plan of a task, ready to be re-checked in many worlds: its pushes as arrays by pusher and
    the models of the pushers' scaled mu, made once each. A trial lands within `tolerance` of the
    goal; `closed_loop`: the run corrects its end to it, so the plan's own end is not asked."""

    def __init__(self, task: Task, plan: Plan, tolerance: Tolerance, closed_loop: bool = False):
        self.task = task
        waypoints = plan.waypoints
        q = np.array([pose_to_si(w.pose) for w in waypoints])
        pushers = np.array([task.pusher_index(w.pushed_by) for w in waypoints[1:]], dtype=int)
        self._pushes: List[Tuple[int, np.ndarray, np.ndarray, np.ndarray]] = [
            (p, np.flatnonzero(pushers == p) + 1, q[:-1][pushers == p], np.diff(q, axis=0)[pushers == p])
            for p in sorted(set(pushers.tolist()))]
        self._end = tuple(q[-1])
        self._last = int(pushers[-1]) if len(pushers) else -1
        self._ask_hold = len(pushers) > 0 and not task.environment.end_on_feature
        self._on_goal = closed_loop or tolerance.within(waypoints[-1].pose, task.goal)
        self._models: Dict[int, object] = {}

    def _pusher_model(self, multiplier: float):
        """The task's model with every pusher's mu times `multiplier` rounded down (PUSHER_MU_QUANTUM)."""
        key = math.floor(multiplier / PUSHER_MU_QUANTUM + 1e-9)
        if key not in self._models:
            scaled = key * PUSHER_MU_QUANTUM
            path = UNCERTAIN["pusher_mu"]
            self._models[key] = self.task.with_values(
                {path.replace("*", p.name): p.mu * scaled for p in self.task.pushers}).model
        return self._models[key]

    def predict(self, world: TrialWorld) -> Prediction:
        """The model's verdict on `world`."""
        return self.predict_scaled(*(world.multipliers[key] for key in VARY_KEYS))

    def predict_scaled(self, pad_mu: float, pusher_mu: float, grip_force: float, mass: float) -> Prediction:
        """The model's verdict on the world of these multipliers of the task's values (VARY_KEYS)."""
        model = self._pusher_model(pusher_mu).in_world(pad_mu, grip_force, mass)
        least, first = math.inf, None
        for pusher, index, q0, dq in self._pushes:
            feasible, margin, _ = model.check_batch(q0, dq, pusher)
            least = min(least, float(margin.min()))
            if not feasible.all():
                at = int(index[np.flatnonzero(~feasible)[0]])
                first = at if first is None else min(first, at)
        if first is not None:
            return Prediction(False, least, "push_slips", first)
        if self._ask_hold and model.hold_ratio(self._end, self._last) < 1.0:
            return Prediction(False, least, "moved_on_release")
        if not self._on_goal:
            return Prediction(False, least, "off_goal")
        return Prediction(True, least)

    def predict_multipliers(self, multipliers: np.ndarray) -> np.ndarray:
        """Whether the model says each world lands, as a bool array: one world a row of
        `multipliers` (columns VARY_KEYS), as predicted_multipliers draws them."""
        return np.fromiter((self.predict_scaled(*row).lands for row in np.asarray(multipliers, float).tolist()),
                           dtype=bool, count=len(multipliers))


def predicted_multipliers(seed: int, count: int, spreads: Spreads) -> np.ndarray:
    """The multipliers (count x VARY_KEYS) of a study's `count` model-only worlds, drawn as its
    trials' are (worlds.draw_world: uniform within each spread) from a generator of their own,
    seeded with (seed, FIRST_PREDICTED_WORLD): no trial's world is drawn from it. The features'
    offsets and the tracker's noise are not drawn: the model does not see them."""
    rng = np.random.default_rng([seed, FIRST_PREDICTED_WORLD])
    spread = np.array([spreads.vary.get(key, 0.0) for key in VARY_KEYS])
    return 1.0 + rng.uniform(-1.0, 1.0, size=(count, len(VARY_KEYS))) * spread


Verdicts = Union[Sequence[bool], np.ndarray]  # one land-or-miss a world


def agreement(predicted: Verdicts, landed: Verdicts) -> Dict[str, int]:
    """The confusion table of the model's verdicts against the simulator's on the same worlds:
    counts of (predicted, landed) as `lands_landed`, `lands_missed`, `misses_landed`,
    `misses_missed`."""
    f, y = np.asarray(predicted, bool), np.asarray(landed, bool)
    return {"lands_landed": int(np.sum(f & y)), "lands_missed": int(np.sum(f & ~y)),
            "misses_landed": int(np.sum(~f & y)), "misses_missed": int(np.sum(~f & ~y))}
