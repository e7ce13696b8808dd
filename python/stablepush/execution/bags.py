"""A plan's trajectory as a ROS 2 bag (rosbag2, MCAP storage; written by the `rosbags` library),
for robot stacks, `ros2 bag play` and Foxglove (`stablepush trajectory PLAN --task TASK -o X.mcap`);
and a run as the executor saw it, in the same form (`RunRecording`, `execute --record run.mcap`).

Frames: `world` (W: x forward, y the gripping axis at home, z up; the arm's base), `gripper` (G,
between the pads), `object` (O, the task's object frame) and `feature_<pusher>` for each feature
(fixed in W, `feature_transform`). Each message is stamped with the bag's start plus its
trajectory time t (s from the start of the stream, as the executor streams it); the start is a
Unix time (`parse_stamp`), by default when the bag is written, so that a bag played beside live
data lies in its time. Topics, one message per trajectory sample unless said:
- `/tf_static` (tf2_msgs/msg/TFMessage, transient local as tf2's static broadcaster offers it), once
  at the start: world -> each feature;
- `/tf` (tf2_msgs/msg/TFMessage): world -> gripper, and gripper -> object: the object's pose in
  the grasp (the plan's pose at the last step reached; during a push, where the feature holds it);
- `/stablepush/gripper_pose` (geometry_msgs/msg/PoseStamped, in world): the CSV's row;
- `/stablepush/gripper_twist` (geometry_msgs/msg/TwistStamped, in world): its velocity;
- `/stablepush/phase` (std_msgs/msg/String): push, settle, retract, move or approach;
- `/stablepush/step` (std_msgs/msg/Int32): the plan step (the one a push heads for);
- `/stablepush/scene` (visualization_msgs/msg/MarkerArray), once at the start: the object's outline
  extruded to its thickness (in object), the pads (in gripper) and each feature's contact segment
  at its world pose (in world);
- `/stablepush/arm_scene` (std_msgs/msg/String), once at the start: the world as the arm protocol's
  hello describes it (JSON in the protocol's conventions, not ROS's: SI but for `object_in_grasp`,
  the plan's x mm, z mm, theta deg; poses [x, y, z, qw, qx, qy, qz];
  `stablepush.execution.scene.Scene.as_dict`), so that a bridge can replay the bag to an arm
  server (examples/bag_to_arm.py).
Units in the ROS messages: m, s, rad; quaternions x, y, z, w.
"""
from __future__ import annotations

import datetime
import json
import os
import re
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Dict, Iterable, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from stablepush.errors import OutputError, SettingError
from stablepush.execution.arm import RobotDescription
from stablepush.execution.trajectory import Trajectory, continuous_quaternions
from stablepush.execution.world import Feature, place_features, scene_description
from stablepush.extras import require
from stablepush.frames import grasp_transform, matrix_to_pose, pose_to_matrix
from stablepush.outputs import check_output
from stablepush.plan.plan import Plan
from stablepush.plan.verify import check_plan
from stablepush.task.model import Task
from stablepush.units import MM

WORLD, GRIPPER, OBJECT = "world", "gripper", "object"
TF_STATIC = "/tf_static"
TOPICS = {
    TF_STATIC: "tf2_msgs/msg/TFMessage",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/stablepush/gripper_pose": "geometry_msgs/msg/PoseStamped",
    "/stablepush/gripper_twist": "geometry_msgs/msg/TwistStamped",
    "/stablepush/phase": "std_msgs/msg/String",
    "/stablepush/step": "std_msgs/msg/Int32",
    "/stablepush/scene": "visualization_msgs/msg/MarkerArray",
    "/stablepush/arm_scene": "std_msgs/msg/String",
}


# ROS 2 stamps hold whole seconds in an int32: a bag starts from 1970 to 2038-01-19, less a day for its length.
STAMP_MAX_S = 2**31 - 1 - 86_400
_UNIX_SECONDS = re.compile(r"\d+(\.\d+)?")


