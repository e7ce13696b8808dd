"""How a simulated world departs from the task it is given: the same on every engine, a new scene
made from the one an engine is given, before it builds its world (SI units, poses as in `scene.py`)."""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Tuple

import numpy as np

from stablepush.errors import SettingError
from stablepush.execution.scene import Scene, SceneFeature
from stablepush.frames import matrix_to_pose, pose_to_matrix, rot_y
from stablepush.task.model import MAX_ANGLE, MAX_COORDINATE
from stablepush.units import is_finite_real, is_integer

SCALE_RANGE = (1e-3, 1e3)  # a world's multiplier of a task's mu, grip force or mass
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
    deviations in mm and deg, drawn from `seed`)."""

    mu_scale: float = 1.0
    tracker_noise_mm: float = 0.0
    tracker_noise_deg: float = 0.0
    seed: int = 0
    pad_mu_scale: float = 1.0
    pusher_mu_scale: float = 1.0
    grip_scale: float = 1.0
    mass_scale: float = 1.0
    feature_offsets: Tuple[Tuple[str, float, float, float], ...] = ()

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

    def apply(self, scene: Scene) -> Scene:
        """`scene` as this world has it: a new Scene."""
        gripper = dataclasses.replace(scene.gripper, mu=scene.gripper.mu * (self.mu_scale * self.pad_mu_scale),
                                      grip_force=scene.gripper.grip_force * self.grip_scale)
        obj = scene.object
        mesh = obj.mesh
        if mesh is not None:  # a mesh part's solid's tensor (scene.object_inertia)
            scaled = (np.asarray(mesh.inertia, float) * self.mass_scale).tolist()
            mesh = dataclasses.replace(mesh, inertia=tuple((a, b, c) for a, b, c in scaled))
        obj = dataclasses.replace(obj, mass=obj.mass * self.mass_scale, inertia=obj.inertia * self.mass_scale,
                                  mesh=mesh)
        offsets = {name: (dx, dz, dth) for name, dx, dz, dth in self.feature_offsets}
        features = []
        for feature in scene.features:
            feature = dataclasses.replace(feature, mu=feature.mu * (self.mu_scale * self.pusher_mu_scale))
            if feature.pusher in offsets:
                feature = _moved(feature, *offsets[feature.pusher])
            features.append(feature)
        return dataclasses.replace(scene, gripper=gripper, object=obj, features=tuple(features))


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
