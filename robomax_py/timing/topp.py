"""Time-optimal timing of a geometric path under velocity and acceleration limits, with toppra.

toppra (reachability analysis, seidel LP solver) gives the largest path speed sd_i at grid points
s_i such that every joint stays within its velocity and acceleration limits, starting and ending at
rest. Between grid points the path acceleration is constant, so s(t) is piecewise quadratic; we
evaluate q(s(t)) on the original path ourselves (positions lie exactly on the path, unlike toppra's
default output, which re-fits a cubic spline through the grid states). Acceleration is bang-bang:
toppra does not limit jerk.

An optional limit on ds/dt along the path (e.g. the TCP speed of a Cartesian line parameterised by
TCP travel) enters as a custom constraint bounding x = sd^2 directly, instead of the usual trick of
appending s as an extra "joint" with a velocity limit.

Paths must be C1 for a move to pass through without stopping; `time_path` stops at every kink
(`paths.kinks`) and times the pieces in between rest to rest.
"""

from __future__ import annotations

import itertools
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.robot import JointLimits
from robomax_py.timing._common import (
    DEFAULT_DT_S,
    KinematicLimits,
    TimingError,
    check_within_limits,
    scaled_limits,
    time_grid,
)
from robomax_py.timing.paths import GeometricPath, kinks
from robomax_py.timing.trajectory import Segment, as_segment, concatenate

# Grid for toppra: at least this many points per rest-to-rest piece ...
MIN_GRID_POINTS = 100
# ... steps of at most this fraction of the piece's joint-space length ...
GRID_STEP_FRACTION = 1.0 / 200.0
# ... refined until the tangent turns by at most this (rad, ~ |q''| ds / |q'|) within a step: the
# limits are enforced at grid points, and between them they then hold to about this squared ...
GRID_TURN_PER_STEP = 0.02
# ... but never beyond this many points.
MAX_GRID_POINTS = 20000

# s -> largest allowed ds/dt at s; vectorised: (k,) -> (k,).
PathSpeedLimit = Callable[[FloatArray], FloatArray]


def time_path(
    path: GeometricPath,
    limits: JointLimits,
    speed: float = 1.0,
    *,
    accel: float = 1.0,
    path_speed_limit: PathSpeedLimit | None = None,
    kind: str = "move",
    label: str = "",
    dt: float = DEFAULT_DT_S,
) -> Segment:
    """Time-optimal motion along `path` from rest to rest under joint velocity/acceleration limits.

    Parameters
    ----------
    path : GeometricPath
        q(s), rad. Where its tangent jumps (a kink) the motion stops.
    limits : JointLimits
        velocity (n,) rad/s and acceleration (n,) rad/s^2 (jerk is not limited by toppra);
        the samples are checked against the position limits.
    speed, accel : float
        Overrides in (0, 1] of the velocity and of the acceleration limits.
    path_speed_limit : callable, optional
        s (k,) -> largest ds/dt (k,) allowed there (units of s per second, > 0), e.g. a TCP speed.
    dt : float
        Sample period, s.

    Returns
    -------
    Segment
        Samples every <= dt; first and last exactly path.start and path.end at rest.

    Raises
    ------
    TimingError
        If toppra finds no parameterisation or the path leaves the joint position limits.
    """
    lim = scaled_limits(limits, speed, accel)
    stops = [0.0, *kinks(path).tolist(), path.length]
    parts: list[Segment] = []
    for a, b in itertools.pairwise(stops):
        piece = path if (a == 0.0 and b == path.length) else path.restrict(a, b)
        shifted = None if path_speed_limit is None else _shifted(path_speed_limit, a)
        parts.append(_time_piece(piece, lim, shifted, dt, kind, label))
    seg = parts[0] if len(parts) == 1 else as_segment(concatenate(parts), kind, label)
    check_within_limits(seg.q, limits, "path")
    return seg


