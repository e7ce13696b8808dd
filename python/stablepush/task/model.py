"""The task: the object, pads, pushers, start and goal in file units (mm, deg, g, N), and the
core's stable-push model built from it in SI (docs/model.md sections 1-4 and 7).

`stablepush.task.schema` makes a Task from a task file; this module knows nothing of files.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from stablepush.compiled import _core
from stablepush.errors import TaskError
from stablepush.pose import Tolerance
from stablepush.task.parts import (
    ANGLE,
    COORDINATE,
    LENGTH,
    MU,
    PHYSICS_LIMITS,
    DynamicsSpec,
    GripperSpec,
    PartSpec,
    check_each,
    check_finite,
    check_integer,
    check_vector,
    check_within,
)

# Re-exported: modules that bound world numbers take them from here.
from stablepush.task.parts import MAX_ANGLE as MAX_ANGLE
from stablepush.task.parts import MAX_COORDINATE as MAX_COORDINATE
from stablepush.task.robot_files import model_source
from stablepush.units import as_triple, is_integer, mm2_to_si, pose_to_si

JOINT_SPEED = (1e-3, 1e3)  # rad/s or m/s: environment.robot.max_joint_speed
# A robot model file is named by one of these endings (MuJoCo compiles both; Drake parses both).
ROBOT_MODEL_SUFFIXES = (".urdf", ".xml", ".mjcf")
MAX_NAME = 100  # characters of a name (a pusher's, the flange's)

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



def _world_pose(field: str, value, size: int) -> None:
    """x, y, z mm (COORDINATE) then angles deg (ANGLE), each named field[i]."""
    check_vector(field, value, size)
    for i, v in enumerate(value):
        check_within(f"{field}[{i}]", v, COORDINATE if i < 3 else ANGLE)



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
        check_finite(f"{field}.{key}", v)
        out[key] = float(v)
    return out



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
            check_within(f"planner.{name}", getattr(self, name), PLANNER_LIMITS[name])
            object.__setattr__(self, name, float(getattr(self, name)))
        for name in ("seed", "max_switches"):
            if isinstance(getattr(self, name), bool) or not is_integer(getattr(self, name)):
                raise TypeError(f"planner.{name} must be an integer, got {getattr(self, name)!r:.40}")
            check_within(f"planner.{name}", getattr(self, name), _core.TRRT_STAR_PARAMETER_RANGES[name][1:])
            object.__setattr__(self, name, int(getattr(self, name)))
        for name in ("step", "tolerance"):
            check_vector(f"planner.{name}", getattr(self, name), 2)
            for i, v in enumerate(getattr(self, name)):
                check_within(f"planner.{name}[{i}]", v, PLANNER_LIMITS[name])
            object.__setattr__(self, name, tuple(float(v) for v in getattr(self, name)))
        if not isinstance(self.tuning, dict):
            raise TypeError(f"planner.tuning must be a mapping, got {type(self.tuning).__name__}")
        object.__setattr__(self, "tuning", dict(self.tuning))  # its own: the caller's mapping may change
        for key, value in self.tuning.items():
            if key not in _core.TRRT_STAR_PARAMETER_RANGES or key in ("seed", "max_switches"):
                raise TaskError(f"planner.{key!s:.40}", "not a planner setting")
            check_within(f"planner.{key}", value, _core.TRRT_STAR_PARAMETER_RANGES[key][1:])

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


# uncertainty (and evaluate's --vary): key -> the path (Task.value) of the quantity it widens, +- this
# fraction of it; `*` stands for each pusher's name. A push must be stable for every value in the
# box (Task.corner_models).
UNCERTAIN = {"pad_mu": "gripper.mu", "pusher_mu": "pushers.*.mu", "grip_force": "gripper.grip_force",
             "mass": "object.mass"}
# The quantities a world or a calibration changes (Task.value, Task.with_values), by their path in
# the task file -> (the Task's group, its field); pushers.NAME.mu is pusher NAME's friction.
VALUE_PATHS = {"gripper.mu": ("gripper", "mu"), "gripper.grip_force": ("gripper", "grip_force"),
               "object.mass": ("object", "mass")}


# The planner section's keys every task has, in the task file's form; a task file (or a Task
# made in code) that leaves one out gets these (docs/model.md section 3).
PLANNER_DEFAULTS: Dict[str, Any] = PlannerSettings().as_dict()


@dataclass(frozen=True)
class Robot:
    """The arm a plan runs on, as the task's `environment.robot` section gives it: `model`, a URDF
    or MJCF file of the arm (None: the shipped arm, stablepush/kinematics/arm.xml), `flange`, the link
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
        check_within("environment.robot.max_joint_speed", self.max_joint_speed, JOINT_SPEED)
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
            check_within(f"environment.{name}", getattr(self, name), LENGTH)
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
            check_each(f"pushers.{self.name:.40}.{end}", getattr(self, end), 2, [COORDINATE])
            object.__setattr__(self, end, tuple(float(v) for v in getattr(self, end)))
        check_within(f"pushers.{self.name:.40}.mu", self.mu, MU)
        check_integer(f"pushers.{self.name:.40}.points", self.points)
        check_within(f"pushers.{self.name:.40}.points", self.points, (1, MAX_PUSHER_POINTS))

    @property
    def is_point(self) -> bool:
        return self.a == self.b


