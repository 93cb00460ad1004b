"""AS's O, A, T angles (deg, R = Rz(O)·Ry(A)·Rz(T)) and robomax's ZYX angles (Rz·Ry·Rx), both
ways, rounded as a program writes them (the package's docstring gives the sources)."""

from __future__ import annotations

import math

import numpy as np

from robomax_py._typing import FloatArray

ANGLE_DECIMALS = 5


def _rz(a: float) -> FloatArray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(a: float) -> FloatArray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rx(a: float) -> FloatArray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def matrix_from_oat(oat_deg: tuple[float, ...]) -> FloatArray:
    """(3, 3) rotation of AS's O, A, T (deg): Rz(O)·Ry(A)·Rz(T)."""
    o, a, t = (math.radians(v) for v in oat_deg)
    out: FloatArray = _rz(o) @ _ry(a) @ _rz(t)
    return out


def oat_from_matrix(R: FloatArray) -> tuple[float, float, float]:
    """Inverse of `matrix_from_oat`: A in [0, 180] deg; at A = 0 or 180 the whole turn is on O."""
    R = np.asarray(R, dtype=float)
    sin_a = math.hypot(R[0, 2], R[1, 2])
    a = math.atan2(sin_a, R[2, 2])
    if sin_a < 1e-12:
        o = math.atan2(R[1, 0], R[0, 0]) if R[2, 2] > 0 else math.atan2(-R[1, 0], -R[0, 0])
        return math.degrees(o), math.degrees(a), 0.0
    o = math.atan2(R[1, 2], R[0, 2])
    t = math.atan2(R[2, 1], -R[2, 0])
    return math.degrees(o), math.degrees(a), math.degrees(t)


def _zyx_matrix(zyx_deg: tuple[float, ...]) -> FloatArray:
    a, b, c = (math.radians(v) for v in zyx_deg)
    out: FloatArray = _rz(a) @ _ry(b) @ _rx(c)
    return out


def oat_from_zyx(zyx_deg: tuple[float, ...]) -> tuple[float, ...]:
    """robomax's ZYX angles (A, B, C: Rz·Ry·Rx) as AS's O, A, T, rounded as the program writes them."""
    return tuple(round(v, ANGLE_DECIMALS) + 0.0 for v in oat_from_matrix(_zyx_matrix(zyx_deg)))


def zyx_from_oat(oat_deg: tuple[float, ...]) -> tuple[float, float, float]:
    """AS's O, A, T as robomax's ZYX angles (deg)."""
    R = matrix_from_oat(oat_deg)
    b = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    if math.hypot(R[0, 0], R[1, 0]) < 1e-12:
        return math.degrees(math.atan2(-R[0, 1], R[1, 1])), math.degrees(b), 0.0
    return math.degrees(math.atan2(R[1, 0], R[0, 0])), math.degrees(b), math.degrees(math.atan2(R[2, 1], R[2, 2]))
