"""The scene: the world a simulated arm builds for a run, as one frozen value (SI units, the world
frame W of `world.py`): the object as simulated, the gripper with its pads, gravity, the fixed
features, and where G and the object are when the run starts. `world.scene_description` makes one
from a task; `WorldDeviation.apply` (stablepush.sim.deviation) makes another from it.

JSON only at the wire: `Scene.as_dict()` is the arm protocol's `hello.scene` (protocol.py) and a
bag's `/stablepush/arm_scene`; `Scene.from_dict` reads one back once `protocol.check_scene` has
checked it (`protocol.read_scene` does both). Sequences are tuples, so that two scenes compare
equal when their worlds are the same (a simulator keeps its world for a resumed run of the same
scene) and a scene can be hashed.

Poses of G and of the object in W are (x, y, z, qw, qx, qy, qz): position in m, a unit quaternion.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Dict, Optional, Sequence, Tuple

from stablepush.pose import Pose

WorldPose = Tuple[float, ...]  # (x, y, z m; qw, qx, qy, qz) in W
Point2 = Tuple[float, float]
Point3 = Tuple[float, float, float]


@dataclass(frozen=True)
class MeshSolid:
    """A mesh part's solid as simulated (execution.part_geometry): its convex `pieces`, each its
    hull's corners in O (m); the solid's `inertia` tensor about its centre of mass (kg m^2, O's
    axes; a simulator takes I_yy from the object's own `inertia`, which a task file may give) and
    that centre's `com_y` (m; the object's `com` gives x and z)."""

    pieces: Tuple[Tuple[Point3, ...], ...]
    inertia: Tuple[Point3, ...]  # 3 rows
    com_y: float

    def as_dict(self) -> Dict[str, Any]:
        return {"pieces": [[list(p) for p in piece] for piece in self.pieces],
                "inertia": [list(row) for row in self.inertia], "com_y": self.com_y}

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "MeshSolid":
        return cls(pieces=tuple(tuple(_point3(p) for p in piece) for piece in d["pieces"]),
                   inertia=tuple(_point3(row) for row in d["inertia"]),
                   com_y=d["com_y"])


@dataclass(frozen=True)
class SceneObject:
    """The held object: its section `polygon` (O's x, z, m, counterclockwise), `thickness` (m along
    O's y), `mass` (kg), centre of mass `com` (O's x, z, m) and moment of inertia about y
    `inertia` (kg m^2); `geometry`, what solid a simulator builds of it in words (None: not said),
    and for a mesh part its convex pieces (`mesh`; None: the prism of the section)."""

    polygon: Tuple[Point2, ...]
    thickness: float
    mass: float
    com: Point2
    inertia: float
    geometry: Optional[str] = None
    mesh: Optional[MeshSolid] = None

    def as_dict(self) -> Dict[str, Any]:
        out: Dict[str, Any] = {"polygon": [list(p) for p in self.polygon], "thickness": self.thickness,
                               "mass": self.mass, "com": list(self.com), "inertia": self.inertia}
        if self.geometry is not None:
            out["geometry"] = self.geometry
        if self.mesh is not None:
            out["mesh"] = self.mesh.as_dict()
        return out

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "SceneObject":
        return cls(polygon=tuple(_point2(p) for p in d["polygon"]), thickness=d["thickness"], mass=d["mass"],
                   com=_point2(d["com"]), inertia=d["inertia"], geometry=d.get("geometry"),
                   mesh=MeshSolid.from_dict(d["mesh"]) if "mesh" in d else None)


@dataclass(frozen=True)
class Pad:
    """A pad disc: its `center` in G's xz-plane (m) and its `radius` (m)."""

    center: Point2
    radius: float

    def as_dict(self) -> Dict[str, Any]:
        return {"center": list(self.center), "radius": self.radius}


