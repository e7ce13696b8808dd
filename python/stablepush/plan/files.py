"""Plan files (docs/model.md section 5): JSON, with a CSV beside it, written atomically."""
from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import numbers
from pathlib import Path
from typing import Optional, Union

from stablepush import strict_json
from stablepush.errors import OutputError, PlanError
from stablepush.inputs import read_capped
from stablepush.outputs import is_stream, protect_input, same_file, write_files
from stablepush.plan.plan import (
    FieldFault,
    Plan,
    PlanOutcome,
    PusherContact,
    Waypoint,
    is_point,
    require_plan,
    value_kind,
    value_shown,
    waypoint_fault,
)
from stablepush.strict_json import is_finite_number
from stablepush.units import is_real

FORMAT = "stablepush.plan/1"
CSV_COLUMNS = ["step", "x", "z", "theta", "pusher", "margin", "margin_per_normal", "case",
               "pusher_from_x", "pusher_from_z", "pusher_to_x", "pusher_to_z", "pusher_normal_x", "pusher_normal_z"]


def _waypoint_dict(w: Waypoint) -> dict:
    out: dict = {"x": w.x, "z": w.z, "theta": w.theta, "pusher": w.pusher, "margin": w.margin,
           "margin_per_normal": w.margin_per_normal, "case": w.case, "pusher_in_gripper": None}
    if w.contact is not None:
        out["pusher_in_gripper"] = {"from": list(w.contact.start), "to": list(w.contact.end),
                                    "normal": list(w.contact.normal)}
    return out


def plan_to_dict(plan: Plan) -> dict:
    """The plan as the JSON document of docs/model.md section 5 (mm, deg; margins in N; the pusher's
    contact in the gripper frame G per waypoint)."""
    return {
        "format": FORMAT,
        "task": plan.task,
        "solved": plan.solved,
        "outcome": plan.outcome,
        "message": plan.message,
        # A solved plan ends at the goal pose itself ("goal") or, when the last, shorter push to it
        # is not stable, within the tolerance ("within_tolerance"); null when not solved.
        "ends_at": ("goal" if plan.ends_at_goal else "within_tolerance") if plan.solved else None,
        "stats": dict(plan.stats),
        # Every push is stable for every value in this box (+- fractions of the task's values;
        # empty: the nominal values only), and each margin is the least over it.
        "uncertainty": dict(plan.uncertainty),
        # Released at the last waypoint, do the pads alone hold the object? ratio: the largest
        # multiple of its weight they hold there (null without gravity: any grasp holds).
        "final_hold": {"ratio": None if math.isinf(plan.final_hold_ratio) else plan.final_hold_ratio,
                       "holds": plan.final_hold_ratio >= 1.0},
        "units": {"x": "mm", "z": "mm", "theta": "deg", "margin": "N", "margin_per_normal": "1 (N per N)",
                  "pusher_in_gripper": "mm in G"},
        # The task it was planned for, whole, and its digest: a plan whose task changed since says what.
        "task_identity": None if plan.task_identity is None else {"digest": task_digest(plan.task_identity),
                                                                  "fields": plan.task_identity},
        "waypoints": [_waypoint_dict(w) for w in plan.waypoints],
    }


