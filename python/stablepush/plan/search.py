"""Planning a task with the core's T-RRT* (docs/model.md section 3), in file units.

`plan_task` turns a validated Task into a `Plan` (stablepush.plan.plan): waypoints in mm and
degrees, the pusher of each push, the test's verdict on it, and the pusher's contact seen from
the gripper.
"""
from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass
from typing import List, Optional, Sequence

from stablepush.compiled import _core
from stablepush.errors import PadFaceError, TaskError
from stablepush.frames import direction_in_gripper, point_in_gripper
from stablepush.plan.files import MAX_WAYPOINTS
from stablepush.plan.plan import Plan, PusherContact, Waypoint
from stablepush.plan.unreachable import why_unreachable
from stablepush.pose import Tolerance
from stablepush.task.fields import LIMITS, number_field, planner_limit, planner_parameter
from stablepush.task.mechanics import blocked_senses
from stablepush.task.mesh import first_pad_off_faces, slab_text
from stablepush.task.model import PlannerSettings, Task, require_task
from stablepush.units import MM, pose_from_si, pose_to_si


def contact_in_gripper(task: Task, model: "_core.StablePushModel", pusher: int, pose_mm_deg) -> PusherContact:
    """Where pusher `pusher` touches the object, seen from G, when the object is at the pose."""
    spec = task.pushers[pusher]
    normal = direction_in_gripper(pose_mm_deg[2], model.pushers[pusher].inward_normal)
    return PusherContact(start=point_in_gripper(pose_mm_deg, spec.a), end=point_in_gripper(pose_mm_deg, spec.b),
                         normal=(float(normal[0]), float(normal[1])))


def require_goal_apart(task: Task) -> None:
    """TaskError (field `goal`) when the task's start is already within its tolerance of the goal:
    there is nothing to plan (`plan`, and `design` before its search, say so in these words)."""
    require_task(task)
    if task.at_goal(task.start):
        tolerance = list(task.planner.tolerance)
        raise TaskError("goal", f"the start {list(task.start)} is already within planner.tolerance {tolerance} of the "
                                f"goal {list(task.goal)}: there is nothing to plan (a task written in metres? task "
                                f"files use mm)", task.source)


@dataclass(frozen=True)
class SearchRules:
    """What a search is asked beyond the task's planner section. `min_transit_hold` > 0: switch
    pushers only where the pads alone hold the object with that factor of its weight in every
    model; `start_pusher`, the pusher in contact at the start (a re-plan from a feature), makes a
    plan that begins with another pusher a transit at the start. After a search that ran out of
    time, `explain` names in the message the senses toward the goal in which no stable push from
    the start moves the object (_toward_goal: some 0.05 s). A solved plan whose end uses more than
    planner.end_within of the tolerance in some coordinate (Tolerance.used) is planned again
    (`deepen`; _deeper). The closed loop's re-plans, which read the outcome alone and plan to the
    loop's own tolerance, neither explain nor deepen. plan_task checks the fields."""

    min_transit_hold: float = 0.0
    start_pusher: Optional[str] = None
    explain: bool = True
    deepen: bool = True


