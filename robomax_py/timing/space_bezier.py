"""A smooth TCP path in space through key poses: quintic Bézier segments joined G2, and the short
straight lines a controller follows it by.

Path. Segment i runs from key point P_i to P_(i+1) over u in [0, 1] with the quintic Hermite form
of the paper's joins (Benko Loknar, Klančar and Blažič, `timing.bezier`): b1 = b0 + T/5,
b2 = b0 + 2T/5 + A/20 at the start, mirrored at the end, with T the tangent and A the second
derivative there. Here A = 0 at every key point, so the curvature is zero there on both sides
and the joins are G2 whatever the tangent lengths; each segment's tangents are as long as its
chord. The tangent at a key point is given where a straight line must be continued (the
electrode axis at an approach point) and is the Catmull-Rom direction P_(i+1) - P_(i-1) elsewhere.
A segment whose two end tangents are its chord's direction is that straight line, so the
approach and retract along the electrode axis stay exactly straight. The paper constructs its
planar curves in seven steps with the curvature free at the joins; in space we keep its joins
and the quintic form but not the planar construction.

Orientation. Between key poses the TCP orientation turns by slerp in proportion to the arclength
travelled within the segment, as a LIN move turns it in proportion to its travel.

Lines. `sample_lines` places the ends of short straight lines on the path: every key point, and
in between as far apart as the curvature allows for the chord's sagitta c^2 kappa / 8 to stay
within a tolerance. A controller flying by each end with a TCP distance below half the shorter
neighbouring chord (`flyby_radius`) stays within about that tolerance of the path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from robomax_py._typing import FloatArray
from robomax_py.spec import frozen_array
from robomax_py.timing._common import TimingError

# Samples per segment for the arclength and curvature tables.
TABLE_SAMPLES = 400
# Key points closer than this (m) are one point.
MIN_CHORD_M = 1e-4


@dataclass(frozen=True, slots=True, eq=False)
class SpacePath:
    """Quintic segments in space: control (m, 6, 3) m; rotations (m + 1, 3, 3) at the key points;
    per segment the tables u (TABLE_SAMPLES + 1,), arclength s from the path's start and
    curvature kappa (1/m) at those u."""

    control: FloatArray
    rotations: FloatArray
    u: FloatArray
    s: FloatArray
    kappa: FloatArray

    @property
    def length(self) -> float:
        return float(self.s[-1, -1])

    @property
    def key_s(self) -> FloatArray:
        """(m + 1,) arclength of each key point."""
        return np.concatenate([[0.0], self.s[:, -1]])

    def points(self, s: FloatArray) -> FloatArray:
        """(k, 3) positions at arclengths s (k,), m (u by linear interpolation of the tables)."""
        seg, u = self._locate(s)
        out = np.zeros((len(seg), 3))
        for i in np.unique(seg):
            sel = seg == i
            out[sel] = _bezier(self.control[i], u[sel])
        return out

    def poses(self, s: FloatArray) -> FloatArray:
        """(k, 4, 4) TCP poses at arclengths s (k,)."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        seg, _ = self._locate(s)
        keys = self.key_s
        T = np.repeat(np.eye(4)[None], len(s), axis=0)
        T[:, :3, 3] = self.points(s)
        for i in np.unique(seg):
            sel = seg == i
            span = keys[i + 1] - keys[i]
            frac = np.clip((s[sel] - keys[i]) / span, 0.0, 1.0) if span > 0 else np.zeros(int(sel.sum()))
            slerp = Slerp([0.0, 1.0], Rotation.from_matrix(self.rotations[i:i + 2]))
            T[sel, :3, :3] = slerp(frac).as_matrix()
        return T

    def curvature(self, s: FloatArray) -> FloatArray:
        """(k,) curvature at arclengths s (k,), 1/m."""
        seg, u = self._locate(s)
        out = np.zeros(len(seg))
        for i in np.unique(seg):
            sel = seg == i
            out[sel] = np.interp(u[sel], self.u, self.kappa[i])
        return out

    def _locate(self, s: FloatArray) -> tuple[np.ndarray, FloatArray]:
        s = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), 0.0, self.length)
        keys = self.key_s
        seg = np.clip(np.searchsorted(keys, s, side="right") - 1, 0, len(self.control) - 1)
        u = np.zeros(len(s))
        for i in np.unique(seg):
            sel = seg == i
            u[sel] = np.interp(s[sel], self.s[i], self.u)
        return seg, u


def _bezier(control: FloatArray, u: FloatArray) -> FloatArray:
    """(k, d) points of one quintic at u (k,) (Bernstein form)."""
    u = np.asarray(u, dtype=float)[:, None]
    w = 1.0 - u
    coeff = [w**5, 5 * u * w**4, 10 * u**2 * w**3, 10 * u**3 * w**2, 5 * u**4 * w, u**5]
    return np.asarray(sum(c * control[k] for k, c in enumerate(coeff)), dtype=float)


def _derivatives(control: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray]:
    """First and second derivatives (k, d) in u of one quintic at u (k,)."""
    d1 = 5.0 * np.diff(control, axis=0)
    d2 = 4.0 * np.diff(d1, axis=0)
    u = np.asarray(u, dtype=float)[:, None]
    w = 1.0 - u
    r1 = w**4 * d1[0] + 4 * u * w**3 * d1[1] + 6 * u**2 * w**2 * d1[2] + 4 * u**3 * w * d1[3] + u**4 * d1[4]
    r2 = w**3 * d2[0] + 3 * u * w**2 * d2[1] + 3 * u**2 * w * d2[2] + u**3 * d2[3]
    return np.asarray(r1, dtype=float), np.asarray(r2, dtype=float)