def task_digest(identity: dict) -> str:
    """SHA-256 of a task's identity (Task.identity) as canonical JSON."""
    text = json.dumps(identity, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return "sha256:" + hashlib.sha256(text.encode()).hexdigest()


def plan_to_csv(plan: Plan) -> str:
    """The plan's waypoints as CSV (CSV_COLUMNS; mm, deg, N; the start's pusher fields empty)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for i, w in enumerate(plan.waypoints):
        contact = ([*w.contact.start, *w.contact.end, *w.contact.normal] if w.contact is not None else [""] * 6)
        writer.writerow(
            [
                i,
                repr(w.x),
                repr(w.z),
                repr(w.theta),
                w.pusher or "",
                "" if w.margin is None else repr(w.margin),
                "" if w.margin_per_normal is None else repr(w.margin_per_normal),
                w.case or "",
                *map(str, contact),
            ]
        )
    return buffer.getvalue()


def write_plan(plan: Plan, json_path: Union[str, Path], csv_path: Optional[Union[str, Path]] = None) -> None:
    """The plan as JSON, and as CSV beside it when `csv_path` is given, replaced together. PlanError
    (naming the field) for a plan load_plan would not read back, a NaN final_hold_ratio say, and
    OutputError when both paths name one file."""
    require_plan(plan)
    source = f"the plan to write to {json_path}"
    for key in ("stats", "uncertainty"):  # mappings, as load_plan reads them (a Plan edited in code)
        if not isinstance(getattr(plan, key), dict):
            raise PlanError(key, f"must be a mapping, got {type(getattr(plan, key)).__name__}", source)
    data = plan_to_dict(plan)
    text = json.dumps(data, indent=1, default=_json_number) + "\n"
    check_plan_dict(json.loads(text), source)  # names a waypoint's field
    for key in ("stats", "uncertainty"):  # what else a plan file holds that must be finite
        try:
            json.dumps(data[key], default=_json_number, allow_nan=False)
        except ValueError:
            raise PlanError(key, "holds a number that is not finite (NaN or infinity), which JSON has not", source)
    files = {json_path: text}
    if csv_path is not None and same_file(csv_path, json_path):
        if not is_stream(json_path):
            raise OutputError(f"{csv_path}: the CSV would overwrite the plan file; give it another name")
        files[json_path] += plan_to_csv(plan)  # one stream: the JSON, then the CSV
    elif csv_path is not None:
        files[csv_path] = plan_to_csv(plan)
    write_files(files)


def _json_number(v):
    """A number JSON does not know (numpy's scalars), as the Python number it is."""
    if is_real(v):
        return int(v) if isinstance(v, numbers.Integral) else float(v)
    raise TypeError(f"a plan holds numbers, strings and lists, not {type(v).__name__}")


def plan_from_dict(data: dict) -> Plan:
    """A plan document (checked by check_plan_dict) as a Plan."""
    check_plan_dict(data)
    waypoints = []
    for w in data["waypoints"]:
        contact = w.get("pusher_in_gripper")
        contact = (PusherContact(tuple(contact["from"]), tuple(contact["to"]), tuple(contact["normal"]))
                   if isinstance(contact, dict) else None)
        waypoints.append(Waypoint(float(w["x"]), float(w["z"]), float(w["theta"]), w.get("pusher"), w.get("margin"),
                                  w.get("case"), contact, w.get("margin_per_normal")))
    hold = (data.get("final_hold") or {}).get("ratio")
    return Plan(task=data["task"], solved=data["solved"], outcome=data.get("outcome", ""),
                message=data.get("message", ""), waypoints=waypoints, stats=dict(data["stats"]),
                final_hold_ratio=math.inf if hold is None else float(hold),
                uncertainty=dict(data.get("uncertainty") or {}), ends_at_goal=data.get("ends_at") == "goal",
                task_identity=(data.get("task_identity") or {}).get("fields"))


def load_plan(path: Union[str, Path]) -> Plan:
    """A plan file as a Plan; PlanError naming the field if it is not a well-formed plan."""
    return plan_from_dict(read_plan(path))


MAX_PLAN_BYTES = 16_000_000
MAX_WAYPOINTS = 10_000  # a plan this long streams for about 2 h at 100 waypoints/s with no retracts
# The counts a plan's stats hold and their largest values: a seed is 32 bits, switch-overs and pushes
# are fewer than the waypoints, the search's own counts far below 10^15.
STATS_COUNTS = {"seed": 2**32 - 1, "switches": MAX_WAYPOINTS, "pushes": MAX_WAYPOINTS, "max_switches": MAX_WAYPOINTS,
                "restarts": 10**15, "iterations": 10**15, "nodes": 10**15, "feasibility_checks": 10**15}


def read_plan(path: Union[str, Path]) -> dict:
    """A plan file as a dict, once its structure is checked (PlanError naming the field): the
    format, `solved` a boolean, `stats` a mapping, at most MAX_WAYPOINTS waypoints, each with
    finite x, z, theta and a pusher name (null at the start). Whether the plan belongs to a task
    is stablepush.plan.verify.check_plan's question."""
    source = str(path)
    try:
        raw = read_capped(path, MAX_PLAN_BYTES)
    except ValueError as exc:  # not a regular file, or too large
        raise PlanError("", f"{exc}; not a plan this tool wrote", source) from None
    except OSError as exc:
        raise PlanError("", f"cannot read the plan file ({exc.strerror or exc})", source) from None
    protect_input(path, "a plan file")
    try:
        data = strict_json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        raise PlanError("", f"not valid JSON ({' '.join(str(exc).split())[:120]})", source) from None
    check_plan_dict(data, source)
    return data


def check_plan_dict(data, source: Optional[str] = None) -> None:
    """PlanError unless `data` has the structure of a plan document (see read_plan)."""
    # Each check may assume the ones before it passed (`or` stops at the first fault).
    fault = (_fields_fault(data) or _outcome_fault(data) or _stats_fault(data["stats"])
             or _waypoints_fault(data["waypoints"]) or _extras_fault(data))
    if fault is not None:
        raise PlanError(*fault, source)


_KIND_NAMES = {str: "a string", bool: "a boolean", dict: "a mapping", list: "a list"}
_REQUIRED = {"task": str, "solved": bool, "stats": dict, "waypoints": list}


def _fields_fault(data) -> FieldFault:
    """The format, the fields every plan has and their kinds."""
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        return "format", f"not a {FORMAT} file"
    for key, kind in _REQUIRED.items():
        if key not in data:
            return key, "missing"
        if not isinstance(data[key], kind):
            return key, f"must be {_KIND_NAMES[kind]}, got {value_kind(data[key])}"
    for key in ("outcome", "message"):
        if key in data and not isinstance(data[key], str):
            return key, f"must be a string, got {value_kind(data[key])}"
    return None


def _outcome_fault(data: dict) -> FieldFault:
    """The outcome, one of PlanOutcome's, and `solved` agreeing with it (absent or empty: not checked)."""
    outcome = data.get("outcome")
    if not outcome:
        return None
    names = [o.value for o in PlanOutcome]
    if outcome not in names:
        return "outcome", f"must be one of {', '.join(names)}, got {value_shown(outcome)}"
    if (outcome == PlanOutcome.goal_reached.value) != data["solved"]:
        return "solved", (f"{json.dumps(data['solved'])} with outcome {outcome}: only a plan that reached its goal "
                          f"is solved")
    return None


def _stats_fault(stats: dict) -> FieldFault:
    """The counts among the stats, whole numbers within STATS_COUNTS."""
    for key, largest in STATS_COUNTS.items():
        value = stats.get(key)
        if value is not None and not (isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= largest):
            return f"stats.{key}", f"must be a whole number from 0 to {largest}, got {value_shown(value)}"
    return None


def _waypoints_fault(waypoints: list) -> FieldFault:
    """The start and at most MAX_WAYPOINTS - 1 pushes, each waypoint as a Waypoint takes it."""
    if not waypoints:
        return "waypoints", "empty; a plan's first waypoint is its start"
    if len(waypoints) > MAX_WAYPOINTS:
        return "waypoints", f"{len(waypoints)} waypoints; a plan has at most {MAX_WAYPOINTS}"
    for i, w in enumerate(waypoints):
        fault = _waypoint_fault(w)
        if fault is not None:
            field, reason = fault
            return f"waypoints[{i}]{'.' + field if field else ''}", reason
    return None


def _waypoint_fault(w) -> FieldFault:
    """One waypoint: a mapping whose fields Waypoint would take ('' names the waypoint itself)."""
    if not isinstance(w, dict):
        return "", f"must be a mapping, got {value_kind(w)}"
    fault = waypoint_fault(w)
    if fault is not None:
        return fault
    contact = w.get("pusher_in_gripper")
    if contact is None:
        return None
    if not isinstance(contact, dict):
        return "pusher_in_gripper", f"must be a mapping or null, got {value_kind(contact)}"
    for key in ("from", "to", "normal"):
        if not (isinstance(contact.get(key), list) and is_point(contact[key])):
            return f"pusher_in_gripper.{key}", "must be a list of 2 finite numbers"
    return None


def _extras_fault(data: dict) -> FieldFault:
    """The optional fields beside the waypoints: final_hold, uncertainty, task_identity and ends_at."""
    hold = data.get("final_hold")
    if hold is not None and not (isinstance(hold, dict) and (hold.get("ratio") is None
                                                             or is_finite_number(hold["ratio"]))):
        return "final_hold", "must be a mapping whose ratio is a finite number or null"
    if data.get("uncertainty") is not None and not isinstance(data["uncertainty"], dict):
        return "uncertainty", f"must be a mapping, got {value_kind(data['uncertainty'])}"
    fault = _identity_fault(data.get("task_identity"))
    if fault is not None:
        return fault
    if data.get("ends_at") not in (None, "goal", "within_tolerance"):
        return "ends_at", "must be goal, within_tolerance or null"
    return None


def _identity_fault(identity) -> FieldFault:
    """The task_identity record: null, or the task's fields with their digest."""
    if identity is None:
        return None
    if not isinstance(identity, dict) or not isinstance(identity.get("fields"), dict):
        return "task_identity", "must be a mapping with the task's fields (or null)"
    if identity.get("digest") != task_digest(identity["fields"]):
        return "task_identity.digest", "does not match its fields: the file was edited by hand"
    return None

