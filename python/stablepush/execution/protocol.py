"""The arm protocol `stablepush.arm/2`: JSON lines over TCP between the executor (client) and an
arm server (`stablepush sim-arm`, or a user's bridge to a real robot).

Versions: arm/2 defines the tracker field `state.object_in_grasp` (below), which the executor's
closed loop reads; it is otherwise arm/1. The simulated arm answers the version the client's hello
asks for; a bridge written for arm/1 that checks the version refuses the executor's arm/2 hello,
and needs only that check widened (nothing else changed).

One JSON object per line, UTF-8, each with a "type". Poses are [x, y, z, qw, qx, qy, qz] of the
gripper frame G in the world, m. The exchange is lock-step: every waypoint is acknowledged before
the next is sent.

client -> server
  {"type": "hello", "protocol": "stablepush.arm/2", "rate_hz": 100, "scene": {...}, "continue": false}
      `scene` describes the world (stablepush.execution.scene.Scene.as_dict, below); a real arm may
      ignore it. A simulator builds a fresh world from it for each session, or, when `continue` is true
      and the scene is the one it has, keeps its world (so a run can resume after a fault). Its
      object may say what solid to simulate: "geometry" (words) and, for a mesh part, "mesh" (its
      convex pieces' corners in the object's frame, m, its inertia tensor and com along y).
  {"type": "waypoint", "seq": 0, "t": 0.01, "step": 1, "phase": "push", "pose": [...]}
      `seq` counts from 0 on each connection, one up per waypoint; `t` is s since the stream began;
      the server moves G to `pose` over one period (1 / rate_hz) and then acknowledges.
  {"type": "stop"}      hold the arm where it is now
  {"type": "bye"}       end of the run (a later session with "continue" may pick the world up)

server -> client
  {"type": "ready", "protocol": "stablepush.arm/2", "arm": "...", "state": {...}}
      optional "engine": the simulator behind the arm ("mujoco"), and "geometry": the solid it
      simulates the object as (words), each reported with the run
  {"type": "ack", "seq": 0, "state": {...}}
  {"type": "stopped", "state": {...}}
  {"type": "error", "seq": 3 or null, "message": "..."}   the server has stopped the arm
      and closes the connection. A server already serving a session answers a second client
      with an error whose message starts "busy" and closes that connection.

Limits: a line is at most MAX_LINE_BYTES; `rate_hz` lies in RATE_HZ. A reader waits at most
its deadline for a whole line (a line trickled a byte at a time does not extend it).

`state` holds at least "ee_pose" (G's pose now, 7 finite numbers) and "joints" [rad]. Optional:
  "object_in_grasp" {x, z mm, theta deg; y mm, tilt deg where known}: the tracker field, the
      object's pose in the grasp as the cell measures it (motion capture, fiducials, tactile
      sensing), in the plan's coordinates. With a sticking pusher this pose is observable, and the
      executor compares it with the plan. A cell without a tracker leaves it out.
  "contact_force" [fx, fy, fz] N in the world: the force the features exert on the held object, as
      a wrist force-torque sensor reads it with the held load's weight and inertia compensated. The
      guarded approach (guard.py) reads a touch from it before the object moves in the grasp; without
      it, from object_in_grasp. Optional in arm/1 and arm/2 alike; the simulated arm reports it in
      the acks of approach waypoints, where the guard reads it.
  "time", "object_pose" (the object's true world pose) and "steps_per_s": from a simulator.
"""
from __future__ import annotations

import json
import math
import socket
import time
from typing import Any, Dict, Optional

from stablepush import strict_json
from stablepush.execution.part_geometry import MAX_PIECE_VERTICES, MAX_PIECES
from stablepush.execution.scene import Scene
from stablepush.strict_json import is_finite_number
from stablepush.task.fields import LIMITS, MIN_POSITIVE_MU
from stablepush.task.parts import ANGLE, COORDINATE
from stablepush.task.schema import MAX_PAD_POINTS, MAX_PAD_RINGS, MAX_PADS, MAX_PUSHERS, MAX_VERTICES
from stablepush.units import MM, G

