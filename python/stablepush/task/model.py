"""The task: the object, pads, pushers, start and goal in file units (mm, deg, g, N), and the
core's stable-push model built from it in SI (docs/model.md sections 1-4 and 7).

`stablepush.task.schema` makes a Task from a task file; this module knows nothing of files.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple

from stablepush.compiled import _core
from stablepush.errors import SettingError, TaskError
from stablepush.pose import Tolerance
from stablepush.task.mesh import PartMesh
from stablepush.task.robot_files import model_source
from stablepush.units import MM, G, as_triple, is_integer, is_real, mm2_to_si, pose_to_si

# Plausible-physics bounds on world numbers, in file units: the task file's (schema.py) and the
# cell's and robot's values made in code alike. Past them the model's arithmetic (doubles and the
# exact re-check) is no longer meaningful. Far wider than any real cell.
MAX_COORDINATE = 1e4  # mm: vertices, com, pusher ends, pad centres, poses, world positions
MAX_ANGLE = 3600.0  # deg: poses and feature orientations
COORDINATE = (-MAX_COORDINATE, MAX_COORDINATE)
ANGLE = (-MAX_ANGLE, MAX_ANGLE)
LENGTH = (1e-2, MAX_COORDINATE)  # mm: sizes, radii, distances
JOINT_SPEED = (1e-3, 1e3)  # rad/s or m/s: environment.robot.max_joint_speed
# A robot model file is named by one of these endings (MuJoCo compiles both; Drake parses both).
ROBOT_MODEL_SUFFIXES = (".urdf", ".xml", ".mjcf")
MAX_NAME = 100  # characters of a name (a pusher's, the flange's)
MU = (0.0, 100.0)  # a friction coefficient
# The part's, the gripper's and the world's numbers (file units), checked by Task whoever makes
# one: the task file (schema.py) and code alike.
PHYSICS_LIMITS: Dict[str, Tuple[float, float]] = {
    "mass": (1e-3, 1e7),  # g
    "inertia": (1e-15, 1e6),  # kg m^2
    "force": (1e-6, 1e5),  # N
    "gravity": (-1e3, 1e3),  # m/s^2 per component
    "step_time": (1e-4, 1e3),  # s
}
MAX_PUSHER_POINTS = 20  # a line pusher's contact points
# The planner section's numbers (file units), checked by PlannerSettings whoever makes one: the
# task file (schema.py) and code alike.
PLANNER_LIMITS: Dict[str, Tuple[float, float]] = {
    "step": (1e-3, 1e3),  # mm or deg per unit step
    "tolerance": (1e-4, 1e4),  # mm or deg
    "time_limit": (1e-6, _core.MAX_TIME_LIMIT),  # s
    "min_margin": (0.0, 1e6),  # N
    "sampling_margin": (0.0, 1e3),  # unit steps
    "min_hold_ratio": (0.0, 1e3),
    "end_within": (0.01, 1.0),  # a share of the tolerance; 1: the tolerance's edge will do
}

# How pushes are made (dynamics.pushes), which decides how gravity turns in G during a push
# (docs/planner.md, "Gravity during a push"): against features fixed in the world, the object keeps its
# world orientation on each feature and the gripper turns; by a moving pusher, the gripper stays.
PUSHES = ("against_fixed_features", "by_moving_pusher")


def _finite(field: str, value) -> None:
    if not is_real(value):
        raise TypeError(f"{field} must be a number, got {type(value).__name__}")
    try:
        ok = math.isfinite(float(value))
    except OverflowError:
        ok = False
    if not ok:
        raise TaskError(field, f"must be finite, got {value!r:.40}")


def _within(field: str, value, within: Tuple[float, float]) -> None:
    """A finite number (TypeError, ValueError as _finite) from within[0] to within[1]: TaskError
    naming `field`, as the task file's own check words it."""
    _finite(field, value)
    if not within[0] <= float(value) <= within[1]:
        raise TaskError(field, f"must be between {within[0]:g} and {within[1]:g}, got {float(value):g}")


def _within_each(field: str, value, size: int, bounds: Sequence[Tuple[float, float]]) -> None:
    """`size` finite numbers (TypeError otherwise), the i-th within bounds[i] (the last bound for
    the rest): TaskError naming field[i]."""
    _finite_vector(field, value, size)
    for i, v in enumerate(value):
        _within(f"{field}[{i}]", v, bounds[min(i, len(bounds) - 1)])


def _world_pose(field: str, value, size: int) -> None:
    """x, y, z mm (COORDINATE) then angles deg (ANGLE), each named field[i]."""
    _finite_vector(field, value, size)
    for i, v in enumerate(value):
        _within(f"{field}[{i}]", v, COORDINATE if i < 3 else ANGLE)


