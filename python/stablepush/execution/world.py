"""The plan in the world: where the features that act as pushers sit, and the scene a simulated
arm builds from them. No arm here (`executor.py` drives one) and no simulation (`stablepush.sim`).

World frame W: x forward, z up, y along the gripping axis at the home pose, where G's axes are
W's. A feature is fixed in W; during a push the object rests on it while the gripper moves
(`stream.py`). Positions in W are in m.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, List, Sequence

import numpy as np

from stablepush.compiled import _core
from stablepush.execution.part_geometry import scene_object_geometry
from stablepush.execution.scene import Pad, Scene, SceneFeature, SceneGripper, SceneObject
from stablepush.frames import grasp_transform, matrix_to_pose, rot_y, translation
from stablepush.plan.plan import Waypoint
from stablepush.pose import Pose, PoseLike
from stablepush.task.model import Task
from stablepush.units import MM, mm2_to_si

# The guarded end of every approach to a feature (stream.py, guard.py): it starts this far short of
# where the plan puts the feature, to find one placed up to half a millimetre and half a degree off
# before it pushes the object. A run whose object touches a feature at home starts this far back.
GUARD_SPAN = 1.0e-3  # m


@dataclass(frozen=True)
class Feature:
    """A fixed feature of the world acting as pusher `pusher`: it touches the object along the
    segment from-to (W, m) when the object is at `object_pose` (T_WO, 4x4); `normal` is the
    pusher's inward normal in W (pointing into the object, away from the feature)."""

    pusher: str
    object_pose: np.ndarray
    start: np.ndarray
    end: np.ndarray
    normal: np.ndarray
    mu: float

    def in_scene(self) -> SceneFeature:
        """This feature as a scene carries it (W, m; the object's pose as a 7-vector)."""
        (ax, ay, az), (bx, by, bz), (nx, ny, nz) = self.start.tolist(), self.end.tolist(), self.normal.tolist()
        return SceneFeature(pusher=self.pusher, start=(ax, ay, az), end=(bx, by, bz), normal=(nx, ny, nz), mu=self.mu,
                            object_pose=tuple(matrix_to_pose(self.object_pose)))

    def as_dict(self) -> dict:
        return self.in_scene().as_dict()


@dataclass(frozen=True)
class Contact:
    """Plan pushes first+1 .. last, all by `pusher` (one stay on one feature)."""

    pusher: str
    first: int
    last: int


# -- the plan in the world ---------------------------------------------------------------------


def contacts_of(steps: Sequence[Waypoint]) -> List[Contact]:
    """The plan's pushes grouped into contacts: runs of consecutive pushes by one pusher."""
    out: List[Contact] = []
    for i, step in enumerate(steps[1:], start=1):
        pusher = step.pusher
        if pusher is None:  # a plan's pushes each name their pusher (plan.verify)
            raise ValueError(f"plan step {i} is a push by no pusher")
        if out and out[-1].pusher == pusher and out[-1].last == i - 1:
            out[-1] = Contact(pusher, out[-1].first, i)
        else:
            out.append(Contact(pusher, i - 1, i))
    return out


def place_features(task: Task, steps: Sequence[Waypoint], every_pusher: bool = False) -> Dict[str, Feature]:
    """One feature per pusher the plan uses (with `every_pusher`, then one for each other pusher of
    the task, as if its first contact began at the plan's start: a re-planned run may use it). The
    task's `environment.features` gives the object's world pose on a feature; otherwise pusher k
    (in order of first use) gets a station `station_offset(k)` times `station_spacing` mm along y
    from home (0, +1, -1, +2, -2, ...: the stations stay within the arm's reach), and the
    feature is placed where the pusher touches the object at the start of its first contact with G
    at that station, turned about y so that the object's world orientation there is the one the
    model assumes for this feature (`Task.feature_angle`: the start's unless environment.features
    says otherwise). Gravity in the world is the task's gravity (G's axes are W's at home)."""
    env = task.environment
    section = task.object.section()
    home = np.asarray(env.home, float) * MM
    features: Dict[str, Feature] = {}
    contacts = contacts_of(steps)
    if every_pusher:
        contacts += [Contact(name, 0, 0) for name in task.pusher_names]
    for contact in contacts:
        name = contact.pusher
        if name in features:
            continue
        if name in env.features:
            x, y, z, theta = env.features[name]
            T_WO = translation(np.array([x, y, z]) * MM)
            T_WO[:3, :3] = rot_y(math.radians(theta))
        else:  # G at the station, turned so that the object has the world orientation the model
            # assumes on this feature (Task.feature_angle): G's turn plus theta is that angle
            station = home + np.array([0.0, station_offset(len(features)) * env.station_spacing * MM, 0.0])
            q_first = steps[contact.first].pose
            T_WG = translation(station)
            T_WG[:3, :3] = rot_y(math.radians(task.feature_angle(name) - q_first[2]))
            T_WO = T_WG @ grasp_transform(q_first)
        index = task.pusher_index(name)
        spec = task.pushers[index]
        pusher = _core.Pusher.on_boundary(section, name, mm2_to_si(spec.a), mm2_to_si(spec.b),
                                          spec.mu, spec.points)  # the pusher alone: its cone is not needed here
        n_O = np.array(pusher.inward_normal, float)
        to_w = lambda p: (T_WO @ np.array([p[0] * MM, 0.0, p[1] * MM, 1.0]))[:3]  # noqa: E731
        features[name] = Feature(pusher=name, object_pose=T_WO, start=to_w(spec.a), end=to_w(spec.b),
                                 normal=T_WO[:3, :3] @ np.array([n_O[0], 0.0, n_O[1]]), mu=spec.mu)
    return features