PROTOCOL = "stablepush.arm/2"
SUPPORTED_PROTOCOLS = ("stablepush.arm/1", PROTOCOL)
DEFAULT_PORT = 47100
DEFAULT_RATE_HZ = 100.0
RATE_HZ = (1.0, 1000.0)  # waypoints per second a hello may ask for
MAX_LINE_BYTES = 4_000_000  # a hello carries the scene (a 1,000-vertex object is about 40 kB)

_CLIENT_FIELDS: Dict[str, Dict[str, Any]] = {
    "hello": {"protocol": str, "rate_hz": (int, float), "scene": dict},
    "waypoint": {"seq": int, "t": (int, float), "step": int, "phase": str, "pose": list},
    "stop": {},
    "bye": {},
}
_SERVER_FIELDS: Dict[str, Dict[str, Any]] = {
    "ready": {"protocol": str, "state": dict},
    "ack": {"seq": int, "state": dict},
    "stopped": {"state": dict},
    "error": {"message": str},
}


# Bounds on what a server reports: no arm reaches farther, and the task files' own limits.
ARM_REACH_M = 10.0
GRASP_REACH_MM = 10_000.0
GRASP_TURN_DEG = 3_600.0
MAX_CONTACT_FORCE_N = 10_000.0


class ProtocolError(ValueError):
    """A message that breaks the protocol: not JSON, not an object, an unknown type, or a field
    missing or of the wrong kind."""


def encode(message: Dict[str, Any]) -> bytes:
    return (json.dumps(message, separators=(",", ":"), allow_nan=False) + "\n").encode()


def decode(line: bytes, sender: str) -> Dict[str, Any]:
    """A message from `sender` ("client" or "server"), checked against the protocol."""
    fields = _CLIENT_FIELDS if sender == "client" else _SERVER_FIELDS
    try:
        message = strict_json.loads(line.decode())
    except (UnicodeDecodeError, ValueError) as exc:
        raise ProtocolError(f"not a JSON line ({exc.__class__.__name__}: {exc}; {_clip(line)})") from None
    if not isinstance(message, dict):
        raise ProtocolError(f"not a JSON object: {_clip(line)}")
    kind = message.get("type")
    if not isinstance(kind, str) or kind not in fields:
        raise ProtocolError(f"unknown message type {kind!r} (expected one of {', '.join(fields)})")
    for name, types in fields[kind].items():
        value = message.get(name)
        if not isinstance(value, types) or isinstance(value, bool):
            raise ProtocolError(f"{kind}: field {name!r} missing or not a {_kind(types)}")
    if kind == "waypoint":
        _check_pose(message["pose"], "waypoint: field 'pose'")
        if abs(math.sqrt(sum(v * v for v in message["pose"][3:])) - 1.0) > 1e-6:
            raise ProtocolError("waypoint: the quaternion in 'pose' is not of unit length")
    if kind == "hello" and not RATE_HZ[0] <= message["rate_hz"] <= RATE_HZ[1]:
        raise ProtocolError(f"hello: rate_hz must be between {RATE_HZ[0]:g} and {RATE_HZ[1]:g}, "
                            f"got {message['rate_hz']}")
    if "state" in fields[kind]:
        check_state(message["state"], kind)
    if kind in ("hello", "ready") and message["protocol"] not in SUPPORTED_PROTOCOLS:
        raise ProtocolError(f"{kind}: protocol {message['protocol']!r} is not one of {', '.join(SUPPORTED_PROTOCOLS)}")
    if kind == "hello":  # after its version: a hello of another protocol may describe its world otherwise
        check_scene(message["scene"])
    return message


def _check_pose(pose: Any, what: str) -> None:
    if not (isinstance(pose, list) and len(pose) == 7 and all(is_finite_number(v) for v in pose)):
        raise ProtocolError(f"{what} must be 7 finite numbers [x, y, z, qw, qx, qy, qz]")


