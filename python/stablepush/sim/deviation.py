"""How a simulated world departs from the task it is given: the same on every engine, a new scene
made from the one an engine is given, before it builds its world (SI units, poses as in `scene.py`)."""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Dict, Tuple

import numpy as np

from stablepush.errors import SettingError
from stablepush.execution.scene import Scene, SceneFeature, SceneObject
from stablepush.frames import matrix_to_pose, pose_to_matrix, rot_y
from stablepush.task.model import MAX_ANGLE, MAX_COORDINATE, VALUE_PATHS, Task
from stablepush.task.parts import MU, PHYSICS_LIMITS
from stablepush.units import is_finite_real, is_integer

SCALE_RANGE = (1e-3, 1e3)  # a world's multiplier of a task's mu, grip force or mass
# The task fields a world may set whatever the task says (Task.value's paths, file units) -> their
# range; pushers.NAME.mu is MU's too.
WORLD_FIELDS = {"gripper.mu": MU, "gripper.grip_force": PHYSICS_LIMITS["force"], "object.mass": PHYSICS_LIMITS["mass"]}
assert set(WORLD_FIELDS) == set(VALUE_PATHS), "a world sets the quantities Task.with_values does"
MAX_SEED = 2**32 - 1  # the tracker's noise seed (numpy's legacy bound, as a study's seed)


def _number(name: str, value, bounds) -> None:
    if isinstance(value, bool) or not is_finite_real(value) or not bounds[0] <= float(value) <= bounds[1]:
        if not is_finite_real(value) and not isinstance(value, (int, float)):
            raise TypeError(f"{name} must be a number, got {type(value).__name__}")
        raise SettingError(name, f"must be a finite number from {bounds[0]:g} to {bounds[1]:g}, got {value!r:.40}")


@dataclass(frozen=True)
class WorldDeviation:
    """How the simulated world departs from the task it is given, to test plans against a world that
    differs from their model: every pad's and feature's mu times `mu_scale`, the pads' mu also times
    `pad_mu_scale` and the features' times `pusher_mu_scale`, the grip force times `grip_scale`, the
    object's mass (and inertia) times `mass_scale`, each feature `feature_offsets` off where the
    plan puts it ((pusher, dx mm, dz mm, dtheta deg) in the world's x, z and about y through the
    middle of its segment), and a tracker whose `object_in_grasp` carries Gaussian noise (standard
    deviations in mm and deg, drawn from `seed`). `world`: (task field, value) pairs the world has
    whatever the task it is given says (`gripper.mu`, `gripper.grip_force` N, `object.mass` g,
    `pushers.NAME.mu`, as Task.with_values names them), before the scales: a world that hides its
    friction from the client, as a real one does."""

    mu_scale: float = 1.0
    tracker_noise_mm: float = 0.0
    tracker_noise_deg: float = 0.0
    seed: int = 0
    pad_mu_scale: float = 1.0
    pusher_mu_scale: float = 1.0
    grip_scale: float = 1.0
    mass_scale: float = 1.0
    feature_offsets: Tuple[Tuple[str, float, float, float], ...] = ()
    world: Tuple[Tuple[str, float], ...] = ()

    def __post_init__(self):
        """Each field within what a world can be (SettingError naming it; TypeError for a wrong
        type): a scale a positive multiplier up to SCALE_RANGE, a noise not negative, a seed a
        whole number from 0, an offset within the task file's bounds on coordinates and angles."""
        for name in ("mu_scale", "pad_mu_scale", "pusher_mu_scale", "grip_scale", "mass_scale"):
            _number(name, getattr(self, name), SCALE_RANGE)
        _number("tracker_noise_mm", self.tracker_noise_mm, (0.0, MAX_COORDINATE))
        _number("tracker_noise_deg", self.tracker_noise_deg, (0.0, MAX_ANGLE))
        if isinstance(self.seed, bool) or not is_integer(self.seed) or not 0 <= self.seed <= MAX_SEED:
            raise SettingError("seed", f"must be a whole number from 0 to {MAX_SEED}, got {self.seed!r:.40}")
        if not isinstance(self.feature_offsets, (tuple, list)):
            raise TypeError(f"feature_offsets must be a sequence of (pusher, dx, dz, dtheta), got "
                            f"{type(self.feature_offsets).__name__}")
        for k, offset in enumerate(self.feature_offsets):
            if not isinstance(offset, (tuple, list)) or len(offset) != 4 or not isinstance(offset[0], str):
                raise TypeError(f"feature_offsets[{k}] must be (pusher, dx mm, dz mm, dtheta deg), got {offset!r:.60}")
            for name, value, bound in zip(("dx", "dz", "dtheta"), offset[1:], (MAX_COORDINATE, MAX_COORDINATE,
                                                                                MAX_ANGLE)):
                _number(f"feature_offsets[{k}].{name}", value, (-bound, bound))
        if not isinstance(self.world, (tuple, list)):
            raise TypeError(f"world must be a sequence of (field, value), got {type(self.world).__name__}")
        for k, pair in enumerate(self.world):
            if not isinstance(pair, (tuple, list)) or len(pair) != 2 or not isinstance(pair[0], str):
                raise TypeError(f"world[{k}] must be (task field, value), got {pair!r:.60}")
            _number(pair[0], pair[1], _world_range(pair[0]))
        object.__setattr__(self, "world", tuple((name, float(value)) for name, value in self.world))

    def world_task(self, task: Task) -> Task:
        """`task` with this world's own values (`world`): the model of the world it simulates, which
        the friction-fidelity contract holds it to. TaskError naming a field the task has not (a
        pusher it lacks)."""
        return task.with_values(dict(self.world))

    def fixed_to(self, task: Task) -> "WorldDeviation":
        """This world with every mu of `task` (the pads', each pusher's) set in `world` where it
        does not set it itself: a world whose friction stays the task's whatever a run's plan was
        made for (a calibration's probes are plans of other worlds than the task's)."""
        own = dict(self.world)
        fields = ["gripper.mu"] + [f"pushers.{p.name}.mu" for p in task.pushers]
        return dataclasses.replace(self, world=tuple((name, own.pop(name, task.value(name))) for name in fields)
                                   + tuple(own.items()))

    def apply(self, scene: Scene) -> Scene:
        """`scene` as this world has it: a new Scene. A pusher's mu in `world` applies to its
        feature where the scene has one (a run places the features its plan uses)."""
        scene = _with_world(scene, dict(self.world))
        gripper = dataclasses.replace(scene.gripper, mu=scene.gripper.mu * (self.mu_scale * self.pad_mu_scale),
                                      grip_force=scene.gripper.grip_force * self.grip_scale)
        obj = _scaled_mass(scene.object, self.mass_scale)
        offsets = {name: (dx, dz, dth) for name, dx, dz, dth in self.feature_offsets}
        features = []
        for feature in scene.features:
            feature = dataclasses.replace(feature, mu=feature.mu * (self.mu_scale * self.pusher_mu_scale))
            if feature.pusher in offsets:
                feature = _moved(feature, *offsets[feature.pusher])
            features.append(feature)
        return dataclasses.replace(scene, gripper=gripper, object=obj, features=tuple(features))