def _robot_model(value: str) -> str:
    """A robot model's file, `~` expanded: an existing URDF or MJCF file (TaskError otherwise)."""
    try:
        path = Path(value).expanduser()
    except RuntimeError:  # ~user of no such user: named as given, and found nowhere
        path = Path(value)
    if path.suffix.lower() not in ROBOT_MODEL_SUFFIXES:
        raise TaskError("environment.robot.model",
                        f"{value!r:.80} is not a URDF or MJCF file (it ends {', '.join(ROBOT_MODEL_SUFFIXES)})")
    try:
        found = path.is_file()
    except OSError:  # a name longer than the system allows, say
        found = False
    if not found:
        raise TaskError("environment.robot.model", f"no file {str(path)!r:.120}")
    model_source(path)  # read now, every file it names protected as an input (RobotError, a TaskError)
    return str(path)


def _integer(field: str, value) -> None:
    if isinstance(value, bool) or not is_integer(value):
        raise TypeError(f"{field} must be an integer, got {value!r:.40}")


def _string_mapping_of_numbers(field: str, value, keys=None) -> Dict[str, float]:
    """`value` as a new dict of names to finite floats (TypeError or ValueError naming the field;
    `keys`: the names it may hold)."""
    if not isinstance(value, dict):
        raise TypeError(f"{field} must be a mapping of names to numbers, got {type(value).__name__}")
    out = {}
    for key, v in value.items():
        if not isinstance(key, str) or (keys is not None and key not in keys):
            allowed = f" (one of {', '.join(keys)})" if keys is not None else ""
            raise TaskError(field, f"{key!r:.40} is not a name it takes{allowed}")
        _finite(f"{field}.{key}", v)
        out[key] = float(v)
    return out


def _finite_vector(field: str, value, size: int) -> None:
    if not isinstance(value, (tuple, list)) or len(value) != size:
        raise TypeError(f"{field} must be {size} numbers, got {value!r:.60}")
    for v in value:
        _finite(field, v)


@dataclass(frozen=True)
class PlannerSettings:
    """The task's `planner:` section as a typed value, in file units (docs/model.md section 3):
    `time_limit` [s], `seed`, `max_switches`, the unit `step` and the goal's `tolerance` (mm, deg),
    `min_margin` [N], `sampling_margin` [unit steps], `min_hold_ratio` [times the weight],
    `end_within` (the share of the tolerance, in each coordinate, a plan's end should lie within:
    plan.search makes a deeper search where the first plan ends further out), and
    `tuning`: T-RRT*'s other declared parameters (goal_bias, pivot_steps, ...: their names and
    ranges are the core's, `_core.TRRT_STAR_PARAMETER_RANGES`), only those given. Made with a
    field of the wrong shape it raises TypeError or ValueError naming it; the task file's ranges
    are checked where the file is read (schema.py)."""

    time_limit: float = 10.0
    seed: int = 1
    max_switches: int = 1
    step: Tuple[float, float] = (1.0, 1.0)
    tolerance: Tuple[float, float] = (1.0, 1.0)
    min_margin: float = 1e-3
    sampling_margin: float = 5.0
    min_hold_ratio: float = 0.0
    end_within: float = 0.5
    tuning: Dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        """Each field's type (TypeError) and range (TaskError naming planner.KEY), as the task
        file's planner section is checked: PLANNER_LIMITS and the core's declared parameters."""
        for name in ("time_limit", "min_margin", "sampling_margin", "min_hold_ratio", "end_within"):
            _within(f"planner.{name}", getattr(self, name), PLANNER_LIMITS[name])
            object.__setattr__(self, name, float(getattr(self, name)))
        for name in ("seed", "max_switches"):
            if isinstance(getattr(self, name), bool) or not is_integer(getattr(self, name)):
                raise TypeError(f"planner.{name} must be an integer, got {getattr(self, name)!r:.40}")
            _within(f"planner.{name}", getattr(self, name), _core.TRRT_STAR_PARAMETER_RANGES[name][1:])
            object.__setattr__(self, name, int(getattr(self, name)))
        for name in ("step", "tolerance"):
            _finite_vector(f"planner.{name}", getattr(self, name), 2)
            for i, v in enumerate(getattr(self, name)):
                _within(f"planner.{name}[{i}]", v, PLANNER_LIMITS[name])
            object.__setattr__(self, name, tuple(float(v) for v in getattr(self, name)))
        if not isinstance(self.tuning, dict):
            raise TypeError(f"planner.tuning must be a mapping, got {type(self.tuning).__name__}")
        object.__setattr__(self, "tuning", dict(self.tuning))  # its own: the caller's mapping may change
        for key, value in self.tuning.items():
            if key not in _core.TRRT_STAR_PARAMETER_RANGES or key in ("seed", "max_switches"):
                raise TaskError(f"planner.{key!s:.40}", "not a planner setting")
            _within(f"planner.{key}", value, _core.TRRT_STAR_PARAMETER_RANGES[key][1:])

    @classmethod
    def from_mapping(cls, values: Dict[str, Any]) -> "PlannerSettings":
        """The settings of a planner section in the task file's form: its keys, the tuning ones
        among them; PLANNER_DEFAULTS for those left out."""
        given = dict(values)
        named = {f.name for f in dataclasses.fields(cls)} - {"tuning"}
        tuning = {key: given.pop(key) for key in list(given) if key not in named}
        return cls(**given, tuning=tuning)

    def replace(self, **changes: Any) -> "PlannerSettings":
        """These settings with `changes`, any key of the task file's planner section, a tuning one
        too (a change of None leaves that key as it is)."""
        return PlannerSettings.from_mapping({**self.as_dict(), **{k: v for k, v in changes.items() if v is not None}})

    def as_dict(self) -> Dict[str, Any]:
        """The settings in the task file's form (plain values; step and tolerance as lists)."""
        out: Dict[str, Any] = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "tuning"}
        out["step"], out["tolerance"] = list(self.step), list(self.tolerance)
        return {**out, **self.tuning}

    def with_check_limit(self, checks: int) -> "PlannerSettings":
        """These settings bounded by at most `checks` stable-push tests (their own check_limit where
        lower)."""
        own = int(self.tuning.get("check_limit", 0))
        return self.replace(check_limit=min(checks, own) if own else checks)

    def core_parameters(self) -> Dict[str, str]:
        """T-RRT*'s declared parameters by name, as text: how an OMPL planner's ParamSet takes them."""
        return {"seed": str(self.seed), "max_switches": str(self.max_switches),
                **{key: repr(value) for key, value in self.tuning.items()}}