def plan_task(
    task: Task,
    *,
    seed: Optional[int] = None,
    time_limit: Optional[float] = None,
    max_switches: Optional[int] = None,
    improve_for: Optional[float] = None,
    check_limit: Optional[int] = None,
    rules: Optional[SearchRules] = None,
) -> Plan:
    """Plan stable pushes from the task's start to its goal. Arguments left as None take the
    task's planner section (which has defaults for every key); `rules` (SearchRules) what the
    search is asked beyond it (None: SearchRules()). The search runs in the task's corner_models
    (built on first use and kept with the task, so that many seeds build them once): with an
    `uncertainty` section every push must be stable at every corner, and each waypoint's margin
    is the least.
    A goal that no plan can reach for a reason decided before the search (plan.unreachable) returns
    at once: outcome `unreachable`, the start alone, the reason in the message.
    A solved plan whose end uses more than planner.end_within of the tolerance in some coordinate
    (Tolerance.used) is planned again, with finish steps and then to that share of the
    tolerance (rules.deepen; _deeper), within DEEPER_CHECKS stable-push tests: a plan that ends at
    the tolerance's edge leaves an open-loop run no room for a real push's drift. Where neither
    finds one, the first plan stands and its stats say how deep it got (`end_used`, `deeper`).
    TaskError (field `goal`) when the start is already within the tolerance of the goal; TypeError
    for rules that are not a SearchRules."""
    rules = SearchRules() if rules is None else rules
    if not isinstance(rules, SearchRules):
        raise TypeError(f"rules must be a SearchRules, got {type(rules).__name__}")
    require_goal_apart(task)
    settings = task.planner.replace(
        seed=None if seed is None else planner_parameter("seed", "seed", seed),
        max_switches=None if max_switches is None else planner_parameter("max_switches", "max_switches", max_switches),
        time_limit=None if time_limit is None else planner_limit("time_limit", time_limit),
        improve_for=None if improve_for is None else planner_parameter("improve_for", "improve_for", improve_for),
        check_limit=None if check_limit is None else planner_parameter("check_limit", "check_limit", check_limit))
    # A hold factor, as planner.min_hold_ratio is (docs/model.md section 3).
    min_transit_hold = number_field("min_transit_hold", rules.min_transit_hold, LIMITS["min_hold_ratio"])
    _check_push_cap(task, settings)
    models = task.corner_models
    model = models[0]
    began = time.perf_counter()
    # The verdicts are bounded by the search's own limit: past it they stop, undecided.
    reason = why_unreachable(task, deadline=began + settings.time_limit)
    if reason is not None:
        return _unreachable(task, models, settings, reason, time.perf_counter() - began)
    pusher_at_start = -1 if rules.start_pusher is None else task.pusher_index(rules.start_pusher, "start_pusher")
    raw = _search(task, models, settings, Tolerance.of(settings.tolerance), min_transit_hold, pusher_at_start)
    first_checks, deep = int(raw.stats.feasibility_checks), None
    if rules.deepen and raw.outcome.name == "goal_reached" and settings.end_within < 1.0:
        deep = _deeper(task, models, settings, raw, min_transit_hold, pusher_at_start)
        if deep is not None:
            raw = deep.pop("raw") or raw
    names = task.pusher_names
    raw_waypoints = raw.waypoints  # a copy of the core's vector on each access: taken once
    if len(raw_waypoints) > MAX_WAYPOINTS:  # refused before the waypoints are made: 0.04 ms each
        raise TaskError("planner.step", f"the plan found takes {len(raw_waypoints) - 1:,} pushes of "
                                        f"{_step_text(settings)}, more than a plan holds ({MAX_PUSHES:,}): take a "
                                        f"larger step", task.source)
    waypoints: List[Waypoint] = []
    for k, w in enumerate(raw_waypoints):
        x, z, theta = pose_from_si(w.pose)
        pose = (float(x), float(z), float(theta))
        if w.pusher < 0:
            waypoints.append(Waypoint(*pose))
        else:
            waypoints.append(Waypoint(*pose, pusher=names[w.pusher], margin=float(w.margin), case=w.contact_case.name,
                                      contact=contact_in_gripper(task, model, w.pusher, pose),
                                      margin_per_normal=_margin_per_normal(models, raw_waypoints[k - 1].pose, w.pose,
                                                                           w.pusher)))

    if task.object.mesh is not None:
        _check_pad_faces(task, waypoints)
    outcome = raw.outcome.name
    s = raw.stats
    stats = {
        "planning_time_s": s.planning_time_s,
        "iterations": int(s.iterations),
        "nodes": int(s.nodes),
        "feasibility_checks": int(s.feasibility_checks),
        "switches": int(s.switches),
        "restarts": int(s.restarts),
        "seed": settings.seed,
        "max_switches": settings.max_switches,
        "time_limit_s": settings.time_limit,
        "pushes": len(waypoints) - 1,
        "path_length_steps": s.length,
        "goal_distance_steps": raw.goal_distance,
        "min_hold_ratio": settings.min_hold_ratio,
        # the search stopped at planner.check_limit (a count: the same on any machine), not at its time limit
        "check_limit_reached": bool(s.check_limit_reached),
    }
    if outcome == "goal_reached":
        stats["end_used"] = task.tolerance.used(waypoints[-1].pose, task.goal)
    if deep is not None:
        stats["deeper"] = deep
        stats["feasibility_checks"] = first_checks + deep["feasibility_checks"]
        stats["planning_time_s"] = time.perf_counter() - began
    if "improve_for" in settings.tuning:
        # the first plan of an anytime search (planner.improve_for), before the improvement; None: no plan
        # (path_min_margin: the same measure for the returned path, the last push to the goal left out)
        solved_once = math.isfinite(s.first_time_s)
        stats["first"] = (
            {
                "planning_time_s": s.first_time_s,
                "switches": int(s.first_switches),
                "path_length_steps": s.first_length,
                "min_margin": s.first_min_margin,
            }
            if solved_once
            else None
        )
        stats["path_min_margin"] = s.path_min_margin if solved_once else None
    last = waypoints[-1]
    last_q, last_pusher = pose_to_si((last.x, last.z, last.theta)), names.index(last.pusher) if last.pusher else -1
    message = _message(outcome, stats, bool(raw.ends_at_goal), settings)
    if outcome == "time_limit" and rules.explain:
        message += _toward_goal(task)
    return Plan(task=task.name, solved=outcome == "goal_reached", outcome=outcome,
                message=message, waypoints=waypoints, stats=stats,
                final_hold_ratio=min(m.hold_ratio(last_q, last_pusher) for m in models),
                uncertainty=dict(task.uncertainty), ends_at_goal=bool(raw.ends_at_goal),
                task_identity=task.identity())


