"""Moves through joint-space waypoints (detours): stop at each, blend with toppra, or fly by with ruckig.

The waypoints come from a planner that collision-checked the polyline through them. Three ways to
move along it, from exact-but-slow to fast-but-off-the-polyline:

``"stop"``  rest at every waypoint; each leg a jerk-limited straight line (ruckig). The path is
            exactly the polyline.
``"blend"`` corners replaced by G2 quintic Bézier blends (`blend.blended_polyline_path`) within
            `blend_radius` of each waypoint, timed time-optimally with toppra under velocity and
            acceleration limits (not jerk); rest only at both ends.
``"jerk"``  jerk-limited fly-by with ruckig, state to state only: straight pieces along the legs
            (exact lines, non-zero speeds at their ends) and, at each corner, a time-synchronised
            ruckig move from the point `r` before the waypoint to the point `r` after it, entering
            and leaving along the legs at a pass speed chosen from the corner angle and the limits.
            A corner whose samples leave the ball of radius r around its waypoint (or the joint
            limits), or a straight piece that would have to overshoot, gets a lower pass speed; at
            a twentieth of the first choice the move stops at that waypoint instead. It also stops
            wherever stopping is faster (small radii, sharp corners): never slower than "stop".

In "blend" and "jerk" the path differs from the polyline only inside balls of radius
`blend_radius` (Euclidean, joint space) around the interior waypoints, so shrinking the radius
shrinks the deviation; radius 0 gives "stop" behaviour. The result carries dense samples of the
geometric path for the caller to re-check for collisions.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.robot import JointLimits
from robomax_py.spec import frozen_array
from robomax_py.timing._common import (
    DEFAULT_DT_S,
    LIMIT_TOL,
    ZERO_MOVE,
    KinematicLimits,
    TimingError,
    check_within_limits,
    scaled_limits,
)
from robomax_py.timing.blend import (
    MAX_BLEND_TURN_RAD,
    MIN_BLEND_RADIUS,
    blended_polyline_path,
)
from robomax_py.timing.paths import distinct_waypoints, polyline_path
from robomax_py.timing.ptp import line_samples, line_speed_limits, state_samples
from robomax_py.timing.topp import time_path
from robomax_py.timing.trajectory import Segment, as_segment, concatenate, evaluate
from robomax_py.tolerances import DEFAULT as TOL

# Spacing of the returned geometric path samples, rad (Euclidean, joint space).
PATH_STEP_RAD = 0.005
# "jerk" mode: corners use at most this fraction of either adjacent leg, so a straight piece of at
# least a fifth of every leg remains between two corners.
JERK_CORNER_LEG_FRACTION = 0.4
# "jerk" mode: factor applied to a corner's pass speed after a failed check, the fraction of the
# first choice below which the move stops at the corner instead, and the number of rounds.
JERK_SPEED_BACKOFF = 0.7
JERK_MIN_SPEED_FRACTION = 0.05
JERK_MAX_ROUNDS = 40
# Slack on the corner-ball check, relative to the radius, and on straight pieces' monotonicity.
JERK_BALL_RTOL = TOL.jerk_ball_rtol
JERK_MONOTONE_TOL = TOL.jerk_monotone_tol

PathMode = Literal["stop", "blend", "jerk"]


@dataclass(frozen=True, slots=True, eq=False)
class PathMove:
    """A timed move through waypoints and the geometric path it follows.

    segment : Segment
    path : (p, n) float, rad
        Points along the joint-space path in order, consecutive ones at most `path_step` apart,
        first and last the end waypoints: what a collision checker should sweep.
    deviation : float
        Largest Euclidean distance of `path` from the waypoint polyline, rad.
    radii : (m,) float
        Corner radius used at each (distinct) waypoint, rad; 0 at the ends and where the move stops.
    """

    segment: Segment
    path: FloatArray
    deviation: float
    radii: FloatArray


def path_move(
    waypoints: FloatArray,
    limits: JointLimits,
    speed: float = 1.0,
    *,
    mode: PathMode = "blend",
    blend_radius: float = 0.1,
    accel: float = 1.0,
    kind: str = "detour",
    label: str = "",
    dt: float = DEFAULT_DT_S,
    path_step: float = PATH_STEP_RAD,
) -> PathMove:
    """Move through joint-space waypoints, at rest at the first and the last.

    Parameters
    ----------
    waypoints : (m, n) float
        Configurations, rad; m >= 2 (consecutive duplicates are dropped).
    limits : JointLimits
    speed, accel : float
        Overrides in (0, 1] of the velocity, and of the acceleration and jerk limits.
    mode : "stop" | "blend" | "jerk"
        See the module docstring.
    blend_radius : float
        rad (Euclidean, joint space): the path leaves the polyline only within this distance of an
        interior waypoint ("blend", "jerk"); ignored by "stop".
    dt : float
        Sample period of the segment, s.
    path_step : float
        Spacing of the returned geometric path samples, rad.

    Returns
    -------
    PathMove
    """
    w = distinct_waypoints(waypoints)
    if not (np.isfinite(blend_radius) and blend_radius >= 0):
        raise TimingError(f"blend_radius must be >= 0 rad, got {blend_radius}")
    if mode == "blend":
        path, radii = blended_polyline_path(w, blend_radius)
        seg = time_path(path, limits, speed, accel=accel, kind=kind, label=label, dt=dt)
        geometric = path.sample(path_step)
    elif mode == "stop" or mode == "jerk":
        lim = scaled_limits(limits, speed, accel)
        radius = blend_radius if mode == "jerk" else 0.0
        seg, radii = _ruckig_through(w, lim, (limits.lower, limits.upper), radius, dt, kind, label)
        check_within_limits(seg.q, limits, "path move")
        geometric = polyline_path(w).sample(path_step) if not np.any(radii) else _densify(seg, path_step)
    else:
        raise TimingError(f"unknown path mode {mode!r}; expected 'stop', 'blend' or 'jerk'")
    return PathMove(
        segment=seg,
        path=frozen_array(geometric),
        deviation=float(np.max(polyline_distance(geometric, w))),
        radii=frozen_array(radii),
    )


def polyline_distance(points: FloatArray, waypoints: FloatArray) -> FloatArray:
    """(p,) Euclidean distance of each point (p, n) from the polyline through waypoints (m, n)."""
    p = np.asarray(points, dtype=float)[:, None, :]
    a = np.asarray(waypoints, dtype=float)[:-1][None]
    d = np.diff(np.asarray(waypoints, dtype=float), axis=0)[None]
    dd = np.maximum(np.sum(d * d, axis=-1), 1e-300)
    u = np.clip(np.sum((p - a) * d, axis=-1) / dd, 0.0, 1.0)
    return np.asarray(np.min(np.linalg.norm(p - (a + u[..., None] * d), axis=-1), axis=1), dtype=float)


def _ruckig_through(
    w: FloatArray, lim: KinematicLimits, box: tuple[FloatArray, FloatArray], radius: float, dt: float, kind: str, label: str
) -> tuple[Segment, FloatArray]:
    """Straight jerk-limited legs with ruckig corners of size <= radius (0: stop at every waypoint)."""
    m = len(w)
    legs = np.linalg.norm(np.diff(w, axis=0), axis=1)
    dirs = np.diff(w, axis=0) / legs[:, None]
    r = np.zeros(m)
    v = np.zeros(m)
    for i in range(1, m - 1):
        turn = float(np.arccos(np.clip(dirs[i - 1] @ dirs[i], -1.0, 1.0)))
        r_i = min(radius, JERK_CORNER_LEG_FRACTION * legs[i - 1], JERK_CORNER_LEG_FRACTION * legs[i])
        if r_i >= MIN_BLEND_RADIUS and turn <= MAX_BLEND_TURN_RAD:
            r[i] = r_i
            v[i] = _corner_speed(r_i, dirs[i - 1], dirs[i], lim)
    v_first = v.copy()
    pieces: list[Segment] | None = None
    for _ in range(JERK_MAX_ROUNDS):
        pieces, slow = _pieces(w, dirs, r, v, lim, box, dt, kind, label)
        if not slow:
            break
        pieces = None
        for i in slow:
            v[i] *= JERK_SPEED_BACKOFF
            if v[i] < JERK_MIN_SPEED_FRACTION * v_first[i]:
                r[i], v[i] = 0.0, 0.0
    if pieces is None:
        r[:] = 0.0
        v[:] = 0.0
        pieces, _ = _pieces(w, dirs, r, v, lim, box, dt, kind, label)
    # A fly-by is not always faster than stopping (the joins carry zero acceleration, and a sharp
    # corner allows only a low pass speed): keep a stop wherever it saves time.
    best = sum(p.duration for p in pieces)
    for i in range(1, m - 1):
        if r[i] == 0.0:
            continue
        r_try, v_try = r.copy(), v.copy()
        r_try[i], v_try[i] = 0.0, 0.0
        tried, slow = _pieces(w, dirs, r_try, v_try, lim, box, dt, kind, label)
        duration = sum(p.duration for p in tried)
        if not slow and duration < best:
            pieces, best, r, v = tried, duration, r_try, v_try
    return as_segment(concatenate(pieces), kind, label), r


def _pieces(
    w: FloatArray, dirs: FloatArray, r: FloatArray, v: FloatArray, lim: KinematicLimits,
    box: tuple[FloatArray, FloatArray], dt: float, kind: str, label: str,
) -> tuple[list[Segment], set[int]]:
    """Segments for the current radii r and pass speeds v; and the corners whose speed must drop.

    box : joint position limits (lower, upper), (n,) each.
    """
    m = len(w)
    pieces: list[Segment] = []
    slow: set[int] = set()
    start, start_speed = w[0], 0.0
    for i in range(1, m):
        corner = i < m - 1 and r[i] > 0
        end = w[i] - r[i] * dirs[i - 1] if corner else w[i]
        end_speed = v[i] if corner else 0.0
        straight = line_samples(start, end, lim, start_speed, end_speed, dt)
        e = dirs[i - 1]
        along = (straight.q - start) @ e
        length = float(np.linalg.norm(end - start))
        if (
            np.min(straight.qd @ e) < -JERK_MONOTONE_TOL
            or np.min(along) < -JERK_MONOTONE_TOL
            or np.max(along) > length + JERK_MONOTONE_TOL
        ):
            slow.add(i - 1 if (start_speed > end_speed and i > 1) else i)
        pieces.append(Segment(t=straight.t, q=straight.q, qd=straight.qd, qdd=straight.qdd, kind=kind, label=label))
        if not corner:
            start, start_speed = w[i], 0.0
            continue
        exit_ = w[i] + r[i] * dirs[i]
        turn = state_samples(end, v[i] * dirs[i - 1], exit_, v[i] * dirs[i], lim, dt)
        outside_ball = np.max(np.linalg.norm(turn.q - w[i], axis=1)) > r[i] * (1.0 + JERK_BALL_RTOL)
        outside_box = np.any(turn.q < box[0] - LIMIT_TOL) or np.any(turn.q > box[1] + LIMIT_TOL)
        if outside_ball or outside_box:
            slow.add(i)
        pieces.append(Segment(t=turn.t, q=turn.q, qd=turn.qd, qdd=turn.qdd, kind=kind, label=label))
        start, start_speed = exit_, float(v[i])
    slow.discard(0)
    slow.discard(m - 1)
    return pieces, slow


def _corner_speed(r: float, d_in: FloatArray, d_out: FloatArray, lim: KinematicLimits) -> float:
    """A pass speed (rad/s along the path) that lets the joints turn within about 2 r of travel.

    Each joint's velocity changes by v |d_out - d_in|_j, which takes about v |dv_j| / a_j + a_j / j_j;
    the corner takes about 2 r / v. Equating gives c v^2 + tau v - 2 r = 0.
    """
    v_line = min(line_speed_limits(d_in, lim)[0], line_speed_limits(d_out, lim)[0])
    dv = np.abs(d_out - d_in)
    turning = dv > ZERO_MOVE
    if not np.any(turning):
        return v_line
    c = float(np.max(dv[turning] / lim.acceleration[turning]))
    tau = float(np.max(lim.acceleration[turning] / lim.jerk[turning]))
    v = (-tau + np.sqrt(tau * tau + 8.0 * r * c)) / (2.0 * c)
    return float(min(v, v_line))


def _densify(seg: Segment, step: float) -> FloatArray:
    """(p, n) the segment's positions with interpolated points in between so that steps are <= step."""
    t = seg.t
    q = seg.q
    for _ in range(20):
        gaps = np.linalg.norm(np.diff(q, axis=0), axis=1)
        if np.all(gaps <= step):
            break
        counts = np.maximum(1, np.ceil(gaps / step)).astype(int)
        t = np.concatenate([*(np.linspace(a, b, k + 1)[:-1] for a, b, k in zip(t[:-1], t[1:], counts)), t[-1:]])
        q = evaluate(seg, t).q
    return q
