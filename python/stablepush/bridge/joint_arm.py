"""A reference bridge from the arm port (stablepush.execution.arm) to a real arm that takes joint
trajectories, as ros2_control's joint_trajectory_controller and most arm vendors' drivers do.

The part a lab fills in is `JointInterface`: the names of its joints, a read of their positions,
a command to reach joint positions over a duration, a halt, and optionally its wrist
force-torque sensor and its object tracker. `JointTrajectoryArm` does the rest with the arm's
model (a task.model.Robot): it checks the plan against the cell before any motion (joint_path),
turns each streamed pose of G into joint positions by IK from the last command (one branch, as
the cell check solved it), refuses a command past a joint's limit or speed, and reports G's pose
through forward kinematics of the measured joints. Poses are (x, y, z, qw, qx, qy, qz) of G in
the world [m]; joints in rad (m for a sliding joint).
"""
from __future__ import annotations

import abc
from typing import Any, Dict, Optional, Sequence

import numpy as np

from stablepush.execution.arm import Arm, ArmError, ArmReady, RobotDescription
from stablepush.execution.scene import Scene
from stablepush.execution.stream import ArmWaypoint
from stablepush.extras import require
from stablepush.frames import matrix_to_pose
from stablepush.kinematics import cell_model, ik
from stablepush.kinematics.arm_kinematics import ArmKinematics
from stablepush.kinematics.cell_path import checked_path
from stablepush.kinematics.robot import arm_model, robot_description
from stablepush.plan.plan import Plan
from stablepush.task.model import Robot, Task


class JointInterface(abc.ABC):
    """A lab's arm at the joint level: what `JointTrajectoryArm` needs of it. Any method may raise
    (any exception): the bridge turns it into ArmError, and the run stops the arm."""

    #: The arm's joint names, as its model (URDF/MJCF) names them, base to flange.
    joint_names: Sequence[str] = ()

    @abc.abstractmethod
    def read_joints(self) -> Sequence[float]:
        """The joints' measured positions now, in `joint_names` order."""

    @abc.abstractmethod
    def send(self, positions: Sequence[float], duration: float) -> None:
        """Reach `positions` (in `joint_names` order) over `duration` s from where the arm is: one
        point of a joint trajectory (time_from_start = duration). Returns when the arm has
        reached it, as the arm port's move does."""

    @abc.abstractmethod
    def halt(self) -> None:
        """Hold still where the arm is now (cancel the trajectory)."""

    def wrist_force(self) -> Optional[Sequence[float]]:
        """The force [N, world frame] the features exert on the held object, as a wrist
        force-torque sensor reads it with the load compensated; None without one (the guarded
        approach then finds no feature by touch)."""
        return None

    def object_in_grasp(self) -> Optional[dict]:
        """The tracked pose of the object in the grasp (x, z mm, theta deg); None without a
        tracker (the run then gets no verdict and no closed loop)."""
        return None

    def close(self) -> None:
        """Release the connection to the arm."""


class JointTrajectoryArm(Arm):
    """The arm port over a `JointInterface`, with the arm's model `robot` for IK and the cell
    check. `paced`: the stream is held to its rate in wall-clock time (a real arm's)."""

    paced = True

    def __init__(self, joints: JointInterface, robot: Robot):
        self.joints, self.robot = joints, robot
        self.arm = arm_model(robot)
        if tuple(joints.joint_names) != self.arm.joints:
            raise ArmError(f"the joint interface names the joints {list(joints.joint_names)}, the robot model "
                           f"{list(self.arm.joints)}")
        self._kinematics: Optional[ArmKinematics] = None
        self._period = 0.01
        self._command: Optional[np.ndarray] = None
        self._home: Optional[np.ndarray] = None

    def check_cell(self, task: Task, plan: Plan, rate_hz: float) -> None:
        checked_path(task, plan, rate_hz, self.robot)

    def robot_description(self) -> RobotDescription:
        return robot_description(self.robot)

    def hello(self, scene: Scene, rate_hz: float, resume: bool) -> ArmReady:
        """The arm's kinematics in the scene's world (its base where the robot says) and the arm's
        state where it stands (the executor's stream starts from there); the posture IK's null
        space pulls toward is the one at the scene's start pose nearest the measured joints."""
        mujoco = require("mujoco", "the arm's kinematics (a joint-level arm)")  # as a kinematics library
        model = mujoco.MjModel.from_xml_string(cell_model.build_mjcf(scene, robot=self.robot))
        self._kinematics = ArmKinematics(model, self.arm.joints)
        self._period = 1.0 / float(rate_hz)
        q = self._read()
        self._command = q
        self._home, _ = ik.find_home(self._kinematics, scene.gripper_pose, (q, *self.arm.home_guesses),
                                     self._kinematics.lower, self._kinematics.upper)
        self.connected = True
        return ArmReady(state=self._state(q, False), arm=f"joint trajectory bridge ({len(self.arm.joints)} joints)")

    def move(self, waypoint: ArmWaypoint) -> dict:
        """IK from the last command to the waypoint's pose, checked against the limits and speeds
        of the model, sent as one trajectory point over the period; the state read back."""
        kin, command, home = self._kinematics, self._command, self._home
        if kin is None or command is None or home is None:
            raise ArmError("a waypoint before hello")
        q, error = ik.follow(kin, waypoint.pose, command, home, kin.lower, kin.upper)
        if error > ik.IK_REACH:
            raise ArmError(f"the arm cannot reach the pose of plan step {waypoint.step} ({waypoint.phase}): IK "
                           f"stays {error * 1e3:.3f} mm off")
        fast = self.arm.too_fast(command, q, self._period)
        if fast is not None:
            raise ArmError(f"{fast} (plan step {waypoint.step}, {waypoint.phase})")
        self._call("send", [float(v) for v in q], self._period)
        self._command = q
        return self._state(self._read(), waypoint.phase == "approach")

    def stop(self) -> Optional[bool]:
        try:
            self.joints.halt()
            return True
        except Exception:  # noqa: BLE001 - stop never raises: the run reports that it did not confirm
            return None

    def close(self) -> None:
        self.joints.close()

    def _read(self) -> np.ndarray:
        q = np.asarray(self._call("read_joints"), float)
        if q.shape != (len(self.arm.joints),) or not np.all(np.isfinite(q)):
            raise ArmError(f"read_joints gave {q.tolist()!r:.120}, not {len(self.arm.joints)} finite positions")
        return q

    def _state(self, q: np.ndarray, contact_force: bool) -> dict:
        if self._kinematics is None:
            raise ArmError("the arm's state before hello")
        R, p, _ = self._kinematics(q)
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, p
        state: Dict[str, Any] = {"ee_pose": matrix_to_pose(T), "joints": [float(v) for v in q]}
        tracked = self._call("object_in_grasp")
        if tracked is not None:
            state["object_in_grasp"] = {k: float(tracked[k]) for k in ("x", "z", "theta")}
        force = self._call("wrist_force") if contact_force else None
        if force is not None:
            state["contact_force"] = [float(v) for v in force]
        return state

    def _call(self, method: str, *args):
        """The interface's `method`; whatever it raises is an ArmError naming it."""
        try:
            return getattr(self.joints, method)(*args)
        except ArmError:
            raise
        except Exception as exc:  # noqa: BLE001 - whatever the lab's interface raises ends the run as a fault
            raise ArmError(f"the joint interface's {method}: {type(exc).__name__}: "
                           f"{' '.join(str(exc).split())[:200]}") from None

