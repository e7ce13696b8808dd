"""The simulated arm: a MuJoCo scene (scene.py) whose joint servos track end-effector poses by
damped least-squares IK. It knows nothing of sockets; `stablepush.sim.server` puts it on one.

Poses are (x, y, z, qw, qx, qy, qz) in the world [m]; the end effector is the gripper frame G,
midway between the pads.
"""
from __future__ import annotations

import copy
import math
import time
from dataclasses import dataclass
from typing import Callable, Dict, Optional, Sequence, Tuple

import numpy as np

from stablepush.frames import angle_about_y, matrix_to_pose, pose_to_matrix, rot_y
from stablepush.sim import ik
from stablepush.sim import scene as scene_mod
from stablepush.sim.friction import CoulombPadFriction, mujoco

SETTLE_TIME = 0.3  # s of simulation after the grasp closes, before the first waypoint


def in_grasp(T_world_gripper: np.ndarray, T_world_object: np.ndarray) -> Dict[str, float]:
    """The object's pose in the grasp as docs/model.md section 1 defines it (x, z mm; theta deg), with the
    out-of-plane parts (y mm, tilt deg) that the planar model assumes to be zero."""
    T = np.linalg.inv(T_world_gripper) @ T_world_object
    R = T[:3, :3]
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, R[1, 1]))))
    return {"x": T[0, 3] * 1e3, "z": T[2, 3] * 1e3, "theta": math.degrees(angle_about_y(R)),
            "y": T[1, 3] * 1e3, "tilt": tilt}


@dataclass(frozen=True)
class WorldDeviation:
    """How the simulated world departs from the task it is given, to test plans against a world that
    differs from their model: every pad's and feature's mu times `mu_scale`, the pads' mu also times
    `pad_mu_scale` and the features' times `pusher_mu_scale`, the grip force times `grip_scale`, the
    object's mass (and inertia) times `mass_scale`, each feature `feature_offsets` off where the
    plan puts it ((pusher, dx mm, dz mm, dtheta deg) in the world's x, z and about y through the
    middle of its segment), and a tracker whose `object_in_grasp` carries Gaussian noise (standard
    deviations in mm and deg, drawn from `seed`)."""

    mu_scale: float = 1.0
    tracker_noise_mm: float = 0.0
    tracker_noise_deg: float = 0.0
    seed: int = 0
    pad_mu_scale: float = 1.0
    pusher_mu_scale: float = 1.0
    grip_scale: float = 1.0
    mass_scale: float = 1.0
    feature_offsets: Tuple[Tuple[str, float, float, float], ...] = ()

    def apply(self, scene: dict) -> dict:
        """`scene` (a scene description, SI units) as this world has it; the scene itself unchanged."""
        scene = copy.deepcopy(scene)
        scene["gripper"]["mu"] *= self.mu_scale * self.pad_mu_scale
        scene["gripper"]["grip_force"] *= self.grip_scale
        obj = scene["object"]
        obj["mass"] *= self.mass_scale
        obj["inertia"] *= self.mass_scale
        offsets = {name: (dx, dz, dth) for name, dx, dz, dth in self.feature_offsets}
        for feature in scene["features"]:
            feature["mu"] *= self.mu_scale * self.pusher_mu_scale
            if feature["pusher"] in offsets:
                _move_feature(feature, *offsets[feature["pusher"]])
        return scene


def _move_feature(feature: dict, dx_mm: float, dz_mm: float, dtheta_deg: float) -> None:
    """Turn a feature by dtheta about the world's y through the middle of its segment, then shift it,
    with the object's pose on it (its segment stays where it was on the object)."""
    a, b = np.asarray(feature["from"], float), np.asarray(feature["to"], float)
    middle = (a + b) / 2
    move = np.eye(4)  # the turn about the middle, then the shift, as one rigid motion in W
    move[:3, :3] = rot_y(math.radians(dtheta_deg))
    move[:3, 3] = middle + np.array([dx_mm * 1e-3, 0.0, dz_mm * 1e-3]) - move[:3, :3] @ middle
    feature["from"] = (move @ np.append(a, 1.0))[:3].tolist()
    feature["to"] = (move @ np.append(b, 1.0))[:3].tolist()
    feature["normal"] = (move[:3, :3] @ np.asarray(feature["normal"], float)).tolist()
    feature["object_pose"] = matrix_to_pose(move @ pose_to_matrix(feature["object_pose"]))