def gridpoints(path: GeometricPath) -> FloatArray:
    """(N + 1,) grid in s for toppra: every break, fine steps, refined where the path turns."""
    c = path.control_points
    polygon = float(np.sum(np.linalg.norm(np.diff(c, axis=1), axis=2)))
    s = path.grid(max(polygon * GRID_STEP_FRACTION, 1e-12))
    while len(s) < MIN_GRID_POINTS:
        s = np.sort(np.concatenate([s, 0.5 * (s[:-1] + s[1:])]))
    turn = _turn(path, s, np.ones(len(s) - 1, dtype=bool), np.empty(len(s) - 1))
    for _ in range(20):
        split = turn > GRID_TURN_PER_STEP
        if not np.any(split) or len(s) + int(np.sum(split)) > MAX_GRID_POINTS:
            break
        # Each step split at its midpoint (which lies between its ends, so the grid stays sorted);
        # only the halves are evaluated anew, the other steps keep their turn (the same ends give
        # the same midpoint and the same value: the path is evaluated point by point).
        at = np.flatnonzero(split)
        s = np.insert(s, at + 1, 0.5 * (s[at] + s[at + 1]))
        fresh = np.repeat(split, np.where(split, 2, 1))
        kept = np.empty(len(s) - 1)
        kept[~fresh] = turn[~split]
        turn = _turn(path, s, fresh, kept)
    return s


def _turn(path: GeometricPath, s: FloatArray, fresh: BoolArray, turn: FloatArray) -> FloatArray:
    """`turn` with its entries where `fresh` set to how far the tangent turns over each step of
    grid s (rad, ~ |q''| ds / |q'| at the step's midpoint)."""
    ds = np.diff(s)[fresh]
    mid = 0.5 * (s[:-1] + s[1:])[fresh]
    turn[fresh] = np.linalg.norm(path(mid, 2), axis=1) * ds / np.maximum(np.linalg.norm(path(mid, 1), axis=1), 1e-12)
    return turn


def _time_piece(
    path: GeometricPath, lim: KinematicLimits, speed_limit: PathSpeedLimit | None, dt: float, kind: str, label: str
) -> Segment:
    """Rest-to-rest toppra timing of a C1 path, sampled every <= dt."""
    law = _TimingLaw.of(path, lim, speed_limit)
    return law.segment(path, law.times(0.0, law.duration, dt), kind, label)


