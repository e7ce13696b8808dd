"""Frames, in one place (docs/model.md section 1): R(theta) in the grasp plane, T_GO(q), and SE(3)
poses to and from vectors.

In the grasp plane a point of O is seen from G at q = (x, z, theta) as p_G = (x, z) + R(theta) p_O,
R(theta) = [[cos, sin], [-sin, cos]]; as a 4x4 transform T_GO(q) = Trans(x, 0, z) Rot_y(theta).
Poses as vectors are [x, y, z, qw, qx, qy, qz] (m; the arm protocol's and MuJoCo's order).
"""
from __future__ import annotations

import math
from typing import List, Sequence, Tuple, Union

import numpy as np

from stablepush.units import MM


def point_in_gripper(pose_mm_deg: Sequence[float], p: Union[Sequence[float], np.ndarray]) -> Tuple[float, float]:
    """A point of O (mm) seen from G at q (x mm, z mm, theta deg): p_G = (x, z) + R(theta) p_O.
    Plain floats: a plan asks this for every waypoint, where numpy's per-call cost would dominate."""
    c, s = math.cos(math.radians(pose_mm_deg[2])), math.sin(math.radians(pose_mm_deg[2]))
    return (pose_mm_deg[0] + c * p[0] + s * p[1], pose_mm_deg[1] - s * p[0] + c * p[1])


def point_in_object(pose_mm_deg: Sequence[float], p: Sequence[float]) -> Tuple[float, float]:
    """A point of G (mm) seen from O at q: point_in_gripper's inverse, p_O = R(theta)^T (p_G - (x, z))."""
    c, s = math.cos(math.radians(pose_mm_deg[2])), math.sin(math.radians(pose_mm_deg[2]))
    dx, dz = p[0] - pose_mm_deg[0], p[1] - pose_mm_deg[1]
    return (c * dx - s * dz, s * dx + c * dz)


def in_gripper(pose_mm_deg: Sequence[float], points) -> np.ndarray:
    """Points of O (n x 2, mm) seen from G at q, as an n x 2 array (point_in_gripper for each)."""
    return np.array([point_in_gripper(pose_mm_deg, p) for p in np.asarray(points, float).reshape(-1, 2)]).reshape(-1, 2)


def direction_in_gripper(theta_deg: float, v: Union[Sequence[float], np.ndarray]) -> Tuple[float, float]:
    """A direction of O seen from G: R(theta) v."""
    c, s = math.cos(math.radians(theta_deg)), math.sin(math.radians(theta_deg))
    return (c * v[0] + s * v[1], -s * v[0] + c * v[1])


def rot_y(angle: float) -> np.ndarray:
    """Right-handed rotation by `angle` rad about +y (docs/model.md section 1: R(theta) in xz)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def angle_about_y(R: np.ndarray) -> float:
    """The angle [rad] of a rotation about y from its matrix: rot_y's inverse (of a rotation that has
    others, the turn of its x axis about y)."""
    return math.atan2(R[0, 2], R[0, 0])


def grasp_transform(pose_mm_deg: Sequence[float]) -> np.ndarray:
    """T_GO(q) = Trans(x, 0, z) · Rot_y(theta), for q in mm and degrees."""
    T = np.eye(4)
    T[:3, :3] = rot_y(math.radians(pose_mm_deg[2]))
    T[0, 3], T[2, 3] = pose_mm_deg[0] * MM, pose_mm_deg[1] * MM
    return T


def translation(p: "Sequence[float] | np.ndarray") -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def matrix_to_pose(T: np.ndarray) -> List[float]:
    """(x, y, z, qw, qx, qy, qz) of a 4x4 transform."""
    R = T[:3, :3]
    w = math.sqrt(max(0.0, 1.0 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    if w > 1e-6:
        q = [w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w), (R[1, 0] - R[0, 1]) / (4 * w)]
    else:  # a half turn: the axis from the largest diagonal term
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        v = math.sqrt(max(0.0, 1.0 + R[i, i] - R[j, j] - R[k, k])) / 2
        q = [0.0, 0.0, 0.0, 0.0]
        q[1 + i] = v
        q[1 + j] = (R[j, i] + R[i, j]) / (4 * v)
        q[1 + k] = (R[k, i] + R[i, k]) / (4 * v)
        q[0] = (R[k, j] - R[j, k]) / (4 * v)
    norm = math.sqrt(sum(c * c for c in q))
    return [float(v) for v in T[:3, 3]] + [c / norm for c in q]


def pose_to_matrix(pose: Sequence[float]) -> np.ndarray:
    w, x, y, z = pose[3:]
    T = np.eye(4)
    T[:3, :3] = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])
    T[:3, 3] = pose[:3]
    return T


def slerp(q0: np.ndarray, q1: np.ndarray, s: float) -> np.ndarray:
    dot = float(np.dot(q0, q1))
    if dot < 0:
        q1, dot = -q1, -dot
    if dot > 0.9995:
        q = q0 + s * (q1 - q0)
        return q / np.linalg.norm(q)
    a = math.acos(dot)
    return (math.sin((1 - s) * a) * q0 + math.sin(s * a) * q1) / math.sin(a)


def quat_about_y(angle: float) -> Tuple[float, float, float, float]:
    """(w, x, y, z) of a right-handed rotation by `angle` rad about +y."""
    return (math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0)


def turn(a: Sequence[float], b: Sequence[float], c: Sequence[float]) -> float:
    """The z of (b - a) x (c - a) for points in a plane: > 0 where a -> b -> c turns left
    (counterclockwise), < 0 right, 0 on one line."""
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
