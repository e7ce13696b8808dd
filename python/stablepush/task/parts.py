"""The task's physical groups as typed values, each the section of the task file it mirrors (file
units: mm, g, N, s): `PartSpec` the `object:` section, `GripperSpec` the `gripper:` section,
`DynamicsSpec` the `dynamics:` section; the bounds every number of a task is checked against, and
the checks themselves (TypeError for a wrong type, TaskError naming the file's path for a value
out of range), which Task and its other values use too.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Dict, Optional, Sequence, Tuple

from stablepush.compiled import _core
from stablepush.errors import TaskError
from stablepush.task.mesh import PartMesh
from stablepush.units import MM, G, is_integer, is_real, mm2_to_si

# Plausible-physics bounds on world numbers, in file units: the task file's (schema.py) and the
# cell's and robot's values made in code alike. Past them the model's arithmetic (doubles and the
# exact re-check) is no longer meaningful. Far wider than any real cell.
MAX_COORDINATE = 1e4  # mm: vertices, com, pusher ends, pad centres, poses, world positions
MAX_ANGLE = 3600.0  # deg: poses and feature orientations
COORDINATE = (-MAX_COORDINATE, MAX_COORDINATE)
ANGLE = (-MAX_ANGLE, MAX_ANGLE)
LENGTH = (1e-2, MAX_COORDINATE)  # mm: sizes, radii, distances
MU = (0.0, 100.0)  # a friction coefficient
# The part's, the gripper's and the world's numbers (file units), checked by the groups and Task
# whoever makes one: the task file (schema.py) and code alike.
PHYSICS_LIMITS: Dict[str, Tuple[float, float]] = {
    "mass": (1e-3, 1e7),  # g
    "inertia": (1e-15, 1e6),  # kg m^2
    "force": (1e-6, 1e5),  # N
    "gravity": (-1e3, 1e3),  # m/s^2 per component
    "step_time": (1e-4, 1e3),  # s
}

# How pushes are made (dynamics.pushes), which decides how gravity turns in G during a push
# (docs/planner.md, "Gravity during a push"): against features fixed in the world, the object keeps its
# world orientation on each feature and the gripper turns; by a moving pusher, the gripper stays.
PUSHES = ("against_fixed_features", "by_moving_pusher")


def check_finite(field: str, value) -> None:
    """A finite number: TypeError for another type, TaskError naming `field` for inf or nan."""
    if not is_real(value):
        raise TypeError(f"{field} must be a number, got {type(value).__name__}")
    try:
        ok = math.isfinite(float(value))
    except OverflowError:
        ok = False
    if not ok:
        raise TaskError(field, f"must be finite, got {value!r:.40}")


def check_within(field: str, value, within: Tuple[float, float]) -> None:
    """A finite number (check_finite) from within[0] to within[1]: TaskError naming `field`, as the
    task file's own check words it."""
    check_finite(field, value)
    if not within[0] <= float(value) <= within[1]:
        raise TaskError(field, f"must be between {within[0]:g} and {within[1]:g}, got {float(value):g}")


def check_vector(field: str, value, size: int) -> None:
    """`size` finite numbers in a tuple or list (TypeError otherwise)."""
    if not isinstance(value, (tuple, list)) or len(value) != size:
        raise TypeError(f"{field} must be {size} numbers, got {value!r:.60}")
    for v in value:
        check_finite(field, v)


def check_each(field: str, value, size: int, bounds: Sequence[Tuple[float, float]]) -> None:
    """`size` finite numbers (TypeError otherwise), the i-th within bounds[i] (the last bound for
    the rest): TaskError naming field[i]."""
    check_vector(field, value, size)
    for i, v in enumerate(value):
        check_within(f"{field}[{i}]", v, bounds[min(i, len(bounds) - 1)])


def check_integer(field: str, value) -> None:
    """An integer, not a bool (TypeError otherwise)."""
    if isinstance(value, bool) or not is_integer(value):
        raise TypeError(f"{field} must be an integer, got {value!r:.40}")


@dataclass(frozen=True)
class PartSpec:
    """The task file's `object:` section: the cross-section's `vertices` in O (mm,
    counterclockwise), the `thickness` along y (mm), the `mass` (g), the centre of mass `com` (mm
    in O; None: the centroid), the moment of inertia `inertia` about the com and y (kg m^2; None:
    a uniform prism's) and, for shape: mesh, the solid the section was cut from (`mesh`: the pads'
    faces are checked on it, the simulators run it; None for a box or a polygon, which are the slab
    itself). Made with a field of the wrong type it raises TypeError, with a number out of range
    TaskError, each naming the field (object.mass)."""

    vertices: Tuple[Tuple[float, float], ...]
    thickness: float
    mass: float
    com: Optional[Tuple[float, float]] = None
    inertia: Optional[float] = None
    mesh: Optional[PartMesh] = None

    def __post_init__(self) -> None:
        check_within("object.thickness", self.thickness, LENGTH)
        check_within("object.mass", self.mass, PHYSICS_LIMITS["mass"])
        if not isinstance(self.vertices, (tuple, list)) or len(self.vertices) < 3:
            raise TypeError("object.vertices must be a sequence of at least 3 (x, z) pairs")
        for i, v in enumerate(self.vertices):
            check_each(f"object.vertices[{i}]", v, 2, [COORDINATE])
        if self.com is not None:  # a numpy array too, taken as the pair it holds
            com: Any = self.com  # typed a pair; an array is taken too
            com = com.tolist() if getattr(com, "ndim", None) == 1 else com
            check_vector("object.com", com, 2)
            object.__setattr__(self, "com", tuple(float(v) for v in com))
        if self.inertia is not None:
            check_within("object.inertia", self.inertia, PHYSICS_LIMITS["inertia"])
        if self.mesh is not None and not isinstance(self.mesh, PartMesh):
            raise TypeError(f"object.mesh must be a PartMesh or None, got {type(self.mesh).__name__}")

    def section(self) -> "_core.CrossSection":
        """The core's cross-section: the outline's corners (outline_corners), in m."""
        return _core.CrossSection([mm2_to_si(v) for v in outline_corners(self.vertices)])

    def rigid_body(self, section: "Optional[_core.CrossSection]" = None) -> "_core.RigidBody":
        """The part's mass [kg], com [m, in O] and moment of inertia about y at the com [kg m^2]."""
        uniform = _core.RigidBody.uniform(section or self.section(), self.mass * G)
        com = mm2_to_si(self.com) if self.com is not None else tuple(uniform.com)
        if self.inertia is not None:
            inertia = self.inertia
        else:  # the uniform body's inertia about the given com (parallel axes)
            offset2 = (com[0] - uniform.com[0]) ** 2 + (com[1] - uniform.com[1]) ** 2
            inertia = uniform.inertia + self.mass * G * offset2
        return _core.RigidBody(self.mass * G, com, inertia)


