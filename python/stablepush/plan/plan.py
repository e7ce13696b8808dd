"""The plan as plain data (docs/model.md section 5): its waypoints, in file units (mm, deg, N).

A waypoint is the object's pose in the grasp after a unit push, the pusher that made the push,
the test's verdict on it and the pusher's contact seen from the gripper, which is what a robot
executes (the pusher is fixed in the world and in O during a push, so in G it moves with the
object). The first waypoint is the start and has no pusher.
"""
from __future__ import annotations

import enum
import json
import math
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Tuple

import numpy as np

from stablepush.errors import PlanError
from stablepush.units import is_finite_real, is_real

FieldFault = Optional[Tuple[str, str]]  # (field, reason) of the first check that fails; None when all pass


@dataclass(frozen=True)
class PusherContact:
    """A pusher's contact in the gripper frame G: the segment from-to (mm; equal for a point
    pusher) and the unit normal pointing into the object. PlanError unless each is 2 finite numbers."""

    start: Tuple[float, float]
    end: Tuple[float, float]
    normal: Tuple[float, float]

    def __post_init__(self):
        for key in ("start", "end", "normal"):
            if not is_point(getattr(self, key)):
                raise PlanError(f"contact.{key}", "must be 2 finite numbers")


@dataclass(frozen=True)
class Waypoint:
    """The pose after a unit push (x mm, z mm, theta deg), the pusher that made the push and the
    test's verdict on it; the first waypoint is the start and has no pusher. PlanError naming the
    field (`waypoint.x`, say) for one a plan file could not hold (waypoint_fault)."""

    x: float
    z: float
    theta: float
    pusher: Optional[str] = None
    margin: Optional[float] = None  # N, depth inside the pusher's cone
    case: Optional[str] = None  # all_sliding | sticking
    contact: Optional[PusherContact] = None  # the pusher's contact in G at this pose
    margin_per_normal: Optional[float] = None  # margin / the pusher's normal force (least stable corner)

    def __post_init__(self):
        # A waypoint that exists can be written, read back and checked against a task: no NaN pose
        # reaches the planner's re-check, a trajectory or a plan file.
        fault = waypoint_fault(vars(self))
        if fault is None and not (self.contact is None or isinstance(self.contact, PusherContact)):
            fault = "contact", f"must be a PusherContact or None, got {type(self.contact).__name__}"
        if fault is not None:
            raise PlanError(f"waypoint.{fault[0]}", fault[1])

    @property
    def pose(self) -> Tuple[float, float, float]:
        """(x mm, z mm, theta deg)."""
        return (self.x, self.z, self.theta)

    @property
    def pushed_by(self) -> str:
        """The pusher of this push: every waypoint after the start has one (check_plan); PlanError
        for one without (the start, which is no push)."""
        if self.pusher is None:
            raise PlanError("waypoint.pusher", "missing: every waypoint after the start is a push by a pusher")
        return self.pusher


def waypoint_fault(fields: Mapping[str, Any]) -> FieldFault:
    """What is wrong with a waypoint's fields, by Waypoint's names (a Waypoint's own, or a plan
    file's waypoint, which may lack a pose field), other than its contact: the first fault as
    (field, reason), None when there is none. Reasons are in JSON's words (null), as a plan file's
    reader reports them."""
    for key in ("x", "z", "theta"):
        if key not in fields:
            return key, "missing"
        if not is_finite_real(fields[key]):
            return key, f"must be a finite number, got {value_shown(fields[key])}"
    if not (fields.get("pusher") is None or isinstance(fields["pusher"], str)):
        return "pusher", f"must be a pusher name or null, got {value_kind(fields['pusher'])}"
    for key in ("margin", "margin_per_normal"):
        if fields.get(key) is not None and not is_finite_real(fields[key]):
            return key, f"must be a finite number or null, got {value_shown(fields[key])}"
    if not (fields.get("case") is None or isinstance(fields["case"], str)):
        return "case", f"must be a string or null, got {value_kind(fields['case'])}"
    return None


def is_point(value: Any) -> bool:
    """Two finite numbers: a plan file's list of them, or a tuple or array in the API."""
    try:
        return len(value) == 2 and all(is_finite_real(c) for c in value)
    except TypeError:  # no length, or no iteration
        return False