# uncertainty: key -> the task value it widens (+- this fraction of it); a push must be stable for
# every value in the box (Task.corner_models).
UNCERTAIN = {"pad_mu": "gripper.mu", "pusher_mu": "pushers[].mu", "grip_force": "gripper.grip_force",
             "mass": "object.mass"}


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


# The planner section's keys every task has, in the task file's form; a task file (or a Task
# made in code) that leaves one out gets these (docs/model.md section 3).
PLANNER_DEFAULTS: Dict[str, Any] = PlannerSettings().as_dict()


@dataclass(frozen=True)
class Robot:
    """The arm a plan runs on, as the task's `environment.robot` section gives it: `model`, a URDF
    or MJCF file of the arm (None: the shipped arm, stablepush/sim/arm.xml), `flange`, the link
    (body) the project's jaws mount on, `tcp`, the grasp frame G in the flange's frame (x, y, z mm
    and the fixed-axis roll, pitch, yaw deg of a URDF `rpy`), `base`, the arm's base in the world
    (x, y, z mm and yaw deg about the world's z), and `max_joint_speed` [rad/s, or m/s for a
    sliding joint], the limit of a joint whose model gives none (URDF `limit velocity` is read).
    Made with a field of the wrong type it raises TypeError naming it; with one the task file
    would refuse (a model that is no URDF or MJCF file, a number out of its range), TaskError
    naming the field, before anything reads the model."""

    model: Optional[str] = None
    flange: str = "hand"
    tcp: Tuple[float, float, float, float, float, float] = (0.0, 0.0, 110.0, 0.0, 180.0, 0.0)
    base: Tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    max_joint_speed: float = 2.5

    def __post_init__(self) -> None:
        if self.model is not None and (not isinstance(self.model, str) or not self.model):
            raise TypeError(f"environment.robot.model must be a file name, got {self.model!r:.60}")
        if not isinstance(self.flange, str):
            raise TypeError(f"environment.robot.flange must be a link name, got {self.flange!r:.60}")
        if not self.flange.strip() or len(self.flange) > MAX_NAME or not self.flange.isprintable():
            raise TaskError("environment.robot.flange", f"must be at most {MAX_NAME} printable characters, not all "
                                                        f"spaces, got {self.flange!r:.60}")
        _world_pose("environment.robot.tcp", self.tcp, 6)
        _world_pose("environment.robot.base", self.base, 4)
        _within("environment.robot.max_joint_speed", self.max_joint_speed, JOINT_SPEED)
        if self.model is not None:
            object.__setattr__(self, "model", _robot_model(self.model))
        object.__setattr__(self, "tcp", tuple(float(v) for v in self.tcp))
        object.__setattr__(self, "base", tuple(float(v) for v in self.base))
        object.__setattr__(self, "max_joint_speed", float(self.max_joint_speed))

    @property
    def shipped(self) -> bool:
        """Whether this is the shipped arm (no model file)."""
        return self.model is None

    @classmethod
    def from_mapping(cls, values: Dict[str, Any]) -> "Robot":
        """The robot of an environment.robot section in the task file's form; defaults for keys
        left out (a model without a flange or tcp has no sensible default: the schema asks)."""
        named = {f.name for f in dataclasses.fields(cls)}
        unknown = [key for key in values if key not in named]
        if unknown:
            raise TaskError(f"environment.robot.{unknown[0]!s:.40}", f"not a setting of the robot "
                                                                     f"({', '.join(sorted(named))})")
        if values.get("model") is not None:  # a lab's model: where its jaws go is its own, no default
            for key in ("flange", "tcp"):
                if key not in values:
                    raise TaskError(f"environment.robot.{key}", "missing: a robot model needs its flange and tcp")
        return cls(**values)

    def replace(self, **changes: Any) -> "Robot":
        """This robot with the fields given not None changed (a command line's options)."""
        return dataclasses.replace(self, **{k: v for k, v in changes.items() if v is not None})

    def as_dict(self) -> Dict[str, Any]:
        """The robot in the task file's form (plain values; lists for vectors)."""
        return {"model": self.model, "flange": self.flange, "tcp": list(self.tcp), "base": list(self.base),
                "max_joint_speed": self.max_joint_speed}


