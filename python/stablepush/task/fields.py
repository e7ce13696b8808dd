"""The checks of a task file's fields, each refusing a bad value with a TaskError that names the
field, and the YAML the file is read from: shared by the task file (schema.py), its robot section
(robot_section.py) and a design file (design_file.py), and by the callers that check an argument as
the task file does (the planner's settings, a reach map's axes, the arm protocol's scene). The
checkers with a leading underscore are the task package's own.

Files use mm, degrees, grams and newtons.
"""
from __future__ import annotations

import datetime
import math
import re
import reprlib
from typing import Any, Dict, Optional, Sequence, Tuple

import yaml

from stablepush.compiled import _core
from stablepush.errors import TaskError
from stablepush.task.model import PLANNER_LIMITS
from stablepush.task.parts import ANGLE, COORDINATE, LENGTH, MU, PHYSICS_LIMITS
from stablepush.units import is_integer, is_real

# mm: a pad radius, retract or spacing under this, or a pusher or world position this near 0 in
# every coordinate, reads as a length written in metres (the warnings and refusals say so).
SUB_MM = 1.0
# Resource caps on a task or design file's text (docs/limits.md, "Limits").
MAX_TASK_BYTES = 1_000_000
MAX_YAML_ALIASES = 1000  # aliases (*name) a task file may use (PyYAML writes one per shared value)
MAX_YAML_NODES = 100_000  # values in the file, aliases expanded
# Plausible-physics bounds on each number, in file units (the world's, COORDINATE, ANGLE and
# LENGTH, are model.py's: the cell and robot values check them too).
LIMITS: Dict[str, Tuple[float, float]] = {  # kind -> (lowest, highest); both inclusive
    "length": LENGTH,  # mm: sizes, radii, distances
    "mu": MU,
    **PHYSICS_LIMITS,
    **PLANNER_LIMITS,
}

# TRRTstar's declared parameters and their ranges live in the C++ planner (declared once there;
# its setters refuse values outside them): key -> (kind, lowest, highest). seed and max_switches
# are among them; the rest are tuning keys, written to the plan only when the task gives them.
PLANNER_PARAMETER_RANGES: Dict[str, Tuple[str, float, float]] = dict(_core.TRRT_STAR_PARAMETER_RANGES)


# ---------------------------------------------------------------------------------------------
# YAML: duplicate keys refused (PyYAML silently keeps the last one), YAML 1.2 numbers (1e-3 is a
# number, not a string), and a budget on aliases and on the values they expand to (a few hundred
# bytes of nested aliases otherwise expand to gigabytes).


class _StrictLoader(yaml.SafeLoader):
    def __init__(self, stream):
        super().__init__(stream)
        self.aliases = 0

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            self.aliases += 1
            if self.aliases > MAX_YAML_ALIASES:
                line = self.peek_event().start_mark.line + 1
                raise TaskError("", f"line {line}: more than {MAX_YAML_ALIASES} YAML aliases (*name); "
                                    f"write the values out")
        return super().compose_node(parent, index)


def _construct_mapping(loader: _StrictLoader, node: yaml.MappingNode, deep: bool = False) -> dict:
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        line = key_node.start_mark.line + 1
        if not isinstance(key, (str, int, float, bool, type(None))):
            raise TaskError("", f"line {line}: a mapping key must be a name, got a {type(key).__name__}")
        if key in seen:
            raise TaskError(str(key), f"duplicate key (line {line})")
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_StrictLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)
_StrictLoader.add_implicit_resolver(  # YAML 1.2 exponents, which 1.1 reads as strings: 1e-3, 2.02e2, 1.5E+2
    "tag:yaml.org,2002:float", re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
    list("-+0123456789."))


def _expanded_size(node: yaml.Node) -> int:
    """How many values `node` stands for with its aliases expanded (TaskError past the budget or
    on a value that contains itself)."""
    sizes: Dict[int, int] = {}
    open_nodes = set()

    def size(n: yaml.Node) -> int:
        if id(n) in sizes:
            return sizes[id(n)]
        if id(n) in open_nodes:
            raise TaskError("", f"line {n.start_mark.line + 1}: a YAML value contains itself (through an alias)")
        open_nodes.add(id(n))
        children = [c for pair in n.value for c in pair] if isinstance(n, yaml.MappingNode) else (
            n.value if isinstance(n, yaml.SequenceNode) else [])
        total = 1
        for child in children:
            total += size(child)
            if total > MAX_YAML_NODES:
                raise TaskError("", f"the file stands for more than {MAX_YAML_NODES} values (aliases expanded)")
        open_nodes.discard(id(n))
        sizes[id(n)] = total
        return total

    return size(node)


