"""Geometric joint-space paths q(s): piecewise polynomials in Bézier form.

A `GeometricPath` is piecewise polynomial in Bézier (Bernstein) form: lines, corner blends
(`blend`) and splines through IK samples share one representation that toppra can time and a
collision checker can sample. The path parameter s is the builder's choice: Euclidean joint-space
arc length (rad) for polylines and blends, metres of TCP travel for Cartesian lines.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BPoly, CubicSpline

from robomax_py._typing import FloatArray, IntArray
from robomax_py.spec import frozen_array
from robomax_py.timing._common import ZERO_MOVE, TimingError
from robomax_py.tolerances import DEFAULT as TOL

# Consecutive paths must meet within this (rad or m) to be joined.
PATH_JOIN_TOL = TOL.path_join_tol


@dataclass(frozen=True, slots=True, eq=False)
class GeometricPath:
    """q(s) for s in [0, length]: m polynomial pieces of degree d in Bézier form.

    breaks : (m + 1,) float
        Piece boundaries in s, breaks[0] == 0, strictly increasing.
    control_points : (m, d + 1, n) float
        Bézier control points of each piece over its own interval, rad (m for prismatic joints).
    """

    breaks: FloatArray
    control_points: FloatArray
    # The scipy polynomial that evaluates the path, built on the first evaluation and kept: a path
    # is evaluated many times (a blend's cut is found by bisection, a timing samples its grid), and
    # building the polynomial cost more than evaluating it. Derived from the two fields above only.
    _poly: BPoly | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        b = np.asarray(self.breaks, dtype=float)
        c = np.asarray(self.control_points, dtype=float)
        if b.ndim != 1 or len(b) < 2 or b[0] != 0.0 or np.any(np.diff(b) <= 0):
            raise TimingError("path breaks must start at 0 and increase strictly")
        if c.ndim != 3 or c.shape[0] != len(b) - 1 or c.shape[1] < 2 or not np.all(np.isfinite(c)):
            raise TimingError(f"control points must be finite with shape ({len(b) - 1}, d + 1, n), got {c.shape}")
        object.__setattr__(self, "breaks", frozen_array(b))
        object.__setattr__(self, "control_points", frozen_array(c))

    @property
    def length(self) -> float:
        """End value of s."""
        return float(self.breaks[-1])

    @property
    def dof(self) -> int:
        return int(self.control_points.shape[2])

    @property
    def degree(self) -> int:
        return int(self.control_points.shape[1] - 1)

    @property
    def start(self) -> FloatArray:
        """(n,) q(0)."""
        return np.asarray(self.control_points[0, 0], dtype=float)

    @property
    def end(self) -> FloatArray:
        """(n,) q(length)."""
        return np.asarray(self.control_points[-1, -1], dtype=float)

    def __call__(self, s: FloatArray | float, order: int = 0) -> FloatArray:
        """d^order q / ds^order at s, clipped into [0, length]: (n,) for a scalar s, else (..., n)."""
        s_arr = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        poly = self._poly
        if poly is None:
            poly = BPoly(np.transpose(self.control_points, (1, 0, 2)), self.breaks)
            object.__setattr__(self, "_poly", poly)
        return np.asarray(poly(s_arr, nu=order) if order else poly(s_arr))

    def sample(self, max_step: float) -> FloatArray:
        """(k, n) points q(s) on a grid in s fine enough that consecutive points are <= max_step apart.

        max_step : Euclidean joint-space distance, rad. Piece boundaries are always included.
        """
        if not (np.isfinite(max_step) and max_step > 0):
            raise TimingError(f"max_step must be > 0, got {max_step}")
        s = self.grid(max_step)
        q = self(s)
        for _ in range(30):
            gaps = np.linalg.norm(np.diff(q, axis=0), axis=1)
            if np.all(gaps <= max_step):
                return q
            split = gaps > max_step
            s = np.sort(np.concatenate([s, 0.5 * (s[:-1][split] + s[1:][split])]))
            q = self(s)
        raise TimingError("cannot sample the path finely enough (is it discontinuous?)")

    def grid(self, max_step: float) -> FloatArray:
        """(k,) values of s containing every break, with steps small enough for ~max_step motion.

        Each piece gets ceil(polygon length of its control points / max_step) equal steps; the
        polygon bounds the piece's arc length.
        """
        c = self.control_points
        polygon = np.sum(np.linalg.norm(np.diff(c, axis=1), axis=2), axis=1)
        counts = np.maximum(1, np.ceil(polygon / max_step)).astype(int)
        return piecewise_linspace(self.breaks, counts)

    def restrict(self, s0: float, s1: float) -> GeometricPath:
        """The part of the path for s in [s0, s1], re-parameterised to start at 0."""
        if not (0.0 <= s0 < s1 <= self.length):
            raise TimingError(f"cannot restrict a path of length {self.length} to [{s0}, {s1}]")
        b = self.breaks
        i0 = int(np.clip(np.searchsorted(b, s0, side="right") - 1, 0, len(b) - 2))
        i1 = int(np.clip(np.searchsorted(b, s1, side="left") - 1, 0, len(b) - 2))
        pieces: list[FloatArray] = []
        breaks = [0.0]
        for i in range(i0, i1 + 1):
            a, z = b[i], b[i + 1]
            lo, hi = max(a, s0), min(z, s1)
            if hi - lo <= 1e-12 * (z - a):                # a sliver left by rounding at a break
                continue
            P = self.control_points[i]
            if hi < z:
                P = split_bezier(P, (hi - a) / (z - a))[0]
                z = hi
            if lo > a:
                P = split_bezier(P, (lo - a) / (z - a))[1]
            pieces.append(P)
            breaks.append(breaks[-1] + (hi - lo))
        return GeometricPath(breaks=np.array(breaks), control_points=np.stack(pieces))


def piecewise_linspace(breaks: FloatArray, counts: IntArray) -> FloatArray:
    """np.linspace(breaks[i], breaks[i + 1], counts[i] + 1)[:-1] for every piece i, and the last
    break: (sum(counts) + 1,) float.

    One vector computation instead of a call per piece (a LIN line's spline has a piece per
    millimetre), with linspace's own arithmetic: the k-th value of a piece is k * step + start,
    step = (stop - start) / count, or (k / count) * (stop - start) where that step is 0 (numpy's
    denormal case), so the values are linspace's bit for bit.
    """
    b = np.asarray(breaks, dtype=float)
    n = np.asarray(counts, dtype=np.int64)
    start, delta = b[:-1], b[1:] - b[:-1]
    step = delta / n
    piece = np.repeat(np.arange(len(n)), n)
    k = (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)).astype(float)
    values = k * step[piece]
    zero = step[piece] == 0
    if np.any(zero):
        values[zero] = k[zero] / n[piece][zero] * delta[piece][zero]
    values += start[piece]
    return np.concatenate([values, b[-1:]])


def line_path(q0: FloatArray, q1: FloatArray) -> GeometricPath:
    """The straight segment q0 -> q1 parameterised by Euclidean joint-space arc length."""
    return polyline_path(np.stack([np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)]))


def polyline_path(waypoints: FloatArray) -> GeometricPath:
    """Straight pieces through (m, n) waypoints, s = cumulative Euclidean arc length (rad).

    Repeated waypoints are dropped; at least two distinct ones are needed.
    """
    w = distinct_waypoints(waypoints)
    lengths = np.linalg.norm(np.diff(w, axis=0), axis=1)
    control = np.stack([w[:-1], w[1:]], axis=1)
    return GeometricPath(breaks=np.concatenate([[0.0], np.cumsum(lengths)]), control_points=control)


def spline_path(s: FloatArray, q: FloatArray) -> GeometricPath:
    """The C2 cubic spline through samples q (k, n) at parameters s (k,), not-a-knot ends (k >= 2)."""
    s = np.asarray(s, dtype=float)
    q = np.asarray(q, dtype=float)
    if len(s) == 2:
        return GeometricPath(breaks=s - s[0], control_points=q[None])
    spline = CubicSpline(s - s[0], q, axis=0, bc_type="not-a-knot")
    bern = BPoly.from_power_basis(spline)
    return GeometricPath(breaks=np.asarray(bern.x), control_points=np.transpose(np.asarray(bern.c), (1, 0, 2)))


def concatenate_paths(paths: Sequence[GeometricPath]) -> GeometricPath:
    """Paths end to end (each must start where the previous ends); degrees raised to the highest.

    The result is only C0 where the pieces meet unless the inputs match there; `time_path` stops at
    joins where the tangent jumps.
    """
    if not paths:
        raise TimingError("cannot concatenate an empty list of paths")
    degree = max(p.degree for p in paths)
    pieces: list[FloatArray] = []
    breaks = [0.0]
    for k, p in enumerate(paths):
        if k and float(np.max(np.abs(p.start - paths[k - 1].end))) > PATH_JOIN_TOL:
            raise TimingError(f"path {k} does not start where path {k - 1} ends")
        pieces.append(elevate(p.control_points, degree))         # every piece of the path at once
        breaks.extend(breaks[-1] + p.breaks[1:])
    return GeometricPath(breaks=np.array(breaks), control_points=np.concatenate(pieces))


def kinks(path: GeometricPath, rtol: float = 1e-6) -> FloatArray:
    """(k,) interior breaks where dq/ds jumps (by more than rtol of its size): the path's corners."""
    c = path.control_points
    d = path.degree
    h = np.diff(path.breaks)
    left = d * (c[:-1, -1] - c[:-1, -2]) / h[:-1, None]
    right = d * (c[1:, 1] - c[1:, 0]) / h[1:, None]
    jump = np.linalg.norm(left - right, axis=1)
    size = np.maximum(np.linalg.norm(left, axis=1), np.linalg.norm(right, axis=1))
    return np.asarray(path.breaks[1:-1][jump > rtol * np.maximum(size, 1e-300)], dtype=float)


