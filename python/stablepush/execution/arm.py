"""The arm port: what a run needs of an arm, whichever arm it is.

A run (executor.py) greets the arm with the scene, streams waypoints of G one at a time and reads
the arm's state after each, tells it to stop on a fault, and says goodbye. `Arm` is that exchange as
calls; the arm protocol (protocol.py) is the same exchange as JSON lines. Implementations:

- `stablepush.execution.tcp_arm.TcpArm`: a client of an arm server over the protocol, for a real
  arm's bridge or `stablepush sim-arm`;
- `stablepush.sim.local_arm.SimulatedArm`: a simulated arm in this process, no socket;
  `stablepush sim-arm` serves one over TCP.

Every call either returns or raises `ArmError`, whose message says why the arm cannot go on; the
executor then ends the run in `ArmFault`. Poses are [x, y, z, qw, qx, qy, qz] of G in the world, m;
a state is the protocol's `state` object (`ee_pose`, `joints` [rad], and optionally
`object_in_grasp`, `contact_force`, `object_pose`, `steps_per_s`).
"""
from __future__ import annotations

import abc
from dataclasses import dataclass
from typing import TYPE_CHECKING, Optional, Tuple

from stablepush.execution.stream import ArmWaypoint

if TYPE_CHECKING:
    from stablepush.execution.scene import Scene
    from stablepush.plan.plan import Plan
    from stablepush.task.model import Task


class ArmError(Exception):
    """The arm cannot go on (gone, refused a waypoint, broke the protocol, silent too long): the
    message says why."""


@dataclass(frozen=True)
class ArmReady:
    """The arm's answer to hello: its `state` where it stands, what it calls itself (`arm`), the
    simulator behind it (`engine`, e.g. "mujoco"; None for a real arm) and the solid that simulator
    built of the object (`geometry`, words, e.g. "l-bracket.stl: CoACD, 2 convex pieces ...")."""

    state: dict
    arm: str = ""
    engine: Optional[str] = None
    geometry: Optional[str] = None


@dataclass(frozen=True)
class RobotDescription:
    """What a viewer needs to draw an arm from its joints: the arm's `joints` as its model names
    them (base to flange, the order of the state's `joints`), its model's `base_link` (the frame a
    joint trajectory is given in) at `base_pose` in the world ([x, y, z, qw, qx, qy, qz], m), and
    the URDF's text (`urdf`; None when the model is MJCF, which ROS viewers do not read)."""

    joints: Tuple[str, ...]
    base_link: str
    base_pose: Tuple[float, ...]
    urdf: Optional[str] = None


class Arm(abc.ABC):
    """One session with an arm: `hello`, then `move` per waypoint, then `bye`; `stop` at any time
    after `hello`. Used as a context manager, it is closed at the end of the block."""

    #: Whether the arm was reached: False until `hello` reached it (a fault before that means
    #: nothing was sent, and nothing moved).
    connected: bool = False
    #: Whether a run holds the stream to its rate in wall-clock time by default (RunOptions.pace
    #: None): a real arm moves in real time; a simulator keeps its own clock.
    paced: bool = False

    def check_cell(self, task: "Task", plan: "Plan", rate_hz: float) -> None:
        """Refuse, before any motion, a plan this arm cannot follow in its cell: a PlanError naming
        the first sample of the timed trajectory it cannot reach, the joint past its limit or the
        link in a fixture (stablepush.kinematics.CellError). An arm that has a model of itself
        checks here (the simulated arm, the joint-trajectory bridge); this default knows none and
        lets every plan pass (`stablepush check-cell --robot` asks the same of a model)."""

    def robot_description(self) -> Optional[RobotDescription]:
        """The arm's model, for a recording to draw the arm from the state's `joints`; None when
        this arm has none (an arm server not checked against a model names no joints)."""
        return None

    @abc.abstractmethod
    def hello(self, scene: "Scene", rate_hz: float, resume: bool) -> ArmReady:
        """Start a session for a run of `scene` (execution.scene.Scene, world.scene_description) at
        `rate_hz` waypoints per second. `resume`: the run continues one that ended in a fault, and
        a simulator keeps its world when the scene is the one it has."""

    @abc.abstractmethod
    def move(self, waypoint: ArmWaypoint) -> dict:
        """Move G to `waypoint.pose` over one period (1 / rate_hz) and return the arm's state."""

    @abc.abstractmethod
    def stop(self) -> Optional[bool]:
        """Hold the arm where it is now: True when it confirmed, None when it could not be reached
        or did not confirm. Never raises."""

    def bye(self) -> None:
        """End the session after the last waypoint."""

    def close(self) -> None:
        """Release what the session holds (a socket); the arm itself stays as it is."""

    def __enter__(self) -> "Arm":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