def _refuse_duplicate_keys(node: yaml.Node, path: str) -> None:
    """TaskError naming the dotted path of a key written twice in one mapping (`object.mass`), before
    anything is constructed; _construct_mapping still refuses keys equal only once read (1 and 1.0)."""
    if isinstance(node, yaml.MappingNode):
        seen = set()
        for key_node, value_node in node.value:
            key = key_node.value if isinstance(key_node, yaml.ScalarNode) else None
            if key is not None and (key_node.tag, key) in seen:
                raise TaskError(_join(path, key), f"duplicate key (line {key_node.start_mark.line + 1})")
            seen.add((key_node.tag, key))
            _refuse_duplicate_keys(value_node, _join(path, key) if key is not None else path)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _refuse_duplicate_keys(item, f"{path}[{i}]")


def _load_yaml(text: str) -> Any:
    if len(text) > MAX_TASK_BYTES:
        raise TaskError("", f"the file has {len(text)} characters; a task file has at most {MAX_TASK_BYTES}")
    loader = _StrictLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _expanded_size(node)
        _refuse_duplicate_keys(node, "")
        return loader.construct_document(node)
    except RecursionError:
        raise TaskError("", "values nested too deeply") from None
    finally:
        loader.dispose()


def _yaml_problem(exc: "yaml.YAMLError") -> str:
    """PyYAML's problem and where, in one line (its own text spans lines, with a caret drawing)."""
    mark = getattr(exc, "problem_mark", None)
    problem = getattr(exc, "problem", None) or " ".join(str(exc).split())
    where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
    return f"{problem}{where}"


# ---------------------------------------------------------------------------------------------
# Field checkers: each takes the dotted path for its message.


def _mapping(path: str, value: Any, required: Sequence[str], optional: Sequence[str]) -> dict:
    if not isinstance(value, dict):
        raise TaskError(path, f"must be a mapping, got {_yaml_kind(value)}")
    if len(value) > 64:
        raise TaskError(path, f"has {len(value)} keys; at most 64")
    for key in value:
        if key not in required and key not in optional:
            allowed = ", ".join(dict.fromkeys([*required, *optional]))
            raise TaskError(_join(path, _shown(key, 40) if not isinstance(key, str) else _shown(key, 40).strip("'")),
                            f"unknown key (allowed here: {allowed})")
    for key in required:
        if key not in value:
            raise TaskError(_join(path, key), "missing")
    return value


def _join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


def _number(path: str, value: Any, within: Optional[Tuple[float, float]] = None) -> float:
    """A finite number (numpy's scalars too, but not a bool), inside `within` (lowest, highest;
    both inclusive) when given."""
    if not is_real(value):
        raise TaskError(path, f"must be a number, got {_shown(value)}")
    try:
        x = float(value)
    except OverflowError:  # an int past the double range
        raise TaskError(path, f"must be finite, got {_shown(value)}") from None
    if not math.isfinite(x):
        raise TaskError(path, f"must be finite, got {_shown(value)}")
    if within is not None and not within[0] <= x <= within[1]:
        # A positive length under the least one is a length in metres (every length field takes LIMITS["length"]).
        slip = _in_metres(x) if tuple(within) == LIMITS["length"] and 0.0 < x < within[0] else ""
        raise TaskError(path, f"must be between {within[0]:g} and {within[1]:g}, got {x:g}{slip}")
    return x


def _in_metres(value: Any) -> str:
    """The hint for a length, a point or points in mm that read as metres: "(0.006 m is 6 mm)"."""
    def shown(v: Any, k: float) -> str:
        return f"{v * k:g}" if isinstance(v, (int, float)) else "[" + ", ".join(shown(c, k) for c in v) + "]"

    return f"; written in metres? task files use mm ({shown(value, 1.0)} m is {shown(value, 1e3)} mm)"


# The least positive friction coefficient: below it the cones' rows underflow (a mu of 1e-170
# reached the exact re-check as infinity), and no material is that slippery without being 0.
MIN_POSITIVE_MU = 1e-6


def _friction(path: str, value: Any) -> float:
    """A friction coefficient: 0 (frictionless) or MIN_POSITIVE_MU to LIMITS["mu"]'s top."""
    mu = _number(path, value, LIMITS["mu"])
    if 0.0 < mu < MIN_POSITIVE_MU:
        raise TaskError(path, f"must be 0 (frictionless) or at least {MIN_POSITIVE_MU:g}, got {mu:g}")
    return mu


def _integer(path: str, value: Any, lowest: int, highest: int) -> int:
    """An integer (numpy's too, but not a bool) from `lowest` to `highest`, as a Python int."""
    if not is_integer(value):
        raise TaskError(path, f"must be an integer, got {_shown(value)}")
    if not lowest <= int(value) <= highest:
        raise TaskError(path, f"must be an integer from {lowest} to {highest}, got {_shown(value)}")
    return int(value)


