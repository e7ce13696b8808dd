"""`stablepush sim-arm`: an in-process simulated arm (local_arm.py) served over the arm protocol
(stablepush.execution.protocol), for a client in another process or on another machine.

One session at a time: a second client is told the arm is busy and let go. Each session starts
from a fresh world built from its hello's scene, unless the hello asks to `continue` and the scene
is the one the server has (an executor resuming after a fault). Every message is validated; a
client that breaks the protocol gets an error and is let go, one silent for `idle_timeout` s (or
stuck in half a line) is dropped, and the arm is stopped whenever a session ends: no client can
stop the server from serving the next one.
"""
from __future__ import annotations

import os
import socket
import sys
import threading
from contextlib import contextmanager
from typing import Callable, Iterator, Optional

from stablepush.errors import SettingError
from stablepush.execution.arm import ArmError
from stablepush.execution.protocol import LineReader, ProtocolError, decode, encode
from stablepush.execution.scene import Scene
from stablepush.execution.stream import ArmWaypoint
from stablepush.sim.deviation import WorldDeviation
from stablepush.sim.engines import DEFAULT_ENGINE
from stablepush.sim.local_arm import SimulatedArm

DEFAULT_IDLE_TIMEOUT = 30.0  # s a client may stay silent within a session
BUSY_WAIT = 2.0  # s a new client waits for a session to end before it is told the arm is busy
ACCEPT_POLL = 0.5  # s


