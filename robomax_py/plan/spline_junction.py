"""A junction between two spots as one smooth TCP path (`planner.cartesian_moves: spline`).

The key poses are the spot left, its approach point up the electrode axis, the detour's via points
(the TCP poses of its joint waypoints, or the via points of its TCP lines), the next approach point
and the next spot; `timing.space_bezier` lays the G2 quintic Bézier path through them, straight
over the approach distance at both ends. The controller follows it as short straight lines flown
by (a TCP distance below half the shorter chord): every dialect can state that, and the planner
times it with the same `chain_path` / `time_chain` the program's parse-back rebuilds it with, so
what verify re-simulates is what was timed. Where the cell has TCP limits, a line's speed keeps
the radial acceleration kappa v^2 within a_R over its stretch (the velocity envelope of the
paper's minimum-time profile, `timing.frenet_profile`).

The variant is kept only where it is faster than the junction the planner chose otherwise (LIN
retract and approach, PTP or LIN detour, with fly-by), its whole path is free of collisions, the
TCP stays on the electrode axis over the approach distance at both spots, and it arrives in the
planned configuration.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.junction import CHECK_STEP_RAD, Junction, PathChecks, WeldEnd
from robomax_py.plan.spline_moves import CartesianChoice, SplineMoves
from robomax_py.program import as_written_pose
from robomax_py.robot import JointLimits, RobotModel, fk_tcp
from robomax_py.spec import TcpLimits
from robomax_py.timing import LinMoveError, Segment, TimingError
from robomax_py.timing.chain import LinStep, chain_path, time_chain
from robomax_py.timing.curve_move import spline_motion
from robomax_py.timing.space_bezier import deviation, sample_lines, space_path

# The spline's points are sampled from the Bézier path so that a chord's sagitta stays within
# this (m): the spline through them then keeps far closer to the Bézier (`deviation_m`) ...
SPLINE_TOL_M = 0.001
# ... with chords between these lengths (m).
MAX_CHORD_M = 0.12
MIN_CHORD_M = 0.01
# Samples of the spline measured against the Bézier path.
DEVIATION_SAMPLES = 400
# The dialects without spline motion fly by each interior spline point at this fraction of the
# shorter chord meeting there (< 0.5: neighbouring blends never overlap; on the small test cell
# 0.4 takes the lines 5 % longer than 0.49) ...
LINES_FLYBY_FRACTION = 0.49
# ... and the approach points, where the straight retract and approach meet the curve, at this
# one: a blend there cuts into the approach line, and verify wants the TCP on the electrode axis
# within 0.1 mm over the approach distance (0.49 left it by 0.15 mm on gazelle_cabin; 0.1 keeps it).
LINES_END_FLYBY_FRACTION = 0.1


def line_flybys(points: FloatArray, start: FloatArray) -> FloatArray:
    """(k,) TCP fly-by distance (same unit as the points) at each of a spline block's points
    (k, 3), written as lines from `start` (3,): `LINES_FLYBY_FRACTION` of the shorter chord
    meeting there, `LINES_END_FLYBY_FRACTION` at the first and second-to-last (the approach
    points), 0 at the last (the spot)."""
    pts = np.vstack([np.asarray(start, dtype=float)[None], np.asarray(points, dtype=float)])
    chords = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    k = len(chords)
    fraction = np.full(k, LINES_FLYBY_FRACTION)
    fraction[[0, max(k - 2, 0)]] = LINES_END_FLYBY_FRACTION
    out = np.zeros(k)
    out[:-1] = fraction[:-1] * np.minimum(chords[:-1], chords[1:])
    return out
# The path must arrive in the planned configuration within this (rad, any joint).
ARRIVAL_TOL_RAD = 1e-3


@dataclass(frozen=True, slots=True)
class SplineSettings:
    """What the variant is built with: the TCP speeds of the approach / retract lines and of the
    curve's lines (m/s, as written, overrides applied), the joint acceleration fraction, the
    cell's TCP limits (None: none), jerk-limited timing of single joint moves."""

    tcp_speed: float
    curve_speed: float
    accel: float = 1.0
    tcp_limits: TcpLimits | None = None
    jerk_limited: bool = True


@dataclass(frozen=True, slots=True, eq=False)
class SplineVariant:
    """The timed spline junction, or why there is none (`problem`)."""

    segments: list[Segment]
    moves: SplineMoves | None
    checks: int
    problem: str = ""

    @property
    def duration(self) -> float:
        return sum(s.duration for s in self.segments) if self.moves is not None else math.inf


def key_poses(robot: RobotModel, waypoints: FloatArray, before: WeldEnd, after: WeldEnd,
              lin_targets: FloatArray | None) -> FloatArray:
    """(k, 4, 4) the path's key poses: spot, approach point, via points, approach point, spot."""
    if lin_targets is not None:
        vias = np.asarray(lin_targets, dtype=float)[:-1]
    else:
        inner = np.asarray(waypoints, dtype=float)[1:-1]
        vias = fk_tcp(robot, inner) if len(inner) else np.zeros((0, 4, 4))
    return np.concatenate([np.asarray([before.T_spot, before.T_app]), vias.reshape(-1, 4, 4),
                           np.asarray([after.T_app, after.T_spot])])