def _vector(path: str, value: Any, n: int, within: Optional[Tuple[float, float]] = None) -> Tuple[float, ...]:
    if not isinstance(value, (list, tuple)) or len(value) != n:
        raise TaskError(path, f"must be a list of {n} numbers, got {_shown(value)}")
    return tuple(_number(f"{path}[{i}]", v, within) for i, v in enumerate(value))


def _pair(path: str, value: Any, within: Optional[Tuple[float, float]] = None) -> Tuple[float, float]:
    """_vector of two numbers, typed as the pair it is (an (x, z) point, gravity)."""
    x, z = _vector(path, value, 2, within)
    return x, z


def number_field(path: str, value: Any, within: Optional[Tuple[float, float]] = None) -> float:
    """An argument that must be a finite number (within `within`, inclusive): TaskError naming `path`."""
    return _number(path, value, within)


def pose_field(path: str, value: Any) -> Tuple[float, float, float]:
    """[x mm, z mm, theta deg] within the coordinate and angle bounds."""
    _vector(path, value, 3)
    return (_number(f"{path}[0]", value[0], COORDINATE), _number(f"{path}[1]", value[1], COORDINATE),
            _number(f"{path}[2]", value[2], ANGLE))


def _name(path: str, value: Any) -> str:
    if isinstance(value, (bool, int, float, datetime.date)):  # YAML 1.1: no/off/yes/on, 007, 2024-01-01
        kind = "boolean" if isinstance(value, bool) else "date" if isinstance(value, datetime.date) else "number"
        raise TaskError(path, f"must be a non-empty string, got {_shown(value)}: YAML read it as a {kind}; put "
                              f"the name in quotes")
    if not isinstance(value, str) or not value.strip():
        raise TaskError(path, f"must be a non-empty string, got {_shown(value)}")
    if len(value) > 100 or any(not ch.isprintable() for ch in value):
        raise TaskError(path, f"must be at most 100 printable characters, got {_shown(value)}")
    return value


def _yaml_kind(value: Any) -> str:
    """What a YAML value is, in YAML's words (an empty value is null)."""
    if value is None:
        return "null (an empty value)"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    kinds: Dict[type, str] = {str: "a string", list: "a list", dict: "a mapping"}
    return kinds.get(type(value), f"a {type(value).__name__}")


def _shown(value: Any, limit: int = 60) -> str:
    """A value for a message: its repr, cut to one short line."""
    text = reprlib.Repr()
    text.maxstring = text.maxother = limit
    text.maxlevel = 2
    shown = text.repr(value).replace("\n", " ")
    return shown if len(shown) <= limit else shown[: limit - 3] + "..."


# An angle written in radians (task files use degrees) is warned about only where no one writes the
# value in degrees, so that a deliberate small turn is not. It is nonzero, at most 2 pi (a radian
# value) and not a whole number of degrees (a turn written in degrees nearly always is), and either
# - in radians it is a round angle: within RADIAN_ROUNDING of a multiple of 5 deg (0.26 is 14.9 deg,
#   0.785 is 45.0, 1.57 is 90.0, 3.14 is 179.9). RADIAN_ROUNDING covers radians rounded to two
#   decimals (off by at most 0.005 rad, 0.29 deg); of the values of one decimal, written in degrees,
#   only 0.7, 1.4, 3.4, 4.1, 4.8, 5.5 and 6.2 lie that near one; or
# - it lies within planner.tolerance's angle of 0: in degrees, a turn the planner cannot tell from
#   none, a fraction nobody writes on purpose.
RADIAN_ROUNDING = 0.3  # deg


def _reads_as_radians(angle: float) -> bool:
    """An angle in degrees that reads as written in radians: nonzero, at most 2 pi, not a whole
    number of degrees, and a round angle in radians (RADIAN_ROUNDING above)."""
    degrees = math.degrees(angle)
    round_angle = abs(degrees - 5.0 * round(degrees / 5.0)) <= RADIAN_ROUNDING and abs(degrees) >= 2.5
    return 0.0 < abs(angle) <= 2.0 * math.pi and angle != round(angle) and round_angle


def planner_parameter(path: str, key: str, value: Any) -> "int | float":
    """`value` for TRRTstar's declared parameter `key`, checked against the core's range for it
    (the CLI's --seed and --max-switches go through here too)."""
    kind, lowest, highest = PLANNER_PARAMETER_RANGES[key]
    if kind == "integer":
        return planner_integer(path, key, value)
    return _number(path, value, (lowest, highest))


def planner_integer(path: str, key: str, value: Any) -> int:
    """planner_parameter of an integer parameter (seed, max_switches, check_limit), typed int."""
    kind, lowest, highest = PLANNER_PARAMETER_RANGES[key]
    assert kind == "integer", f"the planner's {key} is a {kind} parameter"
    return _integer(path, value, int(lowest), int(highest))


def planner_limit(path: str, value: Any) -> float:
    """A time limit [s]: finite, positive, at most the core's MAX_TIME_LIMIT."""
    return _number(path, value, LIMITS["time_limit"])