MAX_PUSHES = MAX_WAYPOINTS - 1  # the pushes a plan file holds: its waypoints less the start
# The stable-push tests the deeper search (planner.end_within) may make: a count, so that whether
# it finds a plan is the same on any machine. The shipped tasks' deeper searches take 0.3k-80k.
DEEPER_CHECKS = 200_000


def _search(task: Task, models, settings: PlannerSettings, tolerance: Tolerance, min_transit_hold: float,
            start_pusher: int):
    """The core's T-RRT* from the task's start to its goal within `tolerance`."""
    # Ctrl-C stops the search at once (KeyboardInterrupt); signals reach the main thread only.
    return _core.plan(models, _core.PlannerSettings(
        start=pose_to_si(task.start), goal=pose_to_si(task.goal),
        step=(settings.step[0] * MM, math.radians(settings.step[1])),
        tolerance=tolerance.si(),
        time_limit=settings.time_limit, min_margin=settings.min_margin, sampling_margin=settings.sampling_margin,
        min_hold_ratio=settings.min_hold_ratio, parameters=settings.core_parameters(),
        min_transit_hold=float(min_transit_hold), start_pusher=start_pusher),
        interruptible=threading.current_thread() is threading.main_thread())


def _deeper(task: Task, models, settings: PlannerSettings, first, min_transit_hold: float, start_pusher: int):
    """When `first` (a solved core plan) ends beyond planner.end_within of the tolerance: first the
    same search with finish steps (its last pusher goes on deeper, no switch-over added), then, if
    that does not end within the share, the search to that share of the tolerance, within
    DEEPER_CHECKS tests (or the task's own check_limit, if lower), the time limit a guard. A record
    of it (`solved`, `end_within`, `by`: finish_steps or search, its tests; `raw`, the plan found),
    or None when the first plan ends deep enough."""
    share, tolerance = settings.end_within, Tolerance.of(settings.tolerance)
    deep_enough = lambda raw: tolerance.used(pose_from_si(raw.waypoints[-1].pose), task.goal) <= share + 1e-9  # noqa: E731
    if deep_enough(first):
        return None
    bounded = settings.with_check_limit(DEEPER_CHECKS)
    limit = int(bounded.tuning["check_limit"])
    spent = 0
    if not settings.tuning.get("finish_steps"):
        finishing = _search(task, models, bounded.replace(finish_steps=1), tolerance, min_transit_hold, start_pusher)
        spent = int(finishing.stats.feasibility_checks)
        if finishing.outcome.name == "goal_reached" and deep_enough(finishing):
            return {"end_within": share, "solved": True, "by": "finish_steps", "check_limit": limit,
                    "feasibility_checks": spent, "check_limit_reached": False, "raw": finishing}
    raw = _search(task, models, bounded, tolerance.scaled(share), min_transit_hold, start_pusher)
    solved = raw.outcome.name == "goal_reached"
    return {"end_within": share, "solved": solved, "by": "search", "check_limit": limit,
            "feasibility_checks": spent + int(raw.stats.feasibility_checks),
            "check_limit_reached": bool(raw.stats.check_limit_reached), "raw": raw if solved else None}