def parse_stamp(value: str) -> int:
    """A bag's start time (`--stamp`) as Unix ns, from Unix seconds (`1764600000.5`, rounded to
    the ns) or an ISO-8601 time with its zone (`2026-12-01T15:00:00Z`, `2026-12-01T16:00:00+01:00`).
    SettingError saying why not."""
    text = value.strip()
    if _UNIX_SECONDS.fullmatch(text):
        ns = int((Decimal(text) * 1_000_000_000).to_integral_value())
    else:
        try:  # Python before 3.11 reads no Z
            when = datetime.datetime.fromisoformat(text[:-1] + "+00:00" if text.endswith(("Z", "z")) else text)
        except ValueError:
            raise SettingError("stamp", f"expected Unix seconds (e.g. 1764600000.5) or an ISO-8601 time with its "
                                        f"zone (e.g. 2026-12-01T15:00:00Z), got {value!r:.60}") from None
        if when.tzinfo is None:
            raise SettingError("stamp", f"{value!r:.60} has no zone: add one (Z for UTC, or an offset such as +01:00)")
        since = when - datetime.datetime(1970, 1, 1, tzinfo=datetime.timezone.utc)
        ns = (since.days * 86_400 + since.seconds) * 1_000_000_000 + since.microseconds * 1_000
    if not 0 <= ns <= STAMP_MAX_S * 1_000_000_000:
        raise SettingError("stamp", f"{value!r:.60} is outside 1970-01-01 to 2038-01-18 (ROS 2 stamps hold int32 "
                                    f"seconds)")
    return ns


def feature_frame(pusher: str) -> str:
    """The tf frame of the feature that acts as `pusher`."""
    return f"feature_{pusher}"


def feature_transform(feature: Feature) -> np.ndarray:
    """T_WF (4x4, m): a feature's frame, at the middle of its contact segment (a point pusher's
    point), z along its normal (into the object), y the object's thickness axis resting on it (the
    gripping axis), x = y cross z (along the segment)."""
    z = feature.normal / np.linalg.norm(feature.normal)
    y = feature.object_pose[:3, 1] - z * float(feature.object_pose[:3, 1] @ z)  # exactly normal to z
    y = y / np.linalg.norm(y)
    out = np.eye(4)
    out[:3, :3] = np.column_stack([np.cross(y, z), y, z])
    out[:3, 3] = (feature.start + feature.end) / 2
    return out


def object_in_gripper(task: Task, plan: Plan, trajectory: Trajectory) -> np.ndarray:
    """T_GO (n x 4 x 4, m) at each sample: during a push the object rests on its feature (T_WO
    fixed), elsewhere it is held at the pose of the last plan step reached."""
    steps = list(plan.waypoints)
    features = place_features(task, steps)
    out = np.empty((len(trajectory), 4, 4))
    for i in range(len(trajectory)):
        step = int(trajectory.step[i])
        if trajectory.phase[i] == "push":
            T_WG = pose_to_matrix([*trajectory.position[i], *trajectory.quaternion_wxyz[i]])
            out[i] = np.linalg.inv(T_WG) @ features[steps[step].pushed_by].object_pose
        else:
            out[i] = grasp_transform(steps[step].pose)
    return out


JOINT_TOPICS = {
    "/joint_states": "sensor_msgs/msg/JointState",
    "/stablepush/joint_trajectory": "trajectory_msgs/msg/JointTrajectory",
}
ROBOT_DESCRIPTION = "/robot_description"


class JointSamples(NamedTuple):
    """The arm's joints at each sample of a trajectory (stablepush.kinematics.cell_path.JointPath.samples):
    their `names`, and one row per sample of `positions` [rad], `velocities` [rad/s] and
    `accelerations` [rad/s^2]; `robot`, the arm's model (its base link, its URDF)."""

    names: Sequence[str]
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray
    robot: RobotDescription