def check_state(state: dict, kind: str) -> None:
    """A server's `state`: ee_pose 7 finite numbers within ARM_REACH_M of the base with a unit
    quaternion; object_in_grasp, when given, x, z within GRASP_REACH_MM and theta within
    GRASP_TURN_DEG; contact_force, when given, 3 finite numbers within MAX_CONTACT_FORCE_N. Values
    past these are a broken arm, tracker or sensor, not a state to act on."""
    _check_pose(state.get("ee_pose"), f"{kind}: state.ee_pose")
    _check_placed(state["ee_pose"], f"{kind}: state.ee_pose")
    tracked = state.get("object_in_grasp")
    well_formed = isinstance(tracked, dict) and all(is_finite_number(tracked.get(k)) for k in ("x", "z", "theta"))
    if tracked is not None and not well_formed:
        raise ProtocolError(f"{kind}: state.object_in_grasp must hold finite numbers x, z, theta")
    if tracked is not None and not (abs(tracked["x"]) <= GRASP_REACH_MM and abs(tracked["z"]) <= GRASP_REACH_MM
                                    and abs(tracked["theta"]) <= GRASP_TURN_DEG):
        raise ProtocolError(f"{kind}: state.object_in_grasp must have |x|, |z| <= {GRASP_REACH_MM:g} mm and "
                            f"|theta| <= {GRASP_TURN_DEG:g} deg")
    force = state.get("contact_force")
    if force is not None and not (isinstance(force, list) and len(force) == 3
                                  and all(is_finite_number(v) and abs(v) <= MAX_CONTACT_FORCE_N for v in force)):
        raise ProtocolError(f"{kind}: state.contact_force must be 3 finite numbers [fx, fy, fz] within "
                            f"+-{MAX_CONTACT_FORCE_N:g} N")
    if "object_pose" in state:
        _check_pose(state["object_pose"], f"{kind}: state.object_pose")
        _check_placed(state["object_pose"], f"{kind}: state.object_pose")


def _check_placed(pose: list, what: str) -> None:
    if math.sqrt(sum(v * v for v in pose[:3])) > ARM_REACH_M:
        raise ProtocolError(f"{what} is more than {ARM_REACH_M:g} m from the arm's base")
    if abs(math.sqrt(sum(v * v for v in pose[3:])) - 1.0) > 1e-3:
        raise ProtocolError(f"{what}: the quaternion is not of unit length")


# A hello's scene (scene.Scene.as_dict, SI units) within the task file's own ranges (fields.LIMITS,
# in mm, g and N there): kind -> (lowest, highest), converted once.
_SCENE_RANGES = {
    "position": (COORDINATE[0] * MM, COORDINATE[1] * MM),  # m: polygon, com, pad centres, feature ends
    "length": (LIMITS["length"][0] * MM, LIMITS["length"][1] * MM),  # m: thickness, pad radii
    "mass": (LIMITS["mass"][0] * G, LIMITS["mass"][1] * G),  # kg
    "inertia": LIMITS["inertia"],  # kg m^2
    "force": LIMITS["force"],  # N
    "mu": LIMITS["mu"],
    "gravity": LIMITS["gravity"],  # m/s^2
    "position_mm": COORDINATE,  # mm: the object's x and z in the grasp
}
UNIT_NORMAL_TOLERANCE = 1e-3  # a feature's normal is of unit length to this
MAX_GEOMETRY_CHARS = 200  # scene.object.geometry: words for a run's report


def read_scene(scene: Any) -> Scene:
    """The Scene of a hello's `scene`, checked (check_scene: ProtocolError naming the field)."""
    check_scene(scene)
    return Scene.from_dict(scene)


