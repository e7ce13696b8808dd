"""The arm of a run as the simulators and the cell check build it: a `task.model.Robot` (the
shipped arm, or a lab's URDF or MJCF with its flange, TCP and base) made into one MJCF tree of the
arm with the project's jaws mounted at G, plus what the tree alone does not say: the arm's joints
from its base to the flange, their speed limits and where IK starts looking for the home posture.

A lab's model is compiled by MuJoCo (which reads URDF and MJCF alike) and saved back as MJCF, so
both engines read one tree: MuJoCo whole, Drake through its MJCF parser. In that tree
- the arm stands in a body `arm_base` at the robot's base pose in the world;
- G (the site GRIPPER_SITE) and the shipped arm's jaws (FINGER_JOINTS, their servos and their
  coupling) hang from the flange at the TCP, X_FG = Trans(tcp[:3]) Rot(rpy(tcp[3:]));
- every joint from the base to the flange gets a position servo named after it, stiff as the
  shipped arm's, and every body is carried by gravity compensation (gravcomp), as the shipped
  arm's are; the model's own actuators, sensors and keyframes are dropped;
- no geom of the arm collides in the simulation (contype 0): the cell check (cell_path.py)
  measures the links' clearance from the fixtures and the floor before any motion instead.
Lengths in m, angles in rad in the tree; the Robot's fields are mm and deg.
"""
from __future__ import annotations

import copy
import functools
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from stablepush.execution.arm import RobotDescription
from stablepush.frames import matrix_to_pose, pose_to_matrix
from stablepush.task.model import Robot
from stablepush.task.robot_files import RobotError, model_source, read_model_text, read_model_xml
from stablepush.units import MM

ARM_XML = Path(__file__).with_name("arm.xml")
SHIPPED_JOINTS = ("j1", "j2", "j3", "j4", "j5", "j6", "j7")
SHIPPED_HOME_GUESS = np.array([0.0, 0.35, 0.0, 1.9, 0.0, 0.89, 0.0])  # rad, hand down in front of the base
FINGER_JOINTS = ("finger_pos", "finger_neg")
GRIPPER_SITE = "G"
BASE_BODY = "arm_base"
# The servos of a lab's arm: as stiff as the shipped arm's middle joints (its kp 20,000-60,000
# N m/rad), with its joint damping and armature where the model gives less.
SERVO_KP = 40000.0  # N m/rad (N/m for a sliding joint)
SERVO_KV = 300.0  # N m s/rad
JOINT_DAMPING = 2.0  # N m s/rad
JOINT_ARMATURE = 0.2  # kg m^2
HOME_STARTS = 24  # seeded joint vectors IK starts from to find a lab's arm's home posture
# What of a lab's model the run has no use for, or replaces by its own.
_DROPPED = ("actuator", "sensor", "keyframe", "contact", "option")
# The names the project gives what it adds to a scene (here, cell_model.py and the 3D video: the base, G,
# the jaws and their servos, the floor, the kinematic hand, the object, the features, the pads, a
# mesh part's slabs). A lab's model that uses one has it renamed LAB_PREFIX + name, with every
# reference to it, so that neither is taken for the other (test_robot_models checks the list).
PROJECT_NAMES = frozenset({BASE_BODY, GRIPPER_SITE, *FINGER_JOINTS, "floor", "hand", "hand_x", "hand_z",
                           "hand_theta", "object", "ghost", "gripper", "backdrop", "view"})
PROJECT_PREFIXES = ("feature_", "pad_", "slab_", "object_", "ghost_")
LAB_PREFIX = "robot/"
# The MJCF attributes that name another element (MuJoCo 3's schema, those a saved model can hold).
_REFERENCES = ("body", "body1", "body2", "joint", "joint1", "joint2", "geom", "geom1", "geom2", "site", "site1",
               "site2", "tendon", "tendon1", "tendon2", "actuator", "mesh", "material", "texture", "hfield", "skin",
               "target", "objname", "slidersite", "cranksite", "jointinparent", "refsite", "camera", "light")