def _unit(v: FloatArray) -> FloatArray:
    n = float(np.linalg.norm(v))
    if n <= 0.0:
        raise TimingError("a tangent of zero length")
    return np.asarray(v, dtype=float) / n


def space_path(poses: FloatArray, start_tangent: FloatArray | None = None,
               end_tangent: FloatArray | None = None, straight_ends: bool = False) -> SpacePath:
    """The G2 quintic path through the key poses (k, 4, 4) (positions and orientations).

    start_tangent, end_tangent : (3,) directions at the first and last key point (None: the first
        and last chord's). straight_ends : the first and last segments are straight lines (their
        inner key point takes the line's direction as its tangent): approach and retract.
    """
    T = np.asarray(poses, dtype=float)
    P = T[:, :3, 3]
    keep = [0]
    for i in range(1, len(P)):
        if float(np.linalg.norm(P[i] - P[keep[-1]])) > MIN_CHORD_M:
            keep.append(i)
    if len(keep) < 2:
        raise TimingError("a spline needs two key points apart")
    if keep[-1] != len(P) - 1:
        keep[-1] = len(P) - 1
    T, P = T[keep], P[keep]
    m = len(P) - 1
    chords = np.diff(P, axis=0)
    tangents = np.zeros((m + 1, 3))
    tangents[0] = _unit(chords[0] if start_tangent is None else start_tangent)
    tangents[m] = _unit(chords[-1] if end_tangent is None else end_tangent)
    for i in range(1, m):
        tangents[i] = _unit(P[i + 1] - P[i - 1])
    if straight_ends and m >= 2:
        tangents[0] = tangents[1] = _unit(chords[0])
        tangents[m] = tangents[m - 1] = _unit(chords[-1])
    control = np.zeros((m, 6, 3))
    lam = np.linspace(0.0, 1.0, TABLE_SAMPLES + 1)
    s_tab = np.zeros((m, len(lam)))
    k_tab = np.zeros((m, len(lam)))
    s0 = 0.0
    for i in range(m):
        L = float(np.linalg.norm(chords[i]))
        t0, t1 = L * tangents[i], L * tangents[i + 1]
        control[i] = [P[i], P[i] + t0 / 5, P[i] + 2 * t0 / 5, P[i + 1] - 2 * t1 / 5, P[i + 1] - t1 / 5, P[i + 1]]
        r1, r2 = _derivatives(control[i], lam)
        speed = np.linalg.norm(r1, axis=1)
        # Arclength by the trapezoid rule on the table (TABLE_SAMPLES intervals: ~1e-6 relative).
        s_tab[i] = s0 + np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(lam))])
        k_tab[i] = np.linalg.norm(np.cross(r1, r2), axis=1) / np.maximum(speed, 1e-12) ** 3
        s0 = float(s_tab[i, -1])
    return SpacePath(frozen_array(control), frozen_array(T[:, :3, :3].copy()), frozen_array(lam),
                     frozen_array(s_tab), frozen_array(k_tab))


@dataclass(frozen=True, slots=True, eq=False)
class LineSamples:
    """Where the short lines following a path end: arclengths s (k + 1,) from 0 to the path's
    length, and the poses there (k + 1, 4, 4)."""

    s: FloatArray
    poses: FloatArray

    @property
    def chords(self) -> FloatArray:
        """(k,) straight distance between consecutive ends, m."""
        return np.asarray(np.linalg.norm(np.diff(self.poses[:, :3, 3], axis=0), axis=1), dtype=float)


def sample_lines(path: SpacePath, tol: float, max_chord: float, min_chord: float) -> LineSamples:
    """Line ends on `path`: every key point, and in between spaced so that the chord's sagitta
    c^2 kappa_max / 8 stays within tol (m), kappa_max the largest curvature over the chord's
    stretch; chords between min_chord and max_chord (m), a segment's chords all alike."""
    out = [0.0]
    keys = path.key_s
    for i in range(len(path.control)):
        a, b = float(keys[i]), float(keys[i + 1])
        kmax = float(np.max(path.kappa[i]))
        chord = max_chord if kmax <= 0 else min(max_chord, math.sqrt(8.0 * tol / kmax))
        chord = max(chord, min_chord)
        n = max(1, int(math.ceil((b - a) / chord - 1e-9)))
        out.extend(np.linspace(a, b, n + 1)[1:].tolist())
    s = np.array(out)
    return LineSamples(frozen_array(s), frozen_array(path.poses(s)))


def flyby_radius(chords: FloatArray, fraction: float) -> FloatArray:
    """(k - 1,) TCP fly-by distance (m) at each interior line end: `fraction` (< 0.5) of the
    shorter of the two chords meeting there, so neighbouring blends never overlap."""
    c = np.asarray(chords, dtype=float)
    return np.asarray(fraction * np.minimum(c[:-1], c[1:]), dtype=float)


def deviation(path: SpacePath, points: FloatArray, samples: int = 4000) -> float:
    """Largest distance (m) from any of `points` (k, 3) to the path: to the polyline through
    `samples` points of it (off the curve by its chords' sagitta, ~1e-8 m here)."""
    ref = path.points(np.linspace(0.0, path.length, samples))
    a, d = ref[:-1], np.diff(ref, axis=0)
    dd = np.maximum(np.einsum("ij,ij->i", d, d), 1e-30)
    best = []
    for p in np.asarray(points, dtype=float):
        u = np.clip(np.einsum("ij,ij->i", p - a, d) / dd, 0.0, 1.0)
        best.append(float(np.min(np.linalg.norm(a + u[:, None] * d - p, axis=1))))
    return max(best) if best else 0.0
