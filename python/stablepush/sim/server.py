"""`stablepush sim-arm`: the simulated arm (arm.py) behind the arm protocol (arm_protocol.py).

One client at a time. The world persists across connections, so an executor can resume a run
after a fault; a `hello` with `reset` true, or with a different scene, rebuilds it.
"""
from __future__ import annotations

import os
import socket
import sys
import threading
from contextlib import contextmanager
from typing import Callable, Iterator, Optional

from stablepush.arm_protocol import ProtocolError, decode, encode
from stablepush.sim.arm import SimArm, WorldDeviation

# The scene keys that describe the world; the object's pose at the start may differ on a resume.
_START_KEYS = ("object_pose", "object_in_grasp")


def _world(scene: dict) -> dict:
    return {k: v for k, v in scene.items() if k not in _START_KEYS}


class SimArmServer:
    """Serves the simulated arm on host:port (port 0 picks a free one; see `.port`)."""

    def __init__(self, host: str = "127.0.0.1", port: int = 0, log: Callable[[str], None] = None,
                 exit_after: Optional[int] = None, deviation: WorldDeviation = WorldDeviation()):
        self.log = log or (lambda text: print(f"sim-arm: {text}", file=sys.stderr, flush=True))
        self.exit_after = exit_after  # fault injection: die abruptly after this many waypoints
        self.deviation = deviation  # how the simulated world departs from each task's model
        self.arm: Optional[SimArm] = None
        self._scene: Optional[dict] = None
        self._waypoints = 0
        self._socket = socket.create_server((host, port))
        self.host, self.port = self._socket.getsockname()[:2]
        self._closed = threading.Event()

    def serve_forever(self) -> None:
        while not self._closed.is_set():
            try:
                connection, peer = self._socket.accept()
            except OSError:
                break
            with connection:
                self._serve(connection)

    def start_in_thread(self) -> threading.Thread:
        thread = threading.Thread(target=self.serve_forever, name="sim-arm", daemon=True)
        thread.start()
        return thread

    def close(self) -> None:
        self._closed.set()
        self._socket.close()

    # -- one connection -----------------------------------------------------------------------

    def _serve(self, connection: socket.socket) -> None:
        reader = connection.makefile("rb")
        expected_seq = 0
        greeted = False
        try:
            for line in reader:
                message = None
                try:
                    message = decode(line, "client")
                    kind = message["type"]
                    if not greeted and kind != "hello":
                        raise ProtocolError(f"expected hello first, got {kind!r}")
                    if kind == "hello":
                        self._hello(message)
                        greeted = True
                        expected_seq = 0
                        connection.sendall(encode({"type": "ready", "protocol": message["protocol"],
                                                   "arm": "stablepush sim-arm (MuJoCo)",
                                                   "state": self.arm.state()}))
                    elif kind == "waypoint":
                        if message["seq"] != expected_seq:
                            raise ProtocolError(f"out-of-order waypoint: expected seq {expected_seq}, got {message['seq']}")
                        self.arm.move_to(message["pose"], self._period)
                        expected_seq += 1
                        self._waypoints += 1
                        if self.exit_after is not None and self._waypoints >= self.exit_after:
                            self.log(f"exiting after {self._waypoints} waypoints (--exit-after)")
                            os._exit(3)
                        connection.sendall(encode({"type": "ack", "seq": message["seq"], "state": self.arm.state()}))
                    elif kind == "stop":
                        self.arm.stop()
                        connection.sendall(encode({"type": "stopped", "state": self.arm.state()}))
                    elif kind == "bye":
                        self.log(f"run ended after {expected_seq} waypoints; {self.arm.steps_per_second:.0f} steps/s")
                        return
                except (ProtocolError, ValueError, KeyError, TypeError) as exc:
                    if self.arm is not None:
                        self.arm.stop()
                    self.log(f"error: {exc}; arm stopped")
                    seq = message.get("seq") if message else None
                    connection.sendall(encode({"type": "error", "seq": seq, "message": f"{exc}; the arm is stopped"}))
                    return
        except (ConnectionError, OSError) as exc:
            self.log(f"connection lost ({exc})")
        if self.arm is not None:
            self.arm.stop()
            self.log(f"client left after {expected_seq} waypoints; arm stopped")

    def _hello(self, message: dict) -> None:
        scene = message["scene"]
        self._period = 1.0 / float(message["rate_hz"])
        if self.arm is None or message.get("reset") or _world(scene) != _world(self._scene):
            self.arm = SimArm(scene, self.deviation)
            self._scene = scene
            self.log(f"world built for {scene.get('task', 'a task')} ({self.arm.model.nbody} bodies, "
                     f"{self.arm.model.npair} contact pairs)")
        else:
            self.log("world kept from the previous connection")


@contextmanager
def running_sim_arm(log: Optional[Callable[[str], None]] = None,
                    deviation: WorldDeviation = WorldDeviation()) -> Iterator[SimArmServer]:
    """A simulated arm served from a thread of this process on a free localhost port, for the
    length of the `with` block (`execute --sim`, the tests, the benchmark)."""
    server = SimArmServer(log=log, deviation=deviation)
    server.start_in_thread()
    try:
        yield server
    finally:
        server.close()