def check_scene(scene: Any) -> None:
    """A hello's `scene` (scene.Scene.as_dict) as a world can be built from: every number finite
    and within the task file's own range for it (fields.LIMITS, in SI), the counts within the task
    file's caps (vertices, pads, pad rings and their points, features), each feature's normal a
    unit vector and its object pose a pose; ProtocolError naming the field otherwise. A simulator
    built worlds from a gripper mu of -1, a normal [0, 0, 0], a mu of 1e300 or no pads."""
    _fields("scene", scene, ("gravity", "object", "gripper", "features", "gripper_pose", "object_pose"))
    _numbers("scene.gravity", scene["gravity"], 2, "gravity")
    _check_object(scene["object"])
    gripper = scene["gripper"]
    _fields("scene.gripper", gripper, ("grip_force", "mu", "pad_rings", "pads"))
    _number("scene.gripper.grip_force", gripper["grip_force"], "force")
    _friction("scene.gripper.mu", gripper["mu"])
    rings = gripper["pad_rings"]
    if isinstance(rings, bool) or not isinstance(rings, int) or not 0 <= rings <= MAX_PAD_RINGS:
        raise ProtocolError(f"hello: scene.gripper.pad_rings must be an integer from 0 to {MAX_PAD_RINGS}, "
                            f"got {_shown(rings)}")
    _count("scene.gripper.pads", gripper["pads"], 1, MAX_PADS)
    points = len(gripper["pads"]) * (1 + 3 * rings * (rings + 1))
    if points > MAX_PAD_POINTS:
        raise ProtocolError(f"hello: scene.gripper: {len(gripper['pads'])} pads of {rings} rings make {points} pad "
                            f"points; at most {MAX_PAD_POINTS}")
    for i, pad in enumerate(gripper["pads"]):
        _fields(f"scene.gripper.pads[{i}]", pad, ("center", "radius"))
        _numbers(f"scene.gripper.pads[{i}].center", pad["center"], 2, "position")
        _number(f"scene.gripper.pads[{i}].radius", pad["radius"], "length")
    _count("scene.features", scene["features"], 0, MAX_PUSHERS)
    for i, feature in enumerate(scene["features"]):
        _check_feature(f"scene.features[{i}]", feature)
    for name in ("gripper_pose", "object_pose"):
        _check_pose(scene[name], f"hello: scene.{name}")
        _check_placed(scene[name], f"hello: scene.{name}")
    if "object_in_grasp" in scene:
        tracked = scene["object_in_grasp"]
        _numbers("scene.object_in_grasp", tracked, 3, "position_mm")
        if not (ANGLE[0] <= tracked[2] <= ANGLE[1]):
            raise ProtocolError(f"hello: scene.object_in_grasp[2] must be from {ANGLE[0]:g} to {ANGLE[1]:g} deg")


def _check_object(obj: Any) -> None:
    """The scene's object: its section, mass properties, and optionally what solid to simulate
    (`geometry`, words) and a mesh part's convex pieces (`mesh`, part_geometry.scene_object_geometry)."""
    _fields("scene.object", obj, ("polygon", "thickness", "mass", "com", "inertia"))
    _count("scene.object.polygon", obj["polygon"], 3, MAX_VERTICES)
    for i, point in enumerate(obj["polygon"]):
        _numbers(f"scene.object.polygon[{i}]", point, 2, "position")
    _number("scene.object.thickness", obj["thickness"], "length")
    _number("scene.object.mass", obj["mass"], "mass")
    _numbers("scene.object.com", obj["com"], 2, "position")
    _number("scene.object.inertia", obj["inertia"], "inertia")
    geometry = obj.get("geometry", "")
    if not isinstance(geometry, str) or len(geometry) > MAX_GEOMETRY_CHARS:
        raise ProtocolError(f"hello: scene.object.geometry must be a string of at most {MAX_GEOMETRY_CHARS} "
                            f"characters, got {_shown(geometry)}")
    if "mesh" not in obj:
        return
    mesh = obj["mesh"]
    _fields("scene.object.mesh", mesh, ("pieces", "inertia", "com_y"))
    _count("scene.object.mesh.pieces", mesh["pieces"], 1, MAX_PIECES)
    for i, piece in enumerate(mesh["pieces"]):
        _count(f"scene.object.mesh.pieces[{i}]", piece, 4, MAX_PIECE_VERTICES)  # a solid has 4 corners or more
        for k, point in enumerate(piece):
            _numbers(f"scene.object.mesh.pieces[{i}][{k}]", point, 3, "position")
    _count("scene.object.mesh.inertia", mesh["inertia"], 3, 3)
    for i, row in enumerate(mesh["inertia"]):
        _numbers(f"scene.object.mesh.inertia[{i}]", row, 3, None)
        _number(f"scene.object.mesh.inertia[{i}][{i}]", row[i], "inertia")
    _number("scene.object.mesh.com_y", mesh["com_y"], "position")