@dataclass(frozen=True)
class SceneGripper:
    """The gripper: each pad pressed with `grip_force` (N), the pads' friction coefficient `mu`
    with the object, each pad a disc of point contacts in `pad_rings` rings (docs/model.md section
    2), the `pads` listed in opposed pairs (pad i on finger i mod 2)."""

    grip_force: float
    mu: float
    pad_rings: int
    pads: Tuple[Pad, ...]

    def as_dict(self) -> Dict[str, Any]:
        return {"grip_force": self.grip_force, "mu": self.mu, "pad_rings": self.pad_rings,
                "pads": [pad.as_dict() for pad in self.pads]}

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "SceneGripper":
        return cls(grip_force=d["grip_force"], mu=d["mu"], pad_rings=d["pad_rings"],
                   pads=tuple(Pad(_point2(p["center"]), p["radius"]) for p in d["pads"]))


@dataclass(frozen=True)
class SceneFeature:
    """A fixed feature acting as pusher `pusher`: it touches the object along the segment `start`
    to `end` (W, m; "from" and "to" on the wire) when the object is at `object_pose` (W); `normal`
    is the pusher's inward unit normal in W (into the object); `mu` its friction with the object."""

    pusher: str
    start: Point3
    end: Point3
    normal: Point3
    mu: float
    object_pose: WorldPose

    def as_dict(self) -> Dict[str, Any]:
        return {"pusher": self.pusher, "from": list(self.start), "to": list(self.end), "normal": list(self.normal),
                "mu": self.mu, "object_pose": list(self.object_pose)}

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "SceneFeature":
        return cls(pusher=d["pusher"], start=_point3(d["from"]), end=_point3(d["to"]), normal=_point3(d["normal"]),
                   mu=d["mu"], object_pose=tuple(d["object_pose"]))


@dataclass(frozen=True)
class Scene:
    """The world of a run: gravity in the grasp plane (`gravity`, W's x and z, m/s^2), the object,
    the gripper, the features, G's pose when the run starts (`gripper_pose`) and the object's
    (`object_pose`), the object's pose in the grasp then (`object_in_grasp`, mm and deg as the
    plan has it; None: not said) and the task's name (None: not said)."""

    gravity: Point2
    object: SceneObject
    gripper: SceneGripper
    features: Tuple[SceneFeature, ...]
    gripper_pose: WorldPose
    object_pose: WorldPose
    object_in_grasp: Optional[Pose] = None
    task: Optional[str] = None

    def as_dict(self) -> Dict[str, Any]:
        """The protocol's `hello.scene` (JSON-ready; protocol.py documents it)."""
        out: Dict[str, Any] = {} if self.task is None else {"task": self.task}
        out.update(gravity=list(self.gravity), object=self.object.as_dict(), gripper=self.gripper.as_dict(),
                   features=[f.as_dict() for f in self.features], gripper_pose=list(self.gripper_pose),
                   object_pose=list(self.object_pose))
        if self.object_in_grasp is not None:
            out["object_in_grasp"] = list(self.object_in_grasp)
        return out

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "Scene":
        """The scene of a `hello.scene` that `protocol.check_scene` has passed (protocol.read_scene
        checks and reads); fields the protocol does not name are dropped."""
        in_grasp = d.get("object_in_grasp")
        return cls(gravity=_point2(d["gravity"]), object=SceneObject.from_dict(d["object"]),
                   gripper=SceneGripper.from_dict(d["gripper"]),
                   features=tuple(SceneFeature.from_dict(f) for f in d["features"]),
                   gripper_pose=tuple(d["gripper_pose"]), object_pose=tuple(d["object_pose"]),
                   object_in_grasp=None if in_grasp is None else Pose.of(in_grasp), task=d.get("task"))

    def same_world(self, other: Optional["Scene"]) -> bool:
        """Whether `other` is this scene's world, wherever the run starts in it (the poses aside):
        a resumed run starts elsewhere in the world it left."""
        return other is not None and self._world() == other._world()

    def _world(self) -> "Scene":
        return dataclasses.replace(self, gripper_pose=(), object_pose=(), object_in_grasp=None)


def _point2(p: Sequence[float]) -> Point2:
    return (p[0], p[1])


def _point3(p: Sequence[float]) -> Point3:
    return (p[0], p[1], p[2])
