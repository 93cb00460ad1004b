"""The TCP's path motion from sampled joint motion: speed, tangential and radial acceleration, for
the TCP limits of a carried part (`spec.TcpLimits`; its jerks are not checked on arm motions).

Finite differences of the TCP positions on the samples' own clock (a trajectory file's samples are
at most 10 ms apart): v = |p'|, a_T = p''·t̂ (t̂ = p'/|p'|), a_R = |p'' - a_T t̂|. Below `REST_SPEED_M_S` the direction of motion is undefined: all acceleration counts
as tangential there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray

REST_SPEED_M_S = 1e-3


@dataclass(frozen=True, slots=True)
class TcpPeaks:
    """The largest value of each quantity over a motion, and the time it is reached (s)."""

    v: tuple[float, float]
    a_T: tuple[float, float]
    a_R: tuple[float, float]


def tcp_series(t: FloatArray, p: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Per sample: TCP speed (m/s), tangential and radial acceleration (m/s^2); t (k,) s, p (k, 3) m."""
    t = np.asarray(t, dtype=float)
    p = np.asarray(p, dtype=float)
    if len(t) < 3:
        return np.zeros(len(t)), np.zeros(len(t)), np.zeros(len(t))
    v = np.gradient(p, t, axis=0)
    a = np.gradient(v, t, axis=0)
    speed = np.linalg.norm(v, axis=1)
    moving = speed > REST_SPEED_M_S
    tangent = np.where(moving[:, None], v / np.maximum(speed, REST_SPEED_M_S)[:, None], 0.0)
    a_t = np.where(moving, np.einsum("ij,ij->i", a, tangent), np.linalg.norm(a, axis=1))
    a_r = np.where(moving, np.linalg.norm(a - a_t[:, None] * tangent, axis=1), 0.0)
    return speed, a_t, a_r


def tcp_peaks(t: FloatArray, p: FloatArray) -> TcpPeaks:
    """Peaks of the TCP's path motion; t (k,) s, p (k, 3) TCP positions, m."""
    t = np.asarray(t, dtype=float)
    if len(t) < 3:
        zero = (0.0, float(t[0]) if len(t) else 0.0)
        return TcpPeaks(zero, zero, zero)

    def peak(x: FloatArray) -> tuple[float, float]:
        i = int(np.argmax(np.abs(x)))
        return float(np.abs(x[i])), float(t[i])

    speed, a_t, a_r = tcp_series(t, p)
    return TcpPeaks(peak(speed), peak(a_t), peak(a_r))
