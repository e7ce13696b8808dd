"""The stable-push test in file units: the Python face of the core's feasibility test."""
from __future__ import annotations

import math
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from stablepush.compiled import _core
from stablepush.errors import TaskError
from stablepush.pose import Tolerance
from stablepush.task.fields import number_field, pose_field
from stablepush.task.model import Task, require_task
from stablepush.units import pose_to_si

SMALLEST_MOVE = 1e-6  # mm or deg: below, the motion's velocity terms are rounding noise


def result_to_dict(result: "_core.PushResult") -> dict:
    """A PushResult as plain data: margin in N, witness (f_x N, f_z N, tau_y N m) in O."""
    return {
        "feasible": bool(result.feasible),
        "case": result.contact_case.name,
        "margin": float(result.margin),
        "witness": [float(v) for v in result.witness],
        "exact": bool(result.exact),
        "sticking_points": int(result.sticking_points),
    }


def _require_grasp(model: "_core.StablePushModel", q: Sequence[float], at: Sequence[float]) -> None:
    """TaskError (field `at`) unless the pads are all on the object at q: the model answers for any
    pose, but a push means something only where the pads hold the object."""
    if not model.grasp_maintained(q):
        raise TaskError("at", f"the pads are not all on the object at {list(at)} (x mm, z mm, theta deg): "
                              f"there is no grasp to push in")


def check_push(
    task: Task,
    at: Sequence[float],
    move: Sequence[float],
    pusher: Optional[str] = None,
) -> Dict[str, dict]:
    """Is the unit motion `move` (dx mm, dz mm, dtheta deg) from pose `at` (x mm, z mm, theta deg)
    a stable push? One entry per pusher (or only `pusher`), keyed by pusher name. With the task's
    `uncertainty`, robustly: the verdict of the least stable corner of the box. The task's models
    are built on its first check (about a millisecond) and kept with it; a loop of many checks
    may call `task.model.check` itself (SI units: stablepush.units.pose_to_si)."""
    require_task(task)
    at = pose_field("at", list(at))
    move = pose_field("move", list(move))
    if max(abs(v) for v in move) < SMALLEST_MOVE:
        raise TaskError("move", f"the motion is zero or too small (every component under {SMALLEST_MOVE:g} mm or deg); "
                                f"give a unit motion (dx, dz, dtheta)")
    q, dq = pose_to_si(at), pose_to_si(move)
    names = [pusher] if pusher is not None else task.pusher_names
    model = task.model
    _require_grasp(model, q, at)
    if any(task.uncertainty.values()):  # the least stable corner of the box decides
        corners = task.corner_models
        return {name: result_to_dict(_core.worst_case(corners, q, dq, task.pusher_index(name))) for name in names}
    if pusher is not None:
        return {pusher: result_to_dict(model.check(q, dq, task.pusher_index(pusher)))}
    return {name: result_to_dict(r) for name, r in zip(task.pusher_names, model.check_all(q, dq))}


ELEVATION_GRID_DEG = 1.0  # deg between the elevations tested at each heading (stable_directions)
HEADING_STEP_DEG = (0.5, 90.0)  # stable_directions' heading step: at most 720 headings, each a root search per pusher
ROOT_BISECTIONS = 50  # a point pusher's surface, to rounding of the elevation


