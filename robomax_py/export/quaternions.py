"""Orientation conversions between the program's ZYX angles and the vendors' quaternions and
rotation vectors. The ZYX angles come back through `transforms.rpy_from_matrix`, the same
decomposition the program values are made with, so a round trip returns the same angles."""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from robomax_py.transforms import rpy_from_matrix

__all__ = ["quaternion_from_zyx", "rotvec_from_zyx", "zyx_from_matrix", "zyx_from_quaternion", "zyx_from_rotvec"]


def _matrix(zyx_deg: tuple[float, ...]) -> np.ndarray:
    a, b, c = zyx_deg
    matrix: np.ndarray = Rotation.from_euler("ZYX", [a, b, c], degrees=True).as_matrix()
    return matrix


def zyx_from_matrix(R: np.ndarray) -> tuple[float, float, float]:
    roll, pitch, yaw = rpy_from_matrix(np.asarray(R, dtype=float))
    return math.degrees(yaw), math.degrees(pitch), math.degrees(roll)


def quaternion_from_zyx(zyx_deg: tuple[float, ...]) -> tuple[float, float, float, float]:
    """(w, x, y, z), w >= 0, as RAPID's [q1, q2, q3, q4]."""
    x, y, z, w = Rotation.from_matrix(_matrix(zyx_deg)).as_quat()
    if w < 0:
        x, y, z, w = -x, -y, -z, -w
    return float(w), float(x), float(y), float(z)


def zyx_from_quaternion(q: tuple[float, ...]) -> tuple[float, float, float]:
    w, x, y, z = q
    return zyx_from_matrix(Rotation.from_quat([x, y, z, w]).as_matrix())


def rotvec_from_zyx(zyx_deg: tuple[float, ...]) -> tuple[float, float, float]:
    """The rotation vector (rad) of URScript poses: axis times angle, angle in [0, pi]."""
    rx, ry, rz = Rotation.from_matrix(_matrix(zyx_deg)).as_rotvec()
    return float(rx), float(ry), float(rz)


def zyx_from_rotvec(r: tuple[float, ...]) -> tuple[float, float, float]:
    return zyx_from_matrix(Rotation.from_rotvec(list(r)).as_matrix())