@dataclass
class ArmModel:
    """One arm made ready for a scene: `tree`, the MJCF of the arm with G and the jaws (a copy per
    call of `arm_tree`), `joints`, the arm's joints from base to flange, `max_speed` per joint
    [rad/s or m/s], and `home_guesses`, joint vectors [rad] IK starts from to find the home
    posture, best first; `base_link`, the model's link the chain to the flange starts from (a
    URDF's root link), at `base_pose` in the world ([x, y, z, qw, qx, qy, qz], m); `urdf`, the
    text of a URDF model (None for MJCF)."""

    tree: ET.Element
    joints: Tuple[str, ...]
    max_speed: np.ndarray
    home_guesses: Tuple[np.ndarray, ...]
    base_link: str = ""
    base_pose: Sequence[float] = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
    urdf: Optional[str] = None

    def too_fast(self, q_from: np.ndarray, q_to: np.ndarray, dt: float) -> Optional[str]:
        """Why moving the joints from `q_from` to `q_to` in `dt` s is past a joint's speed limit:
        the joint furthest past its own (max_speed), named with its speed; None within them."""
        speed = np.abs(np.asarray(q_to) - np.asarray(q_from)) / dt
        if not np.any(speed > self.max_speed):
            return None
        k = int(np.argmax(speed / self.max_speed))
        return f"joint {self.joints[k]} would turn {speed[k]:.2f} rad/s, past its {self.max_speed[k]:g} rad/s"

    def arm_tree(self) -> ET.Element:
        """A fresh copy of the tree, for a scene builder to add to."""
        return copy.deepcopy(self.tree)


def arm_model(robot: Optional[Robot] = None) -> ArmModel:
    """The arm of `robot` (None or the default Robot: the shipped arm, arm.xml as it is). A lab's
    model is compiled once per file version and robot (cached): a study's trials share it."""
    robot = robot or Robot()
    if robot == Robot():
        return _shipped()
    return _built(robot, model_stamp(robot))


def model_stamp(robot: Robot) -> int:
    """Which version of the robot's model file it is (its modification time, ns; 0: the shipped
    arm): what a cache of anything built from it keys on."""
    return os.stat(robot.model).st_mtime_ns if robot.model else 0


@functools.lru_cache(maxsize=1)
def _shipped() -> ArmModel:
    tree = ET.parse(ARM_XML).getroot()
    speeds = np.full(len(SHIPPED_JOINTS), Robot().max_joint_speed)
    base = _find(tree, "worldbody/body")
    return ArmModel(tree, SHIPPED_JOINTS, speeds, (SHIPPED_HOME_GUESS,), _name(base), _body_pose(base))


@functools.lru_cache(maxsize=8)
def _built(robot: Robot, _stamp: int) -> ArmModel:
    model = robot.model  # None: the shipped arm (robot.shipped)
    if model is None:  # the shipped arm on another flange, TCP or base
        root = ET.parse(ARM_XML).getroot()
        hand = _find(root, ".//body[@name='hand']")
        for child in [c for c in hand if c.tag in ("site", "body")]:
            hand.remove(child)  # its G and jaws: remounted at the robot's TCP
        velocity: Dict[str, float] = {}
        renamed: set = set()
    else:
        root = _compiled(model)
        velocity = _urdf_velocity_limits(model)
        for tag in _DROPPED:
            for element in root.findall(tag):
                root.remove(element)
        renamed = _keep_apart(root)
    _mount_on_base(root, robot.base)
    flange = _flange(root, robot.flange if robot.shipped or robot.flange not in renamed else LAB_PREFIX + robot.flange)
    joints = _chain_joints(root, flange)
    if model is not None:
        _refuse_project_joint_names(joints)
        _refuse_empty_ranges(joints)
        _refuse_couplings(root, joints, model)
        _servo(root, joints)
    _mount_jaws(root, flange, robot.tcp)
    names = tuple(_name(j) for j in joints)
    speeds = np.array([velocity.get(name) or robot.max_joint_speed for name in names])
    mount = _find(root, f"worldbody/body[@name='{BASE_BODY}']")
    base = next(body for body in mount if body.tag == "body" and flange in body.iter("body"))
    urdf = read_model_text(model) if model and Path(model).suffix.lower() == ".urdf" else None
    return ArmModel(root, names, speeds, _home_guesses(joints, robot.shipped), _lab_name(_name(base)),
                    matrix_to_pose(pose_to_matrix(_body_pose(mount)) @ pose_to_matrix(_body_pose(base))), urdf)


