"""Plan files (MODEL.md section 5): JSON, with a CSV beside it, written atomically."""
from __future__ import annotations

import csv
import io
import json
import math
import os
import tempfile
from pathlib import Path
from typing import Union

from stablepush.planning import PlanResult, Waypoint

FORMAT = "stablepush.plan/1"
CSV_COLUMNS = ["step", "x", "z", "theta", "pusher", "margin", "case",
               "pusher_from_x", "pusher_from_z", "pusher_to_x", "pusher_to_z", "pusher_normal_x", "pusher_normal_z"]


def _waypoint_dict(w: Waypoint) -> dict:
    out = {"x": w.x, "z": w.z, "theta": w.theta, "pusher": w.pusher, "margin": w.margin, "case": w.case,
           "pusher_in_gripper": None}
    if w.contact is not None:
        out["pusher_in_gripper"] = {"from": list(w.contact.start), "to": list(w.contact.end),
                                    "normal": list(w.contact.normal)}
    return out


def plan_to_dict(plan: PlanResult) -> dict:
    """The plan as the JSON document of MODEL.md section 5 (mm, deg; margins in N; the pusher's
    contact in the gripper frame G per waypoint)."""
    return {
        "format": FORMAT,
        "task": plan.task,
        "solved": plan.solved,
        "outcome": plan.outcome,
        "message": plan.message,
        "stats": dict(plan.stats),
        # Released at the last waypoint, do the pads alone hold the object? ratio: the largest
        # multiple of its weight they hold there (null without gravity: any grasp holds).
        "final_hold": {"ratio": None if math.isinf(plan.final_hold_ratio) else plan.final_hold_ratio,
                       "holds": plan.final_hold_ratio >= 1.0},
        "units": {"x": "mm", "z": "mm", "theta": "deg", "margin": "N", "pusher_in_gripper": "mm in G"},
        "waypoints": [_waypoint_dict(w) for w in plan.waypoints],
    }


def plan_to_csv(plan: PlanResult) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for i, w in enumerate(plan.waypoints):
        contact = ([*w.contact.start, *w.contact.end, *w.contact.normal] if w.contact is not None else [""] * 6)
        writer.writerow([i, repr(w.x), repr(w.z), repr(w.theta), w.pusher or "",
                         "" if w.margin is None else repr(w.margin), w.case or "", *map(str, contact)])
    return buffer.getvalue()


def write_atomically(path: Union[str, Path], text: str) -> None:
    """Write `text` to `path` so that a reader sees the old file or the whole new one, never a part."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent or ".")
    try:
        with os.fdopen(fd, "w") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_plan_json(plan: PlanResult, path: Union[str, Path]) -> None:
    write_atomically(path, json.dumps(plan_to_dict(plan), indent=1) + "\n")


def write_plan_csv(plan: PlanResult, path: Union[str, Path]) -> None:
    write_atomically(path, plan_to_csv(plan))


def read_plan(path: Union[str, Path]) -> dict:
    """A plan file as a dict; ValueError if it is not a stablepush plan."""
    data = json.loads(Path(path).read_text())
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise ValueError(f"{path}: not a {FORMAT} file")
    return data
