"""Plan files (docs/model.md section 5): JSON, with a CSV beside it, written atomically."""
from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import re
import signal
import stat
import tempfile
import threading
from pathlib import Path
from typing import Mapping, Optional, Union

from stablepush import strict_json
from stablepush.errors import OutputError, PlanError
from stablepush.strict_json import is_finite_number

from stablepush.planning import Plan, PlanResult, PusherContact, Waypoint

FORMAT = "stablepush.plan/1"
CSV_COLUMNS = ["step", "x", "z", "theta", "pusher", "margin", "margin_per_normal", "case",
               "pusher_from_x", "pusher_from_z", "pusher_to_x", "pusher_to_z", "pusher_normal_x", "pusher_normal_z"]


def _waypoint_dict(w: Waypoint) -> dict:
    out = {"x": w.x, "z": w.z, "theta": w.theta, "pusher": w.pusher, "margin": w.margin,
           "margin_per_normal": w.margin_per_normal, "case": w.case, "pusher_in_gripper": None}
    if w.contact is not None:
        out["pusher_in_gripper"] = {"from": list(w.contact.start), "to": list(w.contact.end),
                                    "normal": list(w.contact.normal)}
    return out


def plan_to_dict(plan: PlanResult) -> dict:
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
        "waypoints": [_waypoint_dict(w) for w in plan.waypoints],
    }


def plan_to_csv(plan: PlanResult) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for i, w in enumerate(plan.waypoints):
        contact = ([*w.contact.start, *w.contact.end, *w.contact.normal] if w.contact is not None else [""] * 6)
        writer.writerow([i, repr(w.x), repr(w.z), repr(w.theta), w.pusher or "",
                         "" if w.margin is None else repr(w.margin),
                         "" if w.margin_per_normal is None else repr(w.margin_per_normal), w.case or "", *map(str, contact)])
    return buffer.getvalue()


def default_output(input_file: Union[str, Path], suffix: str) -> str:
    """The default output for an input file: its stem plus `suffix`, in the current directory.
    Derived from the file's own name (never from names inside it), so it cannot point elsewhere."""
    stem = Path(input_file).stem or "stablepush"
    return re.sub(r"[^\w.+-]", "_", stem + suffix)


def write_files(files: Mapping[Union[str, Path], Union[str, bytes]]) -> None:
    """Write each file so that a reader sees its old content or the whole new one, never a part,
    and a set of files is replaced together: every new file is written and synced beside its
    target first, then all are renamed into place with SIGINT, SIGTERM and SIGHUP held off, so
    that only a SIGKILL or a power cut between two renames can leave old and new side by side
    (or a temporary file behind).

    A symlink is written through (its target is replaced; the link stays). A character device or
    FIFO (/dev/null, /dev/stdout) is written to, never replaced. A directory or any other kind of
    file is refused, as is a missing directory: OutputError naming the path. New files take the
    umask's permissions; a replaced file keeps its own."""
    plan = []
    for path, content in files.items():
        target = Path(os.path.realpath(path))
        try:
            mode = os.stat(target).st_mode
        except FileNotFoundError:
            mode = None
        except OSError as exc:
            raise OutputError(f"{path}: cannot write ({exc.strerror})") from None
        if mode is not None and (stat.S_ISCHR(mode) or stat.S_ISFIFO(mode)):
            plan.append((path, target, content, "stream", None))
        elif mode is not None and not stat.S_ISREG(mode):
            raise OutputError(f"{path}: not a regular file; refusing to replace it")
        elif not target.parent.is_dir():
            raise OutputError(f"{path}: the directory {target.parent} does not exist")
        else:
            plan.append((path, target, content, "replace", stat.S_IMODE(mode) if mode is not None else None))
    with _signals_deferred():
        _write_and_rename(plan)


def _write_and_rename(plan) -> None:
    temporaries = []  # written, not yet renamed: removed on any failure
    try:
        for path, target, content, how, mode in plan:
            data = content.encode() if isinstance(content, str) else content
            if how == "stream":
                with open(target, "wb") as handle:
                    handle.write(data)
                continue
            fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
            temporaries.append((tmp, target))
            with os.fdopen(fd, "wb") as handle:
                handle.write(data)
                handle.flush()
                os.fsync(handle.fileno())
            os.chmod(tmp, mode if mode is not None else 0o666 & ~_umask())
        for tmp, target in temporaries:
            os.replace(tmp, target)
        temporaries = []
    except OSError as exc:
        raise OutputError(f"cannot write {exc.filename or 'the output'}: {exc.strerror or exc}") from None
    finally:
        for tmp, _ in temporaries:
            with contextlib.suppress(OSError):
                os.unlink(tmp)