@dataclass(frozen=True, slots=True, eq=False)
class _TimingLaw:
    """s(t) from toppra's grid: constant path acceleration between grid points."""

    s_grid: FloatArray
    sd: FloatArray
    u: FloatArray
    t_grid: FloatArray

    @staticmethod
    def of(path: GeometricPath, lim: KinematicLimits, speed_limit: PathSpeedLimit | None) -> _TimingLaw:
        s_grid = gridpoints(path)
        x = _toppra_sd_squared(path, s_grid, lim, speed_limit)
        ds = np.diff(s_grid)
        sd = np.sqrt(x)
        mean = 0.5 * (sd[:-1] + sd[1:])
        if np.any(mean <= 0):
            raise TimingError("toppra returned a standstill inside the path")
        t_grid = np.concatenate([[0.0], np.cumsum(ds / mean)])
        u = (x[1:] - x[:-1]) / (2.0 * ds)                        # path acceleration per interval
        return _TimingLaw(s_grid, sd, u, t_grid)

    @property
    def duration(self) -> float:
        return float(self.t_grid[-1])

    def time_at(self, s: float) -> float:
        """The time the motion passes path parameter s."""
        i = int(np.clip(np.searchsorted(self.s_grid, s, side="right") - 1, 0, len(self.u) - 1))
        rest = float(s - self.s_grid[i])
        v, a = float(self.sd[i]), float(self.u[i])
        if abs(a) < 1e-12:
            tau = rest / v if v > 0 else 0.0
        else:
            tau = (-v + np.sqrt(max(v * v + 2.0 * a * rest, 0.0))) / a
        return float(np.clip(self.t_grid[i] + tau, self.t_grid[i], self.t_grid[i + 1]))

    def times(self, t0: float, t1: float, dt: float) -> FloatArray:
        """Sample times from t0 to t1 (both included), at most dt apart."""
        return t0 + time_grid(max(t1 - t0, 0.0), dt)

    def segment(self, path: GeometricPath, t: FloatArray, kind: str, label: str) -> Segment:
        """The motion sampled at times t (absolute on this law's clock), as a segment starting at 0."""
        i = np.clip(np.searchsorted(self.t_grid, t, side="right") - 1, 0, len(self.u) - 1)
        tau = t - self.t_grid[i]
        s = np.minimum(self.s_grid[i] + self.sd[i] * tau + 0.5 * self.u[i] * tau * tau, self.s_grid[i + 1])
        s_dot = np.maximum(self.sd[i] + self.u[i] * tau, 0.0)
        at_start, at_end = t <= 0.0, t >= self.duration
        s[at_start], s_dot[at_start] = 0.0, 0.0
        s[at_end], s_dot[at_end] = path.length, 0.0
        d1 = path(s, 1)
        q = path(s)
        qd = d1 * s_dot[:, None]
        qdd = path(s, 2) * (s_dot * s_dot)[:, None] + d1 * self.u[i][:, None]
        q[at_start], q[at_end] = path.start, path.end
        qd[at_start | at_end] = 0.0
        return Segment(t=t - t[0], q=q, qd=qd, qdd=qdd, kind=kind, label=label)


def time_path_phases(
    path: GeometricPath,
    limits: JointLimits,
    cuts: FloatArray,
    names: Sequence[tuple[str, str]],
    speed: float = 1.0,
    *,
    accel: float = 1.0,
    path_speed_limit: PathSpeedLimit | None = None,
    dt: float = DEFAULT_DT_S,
) -> list[Segment]:
    """`time_path`, with the motion cut into consecutive segments where s passes `cuts`.

    cuts : (m + 1,) float
        Non-decreasing s values from 0 to path.length; segment k covers [cuts[k], cuts[k + 1]].
    names : m (kind, label) pairs, one per segment.

    The segments join exactly (the cut sample belongs to both), so `concatenate` accepts them;
    their total duration equals `time_path`'s. Empty ranges give zero-duration segments.
    """
    cuts = np.asarray(cuts, dtype=float)
    if len(cuts) != len(names) + 1 or cuts[0] != 0.0 or abs(cuts[-1] - path.length) > 1e-9 * max(path.length, 1.0) \
            or np.any(np.diff(cuts) < 0):
        raise TimingError("cuts must run from 0 to the path length, one more than the names")
    lim = scaled_limits(limits, speed, accel)
    stops = [0.0, *kinks(path).tolist(), path.length]
    laws = []
    for a, b in itertools.pairwise(stops):
        piece = path if (a == 0.0 and b == path.length) else path.restrict(a, b)
        shifted = None if path_speed_limit is None else _shifted(path_speed_limit, a)
        laws.append((a, b, piece, _TimingLaw.of(piece, lim, shifted)))
    out: list[Segment] = []
    for k, (kind, label) in enumerate(names):
        s0, s1 = float(cuts[k]), min(float(cuts[k + 1]), path.length)
        parts: list[Segment] = []
        for a, b, piece, law in laws:
            lo, hi = max(s0, a), min(s1, b)
            if hi < lo or (hi == lo and parts):
                continue
            t0 = law.time_at(lo - a) if lo > a else 0.0
            t1 = law.time_at(hi - a) if hi < b else law.duration
            parts.append(law.segment(piece, law.times(t0, max(t1, t0), dt), kind, label))
        seg = parts[0] if len(parts) == 1 else as_segment(concatenate(parts), kind, label)
        check_within_limits(seg.q, limits, "path")
        out.append(seg)
    return out