class SimArmServer:
    """Serves the simulated arm of `robot` (a task.model.Robot; None: the shipped arm) on
    host:port (port 0 picks a free one; see `.port`)."""

    def __init__(self, host: str = "127.0.0.1", port: int = 0, log: Optional[Callable[[str], None]] = None,
                 exit_after: Optional[int] = None, deviation: WorldDeviation = WorldDeviation(),
                 idle_timeout: float = DEFAULT_IDLE_TIMEOUT, engine: str = DEFAULT_ENGINE, robot=None):
        self.log = log or (lambda text: print(f"sim-arm: {text}", file=sys.stderr, flush=True))
        self.exit_after = exit_after  # fault injection: die abruptly after this many waypoints
        self.idle_timeout = idle_timeout
        # One arm for every session, so that a session may continue the last one's world; its engine
        # is loaded here: a missing one is the caller's to hear of (MissingExtra), not a hello's.
        self.arm = SimulatedArm(engine, deviation, log=self.log, robot=robot)
        self.engine = self.arm.engine
        self._waypoints = 0
        self._session = threading.Lock()
        try:
            self._socket = socket.create_server((host, port))
        except (OSError, OverflowError, UnicodeError) as exc:  # no such host, a port taken or not ours to bind
            self.arm.close()
            raise SettingError("host", f"cannot listen on {host!r:.80} port {port}: "
                                       f"{' '.join(str(exc).split())[:200]}") from None
        self.host, self.port = self._socket.getsockname()[:2]
        self._closed = threading.Event()

    def serve_forever(self) -> None:
        # accept() wakes every ACCEPT_POLL s: a Ctrl-C the kernel hands to a session's thread is only
        # seen when the main thread runs Python again, and a close() from another thread ends the loop.
        self._socket.settimeout(ACCEPT_POLL)
        while not self._closed.is_set():
            try:
                connection, _ = self._socket.accept()
            except socket.timeout:
                continue
            except OSError:
                break
            connection.settimeout(None)
            threading.Thread(target=self._connection, args=(connection,), name="sim-arm client", daemon=True).start()

    def start_in_thread(self) -> threading.Thread:
        thread = threading.Thread(target=self.serve_forever, name="sim-arm", daemon=True)
        thread.start()
        return thread

    def close(self) -> None:
        self._closed.set()
        self._socket.close()

    # -- one session ----------------------------------------------------------------------------

    def _connection(self, connection: socket.socket) -> None:
        # A client that comes straight back after its own session ended waits for it to wind down.
        if self._session.acquire(timeout=BUSY_WAIT):
            self._run_session(connection)
        else:
            self._refusal(connection)

    def _refusal(self, connection: socket.socket) -> None:
        """Tell a second client the arm is busy; read what it sent for up to 1 s first (closing on
        unread data would reset the connection before the client reads the reply)."""
        with connection:
            _send_quietly(connection, {"type": "error", "seq": None,
                                       "message": "busy: the simulated arm is serving another session"})
            try:
                connection.shutdown(socket.SHUT_WR)
                connection.settimeout(1.0)
                for _ in range(64):
                    if not connection.recv(65536):
                        break
            except OSError:
                pass
        self.log("refused a second client (busy)")

    def _run_session(self, connection: socket.socket) -> None:
        try:
            self._serve(connection)
        except Exception as exc:  # noqa: BLE001 - a session must never take the server down
            self.log(f"session ended by {type(exc).__name__}: {' '.join(str(exc).split())[:200]}")
        finally:
            self.arm.stop()
            self._session.release()  # before the client sees the connection close, so it may come straight back
            connection.close()

    def _serve(self, connection: socket.socket) -> None:
        reader = LineReader(connection, "the client")
        expected_seq = 0
        greeted = False
        while True:
            message = None
            try:
                message = decode(reader.read_line(self.idle_timeout), "client")
                kind = message["type"]
                if not greeted and kind != "hello":
                    raise ProtocolError(f"expected hello first, got {kind!r}")
                if kind == "hello":
                    # decode checked the scene (protocol.check_scene)
                    ready = self.arm.hello(Scene.from_dict(message["scene"]), message["rate_hz"],
                                           message.get("continue") is True)
                    greeted = True
                    expected_seq = 0
                    reply = {"type": "ready", "protocol": message["protocol"], "arm": ready.arm,
                             "engine": ready.engine, "geometry": ready.geometry, "state": ready.state}
                elif kind == "waypoint":
                    if message["seq"] != expected_seq:
                        raise ProtocolError(f"out-of-order waypoint: expected seq {expected_seq}, got {message['seq']}")
                    state = self.arm.move(ArmWaypoint(seq=message["seq"], t=message["t"], step=message["step"],
                                                      completes=False, phase=message["phase"],
                                                      pose=tuple(message["pose"])))
                    expected_seq += 1
                    self._waypoints += 1
                    if self.exit_after is not None and self._waypoints >= self.exit_after:
                        self.log(f"exiting after {self._waypoints} waypoints (--exit-after)")
                        os._exit(3)
                    reply = {"type": "ack", "seq": message["seq"], "state": state}
                elif kind == "stop":
                    self.arm.stop()
                    reply = {"type": "stopped", "state": self.arm.state()}
                else:  # bye
                    self.log(f"run ended after {expected_seq} waypoints; {self.arm.steps_per_second:.0f} steps/s")
                    return
                connection.sendall(encode(reply))
            except (TimeoutError, ConnectionError, ProtocolError, ArmError, ValueError, KeyError, TypeError) as exc:
                self.arm.stop()  # stopped before the client hears of it
                self._end(connection, exc, message, expected_seq)
                return

    def _end(self, connection: socket.socket, exc: Exception, message: Optional[dict], expected_seq: int) -> None:
        """Report how a session ended to the log and, unless the client has gone, to the client."""
        if isinstance(exc, ConnectionError):
            self.log(f"connection lost ({exc}) after {expected_seq} waypoints; arm stopped")
            return
        if isinstance(exc, TimeoutError):
            self.log(f"{exc}; client dropped, arm stopped")
        else:
            self.log(f"error: {exc}; arm stopped")
        seq = message.get("seq") if message else None
        _send_quietly(connection, {"type": "error", "seq": seq if isinstance(seq, int) else None,
                                   "message": f"{exc}; the arm is stopped"})


def _send_quietly(connection: socket.socket, message: dict) -> None:
    """Send a last message to a client that may already be gone."""
    try:
        connection.settimeout(1.0)
        connection.sendall(encode(message))
    except OSError:
        pass


@contextmanager
def running_sim_arm(log: Optional[Callable[[str], None]] = None, deviation: WorldDeviation = WorldDeviation(),
                    engine: str = DEFAULT_ENGINE, robot=None) -> Iterator[SimArmServer]:
    """A simulated arm on `engine` served from a thread of this process on a free localhost port,
    for the length of the `with` block: a client of the protocol to test against (a run in this
    process drives `local_arm.SimulatedArm` without a socket)."""
    server = SimArmServer(log=log, deviation=deviation, engine=engine, robot=robot)
    server.start_in_thread()
    try:
        yield server
    finally:
        server.close()