def stable_directions(task: Task, at: Sequence[float], pusher: Optional[str] = None,
                      heading_step: float = 10.0) -> dict:
    """Which ways the pushers can move the object from pose `at` (x mm, z mm, theta deg): the stable
    unit pushes, one unit step (planner.step) long, at headings every `heading_step` deg.

    A unit push is written in unit steps as (cos b cos h, cos b sin h, sin b): heading h in the
    (x, z) plane, elevation b toward +theta. A pusher whose cone is 3-D is tested at every
    ELEVATION_GRID_DEG of elevation; a point pusher's stable pushes lie on its surface
    e . w_required(motion) = 0 (docs/model.md, sections 2 and 3), so its elevations are the roots
    of that equation on the grid, refined by bisection, then tested. Every push returned passed the
    stable-push test (with `uncertainty:`, at every corner of the box) and keeps the grasp.

    Returns {"unit_step": [mm, deg], "pushers": {name: [{"heading", "elevation" (deg), "move"
    (dx mm, dz mm, dtheta deg), "margin" (N)}, ...]}, "largest": {"+x", "-x", "+z", "-z",
    "+theta", "-theta": the largest component along that sense of any push returned, in unit
    steps (<= 0 or None: no stable push moves the object that way)}}."""
    require_task(task)
    at = pose_field("at", list(at))
    heading_step = number_field("heading_step", heading_step, HEADING_STEP_DEG)
    names = [pusher] if pusher is not None else task.pusher_names
    indices = [task.pusher_index(name) for name in names]
    model = task.model
    q = np.array(pose_to_si(at))
    _require_grasp(model, q.tolist(), at)
    corners = task.corner_models
    step_mm, step_deg = task.planner.step
    scale = np.array(pose_to_si((step_mm, step_mm, step_deg)))
    headings = [heading_step * i for i in range(math.ceil(360.0 / heading_step - 1e-9))]  # deg
    elevations = np.radians(np.arange(-90.0 + ELEVATION_GRID_DEG, 90.0, ELEVATION_GRID_DEG))

    def unit(h: float, b: float) -> np.ndarray:
        return np.array([math.cos(b) * math.cos(h), math.cos(b) * math.sin(h), math.sin(b)])

    def verdict(dq: np.ndarray, index: int):
        result = _core.worst_case(corners, q.tolist(), dq.tolist(), index)
        return result.feasible and model.grasp_maintained((q + dq).tolist()), result.margin

    out, units = {}, []
    for name, index in zip(names, indices):
        found = []
        rows = model.pusher_cones[index].equality_rows
        for heading in headings:
            h = math.radians(heading)
            if not rows:  # a 3-D cone: every elevation of the grid, each its own candidate
                candidates: List[Tuple[float, ...]] = [(b,) for b in elevations]  # an elevation, or a root's two sides
            else:
                e = np.asarray(rows[0])

                def off(b: float) -> float:  # e . w_required / its scale: 0 on the surface
                    w = model.motion_wrench(q.tolist(), (unit(h, b) * scale).tolist(), index)
                    return float(e @ np.asarray(w.required)) / w.scale

                values = [off(b) for b in elevations]
                candidates = []
                for lo, hi, f_lo, f_hi in zip(elevations, elevations[1:], values, values[1:]):
                    if f_lo * f_hi >= 0:
                        continue
                    for _ in range(ROOT_BISECTIONS):
                        mid = 0.5 * (lo + hi)
                        lo, hi = (lo, mid) if off(mid) * f_lo < 0 else (mid, hi)
                    candidates.append((lo, hi))  # the side of the root the test accepts, if either
            for sides in candidates:
                for b in sides:
                    stable, margin = verdict(unit(h, b) * scale, index)
                    if stable:
                        found.append({"heading": heading, "elevation": math.degrees(b),
                                      "move": [float(v) for v in unit(h, b) * (step_mm, step_mm, step_deg)],
                                      "margin": float(margin)})
                        units.append(unit(h, b))
                        break
        out[name] = found
    largest = {}
    for axis, label in enumerate(("x", "z", "theta")):
        for sign, s in ((1.0, "+"), (-1.0, "-")):
            best = max((sign * u[axis] for u in units), default=None)
            largest[s + label] = None if best is None else float(best)
    return {"unit_step": [step_mm, step_deg], "pushers": out, "largest": largest}


# A sense of x, z or theta in which no stable push moves the object by more than this fraction of a
# unit step counts as one the pushers cannot push it in (the pegs' -x: 0.05, and only while turning).
NO_WAY_BACK = 0.1


def blocked_senses(task: Task, pose: Sequence[float], gap: Sequence[float],
                   tolerance: "Tolerance | Sequence[float]") -> Optional[str]:
    """The senses of x, z and theta in which `gap` (dx mm, dz mm, dtheta deg: where the goal lies
    from `pose`) is beyond `tolerance` and no stable unit push from `pose` (x mm, z mm,
    theta deg) moves the object by more than NO_WAY_BACK of a unit step (stable_directions,
    headings every 10 deg), each with the largest such push: "-x (none)" (no push moves the object
    that way), "-x (at most 0.05 of a unit step)"; else None, and None where the pads do not hold
    the object at `pose`. Not a proof that the goal is out of reach (a plan may go around, through
    poses with other pushes), but why a search from `pose` finds little."""
    try:
        largest = stable_directions(task, pose)["largest"]
    except TaskError:  # no grasp at the pose: the planner's own refusal says so
        return None
    blocked = []
    tolerance = Tolerance.of(tolerance)
    limits = (tolerance.position, tolerance.position, tolerance.angle)
    for axis, (name, limit) in enumerate(zip(("x", "z", "theta"), limits)):
        sense = ("+" if gap[axis] > 0 else "-") + name
        if abs(gap[axis]) > limit and (largest[sense] is None or largest[sense] < NO_WAY_BACK):
            most = ("none" if largest[sense] is None or largest[sense] <= 1e-9  # 1e-9: cos(90 deg)'s rounding
                    else f"at most {largest[sense]:.2f} of a unit step")
            blocked.append(f"{sense} ({most})")
    return ", ".join(blocked) if blocked else None