def write_bag(path: Union[str, Path], task: Task, plan: Plan, trajectory: Trajectory,
              start_ns: Optional[int] = None, joints: Optional[JointSamples] = None) -> None:
    """Write the trajectory of `plan` as one MCAP file at `path`, each sample stamped `start_ns`
    (Unix ns, `parse_stamp`; default: now) plus its time. With `joints` (one row per sample of the
    trajectory), also the arm's `/joint_states` per sample and, once at the start, the whole
    `/stablepush/joint_trajectory` (trajectory_msgs/JointTrajectory in the arm's base link, each
    point's time_from_start its sample's t, with its velocities and accelerations), what
    ros2_control's joint_trajectory_controller takes, and the arm for a viewer (`_robot_topics`).
    PlanError unless the plan is the task's as it is now (stablepush.plan.verify.check_plan)."""
    check_plan(task, plan)
    start_ns = time.time_ns() if start_ns is None else start_ns
    T_GO = object_in_gripper(task, plan, trajectory)
    steps = list(plan.waypoints)
    features = place_features(task, steps)
    robot = joints.robot if joints is not None else None
    with _mcap(path, {**TOPICS, **(JOINT_TOPICS if joints is not None else {}), **_robot_topics(robot)}) as (T, write):
        start = _time(T, start_ns)
        if joints is not None:
            write("/stablepush/joint_trajectory", start_ns, _joint_trajectory(T, start, trajectory, joints))
            _write_robot(T, write, start_ns, joints.robot)
        write(TF_STATIC, start_ns, _static_transforms(T, start, features.values(), robot))
        write("/stablepush/scene", start_ns, T["visualization_msgs/msg/MarkerArray"](
            markers=_scene_markers(T, start, task, features.values())))
        scene = scene_description(task, features, steps[0].pose)
        write("/stablepush/arm_scene", start_ns, T["std_msgs/msg/String"](data=json.dumps(scene.as_dict())))
        held_poses = _continuous([matrix_to_pose(m) for m in T_GO])
        for i in range(len(trajectory)):
            ns = start_ns + int(round(float(trajectory.t[i]) * 1e9))
            stamp = _time(T, ns)
            pose = _pose(T, trajectory.position[i], trajectory.quaternion_wxyz[i])
            held = held_poses[i]
            assert held is not None, "every sample of a plan's trajectory holds the object"
            write("/tf", ns, T["tf2_msgs/msg/TFMessage"](transforms=[
                _transform(T, stamp, WORLD, GRIPPER, trajectory.position[i], trajectory.quaternion_wxyz[i]),
                _transform(T, stamp, GRIPPER, OBJECT, held[:3], held[3:])]))
            write("/stablepush/gripper_pose", ns, T["geometry_msgs/msg/PoseStamped"](
                header=_header(T, stamp, WORLD), pose=pose))
            write("/stablepush/gripper_twist", ns, T["geometry_msgs/msg/TwistStamped"](
                header=_header(T, stamp, WORLD), twist=T["geometry_msgs/msg/Twist"](
                    linear=_vector3(T, trajectory.linear_velocity[i]),
                    angular=_vector3(T, trajectory.angular_velocity[i]))))
            write("/stablepush/phase", ns, T["std_msgs/msg/String"](data=trajectory.phase[i]))
            write("/stablepush/step", ns, T["std_msgs/msg/Int32"](data=int(trajectory.step[i])))
            if joints is not None:
                write("/joint_states", ns, _joint_state(T, stamp, joints.names, joints.positions[i],
                                                        joints.velocities[i]))


def _joint_state(T, stamp, names: Sequence[str], positions, velocities=()):
    return T["sensor_msgs/msg/JointState"](header=_header(T, stamp, ""), name=list(names),
                                           position=np.asarray(positions, float),
                                           velocity=np.asarray(velocities, float), effort=np.zeros(0))


def _joint_trajectory(T, stamp, trajectory: Trajectory, joints: JointSamples):
    """Every sample's joints as one JointTrajectory in the arm's base link, time_from_start each
    sample's t."""
    points = []
    for t, q, qd, qdd in zip(trajectory.t, joints.positions, joints.velocities, joints.accelerations):
        ns = int(round(float(t) * 1e9))
        points.append(T["trajectory_msgs/msg/JointTrajectoryPoint"](
            positions=np.asarray(q, float), velocities=np.asarray(qd, float), accelerations=np.asarray(qdd, float),
            effort=np.zeros(0), time_from_start=T["builtin_interfaces/msg/Duration"](sec=ns // 1_000_000_000,
                                                                                     nanosec=ns % 1_000_000_000)))
    return T["trajectory_msgs/msg/JointTrajectory"](header=_header(T, stamp, joints.robot.base_link),
                                                    joint_names=list(joints.names), points=points)


def _robot_topics(robot: Optional[RobotDescription]) -> dict:
    """`/robot_description` (std_msgs/String) when the arm's model is a URDF."""
    return {ROBOT_DESCRIPTION: "std_msgs/msg/String"} if robot is not None and robot.urdf is not None else {}


