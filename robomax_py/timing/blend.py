"""Fly-by corners made of quintic Bézier curves, G2 with the straight legs they join.

A corner p_prev -> c -> p_next is replaced, within distance r of c, by the quintic Bézier with
control points

    P0 = c - r d_in,  P1 = c - r/2 d_in,  P2 = P3 = c,  P4 = c + r/2 d_out,  P5 = c + r d_out

(d_in, d_out the unit leg directions) on a parameter interval of length h = 5 r / 2. Then
B'(0) = d_in and B'(h) = d_out (unit speed, as on the arc-length lines) and B''(0) = B''(h) = 0
(P0, P1, P2 and P3, P4, P5 are equally spaced on the legs). The lines therefore join the curve
with continuous first and second derivatives: the path is C2 in s and G2 (curvature continuous,
zero at the joins), so toppra can time it without stopping and with bounded joint acceleration.
All control points lie within r of c, so by the convex-hull property the whole curve does too; it
lies in the plane of the two legs, inside the joint limits whenever the legs are.

`blend_join` matches value, first and second derivative of two arbitrary paths the same way (a
quintic Hermite join), for fly-by between consecutive motions that are not straight lines (e.g.
the end of a Cartesian retract into the next joint move).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.spec import frozen_array
from robomax_py.timing._common import ZERO_MOVE, TimingError
from robomax_py.timing.paths import (
    PATH_JOIN_TOL,
    GeometricPath,
    concatenate_paths,
    distinct_waypoints,
    elevate,
)

# Bisection steps finding where a blend cuts into a path (the bracket is then two adjacent floats),
# and how many of them are evaluated at once (2 ** levels - 1 midpoints per call of the path).
MAX_CUT_BISECTIONS = 60
CUT_LOOKAHEAD_LEVELS = 4
# Turning angles above this (rad) are not blended: near a reversal the corner curve would have to
# turn on the spot; the move stops at the waypoint instead.
MAX_BLEND_TURN_RAD = np.deg2rad(175.0)
# Corners smaller than this (rad) stay sharp: their curve would be shorter than round-off allows.
MIN_BLEND_RADIUS = 1e-6


@dataclass(frozen=True, slots=True, eq=False)
class BlendCorner:
    """A fly-by corner: a quintic Bézier from c - r d_in to c + r d_out (see the module docstring).

    control_points : (6, n) float, rad
    radius : float
        The r used (the requested radius, clipped to the legs), rad; the curve lies within it of c.
    param_length : float
        h = 5 r / 2: the curve's parameter interval, on which its speed is 1 at both ends.
    turn : float
        Angle between the legs' directions, rad (0 = straight on).
    """

    control_points: FloatArray
    radius: float
    param_length: float
    turn: float

    @property
    def path(self) -> GeometricPath:
        """The corner as a one-piece path over [0, param_length]."""
        return GeometricPath(breaks=np.array([0.0, self.param_length]), control_points=self.control_points[None])

    def sample(self, count: int) -> FloatArray:
        """(count, n) points at equal steps of the curve parameter, ends included."""
        return self.path(np.linspace(0.0, self.param_length, max(2, count)))


def blend_corner(p_prev: FloatArray, p_corner: FloatArray, p_next: FloatArray, radius: float) -> BlendCorner:
    """The quintic G2 corner replacing p_prev -> p_corner -> p_next within `radius` of p_corner.

    Parameters
    ----------
    p_prev, p_corner, p_next : (n,) float
        Polyline points, rad (any n >= 1; works as well for Cartesian points in m).
    radius : float
        Largest distance from p_corner at which the curve leaves the legs, >= MIN_BLEND_RADIUS;
        clipped to the length of either leg.

    Returns
    -------
    BlendCorner
        Joins the legs with matching position, unit tangent and zero curvature at both ends.

    Raises
    ------
    TimingError
        For a zero-length leg or a reversal (turn > MAX_BLEND_TURN_RAD), which cannot be blended.
    """
    a, c, b = (np.asarray(p, dtype=float).reshape(-1) for p in (p_prev, p_corner, p_next))
    len_in, len_out = float(np.linalg.norm(c - a)), float(np.linalg.norm(b - c))
    if len_in <= ZERO_MOVE or len_out <= ZERO_MOVE:
        raise TimingError("cannot blend a corner with a zero-length leg")
    d_in, d_out = (c - a) / len_in, (b - c) / len_out
    turn = float(np.arccos(np.clip(d_in @ d_out, -1.0, 1.0)))
    if turn > MAX_BLEND_TURN_RAD:
        raise TimingError(f"cannot blend a corner turning by {np.rad2deg(turn):.1f} deg (a reversal)")
    r = float(min(radius, len_in, len_out))
    if not r >= MIN_BLEND_RADIUS:
        raise TimingError(f"blend radius must be >= {MIN_BLEND_RADIUS} (and the legs as long), got {radius}")
    P = np.stack([c - r * d_in, c - 0.5 * r * d_in, c, c, c + 0.5 * r * d_out, c + r * d_out])
    return BlendCorner(control_points=frozen_array(P), radius=r, param_length=2.5 * r, turn=turn)


def blended_polyline_path(waypoints: FloatArray, radius: float | FloatArray) -> tuple[GeometricPath, FloatArray]:
    """Polyline with G2 quintic corners at the interior waypoints.

    Parameters
    ----------
    waypoints : (m, n) float
        rad; consecutive duplicates are dropped.
    radius : float or (m,) float
        Largest corner size per (distinct) waypoint, rad; entries for the two ends are ignored.
        Each corner uses min(radius, half of either adjacent leg), so neighbouring corners never
        overlap; corners below MIN_BLEND_RADIUS or turning above MAX_BLEND_TURN_RAD stay sharp (the path has
        a kink there, where a timed move stops).

    Returns
    -------
    path : GeometricPath
        s is arc length on the straight parts and the Bézier parameter (h = 5 r / 2) in corners.
    radii : (m,) float
        Corner radius used at each distinct waypoint (0 at the ends and at sharp corners), rad.
    """
    w = distinct_waypoints(waypoints)
    m = len(w)
    r_req = np.full(m, float(radius)) if np.ndim(radius) == 0 else np.asarray(radius, dtype=float)
    if r_req.shape != (m,):
        raise TimingError(f"radius must be a number or one per distinct waypoint ({m}), got shape {r_req.shape}")
    legs = np.linalg.norm(np.diff(w, axis=0), axis=1)
    radii = np.zeros(m)
    corners: dict[int, BlendCorner] = {}
    for i in range(1, m - 1):
        r = min(float(r_req[i]), 0.5 * legs[i - 1], 0.5 * legs[i])
        d_in, d_out = (w[i] - w[i - 1]) / legs[i - 1], (w[i + 1] - w[i]) / legs[i]
        if r < MIN_BLEND_RADIUS or np.arccos(np.clip(d_in @ d_out, -1.0, 1.0)) > MAX_BLEND_TURN_RAD:
            continue
        corners[i] = blend_corner(w[i - 1], w[i], w[i + 1], r)
        radii[i] = corners[i].radius
    pieces: list[FloatArray] = []
    lengths: list[float] = []
    point = w[0]
    for i in range(1, m):
        end = corners[i].control_points[0] if i in corners else w[i]
        if np.linalg.norm(end - point) > ZERO_MOVE:
            pieces.append(elevate(np.stack([point, end]), 5))
            lengths.append(float(np.linalg.norm(end - point)))
        if i in corners:
            pieces.append(np.asarray(corners[i].control_points))
            lengths.append(corners[i].param_length)
            point = corners[i].control_points[-1]
        else:
            point = w[i]
    path = GeometricPath(breaks=np.concatenate([[0.0], np.cumsum(lengths)]), control_points=np.stack(pieces))
    return path, radii


def blend_join(first: GeometricPath, second: GeometricPath, radius: float) -> GeometricPath:
    """Fly-by from `first` into `second` (which starts where `first` ends), C2 in the parameter.

    The last part of `first` and the first part of `second` within joint-space distance `radius`
    of their meeting point (at most half of either path's parameter range) are replaced by a
    quintic matching position, first and second derivative of both paths at the cut points. For
    two straight paths this is exactly `blend_corner`. The join's control points lie within
    `radius` of the meeting point up to the paths' second derivatives at the cuts times h^2 / 20,
    so near-straight paths keep the curve within about `radius` of the meeting point.

    Returns
    -------
    GeometricPath
        first[0, s_a] + join + second[s_b, end], s continuing across the pieces; time it with
        `time_path` (rest at both ends, no stop at the join).
    """
    if not radius >= MIN_BLEND_RADIUS:
        raise TimingError(f"blend radius must be >= {MIN_BLEND_RADIUS}, got {radius}")
    return blend_chain([first, second], [radius]).path


@dataclass(frozen=True, slots=True, eq=False)
class BlendedChain:
    """Consecutive paths joined by `blend_join`-style quintics at every junction.

    path : GeometricPath
    piece_ranges : (m, 2) float
        s range of what is left of each input path in `path` (the joins lie between them).
    radii : (m - 1,) float
        Radius used at each junction, rad; 0 where the junction stays sharp (a kink: a timed
        move stops there).
    """

    path: GeometricPath
    piece_ranges: FloatArray
    radii: FloatArray


def blend_chain(paths: Sequence[GeometricPath], radii: Sequence[float]) -> BlendedChain:
    """Join paths end to start, flying by each junction within its radius (0: keep it sharp).

    Each junction consumes at most half of the parameter range of either adjacent path, so joins
    never overlap; a junction whose radius is below MIN_BLEND_RADIUS, or where a path ends with a
    reversal of direction (turn above MAX_BLEND_TURN_RAD), stays sharp.
    """
    if len(paths) == 0 or len(radii) != len(paths) - 1:
        raise TimingError(f"blend_chain needs m paths and m - 1 radii, got {len(paths)} and {len(radii)}")
    for a, b in itertools.pairwise(paths):
        if float(np.max(np.abs(b.start - a.end))) > PATH_JOIN_TOL:
            raise TimingError("blend_chain: each path must start where the previous one ends")
    m = len(paths)
    lo = np.zeros(m)
    hi = np.array([p.length for p in paths])
    used = np.zeros(m - 1)
    joins: list[GeometricPath | None] = [None] * (m - 1)
    for k in range(m - 1):
        first, second, r = paths[k], paths[k + 1], float(radii[k])
        if r < MIN_BLEND_RADIUS or _turn(first, second) > MAX_BLEND_TURN_RAD:
            continue
        corner = first.end
        s_a = _cut_at_distance(first, corner, r, from_end=True)
        s_b = _cut_at_distance(second, corner, r, from_end=False)
        p0, p5 = first(s_a), second(s_b)
        r_used = max(float(np.linalg.norm(p0 - corner)), float(np.linalg.norm(p5 - corner)))
        if r_used < MIN_BLEND_RADIUS:
            continue
        joins[k] = _join(first, s_a, second, s_b, r_used)
        hi[k], lo[k + 1], used[k] = s_a, s_b, r_used
    parts: list[GeometricPath] = []
    ranges = np.zeros((m, 2))
    s = 0.0
    for k, p in enumerate(paths):
        start = s
        if hi[k] - lo[k] > 1e-12 * max(p.length, 1.0):
            piece = p if (lo[k] == 0.0 and hi[k] == p.length) else p.restrict(lo[k], hi[k])
            parts.append(piece)
            s += piece.length
        ranges[k] = (start, s)
        join = joins[k] if k < m - 1 else None
        if join is not None:
            parts.append(join)
            s += join.length
    return BlendedChain(concatenate_paths(parts), frozen_array(ranges), frozen_array(used))


def _turn(first: GeometricPath, second: GeometricPath) -> float:
    """Angle between the end tangent of `first` and the start tangent of `second`, rad."""
    d0, d1 = first(first.length, 1), second(0.0, 1)
    n0, n1 = float(np.linalg.norm(d0)), float(np.linalg.norm(d1))
    if n0 <= ZERO_MOVE or n1 <= ZERO_MOVE:
        return float(np.pi)
    return float(np.arccos(np.clip(d0 @ d1 / (n0 * n1), -1.0, 1.0)))


def _join(first: GeometricPath, s_a: float, second: GeometricPath, s_b: float, r_used: float) -> GeometricPath:
    """The quintic from first(s_a) to second(s_b) matching value, first and second derivatives."""
    p0, d0, dd0 = first(s_a), first(s_a, 1), first(s_a, 2)
    p5, d5, dd5 = second(s_b), second(s_b, 1), second(s_b, 2)
    speed = max(float(np.linalg.norm(d0)), float(np.linalg.norm(d5)), 1e-12)
    h = 2.5 * r_used / speed
    P = np.stack([
        p0,
        p0 + h / 5 * d0,
        p0 + 2 * h / 5 * d0 + h * h / 20 * dd0,
        p5 - 2 * h / 5 * d5 + h * h / 20 * dd5,
        p5 - h / 5 * d5,
        p5,
    ])
    return GeometricPath(breaks=np.array([0.0, h]), control_points=P[None])


def _cut_at_distance(path: GeometricPath, point: FloatArray, radius: float, *, from_end: bool) -> float:
    """s where the path, walked from its end (or start), first gets `radius` away from `point`.

    Limited to the half of the parameter range next to that end.
    """
    half = 0.5 * path.length
    s = path.grid(radius / 16.0)
    s = s[s >= half][::-1] if from_end else s[s <= half]
    # The half itself is the last point tried: where the radius is reached between it and the last
    # grid step before it, the bisection below finds the crossing. Without it the cut fell to the
    # half, a blend up to one grid step (radius / 16) wider than asked, and whether it did turned
    # on where the grid's steps fell: a via point moved by 0.0004 deg changed a blend from 3.185
    # to 3.0 deg and its move by 3 ms.
    if s[-1] != half:
        s = np.append(s, half)
    dist = np.linalg.norm(path(s) - point, axis=1)
    beyond = np.nonzero(dist >= radius)[0]
    if len(beyond) == 0:
        return half
    k = int(beyond[0])
    lo, hi = float(s[k - 1]), float(s[k])        # dist(lo) < radius <= dist(hi)
    lo_tested = hi_tested = False                # set by this loop's own test (not the grid's)
    steps = 0
    while steps < MAX_CUT_BISECTIONS:
        # The midpoints the next levels of the bisection can visit, as a heap (node j's children
        # are 2j + 1, taken when its midpoint is at least `radius` away, and 2j + 2), evaluated
        # in one call: a call of the path costs far more than a point. Each midpoint is computed
        # as the plain bisection computes it, and a point of a vector call is the scalar call's.
        levels = min(CUT_LOOKAHEAD_LEVELS, MAX_CUT_BISECTIONS - steps)
        brackets = [(lo, hi)]
        mids: list[float] = []
        for a, b in itertools.islice(brackets, 2 ** levels - 1):
            mid = 0.5 * (a + b)
            mids.append(mid)
            brackets += ((a, mid), (mid, b))
        gaps = path(np.array(mids)) - point
        j = 0
        for _ in range(levels):
            g = gaps[j]
            # np.linalg.norm of a vector, without its checks: the square root of its dot product.
            if math.sqrt(g.dot(g)) < radius:
                lo, lo_tested, j = mids[j], True, 2 * j + 2
            else:
                hi, hi_tested, j = mids[j], True, 2 * j + 1
            steps += 1
            # Once the next midpoint is an end this loop has tested (lo and hi adjacent floats),
            # every remaining step tests it again with the same outcome: stop, with the same result.
            after = 0.5 * (lo + hi)
            if (after == lo and lo_tested) or (after == hi and hi_tested):
                return hi
    return hi
