"""Planning a task with the core's T-RRT* (docs/model.md section 3), in file units.

`plan_task` turns a validated Task into a `PlanResult`: waypoints in mm and degrees, the pusher
of each push, the test's verdict on it, and the pusher's contact seen from the gripper, which is
what a robot executes (the pusher is fixed in the world and in O during a push, so in G it moves
with the object).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Dict, List, Optional, Tuple

import numpy as np

from stablepush import _core
from stablepush.frames import direction_in_gripper, point_in_gripper
from stablepush.mechanics import CASE_NAMES
from stablepush.task import MM, PLANNER_TUNING, Task, planner_limit, planner_parameter, pose_from_si, pose_to_si

if TYPE_CHECKING:
    from stablepush.execution import PlanStep

OUTCOME_NAMES = {
    _core.PlanOutcome.goal_reached: "goal_reached",
    _core.PlanOutcome.goal_over_switch_limit: "goal_over_switch_limit",
    _core.PlanOutcome.time_limit: "time_limit",
    _core.PlanOutcome.invalid_start: "invalid_start",
}


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


@dataclass(frozen=True)
class Plan:
    """A plan: waypoints from the start (no pusher) through each unit push (docs/model.md section 5),
    how the search ended, and its statistics. The one plan type: `plan()` makes it, `save` and
    `load` write and read plan files, `check` shows it belongs to a task, and `trajectory` and
    `figure` turn it into what a robot or a reader needs."""

    task: str
    solved: bool  # the goal is reached within tolerance with at most max_switches switch-overs
    outcome: str  # goal_reached | goal_over_switch_limit | time_limit | invalid_start
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

    @property
    def steps(self) -> "List[PlanStep]":
        """The waypoints as the executor takes them (pose, pusher)."""
        from stablepush.execution import PlanStep

        return [PlanStep((w.x, w.z, w.theta), w.pusher) for w in self.waypoints]

    def __repr__(self) -> str:
        return (f"Plan({self.task!r}, {'solved' if self.solved else self.outcome}, {len(self.waypoints) - 1} pushes, "
                f"pushers {' -> '.join(self.pusher_sequence) or '(none)'})")

    def to_dict(self) -> dict:
        """The plan file's JSON document (docs/model.md section 5)."""
        from stablepush.plan_io import plan_to_dict

        return plan_to_dict(self)

    def save(self, path, csv_path=None) -> None:
        """Write the plan file (JSON), and its CSV beside it when `csv_path` is given."""
        from stablepush.plan_io import write_plan

        write_plan(self, path, csv_path)

    @classmethod
    def load(cls, path) -> "Plan":
        """Read a plan file; PlanError naming the field if it is not a well-formed plan."""
        from stablepush.plan_io import plan_from_dict, read_plan

        return plan_from_dict(read_plan(path))

    def check(self, task: Task) -> "Plan":
        """This plan, once it is shown to belong to `task` (every push re-checked as a stable push
        of it; stablepush.executor.plan_steps); PlanError names what differs."""
        from stablepush.executor import plan_steps

        plan_steps(task, self.to_dict())
        return self

    def trajectory(self, task: Task, rate_hz: float = 100.0):
        """The timed gripper trajectory that carries the plan out (stablepush.trajectory)."""
        from stablepush.trajectory import timed_trajectory

        return timed_trajectory(task, self.check(task).steps, rate_hz)

    def figure(self, task: Task):
        """The plan drawn as `stablepush show` draws it (a matplotlib figure)."""
        from stablepush.figures import plan_figure

        title = f"{task.name}: {len(self.waypoints) - 1} pushes, {self.stats.get('switches', '?')} switch-over(s)"
        return plan_figure(task, self.check(task).steps, title)


PlanResult = Plan  # the name planning used before there was one plan type


def contact_in_gripper(task: Task, model: "_core.StablePushModel", pusher: int, pose_mm_deg) -> PusherContact:
    """Where pusher `pusher` touches the object, seen from G, when the object is at the pose."""
    spec = task.pushers[pusher]
    normal = direction_in_gripper(pose_mm_deg[2], model.pushers[pusher].inward_normal)
    return PusherContact(start=point_in_gripper(pose_mm_deg, spec.a), end=point_in_gripper(pose_mm_deg, spec.b),
                         normal=tuple(float(v) for v in normal))