def _write_robot(T, write, ns: int, robot: RobotDescription) -> None:
    """The URDF once, at the start, as robot_state_publisher offers it (transient local: `_mcap`)."""
    if robot.urdf is not None:
        write(ROBOT_DESCRIPTION, ns, T["std_msgs/msg/String"](data=robot.urdf))


def _continuous(poses: Sequence[Optional[Sequence[float]]]) -> List[Optional[List[float]]]:
    """Poses [x, y, z, qw, qx, qy, qz] (None where a sample has none) with their quaternions made
    continuous over the ones present (trajectory.continuous_quaternions): a topic's quaternion
    does not jump to the other sign between two samples."""
    present = [(i, p) for i, p in enumerate(poses) if p is not None]
    out: List[Optional[List[float]]] = [None] * len(poses)
    if present:
        quats = continuous_quaternions(np.array([p[3:] for _, p in present], float))
        for (i, p), q in zip(present, quats):
            out[i] = [*map(float, p[:3]), *map(float, q)]
    return out


@contextmanager
def _mcap(path: Union[str, Path], topics: dict):
    """A ROS 2 bag of `topics` (name -> message type) being written: yields the message types
    (Humble's) and write(topic, stamp ns, message); on leaving, the bag's MCAP file is moved to
    `path` whole (rosbag2 writes a directory; its metadata lives in the MCAP file too)."""
    require("rosbags", "a ROS 2 bag")  # the extra to install, when it is missing
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    check_output(path)  # as given: Path() drops a trailing slash, and "r.mcap/" was written as r.mcap
    path = Path(path)
    try:  # the bag is written beside its output, so that the last move is a rename
        scratch_directory = tempfile.TemporaryDirectory(dir=path.parent if path.parent.exists() else None)
    except OSError as exc:
        raise OutputError(f"{path}: cannot write the bag ({exc.strerror or exc})", output=path) from None
    with scratch_directory as scratch:
        bag = Path(scratch) / "bag"
        with Writer(bag, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
            connections = {topic: writer.add_connection(topic, kind, typestore=store,
                                                        offered_qos_profiles=_latched_qos() if topic in LATCHED
                                                        else ())
                           for topic, kind in topics.items()}

            def write(topic: str, stamp_ns: int, message) -> None:
                writer.write(connections[topic], stamp_ns, store.serialize_cdr(message, topics[topic]))

            yield store.types, write
        try:
            os.replace(bag / "bag.mcap", path)
        except OSError as exc:
            raise OutputError(f"{path}: cannot write the bag ({exc.strerror or exc})", output=path) from None


# Topics published once that a late listener still gets: tf2's static broadcaster and
# robot_state_publisher offer them transient local.
LATCHED = (TF_STATIC, ROBOT_DESCRIPTION)


def _latched_qos() -> list:
    """The QoS tf2's static broadcaster offers on /tf_static, and robot_state_publisher on
    /robot_description (reliable, transient local, the last message kept), recorded so that
    `ros2 bag play` offers it too: a late listener gets the frames and the arm."""
    from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime

    default = QosTime(0, 0)  # no deadline, lifespan or lease
    return [Qos(QosHistory.KEEP_LAST, 1, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL, default, default,
                QosLiveliness.AUTOMATIC, default, False)]


# -- messages ---------------------------------------------------------------------------------


def _time(T, ns: int):
    return T["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def _header(T, stamp, frame: str):
    return T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)


def _vector3(T, v: Sequence[float]):
    return T["geometry_msgs/msg/Vector3"](x=float(v[0]), y=float(v[1]), z=float(v[2]))


def _quaternion(T, q_wxyz: Sequence[float]):
    return T["geometry_msgs/msg/Quaternion"](x=float(q_wxyz[1]), y=float(q_wxyz[2]), z=float(q_wxyz[3]),
                                             w=float(q_wxyz[0]))


def _pose(T, p: Union[Sequence[float], np.ndarray], q_wxyz: Sequence[float]):
    return T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=float(p[0]), y=float(p[1]),
                                                                             z=float(p[2])),
                                       orientation=_quaternion(T, q_wxyz))