def _speeds(settings: SplineSettings, path_kappa: FloatArray, i_ret: int, i_app: int) -> FloatArray:
    """Line speeds (m/s): the approach lines' up to the retract's end and after the approach
    point, the curve's in between, each within the TCP limits' envelope min(v, sqrt(a_R / kappa))
    over its stretch (mm/s floored)."""
    n = len(path_kappa)
    v = np.full(n, settings.curve_speed)
    v[: i_ret + 1] = settings.tcp_speed
    v[i_app + 1:] = settings.tcp_speed
    lim = settings.tcp_limits
    if lim is not None:
        env = np.where(path_kappa > 0, np.sqrt(lim.a_R / np.maximum(path_kappa, 1e-12)), np.inf)
        v = np.minimum(v, np.minimum(lim.v, env))
    out: FloatArray = np.floor(np.maximum(v, 1e-3) * 1000.0) / 1000.0
    return out


def spline_variant(robot: RobotModel, world: PathChecks, limits: JointLimits, q_start: FloatArray,
                   waypoints: FloatArray, kind: str, label: str, before: WeldEnd, after: WeldEnd,
                   settings: SplineSettings, lin_targets: FloatArray | None = None,
                   beat: float = math.inf) -> SplineVariant:
    """The junction from the spot of `before` (at q_start) to the spot of `after` along the
    spline through the points sampled from the Bézier path through its key poses, timed and
    checked (`problem` says why not). Where it is faster than `beat` (s), also timed as the
    lines the dialects without spline motion write (`SplineMoves.lines_time`)."""
    try:
        design = space_path(key_poses(robot, waypoints, before, after, lin_targets), straight_ends=True)
    except TimingError as exc:
        return SplineVariant([], None, 0, f"no path: {exc}")
    samples = sample_lines(design, SPLINE_TOL_M, MAX_CHORD_M, MIN_CHORD_M)
    written = np.array([as_written_pose(T) for T in samples.poses])
    written[0] = design.poses(np.zeros(1))[0]          # the spot left: where the robot is
    try:
        curve = space_path(written, straight_ends=True)
    except TimingError as exc:
        return SplineVariant([], None, 0, f"no path: {exc}")
    keys = curve.key_s
    kappa = np.array([float(np.max(curve.curvature(np.linspace(a, b, 9)))) for a, b in itertools.pairwise(keys)])
    speeds = _speeds(settings, kappa, 0, len(kappa) - 2)
    names = [("retract", before.label), (kind, label), ("approach", after.label)]
    try:
        cp, segments = spline_motion(robot, curve, q_start, speeds, limits, names, accel=settings.accel)
    except (LinMoveError, TimingError) as exc:
        return SplineVariant([], None, 0, f"cannot be followed: {exc}")
    geo = cp.path
    q_targets = np.asarray(geo(np.clip(keys[1:], 0.0, geo.length)), dtype=float)
    if float(np.max(np.abs(q_targets[-2] - np.asarray(waypoints[-1], dtype=float)))) > ARRIVAL_TOL_RAD:
        return SplineVariant([], None, 0, "arrives in another configuration")
    res = world.check_path(geo.sample(CHECK_STEP_RAD))
    if not res.free:
        return SplineVariant([], None, res.checks, "collides")
    dev = deviation(design, curve.points(np.linspace(0.0, curve.length, DEVIATION_SAMPLES)))
    faster = sum(s.duration for s in segments) < beat
    lines = _lines_time(robot, limits, q_start, written, speeds, settings.accel) if faster else None
    return SplineVariant(segments, SplineMoves(written[1:], speeds, q_targets, (), dev, lines), res.checks)


def _lines_time(robot: RobotModel, limits: JointLimits, q_start: FloatArray, written: FloatArray,
                speeds: FloatArray, accel: float) -> float | None:
    """How long the dialects without spline motion take for the block (`export.spline_lines`):
    its points as lines flown by, timed as the controller runs them; None where that fails."""
    radii = line_flybys(written[1:, :3, 3], written[0, :3, 3])
    steps = [LinStep(T, float(v), flyby_tcp=float(r), accel=accel) for T, v, r in zip(written[1:], speeds, radii,
                                                                                        strict=True)]
    try:
        return sum(s.duration for s in time_chain(chain_path(robot, q_start, steps), steps, limits))
    except (LinMoveError, TimingError):
        return None


def choose(junction: Junction, variant: SplineVariant, native: bool = True) -> tuple[Junction, CartesianChoice]:
    """The faster of the junction as planned and its spline variant, and the choice stated.

    `native`: the robot's own controller runs spline blocks (KUKA `SPLINE`). Where it does not,
    its program runs the block as short lines flown by, which take longer than the spline
    (`SplineMoves.lines_time`); the spline is then kept only where those lines beat the fly-by
    too, so that the controller's own program is never slower than without splines."""
    flyby_time = sum(s.duration for s in junction.segments)
    if variant.moves is None:
        return junction, CartesianChoice("flyby", flyby_time, None, variant.problem)
    if variant.duration >= flyby_time:
        return junction, CartesianChoice("flyby", flyby_time, variant.duration, "slower")
    lines = variant.moves.lines_time
    if not native and (lines is None or lines >= flyby_time):
        return junction, CartesianChoice("flyby", flyby_time, variant.duration, "slower as lines")
    chosen = Junction(variant.segments, 0.0, 0.0, junction.checks + variant.checks, spline=variant.moves)
    return chosen, CartesianChoice("spline", flyby_time, variant.duration)