class SimulatedGrasp:
    """A scene's grasp in MuJoCo, shared by the arm and the friction-fidelity rig (`fidelity.py`):
    the model (`scene.build_mjcf`), the jaws closed on the object with the grip force, the pad
    friction (friction.py) stepped with the physics, and the read-outs of the grasp."""

    def __init__(self, scene: dict, kinematic_hand: bool = False):
        self.model = mujoco.MjModel.from_xml_string(scene_mod.build_mjcf(scene, kinematic_hand=kinematic_hand))
        self.data = mujoco.MjData(self.model)
        m = self.model
        self._site = m.site(scene_mod.GRIPPER_SITE).id
        self._object = m.body(scene_mod.OBJECT_BODY).id
        self._object_qpos = m.jnt_qposadr[m.joint(scene_mod.OBJECT_BODY).id]
        self.pad_friction = CoulombPadFriction(m, scene_mod.pad_geoms(m))
        self.steps = 0
        self.step_wall_time = 0.0
        fingers = [m.jnt_qposadr[m.joint(j).id] for j in scene_mod.FINGER_JOINTS]
        self.data.qpos[fingers] = scene["object"]["thickness"] / 2
        self.data.qpos[self._object_qpos:self._object_qpos + 7] = scene["object_pose"]
        # close: the servos saturate at the grip force
        self.data.ctrl[[m.actuator(j).id for j in scene_mod.FINGER_JOINTS]] = 0.0
        self._pad_geoms = set(scene_mod.pad_geoms(m))
        if kinematic_hand:
            self._hand_qpos = [m.jnt_qposadr[m.joint(j).id] for j in scene_mod.HAND_JOINTS]
            self._hand_dof = [m.jnt_dofadr[m.joint(j).id] for j in scene_mod.HAND_JOINTS]
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
        geom = self.model.geom(scene_mod.feature_geom(pusher)).id
        total = np.zeros(3)
        f6 = np.zeros(6)
        for i in range(self.data.ncon):
            c = self.data.contact[i]
            if geom not in (c.geom1, c.geom2):
                continue
            mujoco.mj_contactForce(self.model, self.data, i, f6)
            f = c.frame.reshape(3, 3).T @ f6[:3]  # rows of frame: normal, tangents; the force acts on geom2
            total += f if c.geom1 == geom else -f
        return total

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.step_wall_time if self.step_wall_time > 0 else 0.0