def _toppra_sd_squared(
    path: GeometricPath, s_grid: FloatArray, lim: KinematicLimits, speed_limit: PathSpeedLimit | None
) -> FloatArray:
    """(N + 1,) squared path speeds x = sd^2 at the grid points, rest to rest."""
    from robomax_py._lazy import defer

    defer("matplotlib.pyplot")      # toppra.algorithm imports it for its plots, which we never draw
    import toppra.algorithm as algo
    from toppra import constraint

    constraints: list[Any] = [
        constraint.JointVelocityConstraint(lim.velocity),
        constraint.JointAccelerationConstraint(lim.acceleration),
    ]
    if speed_limit is not None:
        constraints.append(_path_speed_constraint(path.dof, speed_limit))
    instance = algo.TOPPRA(constraints, _toppra_path(path), gridpoints=s_grid, solver_wrapper="seidel")
    toppra_log = logging.getLogger("toppra")
    level = toppra_log.level
    toppra_log.setLevel(logging.ERROR)              # toppra logs failures as warnings; we raise instead
    try:
        _, sd_vec, _ = instance.compute_parameterization(0.0, 0.0)
    finally:
        toppra_log.setLevel(level)
    if sd_vec is None or not np.all(np.isfinite(sd_vec)):
        raise TimingError(f"toppra cannot parameterise the path: {instance.problem_data.return_code}")
    x = np.maximum(np.asarray(sd_vec, dtype=float), 0.0) ** 2
    x[0] = x[-1] = 0.0
    return np.asarray(x, dtype=float)


def _shifted(fn: PathSpeedLimit, offset: float) -> PathSpeedLimit:
    return lambda s: fn(np.asarray(s) + offset)


def _path_speed_constraint(dof: int, speed_limit: PathSpeedLimit) -> Any:
    """A toppra constraint sd <= speed_limit(s), as bounds on x = sd^2 at the grid points."""
    from toppra.constraint import LinearConstraint

    class PathSpeedConstraint(LinearConstraint):  # type: ignore[misc]
        def __init__(self) -> None:
            super().__init__()
            self.dof = dof

        def compute_constraint_params(self, path: Any, gridpoints: FloatArray, *args: Any, **kwargs: Any) -> tuple[Any, ...]:
            v = np.broadcast_to(np.asarray(speed_limit(np.asarray(gridpoints)), dtype=float), np.shape(gridpoints))
            if np.any(~np.isfinite(v)) or np.any(v <= 0):
                raise TimingError("a path speed limit must be finite and > 0 everywhere")
            xbound = np.stack([np.zeros_like(v), v * v], axis=1)
            return None, None, None, None, None, None, xbound

    return PathSpeedConstraint()


def _toppra_path(path: GeometricPath) -> Any:
    """A GeometricPath seen through toppra's AbstractGeometricPath interface (toppra imported lazily)."""
    from toppra.interpolator import AbstractGeometricPath

    class ToppraPath(AbstractGeometricPath):  # type: ignore[misc]
        # toppra's velocity and acceleration constraints each ask for the first derivative at the
        # same grid points: the last answer is kept and handed out again (as a copy: a caller may
        # write into its array).
        last: tuple[int, FloatArray, FloatArray] | None = None

        def __call__(self, path_positions: Any, order: int = 0) -> FloatArray:
            s = np.array(path_positions, dtype=float)
            if self.last is not None and self.last[0] == order and np.array_equal(self.last[1], s):
                return self.last[2].copy()
            out = path(s, order)
            self.last = (order, s, out)
            return out.copy()

        @property
        def dof(self) -> int:
            return path.dof

        @property
        def path_interval(self) -> FloatArray:
            return np.array([0.0, path.length])

        @property
        def waypoints(self) -> FloatArray:
            return np.asarray(path.control_points[:, 0])

    return ToppraPath()