def plan_task(
    task: Task,
    *,
    seed: Optional[int] = None,
    time_limit: Optional[float] = None,
    max_switches: Optional[int] = None,
    improve_for: Optional[float] = None,
    models: "Optional[List[_core.StablePushModel]]" = None,
) -> Plan:
    """Plan stable pushes from the task's start to its goal. Arguments left as None take the
    task's planner section (which has defaults for every key). `models` are the task's
    corner_models() (built here unless given, e.g. once for many seeds): with an `uncertainty`
    section every push must be stable at every corner, and each waypoint's margin is the least."""
    settings = dict(task.planner)
    if seed is not None:
        settings["seed"] = planner_parameter("seed", "seed", seed)
    if max_switches is not None:
        settings["max_switches"] = planner_parameter("max_switches", "max_switches", max_switches)
    if time_limit is not None:
        settings["time_limit"] = planner_limit("time_limit", time_limit)
    if improve_for is not None:
        settings["improve_for"] = planner_parameter("improve_for", "improve_for", improve_for)
    models = models or task.corner_models()
    model = models[0]
    step = (settings["step"][0] * MM, math.radians(settings["step"][1]))
    tolerance = (settings["tolerance"][0] * MM, math.radians(settings["tolerance"][1]))
    parameters = {"seed": str(settings["seed"]), "max_switches": str(settings["max_switches"])}
    parameters.update({key: repr(settings[key]) for key in PLANNER_TUNING if key in settings})
    raw = _core.plan(
        models, pose_to_si(task.start), pose_to_si(task.goal), step, tolerance, float(settings["time_limit"]),
        float(settings["min_margin"]), float(settings["sampling_margin"]), parameters,
        float(settings["min_hold_ratio"]),
    )

    names = task.pusher_names
    waypoints: List[Waypoint] = []
    for k, (q, p, margin, case) in enumerate(zip(raw.poses, raw.pushers, raw.margins, raw.contact_cases)):
        pose = tuple(float(v) for v in pose_from_si(q))
        if p < 0:
            waypoints.append(Waypoint(*pose))
        else:
            waypoints.append(Waypoint(*pose, pusher=names[p], margin=float(margin), case=CASE_NAMES[case],
                                      contact=contact_in_gripper(task, model, p, pose),
                                      margin_per_normal=_margin_per_normal(models, raw.poses[k - 1], q, p)))

    outcome = OUTCOME_NAMES[raw.outcome]
    s = raw.stats
    stats = {
        "planning_time_s": s.planning_time_s,
        "iterations": int(s.iterations),
        "nodes": int(s.nodes),
        "feasibility_checks": int(s.feasibility_checks),
        "switches": int(s.switches),
        "restarts": int(s.restarts),
        "seed": int(settings["seed"]),
        "max_switches": int(settings["max_switches"]),
        "time_limit_s": float(settings["time_limit"]),
        "pushes": len(waypoints) - 1,
        "path_length_steps": s.length,
        "goal_distance_steps": raw.goal_distance,
        "min_hold_ratio": float(settings["min_hold_ratio"]),
    }
    if "improve_for" in settings:
        # the first plan of an anytime search (planner.improve_for), before the improvement; None: no plan
        # (path_min_margin: the same measure for the returned path, the last push to the goal left out)
        solved_once = math.isfinite(s.first_time_s)
        stats["first"] = {"planning_time_s": s.first_time_s, "switches": int(s.first_switches),
                          "path_length_steps": s.first_length, "min_margin": s.first_min_margin} if solved_once else None
        stats["path_min_margin"] = s.path_min_margin if solved_once else None
    last = waypoints[-1]
    last_q, last_pusher = pose_to_si((last.x, last.z, last.theta)), names.index(last.pusher) if last.pusher else -1
    return Plan(task=task.name, solved=outcome == "goal_reached", outcome=outcome,
                      message=_message(outcome, stats, bool(raw.ends_at_goal)), waypoints=waypoints, stats=stats,
                      final_hold_ratio=min(m.hold_ratio(last_q, last_pusher) for m in models),
                      uncertainty=dict(task.uncertainty), ends_at_goal=bool(raw.ends_at_goal))


def _margin_per_normal(models, q0, q1, pusher: int) -> Optional[float]:
    """The push's margin over the pusher's normal force (both at the least stable corner): how
    deep inside the cone the push is, relative to how hard the pusher presses."""
    r = _core.worst_case(models, tuple(q0), tuple(b - a for a, b in zip(q0, q1)), pusher)
    n = models[0].pushers[pusher].inward_normal
    normal_force = r.witness[0] * n[0] + r.witness[1] * n[1]
    return float(r.margin / normal_force) if normal_force > 0 else None


def _message(outcome: str, stats: dict, ends_at_goal: bool) -> str:
    if outcome == "goal_reached":
        end = ("ending at the goal" if ends_at_goal else
               f"ending within tolerance, {stats['goal_distance_steps']:.2f} unit steps from the goal (a last push "
               f"to the goal itself is not stable)")
        return (f"solved in {stats['planning_time_s'] * 1e3:.1f} ms: {stats['pushes']} pushes, "
                f"{stats['switches']} switch-over(s), {end}")
    if outcome == "goal_over_switch_limit":
        return (f"not solved: the time limit ({stats['time_limit_s']:g} s) ran out with the goal reached only with "
                f"{stats['switches']} switch-overs (max_switches {stats['max_switches']}); the plan written is that "
                f"one; allow it with --max-switches {stats['switches']}")
    if outcome == "invalid_start":
        return "not solved: the pads do not hold the object at the start pose"
    held = (f" where the pads alone hold {stats['min_hold_ratio']:g} times the weight (planner.min_hold_ratio)"
            if stats["min_hold_ratio"] > 0 else "")
    return (f"not solved: the time limit ({stats['time_limit_s']:g} s) ran out before the goal was reached{held}; "
            f"the best partial path ends {stats['goal_distance_steps']:.1f} unit steps from the goal")
