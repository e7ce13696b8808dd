"""Poses in the grasp and the tolerance a goal is met within, in file units (docs/model.md
section 1): an in-grasp pose q = (x, z, theta) places O in G, x and z in mm, theta in degrees.

Angles are compared wrapped, in one place (`Pose.minus`): a tracker reports theta within one turn
while a plan's theta may lie beyond it, and a part turned a whole turn in the pads is where it was.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterator, List, Mapping, Sequence, Tuple, Union

from stablepush.errors import SettingError
from stablepush.units import MM, angle_difference_deg

PoseLike = Union["Pose", Sequence[float], Mapping[str, float]]


@dataclass(frozen=True)
class Pose:
    """q = (x, z, theta): O's origin at (x, z) mm in G, turned theta deg about y (docs/model.md
    section 1). Iterates as (x, z, theta), so it goes where a pose tuple went."""

    x: float
    z: float
    theta: float

    @classmethod
    def of(cls, value: PoseLike) -> "Pose":
        """A Pose from a Pose, an (x, z, theta) sequence or a {"x", "z", "theta"} mapping (a
        tracker's or a report's)."""
        if isinstance(value, Pose):
            return value
        if isinstance(value, Mapping):
            return cls(float(value["x"]), float(value["z"]), float(value["theta"]))
        x, z, theta = value
        return cls(float(x), float(z), float(theta))

    def __iter__(self) -> Iterator[float]:
        return iter((self.x, self.z, self.theta))

    def minus(self, other: PoseLike) -> Tuple[float, float, float]:
        """self - other: (dx mm, dz mm, dtheta deg wrapped into [-180, 180))."""
        o = Pose.of(other)
        return self.x - o.x, self.z - o.z, angle_difference_deg(self.theta, o.theta)

    def as_dict(self) -> dict:
        return {"x": self.x, "z": self.z, "theta": self.theta}

    def si(self) -> Tuple[float, float, float]:
        """(x m, z m, theta rad), as the core takes a pose."""
        return self.x * MM, self.z * MM, math.radians(self.theta)


@dataclass(frozen=True)
class Tolerance:
    """How near a pose must be to a goal: within `position` mm in x and in z, each, and within
    `angle` deg in theta (wrapped). The planner's goal, a run's verdict, the closed loop's
    thresholds, evaluate's and design's measures all ask it."""

    position: float  # mm, in x and in z each
    angle: float  # deg

    def __post_init__(self):
        # A nan tolerance would call every pose a miss, a negative one too: refused where it is made.
        if not all(isinstance(v, (int, float)) and math.isfinite(v) and v > 0 for v in (self.position, self.angle)):
            raise SettingError("tolerance", f"must be two finite numbers above 0 (mm, deg), got "
                                            f"({self.position!r:.20}, {self.angle!r:.20})")

    @classmethod
    def of(cls, value: "Tolerance | Sequence[float]") -> "Tolerance":
        """A Tolerance from a Tolerance or a (mm, deg) pair (a task file's planner.tolerance)."""
        if isinstance(value, Tolerance):
            return value
        try:
            position, angle = (float(v) for v in value)
        except (TypeError, ValueError):
            raise SettingError("tolerance", f"must be two finite numbers above 0 (mm, deg), "
                                            f"got {value!r:.60}") from None
        return cls(position, angle)

    def __iter__(self) -> Iterator[float]:
        return iter((self.position, self.angle))

    def offsets(self, pose: PoseLike, goal: PoseLike) -> Tuple[float, float, float]:
        """`pose`'s offsets from `goal` in x, z and theta, each over its tolerance (signed)."""
        dx, dz, dtheta = Pose.of(pose).minus(goal)
        return dx / self.position, dz / self.position, dtheta / self.angle

    def used(self, pose: PoseLike, goal: PoseLike) -> float:
        """The share of the tolerance `pose` uses: the largest of its offsets from `goal` over the
        tolerance, in x, z and theta; 0 at the goal, 1 at the tolerance's edge."""
        return max(abs(v) for v in self.offsets(pose, goal))

    def within(self, pose: PoseLike, goal: PoseLike) -> bool:
        """Whether `pose` lies within the tolerance of `goal` in each coordinate."""
        dx, dz, dtheta = Pose.of(pose).minus(goal)
        return abs(dx) <= self.position and abs(dz) <= self.position and abs(dtheta) <= self.angle

    def scaled(self, share: float) -> "Tolerance":
        """`share` of this tolerance, in each coordinate."""
        return Tolerance(self.position * share, self.angle * share)

    def as_list(self) -> List[float]:
        """[mm, deg], a task file's planner.tolerance."""
        return [self.position, self.angle]

    def si(self) -> Tuple[float, float]:
        """(m, rad), as the core's goal takes it."""
        return self.position * MM, math.radians(self.angle)

    def describe(self) -> str:
        return f"{self.position:g} mm, {self.position:g} mm, {self.angle:g} deg"