def is_project_name(name: str) -> bool:
    """Whether `name` is one the project gives what it adds to a scene (PROJECT_NAMES, PROJECT_PREFIXES)."""
    return name in PROJECT_NAMES or name.startswith(PROJECT_PREFIXES)


def _find(parent: ET.Element, path: str) -> ET.Element:
    """`parent.find(path)`, an element the model is known to hold (arm.xml's hand and jaws, the
    world body MuJoCo saves, the body _mount_on_base adds): RobotError naming the path if not."""
    found = parent.find(path)
    if found is None:
        raise RobotError("environment.robot.model", f"the model has no {path!r:.120}")
    return found


def _name(element: ET.Element) -> str:
    """The name of an element the model names (an arm's joint, checked by _chain_joints; a body
    the chain starts from): RobotError naming its tag if it has none."""
    name = element.get("name")
    if name is None:
        raise RobotError("environment.robot.model", f"a <{element.tag}> of the arm has no name")
    return name


def _keep_apart(root: ET.Element) -> set:
    """Every element of a lab's compiled model named as the project names its own (is_project_name)
    renamed LAB_PREFIX + name, with every reference to it: MuJoCo refuses a repeated name, and a
    lab's geom named floor was taken for the floor. Returns the names renamed."""
    renamed = {name for e in root.iter() if (name := e.get("name")) and is_project_name(name)}
    for element in root.iter():
        for key in ("name", *_REFERENCES):
            value = element.get(key)
            if value is not None and value in renamed:
                element.set(key, LAB_PREFIX + value)
    return renamed


def _lab_name(name: str) -> str:
    """A name of the lab's model as the lab's file writes it (without LAB_PREFIX)."""
    return name[len(LAB_PREFIX):] if name.startswith(LAB_PREFIX) else name


def _refuse_project_joint_names(joints: List[ET.Element]) -> None:
    """A joint of the arm renamed by _keep_apart would reach the lab's controller under a name it
    does not know: RobotError naming it."""
    clashing = [_lab_name(_name(j)) for j in joints if _name(j).startswith(LAB_PREFIX)]
    if clashing:
        raise RobotError("environment.robot.model", f"the arm's joint {clashing[0]!r} has a name stablepush gives "
                                                    f"its own jaws or scene ({', '.join(sorted(PROJECT_NAMES))[:200]}, "
                                                    f"or starting {', '.join(PROJECT_PREFIXES)}): rename it in the "
                                                    f"model")


def _body_pose(body: ET.Element) -> List[float]:
    """A body's pose in its parent ([x, y, z, qw, qx, qy, qz]) from its pos and quat (MuJoCo saves
    a compiled model's orientations as quat)."""
    pos = [float(v) for v in body.get("pos", "0 0 0").split()]
    quat = [float(v) for v in body.get("quat", "1 0 0 0").split()]
    return [*pos, *quat]


def robot_description(robot: Optional[Robot] = None) -> RobotDescription:
    """The arm of `robot` as a recording describes it (execution.arm.RobotDescription): its
    joints, its base link where the robot stands, and its URDF when the model is one."""
    arm = arm_model(robot)
    return RobotDescription(arm.joints, arm.base_link, tuple(float(v) for v in arm.base_pose), arm.urdf)


