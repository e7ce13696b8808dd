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
  {"type": "hello", "protocol": "stablepush.arm/2", "rate_hz": 100, "scene": {...}, "reset": false}
      `scene` describes the world (stablepush.execution.scene_description); a real arm may ignore
      it. A simulator builds its world from it, or keeps the one it has when `reset` is false and
      the scene is the same (so a run can resume).
  {"type": "waypoint", "seq": 0, "t": 0.01, "step": 1, "phase": "push", "pose": [...]}
      `seq` counts from 0 on each connection, one up per waypoint; `t` is s since the stream began;
      the server moves G to `pose` over one period (1 / rate_hz) and then acknowledges.
  {"type": "stop"}      hold the arm where it is now
  {"type": "bye"}       end of the run; the server keeps its state for a later connection

server -> client
  {"type": "ready", "protocol": "stablepush.arm/2", "arm": "...", "state": {...}}
  {"type": "ack", "seq": 0, "state": {...}}
  {"type": "stopped", "state": {...}}
  {"type": "error", "seq": 3 or null, "message": "..."}   the server has stopped the arm
      and closes the connection.

`state` holds at least "ee_pose" (G's pose now) and "joints" [rad]. Optional:
  "object_in_grasp" {x, z mm, theta deg; y mm, tilt deg where known}: the tracker field, the
      object's pose in the grasp as the cell measures it (motion capture, fiducials, tactile
      sensing), in the plan's coordinates. With a sticking pusher this pose is observable, and the
      executor compares it with the plan. A cell without a tracker leaves it out.
  "time", "object_pose" (the object's true world pose) and "steps_per_s": from a simulator.
"""
from __future__ import annotations

import json
import math
from typing import Any, Dict

PROTOCOL = "stablepush.arm/2"
SUPPORTED_PROTOCOLS = ("stablepush.arm/1", PROTOCOL)
DEFAULT_PORT = 47100
DEFAULT_RATE_HZ = 100.0

_CLIENT_FIELDS = {
    "hello": {"protocol": str, "rate_hz": (int, float), "scene": dict},
    "waypoint": {"seq": int, "t": (int, float), "step": int, "phase": str, "pose": list},
    "stop": {},
    "bye": {},
}
_SERVER_FIELDS = {
    "ready": {"protocol": str, "state": dict},
    "ack": {"seq": int, "state": dict},
    "stopped": {"state": dict},
    "error": {"message": str},
}


class ProtocolError(ValueError):
    """A message that breaks the protocol: not JSON, not an object, an unknown type, or a field
    missing or of the wrong kind."""


def encode(message: Dict[str, Any]) -> bytes:
    return (json.dumps(message, separators=(",", ":"), allow_nan=False) + "\n").encode()


def decode(line: bytes, sender: str) -> Dict[str, Any]:
    """A message from `sender` ("client" or "server"), checked against the protocol."""
    fields = _CLIENT_FIELDS if sender == "client" else _SERVER_FIELDS
    try:
        message = json.loads(line.decode())
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ProtocolError(f"not a JSON line ({exc.__class__.__name__}: {_clip(line)})") from None
    if not isinstance(message, dict):
        raise ProtocolError(f"not a JSON object: {_clip(line)}")
    kind = message.get("type")
    if kind not in fields:
        raise ProtocolError(f"unknown message type {kind!r} (expected one of {', '.join(fields)})")
    for name, types in fields[kind].items():
        value = message.get(name)
        if not isinstance(value, types) or isinstance(value, bool):
            raise ProtocolError(f"{kind}: field {name!r} missing or not a {_kind(types)}")
    if kind == "waypoint":
        pose = message["pose"]
        if len(pose) != 7 or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in pose):
            raise ProtocolError("waypoint: field 'pose' must be 7 finite numbers [x, y, z, qw, qx, qy, qz]")
        if abs(math.sqrt(sum(v * v for v in pose[3:])) - 1.0) > 1e-6:
            raise ProtocolError("waypoint: the quaternion in 'pose' is not of unit length")
    if kind in ("hello", "ready") and message["protocol"] not in SUPPORTED_PROTOCOLS:
        raise ProtocolError(f"{kind}: protocol {message['protocol']!r} is not one of {', '.join(SUPPORTED_PROTOCOLS)}")
    return message


def _kind(types) -> str:
    types = types if isinstance(types, tuple) else (types,)
    return " or ".join({int: "integer", float: "number", str: "string", dict: "object", list: "list"}[t] for t in types)


def _clip(line: bytes, n: int = 60) -> str:
    text = line.decode(errors="replace").strip()
    return repr(text if len(text) <= n else text[:n] + "...")