def _check_pad_faces(task: Task, waypoints: Sequence[Waypoint]) -> None:
    """A mesh part's pads rest on its slab's two faces all along the path (the model's grasp is the
    slab's; a step, a curve or an edge under a pad is a grasp the model does not describe):
    PadFaceError naming the pad, the pose and what lies under it."""
    mesh = task.object.mesh
    assert mesh is not None, "only a mesh part's pads are checked against its faces"
    found = first_pad_off_faces(mesh, task.gripper.pads, [w.pose for w in waypoints])
    if found is not None:
        k, i, (x, z), problem = found
        pose = [round(v, 3) for v in waypoints[k].pose]
        raise PadFaceError(f"gripper.pads[{i}]",
                           f"the plan's path takes the pad off the part's faces just after waypoint {k} (pose {pose}; "
                           f"its disc at x, z = {x:.3g}, {z:.3g} mm of the part {problem}): {slab_text(mesh)}",
                           task.source)


def _step_text(settings: PlannerSettings) -> str:
    return f"{settings.step[0]:g} mm / {settings.step[1]:g} deg"


def _check_push_cap(task: Task, settings: PlannerSettings) -> None:
    """TaskError (planner.step) when the unit step is too small for any plan within MAX_PUSHES to
    come within the tolerance of the goal: a unit push moves the object at most one unit step
    (the core's distance, Euclidean over x/step, z/step and theta/step), so no plan is shorter than
    the distance from the start to the tolerance box about the goal, in unit steps. Refused before
    the search, which would otherwise run its time out and make a plan no file can hold."""
    step, tol = settings.step, settings.tolerance
    gap = [max(0.0, abs(g - s) - t) / u for g, s, t, u in
           zip(task.goal, task.start, (tol[0], tol[0], tol[1]), (step[0], step[0], step[1]))]
    fewest = math.ceil(math.sqrt(sum(v * v for v in gap)) - 1e-9)
    if fewest > MAX_PUSHES:
        scale = fewest / MAX_PUSHES
        raise TaskError("planner.step", f"{_step_text(settings)} is too small for this goal: every plan takes at "
                                        f"least {fewest:,} pushes to come within the tolerance, and a plan holds "
                                        f"at most {MAX_PUSHES:,} (a step of at least {step[0] * scale:.3g} mm / "
                                        f"{step[1] * scale:.3g} deg, or more for a plan that is not straight)",
                        task.source)


def _unreachable(task: Task, models, settings: PlannerSettings, reason: str, seconds: float) -> Plan:
    """The plan of a goal found unreachable before the search: the start alone."""
    unit = (settings.step[0] * MM, math.radians(settings.step[1]))
    stats = {"planning_time_s": seconds, "iterations": 0, "nodes": 0, "feasibility_checks": 0, "switches": 0,
             "restarts": 0, "seed": settings.seed, "max_switches": settings.max_switches,
             "time_limit_s": settings.time_limit, "pushes": 0, "path_length_steps": 0.0,
             "goal_distance_steps": _core.steps_between(pose_to_si(task.start), pose_to_si(task.goal), unit),
             "min_hold_ratio": settings.min_hold_ratio}
    start = pose_to_si(task.start)
    return Plan(task=task.name, solved=False, outcome="unreachable", message=f"unreachable: {reason}",
                waypoints=[Waypoint(*task.start)], stats=stats,
                final_hold_ratio=min(m.hold_ratio(start, -1) for m in models), uncertainty=dict(task.uncertainty),
                ends_at_goal=False, task_identity=task.identity())