def distinct_waypoints(waypoints: FloatArray) -> FloatArray:
    w = np.asarray(waypoints, dtype=float)
    if w.ndim != 2 or not np.all(np.isfinite(w)):
        raise TimingError(f"waypoints must be a finite (m, n) array, got shape {w.shape}")
    keep = np.concatenate([[True], np.linalg.norm(np.diff(w, axis=0), axis=1) > ZERO_MOVE])
    w = w[keep]
    if len(w) < 2:
        raise TimingError("a path needs at least two distinct waypoints")
    return np.asarray(w, dtype=float)


def elevate(P: FloatArray, degree: int) -> FloatArray:
    """Bézier control points (..., d + 1, n) of the same curves written with the given degree >= d
    (a stack of curves is elevated at once, each as on its own)."""
    P = np.asarray(P, dtype=float)
    while P.shape[-2] - 1 < degree:
        d = P.shape[-2] - 1
        k = np.arange(1, d + 1)[:, None] / (d + 1)
        P = np.concatenate([P[..., :1, :], k * P[..., :-1, :] + (1 - k) * P[..., 1:, :], P[..., -1:, :]], axis=-2)
    return P


def split_bezier(P: FloatArray, tau: float) -> tuple[FloatArray, FloatArray]:
    """de Casteljau: control points of the curve on [0, tau] and [tau, 1] (local parameter)."""
    rows = [np.asarray(P, dtype=float)]
    while len(rows[-1]) > 1:
        prev = rows[-1]
        rows.append((1 - tau) * prev[:-1] + tau * prev[1:])
    left = np.stack([r[0] for r in rows])
    right = np.stack([r[-1] for r in rows[::-1]])
    return left, right