def _compiled(path: str) -> ET.Element:
    """The model at `path` (URDF or MJCF) compiled by MuJoCo and saved as MJCF: one form for both
    engines, defaults and includes resolved, every angle in radians. A URDF keeps its fixed links
    (fusestatic off: a flange is often one) and its collision geometry. MuJoCo is handed the text
    `model_source` makes of the file: the same from any working folder."""
    from stablepush.extras import require

    mujoco = require("mujoco", "environment.robot.model (MuJoCo compiles a lab's URDF or MJCF for both engines)")
    root = model_source(path)
    if root.tag == "robot":
        extension = root.find("mujoco")
        if extension is None:
            extension = ET.SubElement(root, "mujoco")
        compiler = extension.find("compiler")
        if compiler is None:
            compiler = ET.SubElement(extension, "compiler")
        compiler.set("fusestatic", "false")
        compiler.set("discardvisual", "true")
        for link in root.iter("link"):  # named, so MuJoCo need not warn of each unnamed one
            for k, collision in enumerate(link.iter("collision")):
                collision.set("name", collision.get("name") or f"{link.get('name')}_collision{k}")
    try:
        model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    except ValueError as exc:
        raise RobotError("environment.robot.model", f"MuJoCo cannot compile {path!r:.120}: "
                                                    f"{' '.join(str(exc).split())[:300]}") from None
    with tempfile.TemporaryDirectory() as scratch:
        saved = os.path.join(scratch, "robot.xml")
        mujoco.mj_saveLastXML(saved, model)
        compiled = ET.parse(saved).getroot()
    compiler = compiled.find("compiler")
    if compiler is None:
        compiler = ET.SubElement(compiled, "compiler")
    folder = Path(path).resolve().parent
    for key in ("meshdir", "texturedir"):  # absolute already (model_source); else the model's folder
        compiler.set(key, str(folder / compiler.get(key, "")))
    compiler.set("angle", "radian")
    return compiled


def _urdf_velocity_limits(path: str) -> Dict[str, float]:
    """A URDF's joints' `limit velocity` [rad/s or m/s] by name (MuJoCo keeps none); {} for MJCF,
    which has no such field."""
    if Path(path).suffix.lower() != ".urdf":
        return {}
    out = {}
    for joint in read_model_xml(path).iter("joint"):
        limit = joint.find("limit")
        text = None if limit is None else limit.get("velocity")
        if not text:
            continue
        try:
            velocity = float(text)
        except ValueError:
            raise RobotError("environment.robot.model", f"joint {joint.get('name')!r:.60}: limit velocity "
                                                        f"{text!r:.40} is not a number") from None
        name = joint.get("name")
        if name is not None and math.isfinite(velocity) and velocity > 0:  # an unnamed one: no arm joint
            out[name] = velocity
    return out


def _mount_on_base(root: ET.Element, base: Tuple[float, ...]) -> None:
    """Everything in the model's world body moves into BASE_BODY at `base` (x, y, z mm, yaw deg)."""
    worldbody = _find(root, "worldbody")
    x, y, z, yaw = base
    half = math.radians(yaw) / 2
    mount = ET.Element("body", name=BASE_BODY, pos=_numbers((x * MM, y * MM, z * MM)),
                       quat=_numbers((math.cos(half), 0.0, 0.0, math.sin(half))))
    for child in list(worldbody):
        if child.tag in ("light", "camera") or child.get("type") == "plane":  # the world's, not the arm's
            continue
        worldbody.remove(child)
        mount.append(child)
    worldbody.insert(0, mount)
    if root.find(".//geom[@name='floor']") is None:
        ET.SubElement(worldbody, "geom", name="floor", type="plane", size="1 1 0.01", rgba="0.9 0.9 0.9 1",
                      contype="0", conaffinity="0")


