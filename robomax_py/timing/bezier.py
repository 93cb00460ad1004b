"""Planar paths of quintic Bézier curves joined with continuous curvature, and their minimum-time
speed profile under TCP limits (`spec.TcpLimits`: v, a_T, a_R, j_T, j_R), after Benko Loknar,
Klančar and Blažič (minimum-time Bézier trajectories for warehouse vehicles).

Path. Segment i runs from waypoint P_i to P_(i+1) over u in [0, 1]. Every waypoint has a tangent
T_i (heading theta_i, length d_i) and a second derivative A_i = c_i n_i (n_i the left normal of
T_i), which both segments meeting there take as their end derivatives: b1 = b0 + T/5,
b2 = b0 + 2T/5 + A/20 at the start, mirrored at the end. The curves therefore join C2 in u, so
the unit tangent and the curvature are continuous (G2). The free parameters are, at interior
waypoints, theta_i, d_i, c_i; at the ends d_0 and d_m (the headings there are given: pick-up and
drop-off poses).

Profile. On an arclength grid, b = v^2 is chosen to minimise the travel time sum(2 ds / (v_i +
v_(i+1))) with v = 0 at both ends, v <= v_max, kappa v^2 <= a_R, |dv/dt| <= a_T, and the rates of
change of the tangential and radial accelerations (d a_T/dt, d(kappa v^2)/dt) within j_T and j_R
(SLSQP). Limits hold at the grid's points; `profile_peaks` measures them on a 4x finer resampling.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import minimize

from robomax_py._typing import FloatArray
from robomax_py.spec import TcpLimits

# Samples per curve for arclength and curvature tables.
TABLE_SAMPLES = 400
# The profile's limits are imposed at this many points per interval of its grid.
CONSTRAINT_REFINE = 4


@dataclass(frozen=True, slots=True)
class BezierPath:
    """Quintic segments, (m, 6, 2) control points."""

    control: FloatArray

    @classmethod
    def through(cls, waypoints: FloatArray, headings: FloatArray, lengths: FloatArray, normals: FloatArray) -> BezierPath:
        """The G2 path through `waypoints` (m+1, 2) with, per waypoint, the tangent's heading (rad)
        and length (m) and the second derivative's normal component c_i (m)."""
        P = np.asarray(waypoints, dtype=float)
        T = np.asarray(lengths, dtype=float)[:, None] * np.column_stack([np.cos(headings), np.sin(headings)])
        N = np.column_stack([-np.sin(headings), np.cos(headings)])
        A = np.asarray(normals, dtype=float)[:, None] * N
        b0, b5 = P[:-1], P[1:]
        b1 = b0 + T[:-1] / 5.0
        b2 = b0 + 2.0 * T[:-1] / 5.0 + A[:-1] / 20.0
        b4 = b5 - T[1:] / 5.0
        b3 = b5 - 2.0 * T[1:] / 5.0 + A[1:] / 20.0
        return cls(np.stack([b0, b1, b2, b3, b4, b5], axis=1))

    @property
    def segments(self) -> int:
        return len(self.control)

    def derivatives(self, i: int, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Position, first and second derivative in u of segment i at u (k,): each (k, 2)."""
        u = np.asarray(u, dtype=float)[:, None]
        b = self.control[i]
        w = 1.0 - u
        pos = (w**5 * b[0] + 5 * u * w**4 * b[1] + 10 * u**2 * w**3 * b[2] + 10 * u**3 * w**2 * b[3]
               + 5 * u**4 * w * b[4] + u**5 * b[5])
        d = 5.0 * (b[1:] - b[:-1])                       # quartic hodograph
        d1 = w**4 * d[0] + 4 * u * w**3 * d[1] + 6 * u**2 * w**2 * d[2] + 4 * u**3 * w * d[3] + u**4 * d[4]
        dd = 4.0 * (d[1:] - d[:-1])
        d2 = w**3 * dd[0] + 3 * u * w**2 * dd[1] + 3 * u**2 * w * dd[2] + u**3 * dd[3]
        return pos, d1, d2

    def segment_table(self, i: int, samples: int = TABLE_SAMPLES) -> tuple[FloatArray, FloatArray]:
        """Points (samples + 1, 2) of segment i evenly spaced in u, and the signed curvature there."""
        p, d1, d2 = self.derivatives(i, np.linspace(0.0, 1.0, samples + 1))
        speed = np.linalg.norm(d1, axis=1)
        return p, (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.maximum(speed, 1e-12) ** 3

    def table(self, per_segment: int = TABLE_SAMPLES) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Along the whole path: arclength s (k,), points (k, 2) and signed curvature (k,)."""
        pts, kap = [], []
        for i in range(self.segments):
            p, kappa = self.segment_table(i, per_segment)
            first = 1 if i else 0                  # a segment's start is the end of the one before
            pts.append(p[first:])
            kap.append(kappa[first:])
        points = np.vstack(pts)
        return arclength(points), points, np.concatenate(kap)


def arclength(points: FloatArray) -> FloatArray:
    """Cumulative length (k,) of a polyline (k, d), from 0."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def default_parameters(waypoints: FloatArray) -> FloatArray:
    """Initial free parameters: interior headings along the neighbours' chord, tangent lengths the
    shorter adjacent chord, no normal second derivative. Layout: [d_0, (theta, d, c) per interior
    waypoint, d_m]."""
    P = np.asarray(waypoints, dtype=float)
    chords = np.linalg.norm(np.diff(P, axis=0), axis=1)
    out = [chords[0]]
    for i in range(1, len(P) - 1):
        v = P[i + 1] - P[i - 1]
        out += [math.atan2(v[1], v[0]), min(chords[i - 1], chords[i]), 0.0]
    out.append(chords[-1])
    return np.array(out)


def path_of(waypoints: FloatArray, start_heading: float, end_heading: float, params: FloatArray) -> BezierPath:
    """The path of a parameter vector (see `default_parameters`); lengths are kept positive."""
    m = len(waypoints) - 1
    inner = np.asarray(params[1:-1], dtype=float).reshape(m - 1, 3)
    headings = np.concatenate([[start_heading], inner[:, 0], [end_heading]])
    lengths = np.abs(np.concatenate([[params[0]], inner[:, 1], [params[-1]]])) + 1e-6
    normals = np.concatenate([[0.0], inner[:, 2], [0.0]])
    return BezierPath.through(waypoints, headings, lengths, normals)


@dataclass(frozen=True, slots=True)
class Profile:
    """A speed profile along a path: arclength s (k,) m, speed v (k,) m/s, time t (k,) s."""

    s: FloatArray
    v: FloatArray
    t: FloatArray
    points: FloatArray            # (k, 2)

    @property
    def duration(self) -> float:
        return float(self.t[-1])


def _curvature_table(path: BezierPath) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The path's dense table: arclength, points, curvature and its derivative in arclength."""
    s_tab, p_tab, k_tab = path.table()
    return s_tab, p_tab, k_tab, np.gradient(k_tab, s_tab)


def _grid(path: BezierPath, n: int) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """n points evenly spaced in arclength, with the largest |kappa| and |d kappa/ds| of the dense
    table within half a spacing of each (a tight bend between points is not missed)."""
    s_tab, p_tab, k_tab, dk_tab = _curvature_table(path)
    s = np.linspace(0.0, s_tab[-1], n)
    points = np.column_stack([np.interp(s, s_tab, p_tab[:, j]) for j in range(2)])
    cell = np.clip(np.rint(s_tab / (s[1] - s[0])).astype(int), 0, n - 1)
    kappa = np.zeros(n)
    dkappa = np.zeros(n)
    np.maximum.at(kappa, cell, np.abs(k_tab))
    np.maximum.at(dkappa, cell, np.abs(dk_tab))
    return s, points, kappa, dkappa


def _times(s: FloatArray, v: FloatArray) -> FloatArray:
    ds = np.diff(s)
    return np.concatenate([[0.0], np.cumsum(2.0 * ds / np.maximum(v[:-1] + v[1:], 1e-9))])


def acceleration_limited(path: BezierPath, limits: TcpLimits, n: int = 400) -> Profile:
    """The minimum-time profile under v, a_T and a_R (forward and backward passes), its speed also
    capped where the curvature changes so fast that j_R would be broken at constant speed: the
    travel-time proxy the path's parameters are optimised with."""
    s, points, kappa, dkappa = _grid(path, n)
    ds = s[1] - s[0]
    # Speed caps: v, a_R = kappa v^2, and j_R = kappa' v^3 at a constant speed.
    cap = np.minimum.reduce([np.full(n, limits.v), np.sqrt(limits.a_R / np.maximum(kappa, 1e-12)),
                             np.cbrt(limits.j_R / np.maximum(dkappa, 1e-12))])
    cap[0] = cap[-1] = 0.0
    v = cap.copy()
    for i in range(1, n):
        v[i] = min(v[i], math.sqrt(v[i - 1] ** 2 + 2 * limits.a_T * ds))
    for i in range(n - 2, -1, -1):
        v[i] = min(v[i], math.sqrt(v[i + 1] ** 2 + 2 * limits.a_T * ds))
    return Profile(s, v, _times(s, v), points)


def _kinematics(s_grid: FloatArray, b_grid: FloatArray, s: FloatArray, kappa: FloatArray, dkappa: FloatArray
                ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """v, a_T, a_R, j_T, j_R at arclengths s of the profile whose b = v^2 is the clamped cubic spline
    (zero slope, so zero a_T, at both ends) through (s_grid, b_grid); kappa and d kappa/ds at s."""
    spline = CubicSpline(s_grid, b_grid, bc_type="clamped")
    b = np.maximum(spline(s), 0.0)
    v = np.sqrt(b)
    a_t = spline(s, 1) / 2.0                   # dv/dt = (d b/ds) / 2
    j_t = spline(s, 2) / 2.0 * v               # d a_T/dt = (d a_T/ds) v
    a_r = kappa * b
    j_r = (dkappa * b + kappa * spline(s, 1)) * v    # d(kappa b)/dt
    return v, a_t, a_r, j_t, j_r


def _curvature_at(path: BezierPath, s: FloatArray) -> tuple[FloatArray, FloatArray]:
    s_tab, _, k_tab, dk_tab = _curvature_table(path)
    return np.interp(s, s_tab, k_tab), np.interp(s, s_tab, dk_tab)


def jerk_limited(path: BezierPath, limits: TcpLimits, n: int = 100) -> Profile:
    """The minimum-time profile under all five limits: b = v^2 at n grid points (a clamped cubic
    spline between them) chosen by SLSQP, the limits imposed on a grid CONSTRAINT_REFINE times as fine."""
    s, points, kappa, _ = _grid(path, n)
    fine = np.linspace(0.0, s[-1], CONSTRAINT_REFINE * (n - 1) + 1)
    k_fine, dk_fine = _curvature_at(path, fine)
    cap = np.minimum(limits.v**2, limits.a_R / np.maximum(kappa, 1e-12))
    # Start well inside the jerk limits: the acceleration-limited profile, slowed.
    b0 = (0.5 * acceleration_limited(path, limits, n).v) ** 2
    inner = slice(1, n - 1)

    def full(x: FloatArray) -> FloatArray:
        return np.concatenate([[0.0], x, [0.0]])

    def time(x: FloatArray) -> float:
        return float(_times(s, np.sqrt(np.maximum(full(x), 0.0)))[-1])

    def constraints(x: FloatArray) -> FloatArray:
        v, a_t, a_r, j_t, j_r = _kinematics(s, full(x), fine, k_fine, dk_fine)
        return np.concatenate([limits.v - v, limits.a_T - np.abs(a_t), limits.a_R - np.abs(a_r),
                               limits.j_T - np.abs(j_t), limits.j_R - np.abs(j_r)])

    bounds = [(0.0, float(c)) for c in cap[inner]]
    res = minimize(time, b0[inner], method="SLSQP", bounds=bounds,
                   constraints=[{"type": "ineq", "fun": constraints}], options={"maxiter": 300, "ftol": 1e-10})
    b = np.clip(full(res.x), 0.0, None)
    # A solver end slightly outside a limit is pulled back: speeds scaled until every limit holds.
    for _ in range(200):
        if constraints(b[inner]).min() >= 0.0:
            break
        b *= 0.99
    v = np.sqrt(b)
    return Profile(s, v, _times(s, v), points)


@dataclass(frozen=True, slots=True)
class PathPeaks:
    v: float
    a_T: float
    a_R: float
    j_T: float
    j_R: float


def profile_peaks(profile: Profile, path: BezierPath, refine: int = 8) -> PathPeaks:
    """The largest speed, accelerations and their rates over the profile on a `refine` times finer
    arclength grid than its own (the profile's clamped spline of v^2 between its points)."""
    s = np.linspace(0.0, profile.s[-1], (len(profile.s) - 1) * refine + 1)
    v, a_t, a_r, j_t, j_r = _kinematics(profile.s, profile.v**2, s, *_curvature_at(path, s))
    return PathPeaks(*(float(np.abs(x).max()) for x in (v, a_t, a_r, j_t, j_r)))


def optimise_path(waypoints: FloatArray, start_heading: float, end_heading: float, limits: TcpLimits,
                  iterations: int = 400) -> tuple[FloatArray, BezierPath]:
    """The free parameters minimising the acceleration-limited travel time under `limits`
    (Nelder-Mead from `default_parameters`), and their path."""
    x0 = default_parameters(waypoints)

    def cost(x: FloatArray) -> float:
        return acceleration_limited(path_of(waypoints, start_heading, end_heading, x), limits, 200).duration

    res = minimize(cost, x0, method="Nelder-Mead", options={"maxiter": iterations, "xatol": 1e-4, "fatol": 1e-5})
    return res.x, path_of(waypoints, start_heading, end_heading, res.x)