def _check_feature(path: str, feature: Any) -> None:
    _fields(path, feature, ("pusher", "from", "to", "normal", "mu", "object_pose"))
    if not isinstance(feature["pusher"], str):
        raise ProtocolError(f"hello: {path}.pusher must be a string")
    _numbers(f"{path}.from", feature["from"], 3, "position")
    _numbers(f"{path}.to", feature["to"], 3, "position")
    _numbers(f"{path}.normal", feature["normal"], 3, None)
    if abs(math.sqrt(sum(v * v for v in feature["normal"])) - 1.0) > UNIT_NORMAL_TOLERANCE:
        raise ProtocolError(f"hello: {path}.normal must be a unit vector, got {_shown(feature['normal'])}")
    _friction(f"{path}.mu", feature["mu"])
    _check_pose(feature["object_pose"], f"hello: {path}.object_pose")
    _check_placed(feature["object_pose"], f"hello: {path}.object_pose")


def _fields(path: str, value: Any, names) -> None:
    if not isinstance(value, dict):
        raise ProtocolError(f"hello: {path} must be an object")
    missing = [name for name in names if name not in value]
    if missing:
        raise ProtocolError(f"hello: {path} has no {', '.join(repr(m) for m in missing)}")


def _count(path: str, value: Any, least: int, most: int) -> None:
    if not isinstance(value, list) or not least <= len(value) <= most:
        raise ProtocolError(f"hello: {path} must be a list of {least} to {most}, got {_shown(value)}")


def _number(path: str, value: Any, kind: Optional[str]) -> None:
    low, high = (-math.inf, math.inf) if kind is None else _SCENE_RANGES[kind]
    if not is_finite_number(value) or not low <= value <= high:
        raise ProtocolError(f"hello: {path} must be a finite number" + (f" from {low:g} to {high:g}" if kind else "")
                            + f", got {_shown(value)}")


def _numbers(path: str, value: Any, n: int, kind: Optional[str]) -> None:
    if not isinstance(value, list) or len(value) != n:
        raise ProtocolError(f"hello: {path} must be a list of {n} numbers, got {_shown(value)}")
    for i, v in enumerate(value):
        _number(f"{path}[{i}]", v, kind)


def _friction(path: str, value: Any) -> None:
    """A friction coefficient as a task file takes one (fields._friction): 0, or MIN_POSITIVE_MU up."""
    _number(path, value, "mu")
    if 0.0 < value < MIN_POSITIVE_MU:
        raise ProtocolError(f"hello: {path} must be 0 (frictionless) or at least {MIN_POSITIVE_MU:g}, got {value:g}")


def _shown(value: Any) -> str:
    text = json.dumps(value, allow_nan=True, default=repr) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 60 else text[:60] + "..."


class LineReader:
    """Reads one protocol line at a time from a socket, within a deadline per line: a peer that
    goes silent, or trickles a line a byte at a time, raises TimeoutError when the deadline
    passes; a line over MAX_LINE_BYTES raises ProtocolError; a closed peer ConnectionError."""

    def __init__(self, sock: socket.socket, where: str):
        self.sock = sock
        self.where = where
        self._buffer = b""

    def read_line(self, timeout: float) -> bytes:
        deadline = time.monotonic() + timeout
        while True:
            end = self._buffer.find(b"\n")
            if end >= 0:
                line, self._buffer = self._buffer[: end + 1], self._buffer[end + 1:]
                return line
            if len(self._buffer) > MAX_LINE_BYTES:
                raise ProtocolError(f"a line from {self.where} is longer than {MAX_LINE_BYTES} bytes")
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError(f"no complete message from {self.where} within {timeout:g} s")
            self.sock.settimeout(remaining)
            try:
                data = self.sock.recv(65536)
            except socket.timeout:
                continue  # the loop reports the deadline
            if not data:
                raise ConnectionError(f"{self.where} closed the connection")
            self._buffer += data


def _kind(types) -> str:
    types = types if isinstance(types, tuple) else (types,)
    return " or ".join({int: "integer", float: "number", str: "string", dict: "object", list: "list"}[t] for t in types)


def _clip(line: bytes, n: int = 60) -> str:
    text = line.decode(errors="replace").strip()
    return repr(text if len(text) <= n else text[:n] + "...")
