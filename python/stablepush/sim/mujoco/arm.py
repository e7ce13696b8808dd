"""The simulated arm: a MuJoCo model of the cell (kinematics.cell_model) whose joint servos track end-effector poses by
damped least-squares IK (tracking.py). It knows nothing of runs: `local_arm.SimulatedArm` puts it
behind the arm port, and `server.py` serves that over TCP.

Poses are (x, y, z, qw, qx, qy, qz) in the world [m]; the end effector is the gripper frame G,
midway between the pads.
"""
from __future__ import annotations

import time
from typing import Callable, Dict, Optional, Sequence

import numpy as np

from stablepush.execution.scene import Scene
from stablepush.kinematics import cell_model
from stablepush.kinematics.arm_kinematics import ArmKinematics
from stablepush.kinematics.robot import FINGER_JOINTS, GRIPPER_SITE, arm_model
from stablepush.sim.deviation import WorldDeviation
from stablepush.sim.mujoco.friction import CoulombPadFriction, mujoco
from stablepush.sim.tracking import SETTLE_TIME, TrackingArm, in_grasp
from stablepush.task.model import Robot


class SimulatedGrasp:
    """A scene's grasp in MuJoCo, shared by the arm and the friction-fidelity rig (`fidelity.py`):
    the model (`cell_model.build_mjcf`, with the arm of `robot`), the jaws closed on the object with the
    grip force, the pad friction (friction.py) stepped with the physics, and the read-outs of the
    grasp."""

    def __init__(self, scene: Scene, kinematic_hand: bool = False, robot: Optional[Robot] = None):
        self.arm = arm_model(robot)
        self.model = mujoco.MjModel.from_xml_string(cell_model.build_mjcf(scene, kinematic_hand, robot))
        self.data = mujoco.MjData(self.model)
        m = self.model
        self._site = m.site(GRIPPER_SITE).id
        self._object = m.body(cell_model.OBJECT_BODY).id
        self._object_qpos = m.jnt_qposadr[m.joint(cell_model.OBJECT_BODY).id]
        self.pad_friction = CoulombPadFriction(m, cell_model.pad_geoms(m))
        self.steps = 0
        self.step_wall_time = 0.0
        fingers = [m.jnt_qposadr[m.joint(j).id] for j in FINGER_JOINTS]
        self.data.qpos[fingers] = scene.object.thickness / 2
        self.data.qpos[self._object_qpos:self._object_qpos + 7] = scene.object_pose
        # close: the servos saturate at the grip force
        self.data.ctrl[[m.actuator(j).id for j in FINGER_JOINTS]] = 0.0
        self._pad_geoms = set(cell_model.pad_geoms(m))
        if kinematic_hand:
            self._hand_qpos = [m.jnt_qposadr[m.joint(j).id] for j in cell_model.HAND_JOINTS]
            self._hand_dof = [m.jnt_dofadr[m.joint(j).id] for j in cell_model.HAND_JOINTS]
            mujoco.mj_forward(m, self.data)
        # the arm sets its own drives, then calls mj_forward once

    engine = "mujoco"

    @property
    def timestep(self) -> float:
        return float(self.model.opt.timestep)

    def step_hand(self, motion: Sequence[float], velocity: Sequence[float]) -> None:
        """With a kinematic hand: one time step with the hand at `motion` (x m, z m, theta rad about
        y, from its start) moving at `velocity` (m/s, m/s, rad/s)."""

        def drive_hand(_: int) -> None:
            self.data.qpos[self._hand_qpos] = motion
            self.data.qvel[self._hand_dof] = velocity

        self._run(1, drive_hand)

    def pad_contacts(self) -> int:
        """How many pad points touch the object now."""
        return sum(1 for i in range(self.data.ncon)
                   if self.data.contact[i].geom1 in self._pad_geoms or self.data.contact[i].geom2 in self._pad_geoms)

    def describe(self) -> str:
        return (f"MuJoCo {self.model.nbody} bodies, {self.model.npair} contact pairs, "
                f"{self.timestep * 1e3:g} ms step")

    def _run(self, n: int, before_step: Callable[[int], None]) -> None:
        """n time steps; `before_step(i)` (i = 1..n) sets the drives of step i."""
        t0 = time.perf_counter()
        for i in range(1, n + 1):
            before_step(i)
            self.pad_friction.step(self.data)
        self.step_wall_time += time.perf_counter() - t0
        self.steps += n

    def gripper_matrix(self) -> np.ndarray:
        """T_WG (4x4, m) now."""
        T = np.eye(4)
        T[:3, :3] = self.data.site_xmat[self._site].reshape(3, 3)
        T[:3, 3] = self.data.site_xpos[self._site]
        return T

    def object_matrix(self) -> np.ndarray:
        """T_WO (4x4, m) now."""
        T = np.eye(4)
        T[:3, :3] = self.data.xmat[self._object].reshape(3, 3)
        T[:3, 3] = self.data.xpos[self._object]
        return T

    def in_grasp(self) -> Dict[str, float]:
        """The object's true pose in the grasp now (see `in_grasp`)."""
        return in_grasp(self.gripper_matrix(), self.object_matrix())

    def contact_force_on_object(self, pusher: str) -> np.ndarray:
        """Total force [N, world frame] that pusher `pusher`'s feature exerts on the object now."""
        geoms = set(cell_model.feature_geoms(self.model, pusher))
        total = np.zeros(3)
        f6 = np.zeros(6)
        for i in range(self.data.ncon):
            c = self.data.contact[i]
            if c.geom1 not in geoms and c.geom2 not in geoms:
                continue
            mujoco.mj_contactForce(self.model, self.data, i, f6)
            f = c.frame.reshape(3, 3).T @ f6[:3]  # rows of frame: normal, tangents; the force acts on geom2
            total += f if c.geom1 in geoms else -f
        return total

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.step_wall_time if self.step_wall_time > 0 else 0.0


class SimArm(TrackingArm, SimulatedGrasp):
    """The arm of `robot` (the shipped arm when None), the grasp and the world of one scene (as
    `deviation` alters it)."""

    def __init__(self, scene: Scene, deviation: WorldDeviation = WorldDeviation(), robot: Optional[Robot] = None):
        super().__init__(scene, deviation, robot)
        m = self.model
        self._kinematics = ArmKinematics(m, self.arm.joints)
        self._arm_qpos, self._arm_dof = self._kinematics.qpos_adr, self._kinematics.dof_adr
        self._arm_act = np.array([m.actuator(j).id for j in self.arm.joints])
        self._lower, self._upper = self._kinematics.lower, self._kinematics.upper

        home = self._find_home()
        self.data.qpos[self._arm_qpos] = home
        self._set_servos(home)
        mujoco.mj_forward(m, self.data)
        self.advance(SETTLE_TIME)

    # -- simulation ---------------------------------------------------------------------------

    def _set_servos(self, q_arm: np.ndarray) -> None:
        self.data.ctrl[self._arm_act] = q_arm

    def stop(self) -> None:
        """Hold the joints where they are now."""
        self.target = self.data.qpos[self._arm_qpos].copy()
        self._set_servos(self.target)
        self.data.qvel[self._arm_dof] = 0.0

    # -- state --------------------------------------------------------------------------------

    def state(self, contact_force: bool = False) -> dict:
        """What the arm reports: G's pose and the joints; the tracker's `object_in_grasp` (with the
        deviation's noise); with `contact_force`, the wrist's force reading; and, as a simulation,
        the object's true world pose."""
        return self._report(float(self.data.time), self.data.qpos[self._arm_qpos], contact_force)