def _transform(T, stamp, parent: str, child: str, p, q_wxyz):
    return T["geometry_msgs/msg/TransformStamped"](
        header=_header(T, stamp, parent), child_frame_id=child,
        transform=T["geometry_msgs/msg/Transform"](translation=_vector3(T, p), rotation=_quaternion(T, q_wxyz)))


def _static_transforms(T, stamp, features: Iterable[Feature], robot: Optional[RobotDescription] = None):
    """/tf_static's message: world -> each feature's frame (feature_transform), and world -> the
    arm's base link where the robot stands, when there is an arm."""
    transforms = []
    for feature in features:
        pose = matrix_to_pose(feature_transform(feature))
        transforms.append(_transform(T, stamp, WORLD, feature_frame(feature.pusher), pose[:3], pose[3:]))
    if robot is not None and robot.base_link != WORLD:  # a URDF rooted at a link named world is ours already
        transforms.append(_transform(T, stamp, WORLD, robot.base_link, robot.base_pose[:3], robot.base_pose[3:]))
    return T["tf2_msgs/msg/TFMessage"](transforms=transforms)


@dataclass(frozen=True)
class _Look:
    """How a marker is drawn: its Marker type (LINE_LIST, CYLINDER, ...), its scale (m; a line's
    width in x) and its colour (r, g, b)."""

    kind: int
    scale: Tuple[float, float, float]
    colour: Tuple[float, float, float]


