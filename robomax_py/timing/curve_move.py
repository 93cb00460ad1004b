"""A TCP path in space (`space_bezier.SpacePath`) followed by the arm and timed: the spline
motion of `planner.cartesian_moves: spline`, and how `robomax verify` rebuilds a KRL `SPLINE`
block or an SRCL spline.

The path is sampled every `CURVE_STEP_M` of TCP travel and followed in one IK branch exactly as
a LIN line is (`lin._follow`: the start's column, continued by the nearest solution, bisected
where the joints jump), then refined until the joint path's TCP is within `lin.LIN_PATH_TOL_M` of
the path halfway between samples. The joint path (C2 cubic spline through the samples, path
parameter = TCP arclength, m) is timed time-optimally by toppra under the joint velocity and
acceleration limits with the TCP speed bounded per stretch (ds/dt = TCP speed), from rest to rest.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.robot import JointLimits, RobotModel
from robomax_py.spec import frozen_array
from robomax_py.timing._common import DEFAULT_DT_S, LinMoveError, TimingError
from robomax_py.timing._lin_track import Line, Tracker
from robomax_py.timing.lin import (
    LIN_MAX_JOINT_STEP_RAD,
    LIN_PATH_TOL_M,
    Unrefined,
    _default_ik,
    _follow,
    refine,
)
from robomax_py.timing.paths import GeometricPath, spline_path
from robomax_py.timing.space_bezier import SpacePath
from robomax_py.timing.topp import time_path_phases
from robomax_py.timing.trajectory import Segment

# Samples of TCP travel between IK solutions along a curve, m.
CURVE_STEP_M = 0.002


@dataclass(frozen=True, slots=True, eq=False)
class _CurveLine(Line):
    """A `Line` whose poses are a space path's: the IK tracker follows any pose function u -> T."""

    curve: SpacePath | None = None

    def poses(self, u: FloatArray) -> FloatArray:
        assert self.curve is not None
        return self.curve.poses(np.atleast_1d(np.asarray(u, dtype=float)) * self.curve.length)


@dataclass(frozen=True, slots=True, eq=False)
class CurvePath:
    """The joint path of a space path: s (k,) TCP arclength, m; q (k, n) rad; `path` q(s)."""

    s: FloatArray
    q: FloatArray

    @property
    def path(self) -> GeometricPath:
        return spline_path(self.s, self.q)


def curve_path(robot: RobotModel, curve: SpacePath, q_start: FloatArray, step: float = CURVE_STEP_M) -> CurvePath:
    """Follow `curve` from q_start (which must solve its start pose) in q_start's branch.

    Raises LinMoveError where the branch cannot be followed (reason and position attached)."""
    T = curve.poses(np.array([0.0, curve.length]))
    angle = float(np.arccos(np.clip((np.trace(T[0, :3, :3].T @ T[1, :3, :3]) - 1.0) / 2.0, -1.0, 1.0)))
    line = _CurveLine(T0=T[0], p1=T[1, :3, 3].copy(), rotvec=np.zeros(3), tcp_length=curve.length, tcp_angle=angle,
                      length=curve.length, curve=curve)
    from robomax_py.timing.chain import column_of

    q0 = np.asarray(q_start, dtype=float).reshape(-1)
    ik = _default_ik()
    tracker = Tracker(robot, ik, line, column_of(robot, q0, ik), LIN_MAX_JOINT_STEP_RAD)
    count = 1 + max(2, int(np.ceil(curve.length / step)))
    followed = _follow(tracker, np.linspace(0.0, 1.0, count), q0)
    if not isinstance(followed, tuple):
        raise followed.error()
    refined = refine(tracker, *followed, LIN_PATH_TOL_M)
    if isinstance(refined, Unrefined):
        raise LinMoveError("discontinuous", refined.index, refined.fraction,
                           "the joint path cannot be refined to follow the spline")
    u, q = refined
    return CurvePath(frozen_array(u * curve.length), frozen_array(q))


def time_curve(cp: CurvePath, limits: JointLimits, cuts: FloatArray, names: Sequence[tuple[str, str]],
               speed_at: Callable[[FloatArray], FloatArray], *, accel: float = 1.0,
               dt: float = DEFAULT_DT_S) -> list[Segment]:
    """The followed curve timed from rest to rest, cut into segments at the arclengths `cuts`
    (one (kind, label) per segment); speed_at(s) the TCP speed bound (m/s) at arclengths s."""
    if len(cp.s) < 2:
        raise TimingError("a spline without motion cannot be timed")

    def limit(s: FloatArray) -> FloatArray:
        return np.asarray(speed_at(np.asarray(s, dtype=float)), dtype=float)

    return time_path_phases(cp.path, limits, np.asarray(cuts, dtype=float), names, 1.0, accel=accel,
                            path_speed_limit=limit, dt=dt)


def stretch_speeds(key_s: FloatArray, speeds: FloatArray) -> Callable[[FloatArray], FloatArray]:
    """s -> the TCP speed (m/s) of the stretch between key points holding s: speeds[j] (j >= 0)
    from key_s[j] to key_s[j + 1]; at a key point the lower of its two stretches'."""
    ks = np.asarray(key_s, dtype=float)
    v = np.asarray(speeds, dtype=float)

    def at(s: FloatArray) -> FloatArray:
        s = np.asarray(s, dtype=float)
        right = np.clip(np.searchsorted(ks, s, side="right") - 1, 0, len(v) - 1)
        left = np.clip(np.searchsorted(ks, s, side="left") - 1, 0, len(v) - 1)
        return np.asarray(np.minimum(v[right], v[left]), dtype=float)

    return at


def spline_motion(robot: RobotModel, curve: SpacePath, q_start: FloatArray, speeds: FloatArray,
                  limits: JointLimits, names: Sequence[tuple[str, str]], *, accel: float = 1.0,
                  dt: float = DEFAULT_DT_S) -> tuple[CurvePath, list[Segment]]:
    """A spline through key points followed and timed: `speeds` (m - 1,) the TCP speed of each
    stretch between key points; the motion cut into three segments (names): up to the second
    key point (the retract), up to the second-to-last (the curve), the rest (the approach)."""
    cp = curve_path(robot, curve, q_start)
    keys = curve.key_s
    cuts = np.array([0.0, keys[1], keys[-2], curve.length]) if len(keys) > 3 else np.array([0.0, 0.0, 0.0, curve.length])
    cuts[-1] = float(cp.s[-1])
    return cp, time_curve(cp, limits, cuts, names, stretch_speeds(keys, speeds), accel=accel, dt=dt)
