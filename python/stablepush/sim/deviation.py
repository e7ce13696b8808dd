"""How a simulated world departs from the task it is given: the same on every engine, applied
to the scene description before an engine builds its world (SI units, poses as in `scene.py`)."""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import Tuple

import numpy as np

from stablepush.frames import matrix_to_pose, pose_to_matrix, rot_y


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

    def apply(self, scene: dict) -> dict:
        """`scene` (a scene description, SI units) as this world has it; the scene itself unchanged."""
        scene = copy.deepcopy(scene)
        scene["gripper"]["mu"] *= self.mu_scale * self.pad_mu_scale
        scene["gripper"]["grip_force"] *= self.grip_scale
        obj = scene["object"]
        obj["mass"] *= self.mass_scale
        obj["inertia"] *= self.mass_scale
        if "mesh" in obj:  # a mesh part's solid's tensor (scene.object_inertia)
            obj["mesh"]["inertia"] = (np.asarray(obj["mesh"]["inertia"], float) * self.mass_scale).tolist()
        offsets = {name: (dx, dz, dth) for name, dx, dz, dth in self.feature_offsets}
        for feature in scene["features"]:
            feature["mu"] *= self.mu_scale * self.pusher_mu_scale
            if feature["pusher"] in offsets:
                _move_feature(feature, *offsets[feature["pusher"]])
        return scene


def _move_feature(feature: dict, dx_mm: float, dz_mm: float, dtheta_deg: float) -> None:
    """Turn a feature by dtheta about the world's y through the middle of its segment, then shift it,
    with the object's pose on it (its segment stays where it was on the object)."""
    a, b = np.asarray(feature["from"], float), np.asarray(feature["to"], float)
    middle = (a + b) / 2
    move = np.eye(4)  # the turn about the middle, then the shift, as one rigid motion in W
    move[:3, :3] = rot_y(math.radians(dtheta_deg))
    move[:3, 3] = middle + np.array([dx_mm * 1e-3, 0.0, dz_mm * 1e-3]) - move[:3, :3] @ middle
    feature["from"] = (move @ np.append(a, 1.0))[:3].tolist()
    feature["to"] = (move @ np.append(b, 1.0))[:3].tolist()
    feature["normal"] = (move[:3, :3] @ np.asarray(feature["normal"], float)).tolist()
    feature["object_pose"] = matrix_to_pose(move @ pose_to_matrix(feature["object_pose"]))