def _flange(root: ET.Element, name: str) -> ET.Element:
    flange = next((body for body in root.iter("body") if body.get("name") == name), None)  # any characters
    if flange is None:
        bodies = [n for b in root.iter("body") if (n := b.get("name")) and n != BASE_BODY]
        raise RobotError("environment.robot.flange", f"the model has no link {name!r:.60} (its links: "
                                                     f"{', '.join(bodies)[:300]})")
    return flange


def _chain_joints(root: ET.Element, flange: ET.Element) -> List[ET.Element]:
    """The hinge and slide joints on the way from the world to `flange`, base first."""
    parent = {child: body for body in root.iter() for child in body}
    chain: List[ET.Element] = []
    body: Optional[ET.Element] = flange
    while body is not None and body.tag == "body":
        chain.append(body)
        body = parent.get(body)
    joints = []
    for body in reversed(chain):
        for joint in body:
            if joint.tag == "freejoint" or (joint.tag == "joint" and joint.get("type") in ("free", "ball")):
                raise RobotError("environment.robot.model", f"link {body.get('name')!r} has a "
                                                            f"{joint.get('type', 'free')} joint: an arm's joints "
                                                            f"turn or slide about one axis")
            if joint.tag == "joint":
                if not joint.get("name"):
                    raise RobotError("environment.robot.model", f"a joint of link {body.get('name')!r} has no name "
                                                                f"(a joint trajectory names every joint)")
                joints.append(joint)
    if not joints:
        raise RobotError("environment.robot.flange", f"no joint moves link {flange.get('name')!r}")
    return joints


def _refuse_couplings(root: ET.Element, joints: List[ET.Element], path: str) -> None:
    """RobotError naming any coupling of the arm's joints: a URDF <mimic> (MuJoCo drops it), an
    MJCF <equality> on a joint, or a limited tendon, of the chain. The IK, the cell check and the
    joint trajectory move each joint on its own, so a coupled arm would not follow them."""
    names = {_name(j) for j in joints}
    found = []
    if Path(path).suffix.lower() == ".urdf":
        found += [f"joint {j.get('name')!r} mimics {mimic.get('joint')!r} (URDF <mimic>)"
                  for j in read_model_xml(path).iter("joint")
                  if (mimic := j.find("mimic")) is not None and (names & {j.get("name"), mimic.get("joint")})]
    for equality in root.findall("equality/*"):
        coupled = sorted(names & {equality.get(key) for key in ("joint1", "joint2")})
        if coupled:
            found.append(f"an <equality> {equality.tag} constraint on joint {coupled[0]!r}")
    for tendon in root.findall("tendon/*"):
        coupled = sorted(names & {j.get("joint") for j in tendon.iter("joint")})
        if coupled and tendon.get("range") is not None and tendon.get("limited", "auto") != "false":
            found.append(f"tendon {tendon.get('name') or '(unnamed)'!r} limits joint {coupled[0]!r}")
    if found:
        raise RobotError("environment.robot.model", f"{'; '.join(found)[:300]}: stablepush moves each joint of the "
                                                    f"arm on its own (IK, cell check, joint trajectory), so an arm "
                                                    f"whose joints are coupled is not supported")


def _servo(root: ET.Element, joints: List[ET.Element]) -> None:
    """A position servo per arm joint, every body carried by gravcomp, no arm geom colliding."""
    for joint in joints:
        joint.set("damping", repr(max(float(joint.get("damping", "0")), JOINT_DAMPING)))
        joint.set("armature", repr(max(float(joint.get("armature", "0")), JOINT_ARMATURE)))
    actuators = ET.SubElement(root, "actuator")
    for joint in joints:
        ET.SubElement(actuators, "position", name=_name(joint), joint=_name(joint), kp=repr(SERVO_KP),
                      kv=repr(SERVO_KV))
    for body in root.iter("body"):
        body.set("gravcomp", "1")
    for geom in root.iter("geom"):
        geom.set("contype", "0")
        geom.set("conaffinity", "0")


