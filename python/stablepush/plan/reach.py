"""Where the pushers can take the object (`stablepush reach`): the task's start planned to every
goal of a grid of poses in the grasp, the task otherwise unchanged, each cell on its own, where
`stablepush.runners` says (here, local processes or Ray). A cell's plan depends on the task, the
goal, the seed and the count of stable-push tests each cell may make, so the same seed gives the
same map on every runner under any load, but for a cell whose time limit, a guard, fired first
(`guard_fired`).

Each cell ends with a verdict:
- `reached`: a plan reaches the goal within the task's tolerance and switch-over budget;
- `unreachable`: no plan can, for a reason decided exactly before any search (`reason`): a pad is
  off the object at every pose within the goal's tolerance (no grasp there, so no push can end
  there; the goal pose itself may be off while poses within its tolerance are not), the pads are
  not on the object at the start (the planner's `invalid_start`), or the planner's own verdict
  before its search (`stablepush.plan.unreachable`: every pusher excluded by the uncertainty box,
  no stable push out of the start, none that ends within the goal's tolerance, the goal not held
  well enough anywhere in its tolerance, a pad that would have to leave the object), or, for a
  mesh part, the pads at the goal not on the two faces the model takes (stablepush.task.mesh);
- `not found`: the search ran out of its stable-push tests (`check_limit`) or its time (`outcome`
  says how: `time_limit`, with `guard_fired` when the time stopped it first, or
  `goal_over_switch_limit` when the goal was reached with more switch-overs than allowed), or the
  goal is within the tolerance of the start where the pads do not hold the object as
  `planner.min_hold_ratio` asks, and nothing decides it (`outcome` `at_start`; see at_start_verdict),
  or the plan found takes a mesh part's pads off its faces on the way (`reason` says where).

Poses are (x mm, z mm, theta deg), as in task files.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Dict, List, Tuple

import numpy as np

from stablepush.errors import PadFaceError, TaskError
from stablepush.plan.search import plan_task
from stablepush.plan.unreachable import pads_off_near, why_unreachable
from stablepush.task.fields import number_field, planner_integer, planner_limit
from stablepush.task.mesh import first_pad_off_faces
from stablepush.task.model import Task, require_task
from stablepush.task.parts import ANGLE, COORDINATE
from stablepush.units import as_triple, is_finite_real, pose_to_si

Axis = Tuple[float, float, int]  # from, to, count (count 1: `from` alone)
MAX_AXIS, MAX_CELLS = 1000, 100_000  # values an axis, cells a map


def axis_values(axis: Axis) -> List[float]:
    """The axis' `count` values from `start` to `stop`, evenly spaced, both ends exact. Where
    stop - start overflows, each is a convex combination of the ends instead, which stays finite."""
    start, stop, count = axis
    if count <= 1:
        return [float(start)]
    if np.isfinite(float(stop) - float(start)):
        values = np.linspace(start, stop, int(count))
    else:
        t = np.arange(int(count)) / (int(count) - 1)
        values = (1.0 - t) * start + t * stop
    return [float(v) for v in values]


# Stable-push tests a cell's search may make (planner.check_limit): about a second of a line-pusher
# task's search on 2 cores of 2026, ten for point pushers.
REACH_CHECKS = 1_000_000


@dataclass(frozen=True)
class ReachGrid:
    """The goals a reach map plans to: x by z by theta (mm, mm, deg), each axis (from, to, count).
    Made with an axis out of its range it raises TaskError naming it (the task file's pose bounds,
    at most MAX_AXIS values an axis and MAX_CELLS cells); each axis is kept as grid_axis gives it."""

    x: Axis
    z: Axis
    theta: Axis

    def __post_init__(self) -> None:
        for name, bound in (("x", COORDINATE), ("z", COORDINATE), ("theta", ANGLE)):
            object.__setattr__(self, name, grid_axis(name, getattr(self, name), bound))
        if self.cells > MAX_CELLS:
            raise TaskError("x, z, theta", f"{self.cells} cells; at most {MAX_CELLS}")

    @property
    def axes(self) -> Tuple[Axis, Axis, Axis]:
        return self.x, self.z, self.theta

    @property
    def cells(self) -> int:
        return self.x[2] * self.z[2] * self.theta[2]

    def goals(self) -> Tuple[Tuple[float, float, float], ...]:
        """Every goal of the grid, x fastest, then z, then theta."""
        return tuple((gx, gz, gth) for gth in axis_values(self.theta) for gz in axis_values(self.z)
                     for gx in axis_values(self.x))


@dataclass(frozen=True)
class ReachJob:
    """A reach map's shared part: the task, the goals of the grid (x fastest, then z, then
    theta), the seed and each cell's time limit [s]; `grid` makes it from a ReachGrid."""

    task: Task
    goals: Tuple[Tuple[float, float, float], ...]
    seed: int
    time_limit: float
    axes: Tuple[Axis, ...] = ()  # the grid's (from, to, count) in x, z, theta, when made by `grid`
    # stable-push tests each cell's search may make: a count, so a cell's verdict is the same on any
    # machine; the time limit is then a guard, and a cell it stops says so (`guard_fired`)
    check_limit: int = REACH_CHECKS

    @classmethod
    def grid(cls, task: Task, grid: "ReachGrid", seed: int, time_limit: float,
             check_limit: int = REACH_CHECKS) -> "ReachJob":
        """The job of the grid; TaskError naming `seed`, `time_limit` or `check_limit` when one is
        out of its range (TypeError for a grid that is not a ReachGrid)."""
        if not isinstance(grid, ReachGrid):
            raise TypeError(f"grid must be a ReachGrid(x, z, theta), got {type(grid).__name__}")
        return cls(task=task, goals=grid.goals(), seed=planner_integer("seed", "seed", seed),
                   time_limit=planner_limit("time_limit", time_limit), axes=grid.axes,
                   check_limit=planner_integer("check_limit", "check_limit", check_limit))


