"""File units and SI: task and plan files use mm, degrees and grams; the core is SI (m, rad, kg).

A pose in the grasp plane is q = (x, z, theta): mm, mm, deg in files, m, m, rad in the core.
"""
from __future__ import annotations

import math
import numbers
from typing import Any, Iterable, Sequence, Tuple, TypeVar, cast

MM = 1e-3  # m per mm
G = 1e-3  # kg per g

T = TypeVar("T")


def pose_to_si(q: Sequence[float]) -> Tuple[float, float, float]:
    """(x mm, z mm, theta deg) -> (x m, z m, theta rad)."""
    return (q[0] * MM, q[1] * MM, math.radians(q[2]))


def pose_from_si(q: Sequence[float]) -> Tuple[float, float, float]:
    """(x m, z m, theta rad) -> (x mm, z mm, theta deg)."""
    return (q[0] / MM, q[1] / MM, math.degrees(q[2]))


def mm2_to_si(p: Sequence[float]) -> Tuple[float, float]:
    """A point (mm, mm) -> (m, m)."""
    return (p[0] * MM, p[1] * MM)


def as_pair(values: Iterable[T]) -> Tuple[T, T]:
    """tuple(values), typed as the two it holds (an (x, z) point, a (mm, deg) spread, a video's
    size): for values known to be two, or handed to a value type that checks their count itself."""
    return cast(Tuple[T, T], tuple(values))  # the count is the caller's to know; the type checker cannot


def as_triple(values: Iterable[T]) -> Tuple[T, T, T]:
    """tuple(values), typed as the three it holds (a pose x, z, theta): for values known to be
    three (a plan's or a tracker's pose), or handed to a value type that checks their count itself
    (Task)."""
    return cast(Tuple[T, T, T], tuple(values))  # as as_pair


def is_real(value: Any) -> bool:
    """A real number as the API takes one: Python's and numpy's ints and floats, a Fraction; not a
    bool, and not numpy's timedelta64 (which calls itself an integer but is a duration)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return False
    try:
        float(value)
    except OverflowError:  # an int past the double range: a number, if not a finite double
        return True
    except (TypeError, ValueError):
        return False
    return True


def is_integer(value: Any) -> bool:
    """is_real, and an integer (Python's or numpy's)."""
    return is_real(value) and isinstance(value, numbers.Integral)


def is_finite_real(value: Any) -> bool:
    """is_real, and finite as a double."""
    try:
        return is_real(value) and math.isfinite(float(value))
    except OverflowError:
        return False


def angle_difference_deg(a: float, b: float) -> float:
    """a - b [deg], wrapped into [-180, 180): a tracker reports theta in one turn, while a plan's
    theta may lie beyond it (a task at 360 deg is at 0 deg in the world)."""
    return (a - b + 180.0) % 360.0 - 180.0
