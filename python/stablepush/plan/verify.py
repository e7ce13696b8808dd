"""Does a plan belong to a task? Every push re-checked as a stable push of the task before a plan
is drawn, turned into a trajectory or run, so that a plan made for another version of a task
file, or edited by hand, is refused (PlanError naming the waypoint)."""
from __future__ import annotations

import math
from typing import List, Optional, Sequence

from stablepush.compiled import _core
from stablepush.errors import PlanError
from stablepush.plan.plan import FieldFault, Plan, Waypoint, require_plan
from stablepush.task.fields import PLANNER_PARAMETER_RANGES
from stablepush.task.model import Task, require_task
from stablepush.task.release import needed_hold_ratio
from stablepush.units import MM, pose_to_si

STEP_SLACK = 1e-6  # unit steps: rounding in a plan file's decimal poses
START_SLACK = 1e-6  # mm or deg: the plan's start against the task's


MAX_SWITCHES = int(PLANNER_PARAMETER_RANGES["max_switches"][2])
MARGIN_SLACK = 1e-9  # N (and weights): the re-check's rounding against the planner's own test


def check_plan(task: Task, plan: Plan, source: Optional[str] = None, require_solved: bool = True) -> Plan:
    """`plan`, once it is shown to belong to `task`: solved and ending within the task's tolerance of
    its goal, for the same task name and start, made for the task as it is now (the plan's
    recorded Task.identity, where the file has one: changes_since_planned), with pushers the task
    has, no step longer than the task's unit step, and every push a stable push of this task (at
    every corner of its uncertainty box, when it has one) with the pads inside the object, each
    push's margin at least the task's min_margin and, solved, the pads holding min_hold_ratio
    times the weight at its end. PlanError names what differs (`source`: the plan file, for the
    message). `require_solved=False` lets an unsolved (partial) plan through, for drawing it."""
    require_task(task)
    require_plan(plan)
    # Each check may assume the ones before it passed (`or` stops at the first fault); the
    # waypoints' own fields are Waypoint's to keep.
    fault = (_record_fault(task, plan, require_solved) or _waypoints_fault(task, plan.waypoints, require_solved)
             or _switches_fault(plan) or _ends_fault(task, plan, require_solved))
    if fault is None:
        model = task.model
        # With an uncertainty box every push must be stable at each corner, as the planner made it.
        corners = task.corner_models if task.uncertainty else None
        fault = (_pushes_fault(task, plan.waypoints, model, corners)
                 or _hold_fault(task, plan.waypoints, corners or [model], require_solved))
    if fault is not None:
        raise PlanError(*fault, source)
    return plan


def _record_fault(task: Task, plan: Plan, require_solved: bool) -> FieldFault:
    """The plan's own record: for this task by name, as the task is now, solved when that is required."""
    if not isinstance(plan.task, str):
        return "task", f"must be the task's name, got {type(plan.task).__name__}"
    if not isinstance(plan.stats, dict):
        return "stats", f"must be a mapping, got {type(plan.stats).__name__}"
    if plan.task != task.name:
        return "task", f"the plan is for task {plan.task[:100]!r}, not {task.name!r}"
    changes = changes_since_planned(task, plan)
    if changes:  # its pushes may still pass the re-check below, but not for the reasons it was made
        more = f" and {len(changes) - 6} more" if len(changes) > 6 else ""
        return "task_identity", (f"{task.source or 'the task'} changed since the plan was made "
                                 f"({', '.join(changes[:6])}{more}): plan it again")
    if require_solved and not plan.solved:
        return "solved", f"the plan does not reach the goal ({(plan.message or 'not solved')[:200]})"
    return None


