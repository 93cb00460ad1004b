"""Homogeneous transforms as plain (4, 4) float arrays; angles in radians."""

from __future__ import annotations

import numpy as np

from robomax_py._typing import FloatArray


def rot_x(a: float) -> FloatArray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a: float) -> FloatArray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a: float) -> FloatArray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_matrix(roll: float, pitch: float, yaw: float) -> FloatArray:
    """R = Rz(yaw) Ry(pitch) Rx(roll): fixed-axis X, Y, Z rotations (docs/cell-files.md, "A cell file")."""
    return rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)


def pose_matrix(xyz: FloatArray | list[float], rpy: FloatArray | list[float]) -> FloatArray:
    """(4, 4) transform from a translation (m) and fixed-axis roll, pitch, yaw (rad)."""
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(*np.asarray(rpy, dtype=float))
    T[:3, 3] = np.asarray(xyz, dtype=float)
    return T


def rpy_from_matrix(R: FloatArray) -> FloatArray:
    """Inverse of `rpy_matrix`: (roll, pitch, yaw) in rad, pitch in [-pi/2, pi/2]."""
    pitch = np.arctan2(-R[2, 0], np.hypot(R[0, 0], R[1, 0]))
    if np.hypot(R[0, 0], R[1, 0]) < 1e-12:  # gimbal lock: put the whole rotation on yaw
        return np.array([0.0, pitch, np.arctan2(-R[0, 1], R[1, 1])])
    return np.array([np.arctan2(R[2, 1], R[2, 2]), pitch, np.arctan2(R[1, 0], R[0, 0])])


def invert(T: FloatArray) -> FloatArray:
    """Inverse of rigid transforms, (..., 4, 4)."""
    R = T[..., :3, :3]
    Rt = np.swapaxes(R, -1, -2)
    out = np.zeros_like(T)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def rotation_angle(R_a: FloatArray, R_b: FloatArray) -> FloatArray:
    """Angle (rad) of the rotation taking R_a to R_b, (..., 3, 3) -> (...)."""
    R = np.swapaxes(R_a, -1, -2) @ R_b
    cos = (np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0
    # arccos is ill-conditioned near 0; the skew part gives the small angles accurately.
    skew = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1)
    angle: FloatArray = np.arctan2(np.linalg.norm(skew, axis=-1) / 2.0, cos)
    return angle


def closest_on_line(p: FloatArray, a: FloatArray, p_ref: FloatArray, a_ref: FloatArray) -> FloatArray:
    """Point of the line (p, a) closest to the line (p_ref, a_ref); p itself when they are parallel.

    Lines are a point and a unit direction, (..., 3) each (broadcast), m.
    """
    p, a = np.asarray(p, dtype=float), np.asarray(a, dtype=float)
    p_ref, a_ref = np.asarray(p_ref, dtype=float), np.asarray(a_ref, dtype=float)
    w0 = p - p_ref
    b = np.sum(a * a_ref, axis=-1)
    d = np.sum(a * w0, axis=-1)
    e = np.sum(a_ref * w0, axis=-1)
    denom = 1.0 - b * b
    t = np.where(denom > 1e-12, (b * e - d) / np.where(denom > 1e-12, denom, 1.0), 0.0)
    out: FloatArray = p + t[..., None] * a
    return out
