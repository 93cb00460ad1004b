"""A planar motion measured against the paper's constraint set from its positions alone: speed,
tangential and normal acceleration and jerk (Benko Loknar et al., eqs. 1 and 2) by finite
differences of points sampled at evenly spaced times, so the check shares nothing with how a
profile was made (no curvature, no formula (7)).

Central differences: velocity (r+ - r-)/2dt, acceleration (r+ - 2r + r-)/dt^2, jerk
(r++ - 2r+ + 2r- - r--)/2dt^3. Each is a weighted mean with non-negative weights of the true
derivative over the stencil (a B-spline kernel), so a sampled peak never exceeds the true one by
more than the frame's turn over the stencil (kappa v 2dt). The tangent is the direction of the
central chord; before the first and after the last sample the motion is at rest where it started
and ended, so the stencils there see the start from rest and the stop.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.spec import TcpLimits

DEFAULT_DT_S = 0.005
# Where the sampled chord is shorter than this (m), the motion is at rest and has no direction.
REST_CHORD_M = 1e-12


@dataclass(frozen=True, slots=True)
class FrenetSeries:
    """Per sample (k,): speed (m/s), tangential and normal acceleration (m/s^2) and jerk (m/s^3)."""

    t: FloatArray
    v: FloatArray
    a_T: FloatArray
    a_R: FloatArray
    j_T: FloatArray
    j_R: FloatArray


@dataclass(frozen=True, slots=True)
class ConstraintPeaks:
    """The largest |value| of each quantity, and the largest left-hand sides of the acceleration
    and jerk ellipses (2b, 2c) (<= 1 where they hold)."""

    v: float
    a_T: float
    a_R: float
    j_T: float
    j_R: float
    accel_ellipse: float
    jerk_ellipse: float

    def within(self, limits: TcpLimits, rtol: float) -> bool:
        """Every constraint (2a-2c) and each component on its own, within rtol."""
        return (self.v <= limits.v * (1 + rtol) and self.a_T <= limits.a_T * (1 + rtol)
                and self.a_R <= limits.a_R * (1 + rtol) and self.j_T <= limits.j_T * (1 + rtol)
                and self.j_R <= limits.j_R * (1 + rtol) and self.accel_ellipse <= 1 + rtol
                and self.jerk_ellipse <= 1 + rtol)


def frenet_series(t: FloatArray, points: FloatArray) -> FrenetSeries:
    """The Frenet components of a motion given by points (k, 2) m at evenly spaced times t (k,) s,
    at rest before the first and after the last sample."""
    t = np.asarray(t, dtype=float)
    r = np.asarray(points, dtype=float)
    dt = float(t[1] - t[0])
    padded = np.concatenate([np.repeat(r[:1], 2, axis=0), r, np.repeat(r[-1:], 2, axis=0)])
    rmm, rm, r0, rp, rpp = (padded[i:i + len(r)] for i in range(5))
    vel = (rp - rm) / (2 * dt)
    acc = (rp - 2 * r0 + rm) / dt**2
    jerk = (rpp - 2 * rp + 2 * rm - rmm) / (2 * dt**3)
    chord = rp - rm
    wide = rpp - rmm
    length = np.linalg.norm(chord, axis=1)
    use_wide = length <= REST_CHORD_M
    chord = np.where(use_wide[:, None], wide, chord)
    length = np.linalg.norm(chord, axis=1)
    tangent = chord / np.maximum(length, REST_CHORD_M)[:, None]
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])

    def along(x: FloatArray, u: FloatArray) -> FloatArray:
        return np.asarray(np.einsum("ij,ij->i", x, u), dtype=float)

    return FrenetSeries(t, np.linalg.norm(vel, axis=1), along(acc, tangent), along(acc, normal),
                        along(jerk, tangent), along(jerk, normal))


def peaks(series: FrenetSeries, limits: TcpLimits) -> ConstraintPeaks:
    """The largest values of a series and of the ellipses' left-hand sides under `limits`."""
    acc = (series.a_T / limits.a_T) ** 2 + (series.a_R / limits.a_R) ** 2
    jerk = (series.j_T / limits.j_T) ** 2 + (series.j_R / limits.j_R) ** 2
    def top(x: FloatArray) -> float:
        return float(np.max(np.abs(x)))

    return ConstraintPeaks(top(series.v), top(series.a_T), top(series.a_R), top(series.j_T), top(series.j_R),
                           float(acc.max()), float(jerk.max()))