def _waypoints_fault(task: Task, waypoints: List[Waypoint], require_solved: bool) -> FieldFault:
    """Waypoints, the start and (solved) at least one push, each push by a pusher of the task."""
    for i, w in enumerate(waypoints):
        if not isinstance(w, Waypoint):
            return f"waypoints[{i}]", f"must be a Waypoint (x, z, theta, pusher, ...), got {type(w).__name__}"
    if len(waypoints) < (2 if require_solved else 1):  # a partial plan may have found no push at all
        return "waypoints", "needs the start and at least one push" if require_solved else "needs the start"
    if waypoints[0].pusher is not None:
        return "waypoints[0].pusher", f"the start has no pusher, got {waypoints[0].pusher[:100]!r}"
    for i, w in enumerate(waypoints[1:], 1):
        if w.pusher is None:
            return f"waypoints[{i}].pusher", "missing: every waypoint after the start is a push by a pusher"
        if w.pusher not in task.pusher_names:
            return f"waypoints[{i}].pusher", f"the task has no pusher {w.pusher[:100]!r}"
    return None


def _switches_fault(plan: Plan) -> FieldFault:
    """Each switch-over is a transit between features (hundreds of trajectory samples): no more than
    the plan's own budget, itself within the planner's range. The search extends only nodes within
    the budget, so a node it reports unsolved (the partial path's end, or a goal reached over the
    budget) may be one switch-over past it."""
    switches = max(len(plan.pusher_sequence) - 1, 0)
    recorded = plan.stats.get("max_switches")
    budget = int(recorded) if isinstance(recorded, int) and 0 <= recorded < MAX_SWITCHES else MAX_SWITCHES
    if switches > budget + (0 if plan.solved else 1):
        return "waypoints", (f"{switches} switch-overs, more than the plan's max_switches ({budget})"
                             + ("" if plan.solved else " and the one past it a partial path may end with")
                             + "; not a plan this tool made")
    return None


def _ends_fault(task: Task, plan: Plan, require_solved: bool) -> FieldFault:
    """The plan starts at the task's start and, solved, ends within its tolerance of the goal."""
    waypoints = plan.waypoints
    if max(abs(a - b) for a, b in zip(waypoints[0].pose, task.start)) > START_SLACK:
        return "waypoints[0]", f"the plan starts at {list(waypoints[0].pose)}, the task at {list(task.start)}"
    end = waypoints[-1].pose
    if (require_solved or plan.solved) and not task.at_goal(end):
        return (f"waypoints[{len(waypoints) - 1}]",
                f"the plan ends at {[round(v, 3) for v in end]}, not within planner.tolerance "
                f"{list(task.planner.tolerance)} of the task's goal {list(task.goal)}: made for another goal, or cut "
                f"short?")
    return None


def _pushes_fault(task: Task, waypoints: List[Waypoint], model, corners: Optional[Sequence]) -> FieldFault:
    """Every push at most one unit step, moving the object, stable (for `model`, the task's, or at
    each of the `corners` of its uncertainty box) with at least the task's min_margin, and ending
    with the pads on the object."""
    unit = (task.planner.step[0] * MM, math.radians(task.planner.step[1]))
    min_margin = task.planner.min_margin
    for i in range(1, len(waypoints)):
        q0, q1 = pose_to_si(waypoints[i - 1].pose), pose_to_si(waypoints[i].pose)
        fault = _step_fault(task, q0, q1, unit)
        if fault is None:
            pusher = waypoints[i].pushed_by  # after the start (_waypoints_fault)
            fault = _stability_fault(pusher, task.pusher_index(pusher), q0, q1, model, corners, min_margin)
        if fault is None and not model.grasp_maintained(q1):
            fault = "the pads leave the object at this pose"
        if fault is not None:
            return f"waypoints[{i}]", fault
    return None


def _step_fault(task: Task, q0, q1, unit) -> Optional[str]:
    """Why the step q0 -> q1 (SI) is not a push's: longer than a unit step, or no move at all."""
    length = _core.steps_between(q0, q1, unit)
    if length > 1.0 + STEP_SLACK:
        size = f"{length:.3g} unit steps" if math.isfinite(length) else "more unit steps than a double holds"
        return f"a step of {size} (planner.step {list(task.planner.step)}); a plan's pushes are at most one unit step"
    if max(abs(b - a) for a, b in zip(q0, q1)) < 1e-12:
        return "repeats the pose before it (a push that does not move the object)"
    return None


