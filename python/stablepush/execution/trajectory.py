"""Timed trajectories: the gripper's world poses that carry out a plan, with time, linear and
angular velocity, phase and plan step (`stablepush trajectory`, `sp.trajectory`).

They are the executor's stream (stablepush.execution.stream.arm_trajectory) for an arm that starts where the
executor's world starts it (the task's home pose, or 1 mm back from a feature the object starts on) with every
feature placed as the executor places it, sampled at the stream's rate: each approach ends at the
feature's planned place, as a guarded approach does when the feature stands there.
World frame W (x forward, y the gripping axis at home, z up), m, s. Velocities are those of G's
origin and frame over the period that ends at each sample (backward differences), in W:
v_i = (p_i - p_{i-1}) / dt, omega_i = axis-angle(R_i R_{i-1}^T) / dt.
"""
from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass
from typing import List

import numpy as np

from stablepush.errors import SettingError
from stablepush.execution.protocol import RATE_HZ
from stablepush.execution.stream import arm_trajectory
from stablepush.execution.world import place_features, scene_description
from stablepush.plan.plan import Plan
from stablepush.plan.verify import check_plan
from stablepush.task.model import Task
from stablepush.units import is_real

QUATERNION_ORDERS = ("xyzw", "wxyz")  # xyzw: ROS (geometry_msgs/Quaternion); wxyz: the arm protocol, MuJoCo


@dataclass(frozen=True)
class Trajectory:
    """Samples i = 0..n-1 at t[i] s (the first one period after the start pose, which is not a
    sample): position [m] and unit quaternion (w, x, y, z) of G in W, linear velocity [m/s] and
    angular velocity [rad/s] in W, the phase (push | settle | retract | move | approach) and the plan
    step (the one a push is heading for, else the last one reached)."""

    t: np.ndarray  # (n,)
    position: np.ndarray  # (n, 3)
    quaternion_wxyz: np.ndarray  # (n, 4)
    linear_velocity: np.ndarray  # (n, 3)
    angular_velocity: np.ndarray  # (n, 3)
    phase: List[str]
    step: np.ndarray  # (n,) int
    rate_hz: float

    def __len__(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:
        return (f"Trajectory({len(self)} samples at {self.rate_hz:g} Hz, {self.t[-1] if len(self) else 0:.2f} s, "
                f"plan steps to {int(self.step.max()) if len(self) else 0})")

    def columns(self, quat: str = "xyzw") -> List[str]:
        """The column names of rows(), the quaternion in `quat` order (xyzw or wxyz)."""
        if quat not in QUATERNION_ORDERS:
            raise SettingError("quat", f"must be one of {', '.join(QUATERNION_ORDERS)}, got {quat!r:.40}")
        q = ["qx", "qy", "qz", "qw"] if quat == "xyzw" else ["qw", "qx", "qy", "qz"]
        return ["t", "x", "y", "z", *q, "vx", "vy", "vz", "wx", "wy", "wz", "phase", "step"]

    def rows(self, quat: str = "xyzw") -> List[list]:
        """One list per sample, in columns() order: t s, position m, quaternion, velocity m/s and
        rad/s (world frame), phase, plan step."""
        self.columns(quat)  # checks the order
        q = self.quaternion_wxyz[:, [1, 2, 3, 0]] if quat == "xyzw" else self.quaternion_wxyz
        return [[float(self.t[i]), *map(float, self.position[i]), *map(float, q[i]),
                 *map(float, self.linear_velocity[i]), *map(float, self.angular_velocity[i]), self.phase[i],
                 int(self.step[i])] for i in range(len(self))]

    def to_csv(self, quat: str = "xyzw") -> str:
        """The CSV `stablepush trajectory -o X.csv` writes: a header of columns(), then rows()."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(self.columns(quat))
        writer.writerows(self.rows(quat))
        return buffer.getvalue()

    def to_json(self, quat: str = "xyzw") -> str:
        """The JSON `stablepush trajectory -o X.json` writes: frame, rate, units, columns and rows."""
        return json.dumps({
            "format": "stablepush.trajectory/1", "frame": "world (x forward, y the gripping axis at home, z up)",
            "rate_hz": self.rate_hz, "quaternion_order": quat,
            "units": {"t": "s", "x y z": "m", "v": "m/s", "w": "rad/s"},
            "columns": self.columns(quat), "rows": self.rows(quat)}, indent=None) + "\n"


def timed_trajectory(task: Task, plan: Plan, rate_hz: float = 100.0) -> Trajectory:
    """The executor's stream for a plan checked against the task (stablepush.plan.verify.check_plan),
    from G where the executor's world starts it (world.scene_description). ValueError unless `rate_hz`
    lies in the arm protocol's RATE_HZ."""
    if not is_real(rate_hz) or not RATE_HZ[0] <= rate_hz <= RATE_HZ[1]:
        raise SettingError("rate_hz", f"must be a number from {RATE_HZ[0]:g} to {RATE_HZ[1]:g}, got {rate_hz!r:.40}")
    rate_hz = rate_hz if isinstance(rate_hz, (int, float)) else float(rate_hz)  # numpy's, as the arm's JSON takes
    steps = list(plan.waypoints)
    features = place_features(task, steps)
    start = scene_description(task, features, steps[0].pose, solid=False).gripper_pose
    points = arm_trajectory(task, steps, features, rate_hz, start)
    poses = np.array([start] + [p.pose for p in points], float)  # [x, y, z, qw, qx, qy, qz]
    dt = 1.0 / rate_hz
    quats = continuous_quaternions(poses[:, 3:])
    return Trajectory(
        t=np.array([p.t for p in points]), position=poses[1:, :3], quaternion_wxyz=quats[1:],
        linear_velocity=np.diff(poses[:, :3], axis=0) / dt,
        angular_velocity=np.array([_rotation_vector(a, b) / dt for a, b in zip(quats[:-1], quats[1:])]).reshape(-1, 3),
        phase=[p.phase for p in points], step=np.array([p.step for p in points], int), rate_hz=rate_hz)


def continuous_quaternions(quats: np.ndarray) -> np.ndarray:
    """Unit quaternions (n, 4), each of the two signs chosen: w >= 0 for the first, then each in the
    hemisphere of the one before, so that a stream turning past 180 deg does not jump to the
    other sign between two samples (what interpolating consumers and plots would see)."""
    out = np.array(quats, float)
    if len(out) and out[0, 0] < 0:
        out[0] = -out[0]
    for k in range(1, len(out)):
        if out[k] @ out[k - 1] < 0:
            out[k] = -out[k]
    return out


def _rotation_vector(q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """axis * angle [rad] of the rotation R1 R0^T, from unit quaternions (w, x, y, z), in W."""
    w0, v0 = q0[0], q0[1:]
    w1, v1 = q1[0], q1[1:]
    w = w1 * w0 + v1 @ v0  # q1 * conj(q0)
    v = -w1 * v0 + w0 * v1 - np.cross(v1, v0)
    if w < 0:
        w, v = -w, -v
    s = float(np.linalg.norm(v))
    return np.zeros(3) if s < 1e-15 else v / s * 2.0 * math.atan2(s, w)


def plan_trajectory(task: Task, plan: Plan, rate_hz: float = 100.0) -> Trajectory:
    """The timed trajectory of `plan` once it is shown to belong to `task` (check_plan; PlanError
    names what differs)."""
    return timed_trajectory(task, check_plan(task, plan), rate_hz)