def _mount_jaws(root: ET.Element, flange: ET.Element, tcp: Tuple[float, ...]) -> None:
    """G and the shipped arm's jaws (their bodies, servos and coupling) on `flange` at `tcp`."""
    from scipy.spatial.transform import Rotation

    shipped = ET.parse(ARM_XML).getroot()
    hand = _find(shipped, ".//body[@name='hand']")
    X_FG = np.eye(4)
    X_FG[:3, :3] = Rotation.from_euler("xyz", tcp[3:], degrees=True).as_matrix()
    X_FG[:3, 3] = np.asarray(tcp[:3]) * MM
    pose = matrix_to_pose(X_FG)
    for child in hand:
        if child.tag in ("site", "body"):
            child.set("pos", _numbers(pose[:3]))
            child.set("quat", _numbers(pose[3:]))
            flange.append(child)
    actuators = root.find("actuator")
    if actuators is None:
        actuators = ET.SubElement(root, "actuator")
    for finger in FINGER_JOINTS:  # the shipped arm has them already
        if actuators.find(f"position[@name='{finger}']") is None:
            actuators.append(_find(shipped, f".//actuator/position[@name='{finger}']"))
    if root.find("equality") is None:
        ET.SubElement(root, "equality")
    if root.find("equality/joint[@joint1='finger_neg']") is None:
        _find(root, "equality").append(_find(shipped, "equality/joint"))


def _home_guesses(joints: List[ET.Element], shipped: bool) -> Tuple[np.ndarray, ...]:
    """Where IK starts looking for the home posture: the shipped arm's known posture; for a lab's
    arm, the middle of each joint's range, zero, then HOME_STARTS seeded draws within the ranges."""
    if shipped:
        return (SHIPPED_HOME_GUESS,)
    lower, upper = joint_ranges(joints)
    # Draws within the turn about zero, clipped to each range; a range wholly past a half turn either
    # way (4 to 5 rad, say) is drawn within itself, a turn of it at most.
    lo, hi = np.clip(-math.pi, lower, upper), np.clip(math.pi, lower, upper)
    beyond = (lo == hi) & (lower < upper)
    lo, hi = (np.where(beyond, np.maximum(lower, hi - 2 * math.pi), lo),
              np.where(beyond, np.minimum(upper, lo + 2 * math.pi), hi))
    rng = np.random.default_rng(0)
    return (np.clip((lo + hi) / 2, lower, upper), np.clip(np.zeros(len(joints)), lower, upper),
            *(rng.uniform(lo, hi) for _ in range(HOME_STARTS)))


def _refuse_empty_ranges(joints: List[ET.Element]) -> None:
    """RobotError naming an arm's joint whose range is no interval: its lower end above its upper
    (MuJoCo compiles `range="2.6 -2.6"`, and the IK's draws within it failed as an internal error)."""
    for joint, lower, upper in zip(joints, *joint_ranges(joints)):
        if not lower <= upper:
            raise RobotError("environment.robot.model", f"joint {_lab_name(_name(joint))!r:.60}: its range "
                                                        f"{lower:g} to {upper:g} is empty (the lower end above the "
                                                        f"upper)")


def joint_ranges(joints: List[ET.Element]) -> Tuple[np.ndarray, np.ndarray]:
    """Each joint's [lower, upper] from its MJCF `range` (unlimited: -inf, inf)."""
    lower, upper = [], []
    for joint in joints:
        text = joint.get("range")
        if text is not None and joint.get("limited", "auto") != "false":
            a, b = (float(v) for v in text.split())
        else:
            a, b = -math.inf, math.inf
        lower.append(a)
        upper.append(b)
    return np.array(lower), np.array(upper)


def _numbers(values) -> str:
    return " ".join(repr(float(v)) for v in values)