def grid_axis(name: str, axis, bound: Tuple[float, float]) -> Axis:
    """(from, to, count) checked: two numbers within `bound` and an integer count from 1 to
    MAX_AXIS; TaskError naming `name` otherwise."""
    if not isinstance(axis, (tuple, list, np.ndarray)) or np.ndim(axis) != 1 or len(axis) != 3:
        raise TaskError(name, f"must be (from, to, count), got {axis!r:.60}")
    start, stop = number_field(f"{name}[0]", axis[0], bound), number_field(f"{name}[1]", axis[1], bound)
    count = axis[2]
    if not (is_finite_real(count) and float(count).is_integer() and 1 <= count <= MAX_AXIS):
        raise TaskError(f"{name}[2]", f"the count must be a whole number from 1 to {MAX_AXIS}, got {count!r:.40}")
    # Either would plan other goals than written: a count of 1 takes `from` alone, equal ends one goal.
    if count == 1 and start != stop:
        raise TaskError(f"{name}[2]", f"a count of 1 takes from ({start:g}) alone, not to ({stop:g}): give "
                                      f"{start:g}:{start:g}:1, or a count of 2 or more")
    if count > 1 and start == stop:
        raise TaskError(f"{name}[2]", f"from and to are both {start:g}, so the {int(count)} values would be one goal "
                                      f"planned {int(count)} times: give a count of 1")
    return start, stop, int(count)


def at_start_verdict(task: Task) -> dict:
    """The verdict of a goal within the tolerance of the start, which the planner does not search
    (plan_task refuses it): reached with no push where the pads alone hold the object at the start
    as `planner.min_hold_ratio` asks (no pusher pushed, so gravity as with G's axes the world's);
    else unreachable where one of the planner's verdicts before its search decides it
    (why_unreachable), and otherwise not found (a plan that pushes away and back is not searched)."""
    need = task.planner.min_hold_ratio
    # The models only where a hold is asked for: without one every such goal is reached.
    models = task.corner_models if need > 0.0 else ()
    held = min((m.hold_ratio(pose_to_si(task.start), -1) for m in models), default=float("inf"))
    if held >= need:
        return {"solved": True, "switches": 0, "pushes": 0, "outcome": "at_start", "verdict": "reached"}
    reason = why_unreachable(task)
    if reason is not None:
        return {"outcome": "unreachable", "verdict": "unreachable", "reason": reason}
    return {"outcome": "at_start", "verdict": "not found",
            "reason": f"the goal is within planner.tolerance of the start, where the pads alone hold {held:.3g} times "
                      f"the weight and planner.min_hold_ratio asks for {need:g}; a plan that pushes away and back "
                      f"is not searched"}