def _marker(T, stamp, ident: int, frame: str, look: _Look, points, pose=None):
    Marker = T["visualization_msgs/msg/Marker"]
    return Marker(
        header=_header(T, stamp, frame), ns="stablepush", id=ident, type=look.kind, action=Marker.ADD,
        pose=pose or _pose(T, (0, 0, 0), (1, 0, 0, 0)), scale=_vector3(T, look.scale),
        color=T["std_msgs/msg/ColorRGBA"](r=look.colour[0], g=look.colour[1], b=look.colour[2], a=1.0),
        lifetime=T["builtin_interfaces/msg/Duration"](sec=0, nanosec=0), frame_locked=True,
        points=[T["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=float(z)) for x, y, z in points],
        colors=[], texture_resource="", texture=T["sensor_msgs/msg/CompressedImage"](
            header=_header(T, stamp, ""), format="", data=np.zeros(0, np.uint8)),
        uv_coordinates=[], text="", mesh_resource="",
        mesh_file=T["visualization_msgs/msg/MeshFile"](filename="", data=np.zeros(0, np.uint8)),
        mesh_use_embedded_materials=False)


def _scene_markers(T, stamp, task: Task, features: Iterable[Feature]) -> list:
    """The object's outline extruded to its thickness (LINE_LIST in object), the pads (CYLINDER
    in gripper, axis along y) and each feature's contact segment (LINE_LIST in world)."""
    Marker = T["visualization_msgs/msg/Marker"]
    half = task.object.thickness * MM / 2
    outline = [(x * MM, z * MM) for x, z in task.object.vertices]
    edges = []
    for (x0, z0), (x1, z1) in zip(outline, outline[1:] + outline[:1]):
        for y in (-half, half):
            edges += [(x0, y, z0), (x1, y, z1)]
        edges += [(x0, -half, z0), (x0, half, z0)]
    markers = [_marker(T, stamp, 0, OBJECT, _Look(Marker.LINE_LIST, (0.0005, 0, 0), (0.85, 0.55, 0.25)), edges)]
    along_y = (np.sqrt(0.5), np.sqrt(0.5), 0.0, 0.0)  # the cylinder's z axis turned onto y
    for k, ((cx, cz), r) in enumerate(task.gripper.pads):  # pad k on the finger at +y when k is even
        y = half if k % 2 == 0 else -half
        markers.append(_marker(T, stamp, 1 + k, GRIPPER,
                               _Look(Marker.CYLINDER, (2 * r * MM, 2 * r * MM, 0.002), (0.2, 0.2, 0.2)), [],
                               pose=_pose(T, (cx * MM, y, cz * MM), along_y)))
    blue = (0.3, 0.5, 0.8)
    for k, feature in enumerate(features):
        if np.allclose(feature.start, feature.end):  # a point pusher: a peg
            markers.append(_marker(T, stamp, 100 + k, WORLD, _Look(Marker.SPHERE, (0.004, 0.004, 0.004), blue), [],
                                   pose=_pose(T, feature.start, (1, 0, 0, 0))))
        else:
            markers.append(_marker(T, stamp, 100 + k, WORLD, _Look(Marker.LINE_LIST, (0.003, 0, 0), blue),
                                   [feature.start, feature.end]))
    return markers


# -- a run, recorded ----------------------------------------------------------------------------

RUN_TOPICS = {
    TF_STATIC: "tf2_msgs/msg/TFMessage",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/stablepush/commanded_pose": "geometry_msgs/msg/PoseStamped",
    "/stablepush/gripper_pose": "geometry_msgs/msg/PoseStamped",
    "/stablepush/object_pose": "geometry_msgs/msg/PoseStamped",
    "/stablepush/object_in_grasp": "geometry_msgs/msg/PoseStamped",
    "/stablepush/pusher": "std_msgs/msg/String",
    "/stablepush/phase": "std_msgs/msg/String",
    "/stablepush/step": "std_msgs/msg/Int32",
    "/stablepush/correction": "std_msgs/msg/String",
    "/stablepush/verdict": "std_msgs/msg/String",
}


class RunSample(NamedTuple):
    """One acknowledged waypoint of a recorded run. Poses are [x, y, z, qw, qx, qy, qz] in W (m);
    `object_pose` is None when the arm does not report it (a real arm), `object_in_grasp`
    ({x, z mm, theta deg}) when it has no tracker; `planned` is the plan's pose in the grasp at
    `step` (x mm, z mm, theta deg), in the plan being followed (re-planned after a correction);
    `joints` the arm's joint positions as it reports them [rad], None when it reports none."""

    t: float  # s, the stream's time
    commanded: List[float]
    reported: List[float]  # G as the arm reports it (`ee_pose`)
    object_pose: Optional[List[float]]
    object_in_grasp: Optional[Dict[str, float]]
    pusher: str  # the pusher in contact, "" between contacts
    phase: str
    step: int
    planned: Optional[Tuple[float, float, float]]
    joints: Optional[List[float]] = None


class RunRecording:
    """A run as the executor saw it (`execute --record run.mcap`, `--video run.mp4`), one
    `RunSample` per acknowledged waypoint, stamped with the run's start plus the stream's time. As
    a bag: `/tf_static` world -> each of `features` (the world the run starts in; `for_run`), the
    commanded and the reported gripper pose (world), the object's pose in the world
    (`/stablepush/object_pose`, a simulator's truth) and in the grasp (`/stablepush/object_in_grasp`,
    the tracker's, in gripper), `/tf` world -> gripper -> object, the pusher in contact ("" between
    contacts), phase and step; each correction of the closed loop (`/stablepush/correction`, JSON,
    at the step after which it was made) and the run's report (`/stablepush/verdict`, JSON, at the
    end). With the arm's model (`robot`: run_plan takes it from the arm), also the arm's joints as
    it reports them (`/joint_states`, at each sample whose joints are the model's), its base link
    in `/tf_static` and its URDF (`/robot_description`, once, transient local), from which a viewer
    draws the arm; an MJCF model has no URDF, and its bag has the joints and the base link alone.
    Pass it to `execute_plan(record=...)`."""

    def __init__(self, features: Iterable[Feature] = (), robot: Optional[RobotDescription] = None):
        self.samples: List[RunSample] = []
        self.features = list(features)
        self.robot = robot
        self.started_ns = time.time_ns()  # Unix ns; at the first sample, when the stream's time began

    @classmethod
    def for_run(cls, task: Task, plan: Plan, closed_loop: bool = False) -> "RunRecording":
        """A recording of a run of `plan` on `task`, with the features where `execute_plan` places
        them (every pusher's with a closed loop)."""
        return cls(place_features(task, list(plan.waypoints), every_pusher=closed_loop).values())

    def __call__(self, waypoint, state: dict, pusher) -> None:
        if not self.samples:
            self.started_ns = time.time_ns() - int(round(waypoint.t * 1e9))
        joints = state.get("joints")
        self.samples.append(RunSample(waypoint.t, list(waypoint.pose), list(state["ee_pose"]), state.get("object_pose"),
                                      state.get("object_in_grasp"), pusher or "", waypoint.phase, waypoint.step,
                                      waypoint.planned, None if joints is None else [float(v) for v in joints]))

    def joint_samples(self) -> List[int]:
        """The samples whose reported joints are the arm model's (as many), in order; none without
        a model."""
        if self.robot is None:
            return []
        count = len(self.robot.joints)
        return [k for k, s in enumerate(self.samples) if s.joints is not None and len(s.joints) == count]

    def write(self, path: Union[str, Path], report: dict, start_ns: Optional[int] = None) -> None:
        """Write the recording and `report` (ExecutionReport.as_dict, or a fault's report) as one
        MCAP file at `path`, each sample stamped `start_ns` (Unix ns, `parse_stamp`; default: when
        the run started, as its first acknowledgement less the stream's time then) plus its time."""
        start_ns = self.started_ns if start_ns is None else start_ns
        samples = self.samples
        commanded_poses = _continuous([s.commanded for s in samples])
        reported_poses = _continuous([s.reported for s in samples])
        world_poses = _continuous([s.object_pose for s in samples])
        grasp_poses = _continuous([None if s.object_in_grasp is None else matrix_to_pose(grasp_transform(
            (s.object_in_grasp["x"], s.object_in_grasp["z"], s.object_in_grasp["theta"]))) for s in samples])
        with_joints = set(self.joint_samples())
        topics = {**RUN_TOPICS, **({"/joint_states": JOINT_TOPICS["/joint_states"]} if with_joints else {}),
                  **_robot_topics(self.robot)}
        with _mcap(path, topics) as (T, write):
            write(TF_STATIC, start_ns, _static_transforms(T, _time(T, start_ns), self.features, self.robot))
            if self.robot is not None:
                _write_robot(T, write, start_ns, self.robot)
            last_ns, end_of_step = start_ns, {}
            for k, (t, _, _, _, _, pusher, phase, step, _, joints) in enumerate(samples):
                commanded, reported, in_world, held = (commanded_poses[k], reported_poses[k], world_poses[k],
                                                       grasp_poses[k])
                assert commanded is not None and reported is not None, "every sample has both (__call__)"
                ns = last_ns = start_ns + int(round(t * 1e9))
                end_of_step[step] = ns
                stamp = _time(T, ns)
                write("/stablepush/commanded_pose", ns, T["geometry_msgs/msg/PoseStamped"](
                    header=_header(T, stamp, WORLD), pose=_pose(T, commanded[:3], commanded[3:])))
                write("/stablepush/gripper_pose", ns, T["geometry_msgs/msg/PoseStamped"](
                    header=_header(T, stamp, WORLD), pose=_pose(T, reported[:3], reported[3:])))
                transforms = [_transform(T, stamp, WORLD, GRIPPER, reported[:3], reported[3:])]
                if in_world is not None:
                    write("/stablepush/object_pose", ns, T["geometry_msgs/msg/PoseStamped"](
                        header=_header(T, stamp, WORLD), pose=_pose(T, in_world[:3], in_world[3:])))
                if held is not None:
                    write("/stablepush/object_in_grasp", ns, T["geometry_msgs/msg/PoseStamped"](
                        header=_header(T, stamp, GRIPPER), pose=_pose(T, held[:3], held[3:])))
                    transforms.append(_transform(T, stamp, GRIPPER, OBJECT, held[:3], held[3:]))
                write("/tf", ns, T["tf2_msgs/msg/TFMessage"](transforms=transforms))
                write("/stablepush/pusher", ns, T["std_msgs/msg/String"](data=pusher))
                write("/stablepush/phase", ns, T["std_msgs/msg/String"](data=phase))
                write("/stablepush/step", ns, T["std_msgs/msg/Int32"](data=int(step)))
                if k in with_joints:
                    assert self.robot is not None, "joint samples are the arm model's (joint_samples)"
                    write("/joint_states", ns, _joint_state(T, stamp, self.robot.joints, joints))
            for correction in report.get("replans") or []:
                ns = end_of_step.get(correction["after_step"], last_ns)
                write("/stablepush/correction", ns, T["std_msgs/msg/String"](data=json.dumps(correction)))
            write("/stablepush/verdict", last_ns, T["std_msgs/msg/String"](data=json.dumps(report)))
