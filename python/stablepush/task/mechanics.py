"""The stable-push test in file units: the Python face of the core's feasibility test."""
from __future__ import annotations

from typing import Dict, Optional, Sequence

from stablepush import _core
from stablepush.errors import TaskError
from stablepush.task.model import Task
from stablepush.task.schema import pose_field
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


def check_push(
    task: Task,
    at: Sequence[float],
    move: Sequence[float],
    pusher: Optional[str] = None,
    model: "Optional[_core.StablePushModel]" = None,
) -> Dict[str, dict]:
    """Is the unit motion `move` (dx mm, dz mm, dtheta deg) from pose `at` (x mm, z mm, theta deg)
    a stable push? One entry per pusher (or only `pusher`), keyed by pusher name. With the task's
    `uncertainty`, robustly: the verdict of the least stable corner of the box."""
    at = pose_field("at", list(at))
    move = pose_field("move", list(move))
    if max(abs(v) for v in move) < SMALLEST_MOVE:
        raise TaskError("move", f"the motion is zero or too small (every component under {SMALLEST_MOVE:g} mm or deg); "
                                f"give a unit motion (dx, dz, dtheta)")
    q, dq = pose_to_si(at), pose_to_si(move)
    names = [pusher] if pusher is not None else task.pusher_names
    robust = task.uncertainty and model is None
    model = model or task.build_model()
    # The model answers for any pose, but a push means something only where the pads hold the object.
    if not model.grasp_maintained(q):
        raise TaskError("at", f"the pads are not all on the object at {list(at)} (x mm, z mm, theta deg): "
                              f"there is no grasp to push in")
    if robust:  # the least stable corner of the box decides
        corners = task.corner_models()
        return {name: result_to_dict(_core.worst_case(corners, q, dq, task.pusher_index(name))) for name in names}
    if pusher is not None:
        return {pusher: result_to_dict(model.check(q, dq, task.pusher_index(pusher)))}
    return {name: result_to_dict(r) for name, r in zip(task.pusher_names, model.check_all(q, dq))}