def _stability_fault(pusher: str, index: int, q0, q1, model, corners: Optional[Sequence],
                     min_margin: float) -> Optional[str]:
    """Why the push q0 -> q1 (SI) by `pusher` is not a stable push with min_margin (N) to spare."""
    dq = tuple(b - a for a, b in zip(q0, q1))
    verdict = _core.worst_case(corners, q0, dq, index) if corners else model.check(q0, dq, index)
    if not verdict.feasible:
        return (f"the push by {pusher!r} is not a stable push for this task (margin {verdict.margin:+.4f} N); "
                f"was the plan made for another version of it?")
    if verdict.margin < min_margin - MARGIN_SLACK:
        return (f"the push by {pusher!r} has a margin of {verdict.margin:.4f} N, under the task's "
                f"planner.min_margin {min_margin:g} N")
    return None


def plan_margin(task: Task, plan: Plan) -> float:
    """The least margin [N] of any push of the plan in the stable-push test (docs/model.md section
    3): over every corner of the task's uncertainty box when it has one. How much friction, force
    or weight may change before some push of the plan stops sticking; inf for a plan of no push."""
    model = task.model
    corners = task.corner_models if task.uncertainty else None
    least = math.inf
    for w0, w1 in zip(plan.waypoints, plan.waypoints[1:]):
        q0, q1 = pose_to_si(w0.pose), pose_to_si(w1.pose)
        dq = tuple(b - a for a, b in zip(q0, q1))
        index = task.pusher_index(w1.pushed_by)
        verdict = _core.worst_case(corners, q0, dq, index) if corners else model.check(q0, dq, index)
        least = min(least, verdict.margin)
    return least


def _hold_fault(task: Task, waypoints: List[Waypoint], models: Sequence, require_solved: bool) -> FieldFault:
    """A solved plan's end, where the pads alone hold min_hold_ratio times the weight (in each of `models`)."""
    min_hold = task.planner.min_hold_ratio
    if not (require_solved and min_hold > 0 and len(waypoints) > 1):
        return None
    q, last = pose_to_si(waypoints[-1].pose), task.pusher_index(waypoints[-1].pushed_by)  # a push: len > 1
    held = min(m.hold_ratio(q, last) for m in models)
    if held < min_hold - MARGIN_SLACK:
        return (f"waypoints[{len(waypoints) - 1}]",
                f"the pads hold {held:.3f} times the object's weight at the plan's end, under the task's "
                f"planner.min_hold_ratio {min_hold:g}")
    return None


def release_note(task: Task, plan: Plan) -> Optional[str]:
    """What a run of `plan` meets when its last feature lets go, when the pads alone do not hold
    the object at the plan's end (its `final_hold_ratio` under 1): it moves in the grasp and the
    run misses (the verdict's `moved_on_release`); None when they hold it, or when the task's run
    ends on the feature (environment.end_on_feature). The min_hold_ratio it gives is the one that
    holds the release's load too (task.release.needed_hold_ratio)."""
    hold = plan.final_hold_ratio
    if hold >= 1.0 or task.environment.end_on_feature or len(plan.waypoints) < 2:
        return None
    need = needed_hold_ratio(task, task.pusher_names)
    return (f"at the plan's last pose the pads alone hold only {hold:.2f} times the object's weight: when the last "
            f"feature lets go the object moves in the grasp and the run misses (moved_on_release); "
            f"planner.min_hold_ratio: {need:g} asks for a pose they hold (the weight and the arm's acceleration as "
            f"it lets go), environment.end_on_feature: true ends the run on the feature")


def changes_since_planned(task: Task, plan: Plan) -> List[str]:
    """What of `task` differs from the task `plan` was planned for (its recorded Task.identity),
    as dotted field names (`goal`, `gripper.mu`, `pushers.left.mu`, `object.vertices`); empty when
    nothing did, or when the plan file predates the record."""
    if plan.task_identity is None:
        return []
    return _differences(plan.task_identity, task.identity(), "")


def _differences(then, now, path: str) -> List[str]:
    if isinstance(then, dict) and isinstance(now, dict):
        out: List[str] = []
        for key in sorted(set(then) | set(now)):
            where = f"{path}.{key}" if path else key
            if key not in then or key not in now:
                out.append(where)
            else:
                out.extend(_differences(then[key], now[key], where))
        return out
    return [] if then == now else [path]
