"""An arm reached over the arm protocol (protocol.py): JSON lines over TCP to an arm server, a real
arm's bridge or `stablepush sim-arm`. The wire format is the protocol's; this is its client side.
"""
from __future__ import annotations

import socket
import time
from typing import Optional

from stablepush.errors import SettingError
from stablepush.execution.arm import Arm, ArmError, ArmReady
from stablepush.execution.protocol import MAX_GEOMETRY_CHARS, PROTOCOL, LineReader, ProtocolError, decode, encode
from stablepush.execution.scene import Scene
from stablepush.execution.stream import ArmWaypoint
from stablepush.units import is_finite_real

DEFAULT_ACK_TIMEOUT = 5.0  # s to wait for any reply
# s: the replies' deadline may be set within this; a socket's timeout past about 1e10 s overflows the
# platform's time_t (`--ack-timeout 1e308` was an internal error), and an hour is an arm gone.
ACK_TIMEOUT_RANGE = (0.01, 3600.0)
STOP_WITHIN = 2.0  # s to wait for the arm to confirm a stop (replies that keep coming do not extend it)


class TcpArm(Arm):
    """The arm server at host:port, each reply within `ack_timeout` s. It connects on `hello`; a
    run is paced by default (a real arm's bridge moves in real time)."""

    paced = True

    def __init__(self, host: str, port: int, ack_timeout: float = DEFAULT_ACK_TIMEOUT):
        low, high = ACK_TIMEOUT_RANGE
        if not is_finite_real(ack_timeout) or not low <= ack_timeout <= high:
            raise SettingError("ack_timeout", f"must be a number of seconds from {low:g} to {high:g}, "
                                              f"got {ack_timeout!r:.40}")
        self.host, self.port = host, port
        self.where = f"the arm server at {host}:{port}"
        self.timeout = float(ack_timeout)
        self.sock: Optional[socket.socket] = None
        self.connected = False

    def hello(self, scene: Scene, rate_hz: float, resume: bool) -> ArmReady:
        try:
            self.sock = socket.create_connection((self.host, self.port), timeout=self.timeout)
        except OSError as exc:
            raise ArmError(f"cannot reach {self.where} ({exc.strerror or exc})") from None
        self.connected = True
        self.reader = LineReader(self.sock, self.where)
        ready = self._exchange({"type": "hello", "protocol": PROTOCOL, "rate_hz": rate_hz, "scene": scene.as_dict(),
                                "continue": resume}, "ready")
        geometry = ready.get("geometry")
        return ArmReady(state=ready["state"], arm=str(ready.get("arm", "")), engine=ready.get("engine"),
                        geometry=geometry[:MAX_GEOMETRY_CHARS] if isinstance(geometry, str) else None)

    def move(self, waypoint: ArmWaypoint) -> dict:
        reply = self._exchange({"type": "waypoint", "seq": waypoint.seq, "t": waypoint.t, "step": waypoint.step,
                                "phase": waypoint.phase, "pose": list(waypoint.pose)}, "ack")
        if reply["seq"] != waypoint.seq:
            raise ArmError(f"out-of-order acknowledgement: expected seq {waypoint.seq}, got {reply['seq']}")
        return reply["state"]

    def stop(self) -> Optional[bool]:
        if self.sock is None:
            return None
        deadline = time.monotonic() + STOP_WITHIN
        try:
            self._send({"type": "stop"})
            while True:
                reply = self._receive(max(0.0, deadline - time.monotonic()))
                if reply["type"] in ("stopped", "error"):  # the server stops the arm itself before reporting an error
                    return True
        except (ConnectionError, TimeoutError, ProtocolError, OSError):
            return None

    def bye(self) -> None:
        try:
            self._send({"type": "bye"})
        except OSError as exc:
            raise ArmError(str(exc)) from None

    def close(self) -> None:
        if self.sock is not None:
            try:
                self.sock.close()
            except OSError:
                pass

    def _send(self, message: dict) -> None:
        if self.sock is None:
            raise ConnectionError(f"not connected to {self.where} (no hello)")
        self.sock.settimeout(self.timeout)
        self.sock.sendall(encode(message))

    def _receive(self, timeout: Optional[float] = None) -> dict:
        return decode(self.reader.read_line(self.timeout if timeout is None else timeout), "server")

    def _exchange(self, message: dict, kind: str) -> dict:
        """Send `message` and read the reply of type `kind`: ArmError for anything else, the link
        lost, or no reply within the timeout."""
        try:
            self._send(message)
            reply = self._receive()
            if reply["type"] == "error":
                raise ArmError(f"the arm server reported: {reply['message']}")
            if reply["type"] != kind:
                raise ArmError(f"expected {kind!r} from the arm server, got {reply['type']!r}")
            return reply
        except (ConnectionError, TimeoutError, ProtocolError, OSError) as exc:
            raise ArmError(str(exc)) from None
        except KeyError as exc:
            raise ArmError(f"a reply lacks {exc}") from None