def reach_cell(job: ReachJob, i: int) -> dict:
    """Plan cell i of the map and give its verdict (module docstring); `node` says where it was
    planned (stablepush.runners.this_node)."""
    from stablepush.runners import this_node

    goal = job.goals[i]
    cell = {"goal": list(goal), "seed": job.seed, "solved": False, "planning_time_s": 0.0, "switches": None,
            "pushes": None, "outcome": None, "verdict": None, "reason": None, "node": this_node(),
            "guard_fired": False}
    task = dataclasses.replace(job.task, goal=as_triple(goal))
    off = pads_off_near(task, goal)
    if off:
        return {**cell, "verdict": "unreachable",
                "reason": f"gripper.pads{off} would be off the object at every pose within planner.tolerance of the "
                          f"goal: no grasp there"}
    if task.at_goal(task.start):
        return {**cell, **at_start_verdict(task)}
    try:
        plan = plan_task(task, seed=job.seed, time_limit=job.time_limit, check_limit=job.check_limit or None)
    except PadFaceError as exc:  # a path that takes a mesh part's pads off its faces: the goal's grasp if there
        assert task.object.mesh is not None, "PadFaceError is a mesh part's"
        off_at_goal = first_pad_off_faces(task.object.mesh, task.gripper.pads, [goal]) is not None
        return {**cell, "verdict": "unreachable" if off_at_goal else "not found", "reason": exc.reason}
    s = plan.stats
    cell.update(solved=plan.solved, planning_time_s=s["planning_time_s"], switches=s["switches"],
                pushes=s["pushes"], outcome=plan.outcome,
                guard_fired=plan.guard_fired)
    if plan.solved:
        cell["verdict"] = "reached"
    elif plan.outcome in ("invalid_start", "unreachable"):  # the verdict says it: the reason alone
        cell.update(verdict="unreachable", reason=plan.message.removeprefix("unreachable: "))
    else:
        cell.update(verdict="not found", reason=plan.message)
    return cell


@dataclass(frozen=True)
class ReachMap:
    """A reach map: the task's name and start, the grid's axes, the seed and each cell's time limit
    [s], its cells in the order of ReachJob.goals (each a dict: goal, verdict, reason, solved, seed,
    planning_time_s, switches, pushes, outcome, node), the wall time [s] and the runner that planned it."""

    task: str
    start: Tuple[float, float, float]
    axes: dict  # "x", "z", "theta" -> [from, to, count]
    seed: int
    time_limit: float
    cells: List[dict]
    wall_s: float
    runner: str
    check_limit: int = REACH_CHECKS

    def counts(self) -> dict:
        """How many cells have each verdict: reached, unreachable, not found."""
        out = {"reached": 0, "unreachable": 0, "not found": 0}
        for c in self.cells:
            out[c["verdict"]] += 1
        return out

    def as_dict(self) -> dict:
        """The map as `stablepush reach --json` writes it (plain data; the cells under `cells`)."""
        return {"task": self.task, "start": list(self.start), "axes": self.axes, "seed": self.seed,
                "time_limit_s": self.time_limit, "check_limit": self.check_limit, "counts": self.counts(),
                "guard_fired": self.guard_fired(), "wall_s": self.wall_s, "runner": self.runner, "cells": self.cells}

    def guard_fired(self) -> int:
        """Cells whose search the time limit stopped before its count of tests: their verdict may
        differ on a less loaded machine."""
        return sum(1 for c in self.cells if c.get("guard_fired"))


def reach_map(task: Task, grid: ReachGrid, seed: int = 1, time_limit: float = 10.0, runner=None, progress=None,
              check_limit: int = REACH_CHECKS) -> ReachMap:
    """The reach map of `task` over `grid`, each cell's search bounded by `check_limit`
    stable-push tests (0: by `time_limit` [s] alone, which then decides what a machine's load may
    change); `runner` a `stablepush.runners.Runner` (None: here); `progress(cell)` after each cell."""
    import time

    from stablepush.runners import Runner, WorkerLost, run_all

    require_task(task)
    job = ReachJob.grid(task, grid, seed, time_limit, check_limit)
    runner = runner or Runner()
    started = time.perf_counter()
    cells: Dict[int, dict] = {}  # by index: run_all yields each once, as it finishes
    for i, cell in run_all(reach_cell, job, range(len(job.goals)), runner):
        if isinstance(cell, WorkerLost):
            cell = {"goal": list(job.goals[i]), "seed": job.seed, "solved": False, "planning_time_s": 0.0,
                    "switches": None, "pushes": None, "outcome": "worker_lost", "verdict": "not found",
                    "reason": cell.why, "node": None}
        cells[i] = cell
        if progress is not None:
            progress(cell)
    return ReachMap(task=task.name, start=as_triple(task.start),
                    axes=dict(zip(("x", "z", "theta"), map(list, job.axes))), seed=job.seed,
                    time_limit=job.time_limit, cells=[cells[i] for i in range(len(job.goals))],
                    wall_s=time.perf_counter() - started,
                    runner=runner.describe(len(cells)), check_limit=job.check_limit)