@dataclass(frozen=True)
class Task:
    """A validated task, in file units (mm, deg, g, N), its groups the task file's sections (a
    quantity's path on a Task is its path in the file: task.gripper.mu is gripper.mu); `model` and
    `corner_models` are the core's, in SI, built from it on first use."""

    name: str
    object: PartSpec  # the part: its section, thickness, mass, com, inertia, mesh
    gripper: GripperSpec  # the grip force, the pads' mu, their rings and the pads
    gravity: Tuple[float, float]  # m/s^2 in G while G's axes are the world's (at the home pose)
    dynamics: DynamicsSpec  # a unit push's time, the sticking polygons' sides, how pushes are made
    pushers: Tuple[PusherSpec, ...]
    start: Tuple[float, float, float]  # mm, mm, deg
    goal: Tuple[float, float, float]
    # A mapping in the task file's form is taken as PlannerSettings.from_mapping of it.
    planner: PlannerSettings = field(default_factory=PlannerSettings)
    environment: Cell = field(default_factory=Cell)  # a mapping in the file's form is taken as Cell.from_mapping
    source: Optional[str] = None
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
        before anything reaches the core. The groups check their own fields."""
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
        for name, kind in (("object", PartSpec), ("gripper", GripperSpec), ("dynamics", DynamicsSpec)):
            if not isinstance(getattr(self, name), kind):
                raise TypeError(f"Task.{name} must be a {kind.__name__}, got {type(getattr(self, name)).__name__}")
        check_each("Task.gravity", self.gravity, 2, [PHYSICS_LIMITS["gravity"]])
        check_each("Task.start", self.start, 3, [COORDINATE, COORDINATE, ANGLE])
        check_each("Task.goal", self.goal, 3, [COORDINATE, COORDINATE, ANGLE])
        if not isinstance(self.pushers, (tuple, list)) or not all(isinstance(p, PusherSpec) for p in self.pushers):
            raise TypeError("Task.pushers must be a sequence of PusherSpec")
        self._check_the_other_fields()

    def _check_the_other_fields(self) -> None:
        """The fields __post_init__ has not checked: each one's type, named (an edited Task with
        uncertainty=None, say, escaped from sp.check and sp.plan_task as an AttributeError)."""
        if self.source is not None and not isinstance(self.source, str):
            raise TypeError(f"Task.source must be a string or None, got {type(self.source).__name__}")
        object.__setattr__(self, "uncertainty", _string_mapping_of_numbers("Task.uncertainty", self.uncertainty,
                                                                           tuple(UNCERTAIN)))
        object.__setattr__(self, "feature_orientations",
                           _string_mapping_of_numbers("Task.feature_orientations", self.feature_orientations))
        if not isinstance(self.warnings, (tuple, list)) or not all(isinstance(w, str) for w in self.warnings):
            raise TypeError(f"Task.warnings must be a sequence of strings, got {self.warnings!r:.40}")
        object.__setattr__(self, "warnings", tuple(self.warnings))

    def __getstate__(self) -> Dict[str, Any]:
        """The fields without the built models (MODEL_CACHE): a pickled or copied Task (Ray sends
        Tasks to its workers) builds its own where it is used; the core's models do not pickle."""
        return {k: v for k, v in self.__dict__.items() if k not in MODEL_CACHE}

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
        part, grip = self.object, self.gripper
        return json_values({
            "name": self.name,
            "object": {"vertices": part.vertices, "thickness": part.thickness, "mass": part.mass, "com": part.com,
                       "inertia": part.inertia},
            "gripper": {"grip_force": grip.grip_force, "mu": grip.mu, "pad_rings": grip.pad_rings, "pads": grip.pads},
            "gravity": self.gravity, "step_time": self.dynamics.step_time, "pushes": self.dynamics.pushes,
            "friction_polygon_sides": self.dynamics.friction_polygon_sides,
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

    def value(self, path: str) -> float:
        """The quantity at `path`, named as in the task file: gripper.mu, gripper.grip_force,
        object.mass or pushers.NAME.mu (VALUE_PATHS); TaskError naming an unknown path or pusher."""
        group, key = self._value_at(path)
        if group == "pushers":
            return self.pushers[key].mu
        return getattr(getattr(self, group), key)

    def with_values(self, values: Mapping[str, float]) -> "Task":
        """A new Task with the quantities at these paths (value's) changed, each refused by its
        group's own check when out of range (TaskError naming it). A new object.mass scales a
        given object.inertia with it (the same part, denser or lighter)."""
        if not isinstance(values, Mapping):
            raise TypeError(f"with_values takes a mapping of paths to numbers, got {type(values).__name__}")
        changes: Dict[str, Dict[str, Any]] = {}
        pushers = list(self.pushers)
        for path, new in values.items():
            group, key = self._value_at(path)
            if group == "pushers":
                pushers[key] = dataclasses.replace(pushers[key], mu=new)
            else:
                changes.setdefault(group, {})[key] = new
        groups = {group: dataclasses.replace(getattr(self, group), **fields) for group, fields in changes.items()}
        part = groups.get("object")
        if part is not None and part.inertia is not None:
            groups["object"] = dataclasses.replace(part, inertia=part.inertia * (part.mass / self.object.mass))
        return dataclasses.replace(self, pushers=tuple(pushers), **groups)

    def _value_at(self, path: str) -> Tuple[str, Any]:
        """Where `path` (value's) lies: (group, field), or ("pushers", the pusher's index)."""
        if not isinstance(path, str):
            raise TypeError(f"a value's path is a string (gripper.mu), got {type(path).__name__}")
        if path in VALUE_PATHS:
            return VALUE_PATHS[path]
        if path.startswith("pushers.") and path.endswith(".mu") and len(path) > len("pushers..mu"):
            return "pushers", self.pusher_index(path[len("pushers."):-len(".mu")], path)
        raise TaskError(f"{path:.60}", f"not a value of a task ({', '.join(VALUE_PATHS)} or pushers.NAME.mu)")

    @functools.cached_property
    def model(self) -> "_core.StablePushModel":
        """The core's stable-push model of this task, in SI units, built on first use and kept with
        this Task (a Task made from it, by dataclasses.replace or with_values, builds its own)."""
        section = self.object.section()
        pushers = [_core.Pusher.on_boundary(section, p.name, mm2_to_si(p.a), mm2_to_si(p.b), p.mu, p.points)
                   for p in self.pushers]
        fixed = self.dynamics.pushes == "against_fixed_features"
        return _core.StablePushModel(
            section=section, body=self.object.rigid_body(section), gripper=self.gripper.core(), pushers=pushers,
            gravity=self.gravity, step_time=self.dynamics.step_time,
            friction_polygon_sides=self.dynamics.friction_polygon_sides,
            gravity_frame=_core.GravityFrame.object if fixed else _core.GravityFrame.gripper,
            feature_angles=[math.radians(self.feature_angle(p.name)) for p in self.pushers],
        )

    @functools.cached_property
    def corner_models(self) -> Tuple["_core.StablePushModel", ...]:
        """The models every push must be stable in (docs/model.md section 7), each corner task's
        `model`: the nominal model alone, or with `uncertainty`, the 4 corners of (pad mu x grip
        force, mass) at the smallest pusher mu. The required pusher wrench is affine in mu N and in
        m, the sticking polygons scale with mu N and a pusher's cone shrinks with its mu, so a push
        stable at these corners is stable for every value in the box (a convex combination of the
        corners' witnesses is a witness). mu and N enter only as their product, so the corners
        scale mu alone."""
        return tuple(corner.model for corner in self.corner_tasks)

    @functools.cached_property
    def corner_tasks(self) -> Tuple["Task", ...]:
        """This task at each corner of its uncertainty box (corner_models), each without a box of
        its own; this task alone when it has none."""
        u = self.uncertainty
        if not any(u.values()):
            return (self,)
        pad_mu, mass = UNCERTAIN["pad_mu"], UNCERTAIN["mass"]
        low_pushers = {UNCERTAIN["pusher_mu"].replace("*", p.name): p.mu * (1.0 - u.get("pusher_mu", 0.0))
                       for p in self.pushers}
        friction = [(1.0 - u.get("pad_mu", 0.0)) * (1.0 - u.get("grip_force", 0.0)),
                    (1.0 + u.get("pad_mu", 0.0)) * (1.0 + u.get("grip_force", 0.0))]
        masses = [1.0 - u.get("mass", 0.0), 1.0 + u.get("mass", 0.0)]
        point = dataclasses.replace(self, uncertainty={})
        return tuple(point.with_values({pad_mu: self.value(pad_mu) * f, mass: self.value(mass) * m, **low_pushers})
                     for f in friction for m in masses)

    def goal_hold_ratios(self) -> Dict[str, float]:
        """Per pusher, `hold_ratio` at the goal with gravity as while that pusher's feature holds
        the object (the last push's, when the feature lets go), the least over the uncertainty
        box's corners: below 1 the pads alone do not hold the object there against gravity
        (docs/model.md section 2, "Holding without a pusher"); +inf without gravity."""
        q = pose_to_si(self.goal)
        return {p.name: min(m.hold_ratio(q, i) for m in self.corner_models) for i, p in enumerate(self.pushers)}


# The Task's attributes that hold what it built (functools.cached_property), which its pickled or
# copied state leaves out (Task.__getstate__).
MODEL_CACHE = ("model", "corner_models", "corner_tasks")


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