class TrackingArm:
    """What the arm does the same on every engine: the world `deviation` makes of the scene, IK on
    the engine's kinematics (`_kinematics(q)` -> R_WG, p_WG, J; `ik.solve_ik`) from the home
    posture, servo set-points moved linearly from one streamed waypoint's joint angles to the
    next's over the waypoint period (`_set_servos`, `_run`), and the report with the tracker's
    noise. Mixed in before the engine's grasp class, whose constructor takes the altered scene."""

    def __init__(self, scene: dict, deviation: WorldDeviation = WorldDeviation()):
        super().__init__(deviation.apply(scene))
        self.scene = scene
        self.deviation = deviation
        self._tracker_rng = np.random.default_rng(deviation.seed)

    def _find_home(self) -> np.ndarray:
        """The joint angles [rad] that put G at the scene's gripper pose: the posture IK's
        null space pulls toward, and the servos' first target."""
        self.home_posture = ik.HOME_GUESS.copy()
        self.home_posture = self.solve_ik(self.scene["gripper_pose"], ik.HOME_GUESS, strict=True, iterations=1000)
        self.target = self.home_posture.copy()
        return self.home_posture

    def solve_ik(self, pose: Sequence[float], q_start: np.ndarray, strict: bool = False,
                 iterations: int = ik.IK_ITERATIONS) -> np.ndarray:
        """Joint angles [rad] that put G at `pose`, from `q_start`."""
        q, error = ik.solve_ik(self._kinematics, pose, q_start, self.home_posture, self._lower, self._upper,
                               iterations)
        if strict and error > 1e-6:
            raise ik.unreachable(pose, error)
        self.ik_error = error
        return q

    def advance(self, duration: float, target: Optional[np.ndarray] = None) -> None:
        """Step the physics for `duration` s while the joint servo set-points move linearly from the
        current target to `target` (the servos interpolate between streamed waypoints)."""
        n = max(1, int(round(duration / self.timestep)))
        start = self.target.copy()
        end = start if target is None else np.asarray(target, float)
        self._run(n, lambda i: self._set_servos(start + (end - start) * (i / n)))
        self.target = end.copy()

    def move_to(self, pose: Sequence[float], duration: float) -> None:
        """Track G toward `pose` over `duration` s (one streamed waypoint period). ValueError, the
        arm held where it is, when no joint angles within the limits put G there (IK_REACH):
        driven there anyway, the servos fight the limits and the arm leaves the stream."""
        q = self.solve_ik(pose, self.target)
        if self.ik_error > ik.IK_REACH:  # slow to converge near the edge of reach: look harder first
            q = self.solve_ik(pose, self.target, iterations=10 * ik.IK_ITERATIONS)
        if self.ik_error > ik.IK_REACH:
            raise ik.unreachable(pose, self.ik_error)
        self.advance(duration, q)

    def _report(self, time_s: float, joints, contact_force: bool) -> dict:
        """The arm's state message: G's pose and the joints [rad]; the tracker's `object_in_grasp`,
        the truth plus the deviation's noise; with `contact_force`, the features' force on the object
        (N, W), what a wrist force-torque sensor reads with the held load compensated; the
        object's true world pose."""
        T_g, T_o = self.gripper_matrix(), self.object_matrix()
        tracked = in_grasp(T_g, T_o)
        d = self.deviation
        if d.tracker_noise_mm > 0 or d.tracker_noise_deg > 0:
            nx, nz, nth = self._tracker_rng.normal(0.0, [d.tracker_noise_mm, d.tracker_noise_mm, d.tracker_noise_deg])
            tracked.update(x=tracked["x"] + nx, z=tracked["z"] + nz, theta=tracked["theta"] + nth)
        report = {
            "time": time_s,
            "ee_pose": matrix_to_pose(T_g),
            "joints": [float(v) for v in joints],
            "object_pose": matrix_to_pose(T_o),
            "object_in_grasp": tracked,
            "steps_per_s": round(self.steps_per_second, 1),
        }
        if contact_force:
            report["contact_force"] = [float(v) for v in sum((self.contact_force_on_object(f["pusher"])
                                                              for f in self.scene["features"]), np.zeros(3))]
        return report


class SimArm(TrackingArm, SimulatedGrasp):
    """The arm, the grasp and the world of one scene description (as `deviation` alters it)."""

    def __init__(self, scene: dict, deviation: WorldDeviation = WorldDeviation()):
        super().__init__(scene, deviation)
        m = self.model
        self._arm_qpos = np.array([m.jnt_qposadr[m.joint(j).id] for j in scene_mod.ARM_JOINTS])
        self._arm_dof = np.array([m.jnt_dofadr[m.joint(j).id] for j in scene_mod.ARM_JOINTS])
        self._arm_act = np.array([m.actuator(j).id for j in scene_mod.ARM_JOINTS])
        self._scratch = mujoco.MjData(m)
        joints = [m.joint(j).id for j in scene_mod.ARM_JOINTS]
        self._lower, self._upper = m.jnt_range[joints, 0], m.jnt_range[joints, 1]
        self._jacp = np.zeros((3, m.nv))
        self._jacr = np.zeros((3, m.nv))

        home = self._find_home()
        self.data.qpos[self._arm_qpos] = home
        self._set_servos(home)
        mujoco.mj_forward(m, self.data)
        self.advance(SETTLE_TIME)

    # -- kinematics ---------------------------------------------------------------------------

    def _kinematics(self, q: np.ndarray):
        d = self._scratch
        d.qpos[self._arm_qpos] = q
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_comPos(self.model, d)
        mujoco.mj_jacSite(self.model, d, self._jacp, self._jacr, self._site)
        J = np.vstack([self._jacp, self._jacr])[:, self._arm_dof]
        return d.site_xmat[self._site].reshape(3, 3), d.site_xpos[self._site].copy(), J

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