@dataclass(frozen=True)
class Cell:
    """The task's `environment:` section, the cell the arm works in, as a typed value (mm and deg in
    the world frame: x forward, y along the gripping axis at home, z up): G's `home` position (G's
    axes are the world's there), how far the object backs off a feature (`retract`), how far apart
    default features stand along y (`station_spacing`) and how far from a feature moves between
    them run (`lane_offset`), where given features hold the object (`features`: pusher -> [x, y,
    z, theta about world y]; the others are placed by stablepush.execution.world), whether a
    run ends with the object on its last feature (`end_on_feature`), and the arm (`robot`, a
    Robot; the shipped arm when the task names none). Made with a field of the wrong
    shape it raises TypeError or ValueError naming it, with a number out of the task file's range
    TaskError naming the field (which features name the task's pushers is the task's check)."""

    home: Tuple[float, float, float] = (450.0, 0.0, 300.0)
    retract: float = 20.0
    station_spacing: float = 150.0
    lane_offset: float = 75.0
    features: Dict[str, Tuple[float, float, float, float]] = field(default_factory=dict)
    end_on_feature: bool = False
    robot: Robot = field(default_factory=Robot)

    def __post_init__(self) -> None:
        _world_pose("environment.home", self.home, 3)
        if isinstance(self.robot, dict):
            object.__setattr__(self, "robot", Robot.from_mapping(self.robot))
        if not isinstance(self.robot, Robot):
            raise TypeError(f"environment.robot must be a Robot or a mapping, got {type(self.robot).__name__}")
        object.__setattr__(self, "home", tuple(float(v) for v in self.home))
        for name in ("retract", "station_spacing", "lane_offset"):
            _within(f"environment.{name}", getattr(self, name), LENGTH)
            object.__setattr__(self, name, float(getattr(self, name)))
        if not isinstance(self.end_on_feature, bool):
            raise TypeError(f"environment.end_on_feature must be true or false, got {self.end_on_feature!r:.40}")
        if not isinstance(self.features, dict):
            raise TypeError("environment.features must map pusher names to [x, y, z, theta] (mm, deg)")
        for name, pose in self.features.items():
            if not isinstance(name, str):
                raise TypeError(f"environment.features: its keys are pusher names, got {name!r:.40}")
            _world_pose(f"environment.features.{name}", pose, 4)
        object.__setattr__(self, "features", {name: tuple(float(v) for v in pose)
                                              for name, pose in self.features.items()})

    @classmethod
    def from_mapping(cls, values: Dict[str, Any]) -> "Cell":
        """The cell of an environment section in the task file's form; defaults for keys left out."""
        named = {f.name for f in dataclasses.fields(cls)}
        unknown = [key for key in values if key not in named]
        if unknown:
            raise TaskError(f"environment.{unknown[0]!s:.40}",
                            f"not a setting of the cell ({', '.join(sorted(named))})")
        return cls(**values)

    def as_dict(self) -> Dict[str, Any]:
        """The cell in the task file's form (plain values; lists for vectors)."""
        return {"home": list(self.home), "retract": self.retract, "station_spacing": self.station_spacing,
                "lane_offset": self.lane_offset, "features": {k: list(v) for k, v in self.features.items()},
                "end_on_feature": self.end_on_feature, "robot": self.robot.as_dict()}