@contextlib.contextmanager
def _signals_deferred():
    """Hold SIGINT, SIGTERM and SIGHUP until the block ends, then deliver them as if they came
    then. A handler, not a signal mask: a process-directed signal goes to any thread that does
    not block it (numpy's BLAS threads), and its default action ends the whole process."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pending = []
    previous = {sig: signal.signal(sig, lambda signum, frame: pending.append(signum)) for sig in _DEFERRED}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        for sig in dict.fromkeys(pending):
            signal.raise_signal(sig)


_DEFERRED = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def write_atomically(path: Union[str, Path], text: Union[str, bytes]) -> None:
    """Write one file as `write_files` does."""
    write_files({path: text})


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def write_plan(plan: PlanResult, json_path: Union[str, Path], csv_path: Optional[Union[str, Path]] = None) -> None:
    """The plan as JSON, and as CSV beside it when `csv_path` is given, replaced together."""
    files = {json_path: json.dumps(plan_to_dict(plan), indent=1) + "\n"}
    if csv_path:
        files[csv_path] = plan_to_csv(plan)
    write_files(files)


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
                uncertainty=dict(data.get("uncertainty") or {}), ends_at_goal=data.get("ends_at") == "goal")


MAX_PLAN_BYTES = 16_000_000
MAX_WAYPOINTS = 10_000  # a plan this long streams for about 2 h at 100 waypoints/s with no retracts


def read_plan(path: Union[str, Path]) -> dict:
    """A plan file as a dict, once its structure is checked (PlanError naming the field): the
    format, `solved` a boolean, `stats` a mapping, at most MAX_WAYPOINTS waypoints, each with
    finite x, z, theta and a pusher name (null at the start). Whether the plan belongs to a task
    is stablepush.executor.plan_steps's question."""
    source = str(path)
    try:
        with open(path, "rb") as handle:
            raw = handle.read(MAX_PLAN_BYTES + 1)
    except OSError as exc:
        raise PlanError("", f"cannot read the plan file ({exc.strerror or exc})", source) from None
    if len(raw) > MAX_PLAN_BYTES:
        raise PlanError("", f"larger than {MAX_PLAN_BYTES} bytes; not a plan this tool wrote", source)
    try:
        data = strict_json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        raise PlanError("", f"not valid JSON ({' '.join(str(exc).split())[:120]})", source) from None
    check_plan_dict(data, source)
    return data


def check_plan_dict(data, source: Optional[str] = None) -> None:
    """PlanError unless `data` has the structure of a plan document (see read_plan)."""
    def fail(field: str, reason: str):
        raise PlanError(field, reason, source)

    if not isinstance(data, dict) or data.get("format") != FORMAT:
        fail("format", f"not a {FORMAT} file")
    for key, kind in (("task", str), ("solved", bool), ("stats", dict), ("waypoints", list)):
        if not isinstance(data.get(key), kind):
            fail(key, f"must be {'a boolean' if kind is bool else 'a ' + _KIND_NAMES[kind]}, got "
                      f"{_json_kind(data.get(key))}")
    for key in ("outcome", "message"):
        if key in data and not isinstance(data[key], str):
            fail(key, f"must be a string, got {_json_kind(data[key])}")
    waypoints = data["waypoints"]
    if len(waypoints) > MAX_WAYPOINTS:
        fail("waypoints", f"{len(waypoints)} waypoints; a plan has at most {MAX_WAYPOINTS}")
    for i, w in enumerate(waypoints):
        field = f"waypoints[{i}]"
        if not isinstance(w, dict):
            fail(field, f"must be a mapping, got {_json_kind(w)}")
        for key in ("x", "z", "theta"):
            if not is_finite_number(w.get(key)):
                fail(f"{field}.{key}", f"must be a finite number, got {str(w.get(key))[:40]}")
        if not (w.get("pusher") is None or isinstance(w.get("pusher"), str)):
            fail(f"{field}.pusher", f"must be a pusher name or null, got {_json_kind(w.get('pusher'))}")


_KIND_NAMES = {str: "string", dict: "mapping", list: "list"}


def _json_kind(v) -> str:
    """What a JSON value is, in JSON's words."""
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "a boolean"
    return {str: "a string", dict: "a mapping", list: "a list"}.get(type(v), "a number")

