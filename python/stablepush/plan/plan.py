"""The plan as plain data (docs/model.md section 5): its waypoints, in file units (mm, deg, N).

A waypoint is the object's pose in the grasp after a unit push, the pusher that made the push,
the test's verdict on it and the pusher's contact seen from the gripper, which is what a robot
executes (the pusher is fixed in the world and in O during a push, so in G it moves with the
object). The first waypoint is the start and has no pusher.
"""
from __future__ import annotations

import enum
import math
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

import numpy as np


@dataclass(frozen=True)
class PusherContact:
    """A pusher's contact in the gripper frame G: the segment from-to (mm; equal for a point
    pusher) and the unit normal pointing into the object."""

    start: Tuple[float, float]
    end: Tuple[float, float]
    normal: Tuple[float, float]


@dataclass(frozen=True)
class Waypoint:
    """The pose after a unit push (x mm, z mm, theta deg), the pusher that made the push and the
    test's verdict on it; the first waypoint is the start and has no pusher."""

    x: float
    z: float
    theta: float
    pusher: Optional[str] = None
    margin: Optional[float] = None  # N, depth inside the pusher's cone
    case: Optional[str] = None  # all_sliding | sticking
    contact: Optional[PusherContact] = None  # the pusher's contact in G at this pose
    margin_per_normal: Optional[float] = None  # margin / the pusher's normal force (least stable corner)

    @property
    def pose(self) -> Tuple[float, float, float]:
        """(x mm, z mm, theta deg)."""
        return (self.x, self.z, self.theta)


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
    stats: Dict[str, float] = field(default_factory=dict)
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
            if not out or out[-1] != w.pusher:
                out.append(w.pusher)
        return out

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