@dataclass(frozen=True)
class PusherSpec:
    """A pusher as the task gives it, in O [mm]; `a == b` for a point pusher."""

    name: str
    a: Tuple[float, float]
    b: Tuple[float, float]
    mu: float
    points: int

    def __post_init__(self) -> None:
        """The shape of the fields (TypeError or ValueError naming the field), as Task's."""
        if not isinstance(self.name, str):
            raise TypeError(f"PusherSpec.name must be a string, got {type(self.name).__name__}")
        if not self.name.strip() or len(self.name) > MAX_NAME:
            raise TaskError("pushers[].name", f"must be a name of 1 to {MAX_NAME} characters, got {self.name!r:.40}")
        for end in ("a", "b"):
            _within_each(f"pushers.{self.name:.40}.{end}", getattr(self, end), 2, [COORDINATE])
            object.__setattr__(self, end, tuple(float(v) for v in getattr(self, end)))
        _within(f"pushers.{self.name:.40}.mu", self.mu, MU)
        _integer(f"pushers.{self.name:.40}.points", self.points)
        _within(f"pushers.{self.name:.40}.points", self.points, (1, MAX_PUSHER_POINTS))

    @property
    def is_point(self) -> bool:
        return self.a == self.b


@dataclass(frozen=True)
class Task:
    """A validated task, in file units (mm, deg, g, N); `build_model` converts to SI."""

    name: str
    vertices: Tuple[Tuple[float, float], ...]  # cross-section in O, mm, counterclockwise
    thickness: float  # mm along y
    mass: float  # g
    com: Optional[Tuple[float, float]]  # mm in O; None: the centroid
    inertia: Optional[float]  # kg m^2 about the com; None: uniform body
    grip_force: float  # N per pad
    mu: float  # pad-object friction
    pad_rings: int
    pads: Tuple[Tuple[Tuple[float, float], float], ...]  # (centre mm in G, radius mm)
    gravity: Tuple[float, float]  # m/s^2 in G while G's axes are the world's (at the home pose)
    step_time: float  # s
    friction_polygon_sides: int
    pushers: Tuple[PusherSpec, ...]
    start: Tuple[float, float, float]  # mm, mm, deg
    goal: Tuple[float, float, float]
    # A mapping in the task file's form is taken as PlannerSettings.from_mapping of it.
    planner: PlannerSettings = field(default_factory=PlannerSettings)
    environment: Cell = field(default_factory=Cell)  # a mapping in the file's form is taken as Cell.from_mapping
    source: Optional[str] = None
    pushes: str = PUSHES[0]  # see PUSHES
    # shape: mesh: the solid the section was cut from (the pads' faces are checked on it, the
    # simulators run it); None for a box or a polygon, which are the slab itself.
    mesh: Optional[PartMesh] = None
    uncertainty: Dict[str, float] = field(default_factory=dict)  # key -> +- fraction of nominal (UNCERTAIN)
    # What the file says that is legal but probably not meant (each names the field); the CLI
    # prints them as "warning:" lines.
    warnings: Tuple[str, ...] = ()
    # Per pusher, the object's world orientation on its feature (deg) where environment.features
    # does not give it; empty: the start's. with_start fills it.
    feature_orientations: Dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        """The shape of the fields (TypeError or ValueError naming the field): a Task made by
        `load_task`/`parse_task` always has it; one edited in code (dataclasses.replace) must too,
        before anything reaches the core."""
        if not isinstance(self.name, str):
            raise TypeError(f"Task.name must be a string, got {type(self.name).__name__}")
        if isinstance(self.planner, dict):
            object.__setattr__(self, "planner", PlannerSettings.from_mapping(self.planner))
        if not isinstance(self.planner, PlannerSettings):
            raise TypeError(f"Task.planner must be PlannerSettings or a mapping, got {type(self.planner).__name__}")
        if isinstance(self.environment, dict):
            object.__setattr__(self, "environment", Cell.from_mapping(self.environment))
        if not isinstance(self.environment, Cell):
            raise TypeError(f"Task.environment must be a Cell or a mapping, got {type(self.environment).__name__}")
        for name, bounds in (("thickness", LENGTH), ("mass", PHYSICS_LIMITS["mass"]),
                             ("grip_force", PHYSICS_LIMITS["force"]), ("mu", MU),
                             ("step_time", PHYSICS_LIMITS["step_time"])):
            _within(f"Task.{name}", getattr(self, name), bounds)
        _within_each("Task.gravity", self.gravity, 2, [PHYSICS_LIMITS["gravity"]])
        _within_each("Task.start", self.start, 3, [COORDINATE, COORDINATE, ANGLE])
        _within_each("Task.goal", self.goal, 3, [COORDINATE, COORDINATE, ANGLE])
        if not isinstance(self.vertices, (tuple, list)) or len(self.vertices) < 3:
            raise TypeError("Task.vertices must be a sequence of at least 3 (x, z) pairs")
        for i, v in enumerate(self.vertices):
            _within_each(f"Task.vertices[{i}]", v, 2, [COORDINATE])
        if not isinstance(self.pads, (tuple, list)) or not self.pads:
            raise TypeError("Task.pads must be a sequence of ((x, z), radius)")
        for i, pad in enumerate(self.pads):
            if not isinstance(pad, (tuple, list)) or len(pad) != 2:
                raise TypeError(f"Task.pads[{i}] must be ((x, z), radius)")
            _within_each(f"Task.pads[{i}].center", pad[0], 2, [COORDINATE])
            _within(f"Task.pads[{i}] radius", pad[1], LENGTH)
        if not isinstance(self.pushers, (tuple, list)) or not all(isinstance(p, PusherSpec) for p in self.pushers):
            raise TypeError("Task.pushers must be a sequence of PusherSpec")
        self._check_the_other_fields()

    def _check_the_other_fields(self) -> None:
        """The fields __post_init__ has not checked: each one's type, named (an edited Task with
        uncertainty=None, say, escaped from sp.check and sp.plan_task as an AttributeError)."""
        if self.com is not None:  # a numpy array too, taken as the pair it holds
            com: Any = self.com  # typed a pair; an array is taken too
            com = com.tolist() if getattr(com, "ndim", None) == 1 else com
            _finite_vector("Task.com", com, 2)
            object.__setattr__(self, "com", tuple(float(v) for v in com))
        if self.inertia is not None:
            _within("Task.inertia", self.inertia, PHYSICS_LIMITS["inertia"])
        _integer("Task.pad_rings", self.pad_rings)
        _integer("Task.friction_polygon_sides", self.friction_polygon_sides)
        if self.source is not None and not isinstance(self.source, str):
            raise TypeError(f"Task.source must be a string or None, got {type(self.source).__name__}")
        if self.mesh is not None and not isinstance(self.mesh, PartMesh):
            raise TypeError(f"Task.mesh must be a PartMesh or None, got {type(self.mesh).__name__}")
        if not isinstance(self.pushes, str) or self.pushes not in PUSHES:
            raise TaskError("dynamics.pushes", f"must be one of {', '.join(PUSHES)}, got {self.pushes!r:.40}")
        object.__setattr__(self, "uncertainty", _string_mapping_of_numbers("Task.uncertainty", self.uncertainty,
                                                                           tuple(UNCERTAIN)))
        object.__setattr__(self, "feature_orientations",
                           _string_mapping_of_numbers("Task.feature_orientations", self.feature_orientations))
        if not isinstance(self.warnings, (tuple, list)) or not all(isinstance(w, str) for w in self.warnings):
            raise TypeError(f"Task.warnings must be a sequence of strings, got {self.warnings!r:.40}")
        object.__setattr__(self, "warnings", tuple(self.warnings))

    def feature_angle(self, pusher: str) -> float:
        """The object's world orientation (deg about the world's y) while it rests on `pusher`'s
        feature: environment.features gives it, else the start's (the executor places the
        features so; stablepush.execution.world.place_features)."""
        pose = self.environment.features.get(pusher)
        if pose is not None:
            return float(pose[3])
        return float(self.feature_orientations.get(pusher, self.start[2]))

    def with_start(self, start: Sequence[float]) -> "Task":
        """The same task from another start (x mm, z mm, theta deg) in the same world: each feature
        keeps the object's world orientation it had, not the new start's (a re-plan from a measured
        pose, where gravity in O on a feature must stay the one the world has)."""
        return dataclasses.replace(self, start=as_triple(float(v) for v in start),
                                   feature_orientations={p: self.feature_angle(p) for p in self.pusher_names})

    def identity(self) -> Dict[str, Any]:
        """What a plan of this task rests on, as plain JSON values (file units): the object, the
        pads, gravity and pushes, the pushers, the start and goal, the planner settings that bound
        a plan (not its seed or time limit), the uncertainty box and where environment.features
        hold the object. A plan file keeps it (docs/model.md section 5), so a plan whose task
        changed since can say what changed (`stablepush.plan.verify.changes_since_planned`)."""
        planner = {k: self.planner.as_dict()[k] for k in ("step", "tolerance", "max_switches", "min_margin",
                                                          "min_hold_ratio")}
        return json_values({
            "name": self.name,
            "object": {"vertices": self.vertices, "thickness": self.thickness, "mass": self.mass, "com": self.com,
                       "inertia": self.inertia},
            "gripper": {"grip_force": self.grip_force, "mu": self.mu, "pad_rings": self.pad_rings, "pads": self.pads},
            "gravity": self.gravity, "step_time": self.step_time, "pushes": self.pushes,
            "friction_polygon_sides": self.friction_polygon_sides,
            "pushers": {p.name: {"from": p.a, "to": p.b, "mu": p.mu} for p in self.pushers},
            "start": self.start, "goal": self.goal, "planner": planner, "uncertainty": self.uncertainty,
            "features": {name: self.feature_angle(name) for name in self.pusher_names},
        })

    @property
    def tolerance(self) -> Tolerance:
        """planner.tolerance, the goal's: how near the goal a plan must end."""
        return Tolerance.of(self.planner.tolerance)

    def at_goal(self, pose) -> bool:
        """Whether `pose` (x mm, z mm, theta deg) lies within planner.tolerance of the goal, in each
        coordinate (theta wrapped: Tolerance.within)."""
        return self.tolerance.within(pose, self.goal)

    @property
    def pusher_names(self) -> List[str]:
        """The pushers' names, in the task file's order (a pusher's index in the core's model)."""
        return [p.name for p in self.pushers]

    def pusher_index(self, name: str, field: str = "pusher") -> int:
        """The index of the pusher called `name`; TaskError (naming `field`) when there is none."""
        try:
            return self.pusher_names.index(name)
        except ValueError:
            names = ", ".join(self.pusher_names)
            raise TaskError(field, f"no pusher named {name!r:.60} (the task has {names})") from None

    def section(self) -> "_core.CrossSection":
        """The core's cross-section: the outline's corners (outline_corners), in m."""
        return _core.CrossSection([mm2_to_si(v) for v in outline_corners(self.vertices)])

    def rigid_body(self, section: "Optional[_core.CrossSection]" = None) -> "_core.RigidBody":
        """The object's mass [kg], com [m, in O] and moment of inertia about y at the com [kg m^2]."""
        uniform = _core.RigidBody.uniform(section or self.section(), self.mass * G)
        com = mm2_to_si(self.com) if self.com is not None else tuple(uniform.com)
        if self.inertia is not None:
            inertia = self.inertia
        else:  # the uniform body's inertia about the given com (parallel axes)
            offset2 = (com[0] - uniform.com[0]) ** 2 + (com[1] - uniform.com[1]) ** 2
            inertia = uniform.inertia + self.mass * G * offset2
        return _core.RigidBody(self.mass * G, com, inertia)

    def corner_models(self) -> List["_core.StablePushModel"]:
        """The models every push must be stable in (docs/model.md section 7): the nominal model
        alone, or with `uncertainty`, the 4 corners of (pad mu x grip force, mass) at the smallest
        pusher mu. The required pusher wrench is affine in mu N and in m, the sticking polygons
        scale with mu N and a pusher's cone shrinks with its mu, so a push stable at these corners
        is stable for every value in the box (a convex combination of the corners' witnesses is a
        witness). mu and N enter only as their product, so the corners scale mu alone."""
        return [corner.build_model() for corner in self._corner_tasks()]

    def _corner_tasks(self) -> List["Task"]:
        """This task at each corner of its uncertainty box (corner_models), or itself alone."""
        u = self.uncertainty
        if not any(u.values()):
            return [self]
        low_pushers = tuple(dataclasses.replace(p, mu=p.mu * (1.0 - u.get("pusher_mu", 0.0))) for p in self.pushers)
        friction = [(1.0 - u.get("pad_mu", 0.0)) * (1.0 - u.get("grip_force", 0.0)),
                    (1.0 + u.get("pad_mu", 0.0)) * (1.0 + u.get("grip_force", 0.0))]
        masses = [1.0 - u.get("mass", 0.0), 1.0 + u.get("mass", 0.0)]
        return [dataclasses.replace(self, mu=self.mu * f, mass=self.mass * m, pushers=low_pushers,
                                    inertia=None if self.inertia is None else self.inertia * m, uncertainty={})
                for f in friction for m in masses]

    def goal_hold_ratios(self) -> Dict[str, float]:
        """Per pusher, `hold_ratio` at the goal with gravity as while that pusher's feature holds
        the object (the last push's, when the feature lets go), the least over the uncertainty
        box's corners: below 1 the pads alone do not hold the object there against gravity
        (docs/model.md section 2, "Holding without a pusher"); +inf without gravity."""
        q = pose_to_si(self.goal)
        models = self.corner_models()
        return {p.name: min(m.hold_ratio(q, i) for m in models) for i, p in enumerate(self.pushers)}

    def check_models(self, models: Sequence["_core.StablePushModel"], field: str = "models") -> None:
        """TypeError or ValueError (naming `field[k]`) unless `models` are this task's corner_models(),
        every corner present, in any order: each model must have been built by build_model from what
        one corner's model is built from (model_inputs), which is recorded beside each model built.
        A model of another task, or the nominal model of a task with an uncertainty box, would give
        answers that are not this task's."""
        expected = {corner.model_inputs() for corner in self._corner_tasks()}
        found = set()
        for k, model in enumerate(models):
            name = f"{field}[{k}]"
            if not isinstance(model, _core.StablePushModel):
                raise TypeError(f"{name}: expected a StablePushModel (task.corner_models()), "
                                f"got {type(model).__name__}")
            made_from = _MODEL_INPUTS.get(model)
            if made_from not in expected:
                box = " (the task has an uncertainty box: its corner models)" if any(self.uncertainty.values()) else ""
                raise SettingError(name, f"not one of the corner_models() of task {self.name!r}{box}: a model of "
                                         f"another task, or not made by Task.build_model")
            found.add(made_from)
        if found != expected:
            raise SettingError(field, f"{len(models)} model(s), not the {len(expected)} of task.corner_models()")

    def model_inputs(self) -> str:
        """What build_model builds from, as canonical JSON (numbers as floats, so 62 and 62.0 are
        one mass): the object, the pads, gravity and how pushes are made, the pushers and, against
        fixed features, the object's orientation on each (the start's where environment.features
        does not give it); not the goal or planner, which a model does not depend on."""
        fixed = self.pushes == "against_fixed_features"
        return json.dumps(_floats(json_values({
            "object": [self.vertices, self.thickness, self.mass, self.com, self.inertia],
            "gripper": [self.grip_force, self.mu, self.pad_rings, self.pads],
            "dynamics": [self.gravity, self.step_time, self.friction_polygon_sides, self.pushes],
            "pushers": [[p.name, p.a, p.b, p.mu, p.points, self.feature_angle(p.name) if fixed else None]
                        for p in self.pushers],
        })), sort_keys=True)

    def build_model(self) -> "_core.StablePushModel":
        """The core's stable-push model of this task, in SI units."""
        section = self.section()
        body = self.rigid_body(section)
        gripper = make_gripper(self.pads, self.grip_force, self.mu, self.pad_rings)
        pushers = [
            _core.Pusher.on_boundary(section, p.name, mm2_to_si(p.a), mm2_to_si(p.b), p.mu, p.points)
            for p in self.pushers
        ]
        fixed = self.pushes == "against_fixed_features"
        model = _core.StablePushModel(
            section=section, body=body, gripper=gripper, pushers=pushers, gravity=self.gravity,
            step_time=self.step_time, friction_polygon_sides=self.friction_polygon_sides,
            gravity_frame=_core.GravityFrame.object if fixed else _core.GravityFrame.gripper,
            feature_angles=[math.radians(self.feature_angle(p.name)) for p in self.pushers],
        )
        _MODEL_INPUTS[model] = self.model_inputs()
        return model