def _world_range(name: str) -> Tuple[float, float]:
    """The range of a world's field (SettingError naming one a world cannot set)."""
    parts = name.split(".")
    if name in WORLD_FIELDS:
        return WORLD_FIELDS[name]
    if len(parts) >= 3 and parts[0] == "pushers" and parts[-1] == "mu":
        return MU
    raise SettingError("world", f"{name!r:.60} is not a field a world sets (one of {', '.join(WORLD_FIELDS)}, "
                                f"pushers.NAME.mu)")


def _with_world(scene: Scene, values: Dict[str, float]) -> Scene:
    """`scene` with the world's own values of task fields (WorldDeviation.world)."""
    if not values:
        return scene
    gripper = dataclasses.replace(scene.gripper, mu=values.get("gripper.mu", scene.gripper.mu),
                                  grip_force=values.get("gripper.grip_force", scene.gripper.grip_force))
    obj = scene.object
    if "object.mass" in values:
        obj = _scaled_mass(obj, values["object.mass"] * 1e-3 / obj.mass)
    features = tuple(dataclasses.replace(f, mu=values.get(f"pushers.{f.pusher}.mu", f.mu)) for f in scene.features)
    return dataclasses.replace(scene, gripper=gripper, object=obj, features=features)


def _scaled_mass(obj: SceneObject, scale: float) -> SceneObject:
    """The object `scale` times as heavy: its mass and inertia, and a mesh solid's tensor."""
    mesh = obj.mesh
    if mesh is not None:  # a mesh part's solid's tensor (cell_model.object_inertia)
        scaled = (np.asarray(mesh.inertia, float) * scale).tolist()
        mesh = dataclasses.replace(mesh, inertia=tuple((a, b, c) for a, b, c in scaled))
    return dataclasses.replace(obj, mass=obj.mass * scale, inertia=obj.inertia * scale, mesh=mesh)


def _moved(feature: SceneFeature, dx_mm: float, dz_mm: float, dtheta_deg: float) -> SceneFeature:
    """The feature turned by dtheta about the world's y through the middle of its segment, then
    shifted, with the object's pose on it (its segment stays where it was on the object)."""
    a, b = np.asarray(feature.start, float), np.asarray(feature.end, float)
    middle = (a + b) / 2
    move = np.eye(4)  # the turn about the middle, then the shift, as one rigid motion in W
    move[:3, :3] = rot_y(math.radians(dtheta_deg))
    move[:3, 3] = middle + np.array([dx_mm * 1e-3, 0.0, dz_mm * 1e-3]) - move[:3, :3] @ middle
    (ax, ay, az), (bx, by, bz) = (move @ np.append(a, 1.0))[:3].tolist(), (move @ np.append(b, 1.0))[:3].tolist()
    nx, ny, nz = (move[:3, :3] @ np.asarray(feature.normal, float)).tolist()
    return dataclasses.replace(feature, start=(ax, ay, az), end=(bx, by, bz), normal=(nx, ny, nz),
                               object_pose=tuple(matrix_to_pose(move @ pose_to_matrix(feature.object_pose))))