@dataclass(frozen=True)
class GripperSpec:
    """The task file's `gripper:` section: the `grip_force` per pad (N), the pads' friction `mu`
    with the object, `pad_rings` (the rings of contact points each pad is replaced by,
    docs/model.md section 2) and the `pads`, each ((x, z) centre mm in G, radius mm). Made with a
    field of the wrong type it raises TypeError, with a number out of range TaskError, each naming
    the field (gripper.mu)."""

    grip_force: float
    mu: float
    pad_rings: int
    pads: Tuple[Tuple[Tuple[float, float], float], ...]

    def __post_init__(self) -> None:
        check_within("gripper.grip_force", self.grip_force, PHYSICS_LIMITS["force"])
        check_within("gripper.mu", self.mu, MU)
        if not isinstance(self.pads, (tuple, list)) or not self.pads:
            raise TypeError("gripper.pads must be a sequence of ((x, z), radius)")
        for i, pad in enumerate(self.pads):
            if not isinstance(pad, (tuple, list)) or len(pad) != 2:
                raise TypeError(f"gripper.pads[{i}] must be ((x, z), radius)")
            check_each(f"gripper.pads[{i}].center", pad[0], 2, [COORDINATE])
            check_within(f"gripper.pads[{i}].radius", pad[1], LENGTH)
        check_integer("gripper.pad_rings", self.pad_rings)

    def core(self) -> "_core.Gripper":
        """The core's gripper: the pads in m, each replaced by its rings of points."""
        return _core.Gripper([_core.Pad(mm2_to_si(c), r * MM) for c, r in self.pads], self.grip_force, self.mu,
                             self.pad_rings)


@dataclass(frozen=True)
class DynamicsSpec:
    """The task file's `dynamics:` section: the `step_time` a unit push takes (s), the sides of the
    polygon a sticking point's friction disc is replaced by (`friction_polygon_sides`) and how
    pushes are made (`pushes`, one of PUSHES). Made with a field of the wrong type it raises
    TypeError, with a value the file refuses TaskError, each naming the field (dynamics.step_time)."""

    step_time: float
    friction_polygon_sides: int
    pushes: str = PUSHES[0]

    def __post_init__(self) -> None:
        check_within("dynamics.step_time", self.step_time, PHYSICS_LIMITS["step_time"])
        check_integer("dynamics.friction_polygon_sides", self.friction_polygon_sides)
        if not isinstance(self.pushes, str) or self.pushes not in PUSHES:
            raise TaskError("dynamics.pushes", f"must be one of {', '.join(PUSHES)}, got {self.pushes!r:.40}")


ON_BOUNDARY = 1e-6  # mm: closer than this, a point is on an edge (the core's tolerance, 1e-9 m)


def outline_corners(vertices: Sequence[Tuple[float, float]]) -> Tuple[Tuple[float, float], ...]:
    """The outline's vertices less its straight ones, as the core takes them (mm, in order).

    A vertex is straight when it lies within ON_BOUNDARY of the segment between its neighbours and
    between them; CAD outlines have them. The core takes each edge as one face, so a pusher across
    a straight vertex would be off every edge and one at it on a corner. A run of straight vertices
    between two corners is dropped only when every one of them lies within ON_BOUNDARY of the
    segment joining those corners, in order along it, so the shape stays the same to ON_BOUNDARY.
    An outline with fewer than three corners is returned as it is (CrossSection.defect names it)."""
    n = len(vertices)

    def straight(a, v, b) -> bool:
        chord = (b[0] - a[0], b[1] - a[1])
        length = math.hypot(*chord)
        if length == 0.0:
            return False
        along = ((v[0] - a[0]) * chord[0] + (v[1] - a[1]) * chord[1]) / length
        off = abs(chord[0] * (v[1] - a[1]) - chord[1] * (v[0] - a[0])) / length
        return off <= ON_BOUNDARY and 0.0 < along < length

    corners = [i for i in range(n) if not straight(vertices[i - 1], vertices[i], vertices[(i + 1) % n])]
    if len(corners) < 3:
        return tuple(vertices)
    kept = []
    for k, a in enumerate(corners):
        b = corners[(k + 1) % len(corners)]
        run = [(a + j) % n for j in range(1, (b - a) % n)]
        kept.append(a)
        line = [vertices[a]] + [vertices[i] for i in run] + [vertices[b]]
        on_one_edge = all(straight(vertices[a], vertices[i], vertices[b]) for i in run) and all(
            straight(p, q, vertices[b]) for p, q in zip(line, line[1:-1]))  # in order along the edge
        if not on_one_edge:
            kept.extend(run)
    return tuple(vertices[i] for i in kept)
