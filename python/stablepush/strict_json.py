"""JSON as stablepush reads it from files and sockets: numbers must be finite, and nesting ends
in a ValueError rather than a RecursionError. Shared by plan files (plan_io) and the arm protocol."""
from __future__ import annotations

import json
import math
from typing import Any


def loads(text: str) -> Any:
    """json.loads, refusing NaN and Infinity; ValueError (json.JSONDecodeError among them) on any
    malformed or too deeply nested text."""
    try:
        return json.loads(text, parse_constant=_refuse_constant)
    except RecursionError:
        raise ValueError("nested too deeply") from None


def is_finite_number(v: Any) -> bool:
    """A JSON number that is a finite double (an integer past the double range is not)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return False
    try:
        return math.isfinite(v)
    except OverflowError:
        return False


def _refuse_constant(name: str):
    raise ValueError(f"{name} is not a number JSON allows here")