# Each model build_model made -> its task's model_inputs(), for check_models; weak, so a model
# outlives no reference of its own.
_MODEL_INPUTS: "weakref.WeakKeyDictionary[_core.StablePushModel, str]" = weakref.WeakKeyDictionary()


def require_task(value: Any, field: str = "task") -> Task:
    """`value` when it is a Task; TypeError naming `field` otherwise (a path, say, where the API
    wants the loaded task)."""
    if not isinstance(value, Task):
        hint = " (load it first: sp.load_task(path))" if isinstance(value, (str, os.PathLike)) else ""
        raise TypeError(f"{field}: expected a Task, got {type(value).__name__}{hint}")
    return value


def json_values(value):
    """`value` with tuples (and numpy arrays) as lists and numbers as floats or ints, as JSON reads
    it back."""
    if isinstance(value, dict):
        return {str(k): json_values(v) for k, v in value.items()}
    if hasattr(value, "tolist") and getattr(value, "ndim", 0) > 0:  # a numpy array
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [json_values(v) for v in value]
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int):
        return int(value)
    return float(value)


def _floats(value):
    """json_values' output with every int a float."""
    if isinstance(value, list):
        return [_floats(v) for v in value]
    if isinstance(value, dict):
        return {k: _floats(v) for k, v in value.items()}
    return float(value) if isinstance(value, int) and not isinstance(value, bool) else value


def make_gripper(pads, grip_force: float, mu: float, pad_rings: int) -> "_core.Gripper":
    return _core.Gripper([_core.Pad(mm2_to_si(c), r * MM) for c, r in pads], grip_force, mu, pad_rings)