def station_offset(k: int) -> int:
    """The k-th default station's place along y, in station spacings: 0, +1, -1, +2, -2, ...,
    alternating about home so that six pushers span five spacings, not ten to one side."""
    return (k + 1) // 2 if k % 2 else -(k // 2)


def scene_description(task: Task, features: Dict[str, Feature], in_grasp: PoseLike,
                      start_clear: bool = True, solid: bool = True) -> Scene:
    """What a simulated arm needs to build the world (scene.Scene, SI units): the object, the
    gripper, gravity, the features, G's pose when the run starts and the object's pose then
    (`in_grasp`, mm/deg). G starts at home, or, with `start_clear`, GUARD_SPAN back from a feature
    the object would touch there, which the run's guarded approach then finds (the executor's
    world); without it, the object starts on that feature (the friction-fidelity rigs, which load
    it from the start). With `solid`, the object says what solid to simulate
    (part_geometry.scene_object_geometry: a mesh part's convex pieces, which needs CoACD for a
    non-convex one); without, a simulator builds the prism of the section (for callers that read
    only the poses)."""
    body = task.object.rigid_body()
    q = Pose.of(in_grasp)
    T_GO = grasp_transform(tuple(q))
    start = translation(np.asarray(task.environment.home, float) * MM)
    for feature in features.values() if start_clear else ():
        if near_pose(start, feature.object_pose @ np.linalg.inv(T_GO)):
            start = translation(feature.normal * GUARD_SPAN) @ start
            break
    geometry, mesh = scene_object_geometry(task) if solid else (None, None)
    com_x, com_z = body.com
    gravity_x, gravity_z = task.gravity
    part, grip = task.object, task.gripper
    return Scene(
        task=task.name,
        gravity=(gravity_x, gravity_z),
        object=SceneObject(polygon=tuple((x * MM, z * MM) for x, z in part.vertices), thickness=part.thickness * MM,
                           mass=body.mass, com=(com_x, com_z), inertia=body.inertia, geometry=geometry, mesh=mesh),
        gripper=SceneGripper(grip_force=grip.grip_force, mu=grip.mu, pad_rings=grip.pad_rings,
                             pads=tuple(Pad(center=(c[0] * MM, c[1] * MM), radius=r * MM) for c, r in grip.pads)),
        features=tuple(f.in_scene() for f in features.values()),
        gripper_pose=tuple(matrix_to_pose(start)),
        object_pose=tuple(matrix_to_pose(start @ T_GO)),
        object_in_grasp=q,
    )


RESTING_DISTANCE = 1e-3  # m: G this near the pose that holds the object on a feature rests it there (near_pose)
RESTING_ANGLE = math.radians(0.5)  # rad: and this near in orientation


def near_pose(a: np.ndarray, b: np.ndarray, distance: float = RESTING_DISTANCE, angle: float = RESTING_ANGLE) -> bool:
    """Whether two poses of G (4x4, m) lie within `distance` [m] and `angle` [rad] of each other."""
    cos = (np.trace(a[:3, :3].T @ b[:3, :3]) - 1) / 2
    return bool(np.linalg.norm(a[:3, 3] - b[:3, 3]) < distance and cos > math.cos(angle))
