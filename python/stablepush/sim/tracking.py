"""What a simulated arm does the same on every engine (MuJoCo's `mujoco/arm.py`, Drake's `drake/arm.py`):
the pose in the grasp it reports, the IK that turns a streamed pose of G into joint set-points,
the servo ramp between waypoints, and the state message with the tracker's noise. Imports no engine.

Poses are (x, y, z, qw, qx, qy, qz) in the world [m]; the end effector is the gripper frame G,
midway between the pads.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Callable, Dict, Optional, Sequence

import numpy as np

from stablepush.execution.scene import Scene
from stablepush.frames import angle_about_y, matrix_to_pose
from stablepush.kinematics import ik
from stablepush.sim.deviation import WorldDeviation

if TYPE_CHECKING:
    from stablepush.kinematics.robot import ArmModel

SETTLE_TIME = 0.3  # s of simulation after the grasp closes, before the first waypoint


def in_grasp(T_world_gripper: np.ndarray, T_world_object: np.ndarray) -> Dict[str, float]:
    """The object's pose in the grasp as docs/model.md section 1 defines it (x, z mm; theta deg), with the
    out-of-plane parts (y mm, tilt deg) that the planar model assumes to be zero."""
    T = np.linalg.inv(T_world_gripper) @ T_world_object
    R = T[:3, :3]
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, R[1, 1]))))
    return {"x": T[0, 3] * 1e3, "z": T[2, 3] * 1e3, "theta": math.degrees(angle_about_y(R)),
            "y": T[1, 3] * 1e3, "tilt": tilt}


class TrackingArm:
    """What the arm does the same on every engine: the world `deviation` makes of the scene, IK on
    the engine's kinematics (`_kinematics(q)` -> R_WG, p_WG, J; `ik.solve_ik`) from the home
    posture, servo set-points moved linearly from one streamed waypoint's joint angles to the
    next's over the waypoint period (`_set_servos`, `_run`), and the report with the tracker's
    noise. Mixed in before the engine's grasp class, whose constructor takes the altered scene."""

    if TYPE_CHECKING:  # what the engine's grasp and arm class give (mujoco.arm.SimArm, drake.arm.DrakeArm)
        arm: ArmModel
        timestep: float
        steps_per_second: float
        _kinematics: ik.Kinematics
        _lower: np.ndarray
        _upper: np.ndarray

        def _set_servos(self, q_arm: np.ndarray) -> None: ...
        def _run(self, n: int, before_step: Callable[[int], None]) -> None: ...
        def gripper_matrix(self) -> np.ndarray: ...
        def object_matrix(self) -> np.ndarray: ...
        def contact_force_on_object(self, pusher: str) -> np.ndarray: ...

    def __init__(self, scene: Scene, deviation: WorldDeviation = WorldDeviation(), robot=None):
        super().__init__(deviation.apply(scene), robot=robot)  # type: ignore[call-arg]  # the engine's grasp
        self.scene = scene
        self.deviation = deviation
        self._tracker_rng = np.random.default_rng(deviation.seed)

    def _find_home(self) -> np.ndarray:
        """The joint angles [rad] that put G at the scene's gripper pose: the posture IK's
        null space pulls toward, and the servos' first target (ik.find_home from the arm's
        guesses)."""
        self.home_posture, error = ik.find_home(self._kinematics, self.scene.gripper_pose, self.arm.home_guesses,
                                                self._lower, self._upper)
        if error > ik.HOME_TOLERANCE:
            raise ik.unreachable(self.scene.gripper_pose, error)
        self.target = self.home_posture.copy()
        return self.home_posture

    def solve_ik(self, pose: Sequence[float], q_start: np.ndarray, iterations: int = ik.IK_ITERATIONS) -> np.ndarray:
        """Joint angles [rad] that put G at `pose`, from `q_start` (the pose error left: `ik_error`)."""
        q, self.ik_error = ik.solve_ik(self._kinematics, pose, q_start, self.home_posture, self._lower, self._upper,
                                       iterations)
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
        q, self.ik_error = ik.follow(self._kinematics, pose, self.target, self.home_posture, self._lower,
                                     self._upper)
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
            report["contact_force"] = [float(v) for v in sum((self.contact_force_on_object(f.pusher)
                                                              for f in self.scene.features), np.zeros(3))]
        return report
