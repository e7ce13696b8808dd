"""Inverse kinematics of the arm, the same for both engines, the cell check and a joint-level arm:
damped least squares on G's pose, with a null-space pull toward the home posture (the arm has one
joint more than the pose needs). The caller supplies the forward kinematics; this is the arm's
controller, not physics, so both engines track a waypoint with the same joint set-points.

Poses are (x, y, z, qw, qx, qy, qz) in the world [m]; joint angles in rad.
"""
from __future__ import annotations

from typing import Callable, Sequence, Tuple

import numpy as np

from stablepush.frames import pose_to_matrix

IK_DAMPING = 1e-4  # DLS damping lambda^2 [m^2]
IK_ITERATIONS = 50
IK_TOLERANCE = 1e-9  # m (and rad) of pose error
IK_REACH = 1e-3  # m (and rad): a waypoint whose IK ends farther off than this is out of the arm's reach
POSTURE_GAIN = 0.05  # null-space pull toward the home posture per IK iteration
HOME_TOLERANCE = 1e-6  # m (and rad): the home posture puts G this close to the start pose
HOME_ITERATIONS = 1000

# q -> (R_WG 3x3, p_WG [m], J 6 x n_joints: G's angular velocity over linear velocity rows as
# [linear; angular] of the world frame)
Kinematics = Callable[[np.ndarray], Tuple[np.ndarray, np.ndarray, np.ndarray]]


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """The axis-angle vector [rad] of rotation matrix R (the log map), robust near 0 and pi."""
    cos = max(-1.0, min(1.0, (np.trace(R) - 1.0) / 2.0))
    angle = float(np.arccos(cos))
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-6:
        return w / 2.0
    if np.pi - angle < 1e-6:  # near a half turn: the axis from R + I
        k = int(np.argmax(np.diag(R)))
        axis = (R[:, k] + np.eye(3)[:, k]) / np.sqrt(2.0 * (1.0 + R[k, k]))
        return angle * axis
    return angle * w / (2.0 * np.sin(angle))


def solve_ik(kinematics: Kinematics, pose: Sequence[float], q_start: np.ndarray, home_posture: np.ndarray,
             lower: np.ndarray, upper: np.ndarray, iterations: int = IK_ITERATIONS) -> Tuple[np.ndarray, float]:
    """Joint angles [rad] that put G at `pose`, from `q_start`, within [lower, upper]; with the
    remaining pose error [m and rad, as one norm]. Each iteration: dq = J^T (J J^T + lambda^2 I)^-1 e
    plus the null-space pull POSTURE_GAIN (home_posture - q)."""
    target = pose_to_matrix(pose)
    q = np.array(q_start, float)
    error = np.inf
    for _ in range(iterations):
        R, p, J = kinematics(q)
        e = np.concatenate([target[:3, 3] - p, rotation_vector(target[:3, :3] @ R.T)])
        error = float(np.linalg.norm(e))
        if error < IK_TOLERANCE:
            break
        dq = J.T @ np.linalg.solve(J @ J.T + IK_DAMPING * np.eye(6), e)
        null_space = np.eye(len(q)) - np.linalg.pinv(J, rcond=1e-6) @ J
        dq += null_space @ (POSTURE_GAIN * (home_posture - q))
        q = np.clip(q + dq, lower, upper)
    return q, error


def follow(kinematics: Kinematics, pose: Sequence[float], q_last: np.ndarray, home_posture: np.ndarray,
           lower: np.ndarray, upper: np.ndarray) -> Tuple[np.ndarray, float]:
    """The joints for the next pose of a stream: solve_ik from the last command `q_last`, and,
    where that ends farther off than IK_REACH (slow to converge near the edge of reach), again
    from `q_last` with ten times the iterations. With the pose error left (past IK_REACH: the
    pose is out of reach, `unreachable`)."""
    q, error = solve_ik(kinematics, pose, q_last, home_posture, lower, upper)
    if error > IK_REACH:
        q, error = solve_ik(kinematics, pose, q_last, home_posture, lower, upper, 10 * IK_ITERATIONS)
    return q, error


def find_home(kinematics: Kinematics, pose: Sequence[float], guesses: Sequence[np.ndarray], lower: np.ndarray,
              upper: np.ndarray) -> Tuple[np.ndarray, float]:
    """The home posture [rad]: joint angles within [lower, upper] that put G at `pose`, by IK from
    each of `guesses` (pulled toward that guess in the null space); of those that end within
    HOME_TOLERANCE, the one farthest from a singularity (the largest manipulability,
    sqrt(det(J J^T))), which leaves the arm room to follow the plan on one branch. With its pose
    error (m and rad, one norm: the least found when none ends within it)."""
    best: Tuple[np.ndarray, float] = (np.asarray(guesses[0], float), np.inf)
    chosen, dexterity = None, -1.0
    for guess in guesses:
        guess = np.clip(np.asarray(guess, float), lower, upper)
        q, error = solve_ik(kinematics, pose, guess, guess, lower, upper, HOME_ITERATIONS)
        if error >= HOME_TOLERANCE:
            best = min(best, (q, error), key=lambda b: b[1])
            continue
        J = kinematics(q)[2]
        manipulability = float(np.sqrt(max(np.linalg.det(J @ J.T), 0.0)))
        if manipulability > dexterity:
            chosen, dexterity = (q, error), manipulability
    return chosen if chosen is not None else best


def unreachable(pose: Sequence[float], error: float) -> ValueError:
    shown = [round(float(v), 4) for v in pose]
    return ValueError(f"the arm cannot reach the pose {shown} (IK error {error:.2e})")