def value_shown(v: Any, limit: int = 40) -> str:
    """A value for a message, as JSON writes it (a string in quotes, NaN), cut to `limit` characters."""
    text = json.dumps(v, allow_nan=True, default=str)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def value_kind(v: Any) -> str:
    """What a value is, in JSON's words (a Python type's name for what JSON has not)."""
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "a boolean"
    kinds: Dict[type, str] = {str: "a string", dict: "a mapping", list: "a list"}
    return kinds.get(type(v), "a number" if is_real(v) else type(v).__name__)


class PlanOutcome(str, enum.Enum):
    """How a plan's search ended: `Plan.outcome` is one of these names (a plain string, as the plan
    file holds it; `PlanOutcome(plan.outcome)` gives the member). The core's search ends in the
    first four; `unreachable` is decided before it (stablepush.plan.unreachable)."""

    goal_reached = "goal_reached"  # solved
    goal_over_switch_limit = "goal_over_switch_limit"  # reached only with more switch-overs than allowed
    time_limit = "time_limit"  # the path to the node nearest the goal
    invalid_start = "invalid_start"  # the pads are not on the object at the start
    unreachable = "unreachable"  # no plan can reach the goal; the reason is in the message


@dataclass(frozen=True)
class Plan:
    """A plan: waypoints from the start (no pusher) through each unit push (docs/model.md section 5),
    how the search ended, and its statistics. Plain data: `stablepush.plan.search.plan_task` makes
    it, `stablepush.plan.files` writes and reads it, `stablepush.plan.verify.check_plan` shows it
    belongs to a task."""

    task: str
    solved: bool  # the goal is reached within tolerance with at most max_switches switch-overs
    outcome: str  # goal_reached | goal_over_switch_limit | time_limit | invalid_start | unreachable
    message: str
    waypoints: List[Waypoint]
    stats: Dict[str, Any] = field(default_factory=dict)  # numbers, flags, and "first" (the anytime search's first plan)
    # The largest multiple of the weight the pads alone hold at the last waypoint, gravity as during
    # the last push (>= 1: released there, the object stays; inf without gravity). hold_ratio.
    final_hold_ratio: float = math.inf
    uncertainty: Dict[str, float] = field(default_factory=dict)  # the task's, under which every push is stable
    # A solved plan's last push reaches the goal pose itself; False: it ends within the tolerance
    # (the last, shorter push to the goal was not a stable push).
    ends_at_goal: bool = False
    # The task it was planned for (Task.identity); None for a plan file older than this field.
    task_identity: Optional[Dict[str, Any]] = None

    @property
    def pusher_sequence(self) -> List[str]:
        """The pushers in the order they are used, one entry per contact."""
        out: List[str] = []
        for w in self.waypoints[1:]:
            if w.pusher is None:  # the start only (require_plan)
                continue
            if not out or out[-1] != w.pusher:
                out.append(w.pusher)
        return out

    @property
    def guard_fired(self) -> bool:
        """Whether the search stopped at its time limit, not at its count of stable-push tests
        (planner.check_limit): where that count bounds it, the time limit is a guard, and a plan it
        stopped may differ on a less loaded machine."""
        return self.outcome == "time_limit" and not self.stats.get("check_limit_reached", False)

    @property
    def poses(self) -> np.ndarray:
        """(n, 3): x mm, z mm, theta deg of every waypoint, the start first."""
        return np.array([(w.x, w.z, w.theta) for w in self.waypoints], float)

    def __repr__(self) -> str:
        return (f"Plan({self.task!r}, {'solved' if self.solved else self.outcome}, {len(self.waypoints) - 1} pushes, "
                f"pushers {' -> '.join(self.pusher_sequence) or '(none)'})")


def require_plan(value: Any, field: str = "plan") -> "Plan":
    """`value` when it is a Plan; TypeError naming `field` otherwise (a path, say, where the API
    wants the loaded plan)."""
    if not isinstance(value, Plan):
        hint = " (load it first: sp.load_plan(path))" if isinstance(value, (str, os.PathLike)) else ""
        raise TypeError(f"{field}: expected a Plan, got {type(value).__name__}{hint}")
    return value
