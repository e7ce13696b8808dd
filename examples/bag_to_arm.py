"""Replay a plan's ROS 2 bag to an arm over the arm protocol (stablepush.arm/2): the whole loop
from a bag to an arm, in the form a lab's bridge would take.

    stablepush plan data/tasks/t-shaped.yaml -o t.plan.json
    stablepush trajectory t.plan.json --task data/tasks/t-shaped.yaml -o t.mcap
    stablepush sim-arm --port 47100 &        # or your robot's bridge
    python3 examples/bag_to_arm.py t.mcap --arm 127.0.0.1:47100

It reads the bag with `rosbags` (the gripper's PoseStamped on /stablepush/gripper_pose, the plan
step and phase, and the world on /stablepush/arm_scene), says hello with that world, streams each
pose as a waypoint at the bag's rate, lock-step on the arm's acknowledgements, and prints where the
arm says the object ended in the grasp. On any error it tells the arm to stop.
"""
from __future__ import annotations

import argparse
import json
import socket
import sys
from pathlib import Path

from rosbags.rosbag2 import Reader, ReaderError
from rosbags.typesys import Stores, get_typestore

from stablepush.execution.protocol import PROTOCOL, LineReader, decode, encode

STORE = get_typestore(Stores.ROS2_HUMBLE)


def read_bag(path: Path):
    """The arm's scene, the rate [Hz] and the waypoints (t s from the bag's start, pose
    [x, y, z, qw, qx, qy, qz] m, step, phase) of a stablepush bag."""
    poses, steps, phases, scene, start = [], [], [], None, None
    try:
        reader = Reader(path)
        reader.open()
    except ReaderError as exc:
        raise ValueError(f"{path}: cannot read it as a ROS 2 bag ({exc})") from None
    try:
        for connection, stamp, raw in reader.messages():  # in time order: the first is at the bag's start
            start = stamp if start is None else start
            msg = STORE.deserialize_cdr(raw, connection.msgtype)
            if connection.topic == "/stablepush/gripper_pose":
                p, q = msg.pose.position, msg.pose.orientation
                poses.append(((stamp - start) * 1e-9, [p.x, p.y, p.z, q.w, q.x, q.y, q.z]))
            elif connection.topic == "/stablepush/step":
                steps.append(int(msg.data))
            elif connection.topic == "/stablepush/phase":
                phases.append(msg.data)
            elif connection.topic == "/stablepush/arm_scene":
                scene = json.loads(msg.data)
    finally:
        reader.close()
    if scene is None or not poses or not len(poses) == len(steps) == len(phases):
        raise ValueError(f"{path}: not a stablepush bag (stablepush trajectory -o X.mcap writes one)")
    rate = 1.0 / (poses[1][0] - poses[0][0]) if len(poses) > 1 else 100.0
    return scene, rate, [(t, pose, step, phase) for (t, pose), step, phase in zip(poses, steps, phases)]


def replay(path: Path, host: str, port: int, timeout: float = 10.0) -> dict:
    """Stream the bag to the arm at host:port; the arm's last state."""
    scene, rate, waypoints = read_bag(path)
    with socket.create_connection((host, port), timeout=timeout) as conn:
        reader = LineReader(conn, f"the arm at {host}:{port}")
        try:
            conn.sendall(encode({"type": "hello", "protocol": PROTOCOL, "rate_hz": rate, "scene": scene}))
            state = _expect(decode(reader.read_line(timeout), "arm"), "ready")["state"]
            for seq, (t, pose, step, phase) in enumerate(waypoints):
                conn.sendall(encode({"type": "waypoint", "seq": seq, "t": t, "step": step, "phase": phase,
                                     "pose": pose}))
                state = _expect(decode(reader.read_line(timeout), "arm"), "ack")["state"]
            conn.sendall(encode({"type": "bye"}))
            return state
        except BaseException:
            try:
                conn.sendall(encode({"type": "stop"}))
            except OSError:
                pass
            raise


def _expect(message: dict, kind: str) -> dict:
    if message.get("type") != kind:
        raise RuntimeError(f"expected {kind!r} from the arm, got {message.get('type')!r}: {message.get('message')}")
    return message


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("bag", type=Path, help="a bag written by `stablepush trajectory ... -o X.mcap`")
    parser.add_argument("--arm", default="127.0.0.1:47100", metavar="HOST:PORT")
    args = parser.parse_args()
    host, _, port = args.arm.rpartition(":")
    try:
        state = replay(args.bag, host or "127.0.0.1", int(port))
    except (OSError, ValueError, RuntimeError) as exc:
        sys.exit(f"error: {exc}")
    where = state.get("object_in_grasp")
    print("replayed; the object ends in the grasp at " + (
        f"x {where['x']:.3f} z {where['z']:.3f} mm, theta {where['theta']:.3f} deg" if where else "(no tracker)"))


if __name__ == "__main__":
    main()