def _toward_goal(task: Task) -> str:
    """For a search that ran out of time: the senses of x, z and theta toward the goal, beyond its
    tolerance, in which no stable push from the start moves the object (mechanics.blocked_senses),
    with where the goal lies; "" when there is none. Not a proof that the goal is out of reach (a
    plan may go around, through poses where other pushes are stable): why the search found little."""
    gap = tuple(g - s for g, s in zip(task.goal, task.start))  # theta unwrapped, as the planner turns
    blocked = blocked_senses(task, task.start, gap, task.tolerance)
    if blocked is None:
        return ""
    return (f"; the goal lies at dx {gap[0]:g} mm, dz {gap[1]:g} mm, dtheta {gap[2]:g} deg from the start, and no "
            f"stable push from there moves the object along {blocked}: a plan must go around, if any can (each "
            f"pusher's stable pushes from the start: stable_directions)")


def _margin_per_normal(models, q0, q1, pusher: int) -> Optional[float]:
    """The push's margin over the pusher's normal force (both at the least stable corner): how
    deep inside the cone the push is, relative to how hard the pusher presses."""
    r = _core.worst_case(models, q0, tuple(b - a for a, b in zip(q0, q1)), pusher)
    n = models[0].pushers[pusher].inward_normal
    normal_force = r.witness[0] * n[0] + r.witness[1] * n[1]
    return float(r.margin / normal_force) if normal_force > 0 else None


def _message(outcome: str, stats: dict, ends_at_goal: bool, settings: PlannerSettings) -> str:
    if outcome == "goal_reached":
        return (f"solved in {stats['planning_time_s'] * 1e3:.1f} ms: {stats['pushes']} pushes, "
                f"{stats['switches']} switch-over(s), ending {end_text(stats, ends_at_goal, settings.end_within)}")
    if outcome == "goal_over_switch_limit":
        return (f"not solved: the time limit ({stats['time_limit_s']:g} s) ran out with the goal reached only with "
                f"{stats['switches']} switch-overs (max_switches {stats['max_switches']}); the plan written is that "
                f"one; allow it with planner.max_switches: {stats['switches']}")
    if outcome == "invalid_start":
        return "not solved: the pads do not hold the object at the start pose"
    if stats["check_limit_reached"]:
        return (f"not solved: the check limit ({settings.tuning['check_limit']:,.0f} stable-push tests) ran out before "
                f"the goal was reached; the best partial path ends {stats['goal_distance_steps']:.1f} unit steps "
                f"from the goal")
    held = (f" where the pads alone hold {stats['min_hold_ratio']:g} times the weight (planner.min_hold_ratio)"
            if stats["min_hold_ratio"] > 0 else "")
    return (f"not solved: the time limit ({stats['time_limit_s']:g} s) ran out before the goal was reached{held}; "
            f"the best partial path ends {stats['goal_distance_steps']:.1f} unit steps from the goal")


def end_text(stats: dict, ends_at_goal: bool, end_within: float) -> str:
    """Where a solved plan ends (the words after "ends"), from its stats: at the goal pose, or
    within the tolerance at the share of it its end uses (`end_used`), and, where the deeper search
    for a plan ending within `end_within` of it (planner.end_within) found none, how far it went."""
    if ends_at_goal:
        return "at the goal pose"
    end = f"within tolerance, {stats['goal_distance_steps']:.2f} unit steps from the goal"
    if stats.get("end_used") is not None:
        end += f", using {stats['end_used']:.2f} of its tolerance"
    deeper = stats.get("deeper")
    if deeper is not None and not deeper["solved"]:
        why = "ran out" if deeper["check_limit_reached"] else "found none"
        end += (f"; a search for a plan ending within {end_within:g} of it {why} after "
                f"{deeper['feasibility_checks']:,} stable-push tests")
    return end + " (a last push to the goal itself is not stable)"
