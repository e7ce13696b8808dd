"""Design files (`stablepush design`): a task file whose `candidates` stand in for its `pushers`,
read into the task's mapping and the candidate pushers, each checked as the task file checks its
own (schema.py). Files use mm and degrees; TaskError names the field.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Dict, List, Mapping, Optional, Tuple

import yaml

from stablepush.compiled import _core
from stablepush.errors import TaskError
from stablepush.frames import turn
from stablepush.inputs import read_capped
from stablepush.outputs import protect_input
from stablepush.task.fields import MAX_TASK_BYTES, _friction, _integer, _load_yaml, _mapping, _yaml_problem
from stablepush.task.model import MAX_PUSHER_POINTS
from stablepush.task.parts import outline_corners
from stablepush.task.schema import DEFAULT_PUSHER_POINTS, MAX_PUSHERS, _validate_object, _validate_pushers
from stablepush.units import mm2_to_si


def load_design(path: "str | Path") -> Tuple[Dict[str, Any], List[Dict[str, Any]]]:
    """A design task file (`stablepush design`): a task whose `candidates` stand in for its
    `pushers`. Returns the task's mapping without them and the candidate pushers as pusher entries
    of the task file's form (`candidate_pushers`); every layout of them is then a task of its own
    (parse_task of the mapping with `pushers` set). TaskError naming the field; `environment.features`
    is refused: the design places the fixtures."""
    source = str(path)
    try:
        data = _load_yaml(read_capped(path, MAX_TASK_BYTES).decode("utf-8"))
        protect_input(path, "a design file")
    except ValueError as exc:
        raise TaskError("", f"cannot read the design file: {exc}", source) from None
    except OSError as exc:
        raise TaskError("", f"cannot read the design file ({exc.strerror or exc})", source) from None
    except yaml.YAMLError as exc:
        raise TaskError("", f"not valid YAML ({_yaml_problem(exc)})", source) from None
    if not isinstance(data, dict):
        raise TaskError("", "a design file is a mapping, as a task file is", source)
    if "pushers" in data:
        raise TaskError("pushers", "a design file gives candidates instead of pushers (candidates: {mu: 0.5}, or a "
                                   "list of pusher entries)", source)
    if "candidates" not in data:
        raise TaskError("candidates", "missing: {mu: M} (every edge and convex corner of the section), or a list of "
                                      "pusher entries", source)
    environment = data.get("environment")
    if isinstance(environment, dict) and "features" in environment:  # else every layout without one is refused
        raise TaskError("environment.features", "a design places its fixtures itself (each design's "
                                                "environment.features is where its plan puts them): remove it from "
                                                "the design file", source)
    task = {k: v for k, v in data.items() if k != "candidates"}
    try:
        return task, candidate_pushers(data["candidates"], task, source)
    except TaskError as exc:
        raise TaskError(exc.field, exc.reason, source) from None


def candidate_pushers(value: Any, task: Mapping[str, Any], source: Optional[str] = None) -> List[Dict[str, Any]]:
    """The candidates of a design file as pusher entries: `{mu: M}` (optional `points`) makes every
    edge of the object's section a segment pusher (`edge<k>`, from corner k to corner k+1, in the
    section's counterclockwise order) and every convex corner two point pushers, CORNER_INSET
    along each of its edges (`corner<k>a` toward corner k-1, `corner<k>b` toward k+1: at the corner
    itself a point contact's normal is not defined, docs/model.md section 2), each of friction M; a
    list is taken as pusher entries as they are (checked as `pushers` is)."""
    if isinstance(value, list):
        if not value:
            raise TaskError("candidates", "an empty list: give at least one pusher entry")
        _validate_pushers(value, _core.CrossSection([mm2_to_si(v) for v in _corners_of(task, source)]), [])
        return [dict(entry) for entry in value]
    spec = _mapping("candidates", value, ["mu"], ["points"])
    mu = _friction("candidates.mu", spec["mu"])
    points = _integer("candidates.points", spec.get("points", DEFAULT_PUSHER_POINTS), 2, MAX_PUSHER_POINTS)
    corners = _corners_of(task, source)
    n = len(corners)
    edges = [{"name": f"edge{k}", "from": list(corners[k]), "to": list(corners[(k + 1) % n]), "mu": mu,
              "points": points} for k in range(n)]
    convex = []
    for k in range(n):  # at a corner itself a point contact's normal is not defined: just beside it
        if turn(corners[k - 1], corners[k], corners[(k + 1) % n]) > 0:
            for side, neighbour in (("a", corners[k - 1]), ("b", corners[(k + 1) % n])):
                convex.append({"name": f"corner{k}{side}", "at": _toward(corners[k], neighbour), "mu": mu})
    candidates = edges + convex
    if len(candidates) > MAX_PUSHERS:
        raise TaskError("candidates", f"the section's {n} corners make {len(candidates)} candidates, more than "
                                      f"{MAX_PUSHERS}: list the candidates instead")
    return candidates


# mm along an edge from a corner where its point-pusher candidates sit (at most a quarter of the edge)
CORNER_INSET = 1.0


def _toward(corner, neighbour) -> List[float]:
    """The point CORNER_INSET from `corner` along the edge toward `neighbour` (mm)."""
    dx, dz = neighbour[0] - corner[0], neighbour[1] - corner[1]
    length = math.hypot(dx, dz)
    inset = min(CORNER_INSET, length / 4)
    return [corner[0] + dx / length * inset, corner[1] + dz / length * inset]


def _corners_of(task: Mapping[str, Any], source: Optional[str]) -> Tuple[Tuple[float, float], ...]:
    """The corners of a task mapping's object section (mm, counterclockwise), its object checked."""
    vertices, *_ = _validate_object(_mapping("", task, ["object"], list(task))["object"], source, [])
    return outline_corners(vertices)
