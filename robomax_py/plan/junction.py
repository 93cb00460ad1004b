"""The motion between two stops at spots: retract, move or detour, approach — exact or flying by.

A junction is the list of program moves from one spot (or home) to the next: the LIN retract
from the last spot, PTP moves through the transition's waypoints, the LIN approach to the next
spot. Each variant states where the robot flies by (radii in whole or half degrees, so a program
states them exactly); every variant but the exact-stop one leaves the checked polyline and lines,
so it is used only when its geometric path checks collision-free and it is faster.

The electrode tips may come near the part only on the electrode axis: over `process.approach`
from the spot the TCP stays on the line. A blend cuts into the lines it joins, so a
variant that flies by a retract or an approach extends that line beyond the approach point, to
`WeldEnd.T_ext`, by as much as its largest blend cuts in (`extension`); the blend then starts and
ends beyond the approach distance, and `_straight` checks that it does.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.spline_moves import SplineMoves
from robomax_py.program import as_written_joints
from robomax_py.robot import JointLimits, RobotModel, fk_tcp, prismatic_mask
from robomax_py.robot.ik.turns import wrap_to_pi
from robomax_py.timing import Segment, TimingError, ptp_time_estimate
from robomax_py.timing.chain import (
    ChainPath,
    LinStep,
    PtpStep,
    Step,
    chain_path,
    column_of,
    lin_key,
    time_chain,
)
from robomax_py.timing.lin import LinPath, lin_path
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.world.collision import SegmentCheck

# Fly-by radii (deg, Euclidean over the joints) tried where a retract meets a move and a move meets
# an approach; measured on the reference cell: ~1 deg saves a third of the junction's time, larger
# radii reach into the LIN lines' TCP speed limit and gain less.
JUNCTION_RADII_DEG = (1.2, 0.6)
# ... and at the corners of detours (largest first).
DETOUR_RADII_DEG = (12.0, 6.0, 3.0)
# Relative slack taken off the exact-stop lower bound: the timing solvers meet the limits to ~1e-5.
EXACT_BOUND_SLACK = 1e-3
# Spacing of the geometric path samples checked for collisions, rad (Euclidean, joint space).
CHECK_STEP_RAD = 0.005
# A continued line ending this far (rad, any joint) from its approach point changed branch: not used.
MAX_EXTENSION_JOINT_RAD = 0.5
# The TCP is on the electrode axis within this (m) over the approach distance.
STRAIGHT_TOL_M = TOL.straight_tol_m


class PathChecks(Protocol):
    """What a junction needs of a collision world: `CollisionWorld.check_path`."""

    def check_path(self, points: FloatArray) -> SegmentCheck: ...


@dataclass(frozen=True, slots=True, eq=False)
class WeldEnd:
    """One end of a junction at a spot: the TCP poses (robot base frame) and the IK branch."""

    T_spot: FloatArray
    T_app: FloatArray
    column: int | None          # None: the column of the configuration the line starts from
    label: str
    T_ext: FloatArray | None = None     # the line continued beyond T_app (None: no fly-by here)


@dataclass(frozen=True, slots=True, eq=False)
class Extension:
    """Where a fly-by variant's lines end: the retract's target beyond the approach point of the
    spot before (pose and configuration) and the configuration the approach to the next spot
    starts from (None where the line stops at its approach point)."""

    retract_T: FloatArray | None = None
    retract_q: FloatArray | None = None
    approach_q: FloatArray | None = None


@dataclass(frozen=True, slots=True, eq=False)
class Junction:
    """The timed motion of a junction and the fly-by radii it uses (rad; 0: exact stop)."""

    segments: list[Segment]
    junction_radius: float
    corner_radius: float
    checks: int
    extension: Extension = Extension()
    spline: SplineMoves | None = None       # the junction as one Bézier TCP path (`plan.spline_junction`)


def time_junction(
    robot: RobotModel,
    world: PathChecks,
    limits: JointLimits,
    q_start: FloatArray,
    waypoints: FloatArray,
    kind: str,
    label: str,
    before: WeldEnd | None,
    after: WeldEnd | None,
    *,
    tcp_speed: float,
    speed: float = 1.0,
    accel: float = 1.0,
    jerk_limited: bool = True,
    flyby: bool = True,
    lin_targets: FloatArray | None = None,
    lin_speed: float = 0.0,
) -> Junction:
    """The fastest collision-free way through a junction.

    tcp_speed : the LIN lines' TCP speed, m/s (any override applied).
    speed, accel : the PTP moves' speed and acceleration fractions.
    q_start : the configuration at the start (at the spot when `before` is given, else home).
    waypoints : (m, n) the transition's joint path: first row where it starts (not used: the
        motion starts where the retract ends, or at q_start), then the PTP targets, the last the
        approach point of `after` (or home).
    lin_targets : (m - 1, 4, 4), optional: the waypoints after the first are reached by straight
        TCP lines to these poses (robot base frame) at `lin_speed` m/s instead of joint moves; the
        robot then stops at every line's end (no fly-by: the TCP stays on the lines).
    """
    if lin_targets is not None:
        flyby = False
    lin_cache: dict[bytes, LinPath] = {}
    extended = _extension(robot, np.asarray(q_start, dtype=float), waypoints, before, after, lin_cache) if flyby else None

    def steps_of(rj: float, rd: float) -> list[Step] | None:
        ext = extended if rj > 0 else None
        if rj > 0 and ext is None:
            return None
        return _steps(waypoints, kind, label, before, after, tcp_speed, speed, rj, rd, ext, accel,
                      lin_targets=lin_targets, lin_speed=lin_speed)

    def shaped(rj: float, rd: float) -> _Shape | None:
        """The variant's chains and their geometric paths; None where a line cannot be followed."""
        steps = steps_of(rj, rd)
        try:
            return None if steps is None else _chain_paths(robot, q_start, steps, lin_cache)
        except TimingError:
            return None

    def timed_shape(shape: _Shape) -> tuple[float, list[ChainPath], list[Segment]] | None:
        try:
            return _time_shape(shape, limits, jerk_limited)
        except TimingError:
            return None

    def timed(rj: float, rd: float) -> tuple[float, list[ChainPath], list[Segment]] | None:
        shape = shaped(rj, rd)
        return None if shape is None else timed_shape(shape)

    exact: tuple[float, list[ChainPath], list[Segment]] | None = None

    def exact_motion() -> tuple[float, list[ChainPath], list[Segment]]:
        nonlocal exact
        if exact is None:
            exact = timed(0.0, 0.0)
            if exact is None:
                raise TimingError(f"{label}: the exact-stop motion cannot be timed")
        return exact

    if not flyby:
        return Junction(exact_motion()[2], 0.0, 0.0, 0)
    # The exact-stop motion is only the fallback and the time to beat: a fly-by variant faster
    # than a lower bound of its time beats it without it being timed (same choice, less work).
    best: tuple[float, list[ChainPath], list[Segment]] | None = None
    best_rj, best_rd, checks = 0.0, 0.0, 0

    def faster(trial: tuple[float, list[ChainPath], list[Segment]]) -> bool:
        if best is not None:
            return trial[0] < best[0]
        stops = _steps(waypoints, kind, label, before, after, tcp_speed, speed, 0.0, 0.0, accel=accel)
        bound = _exact_lower_bound(q_start, stops, trial[1], limits)
        return trial[0] < bound or trial[0] < exact_motion()[0]

    corner_options = [np.deg2rad(r) for r in DETOUR_RADII_DEG] if len(waypoints) > 2 else []
    junction_options = [np.deg2rad(r) for r in JUNCTION_RADII_DEG] if (before or after) else []
    # Corners on their own first (the fastest radius that checks free), then the junctions with
    # that corner radius (the first radius, largest first, that is faster and checks free).
    # A variant is taken where it is faster and its path checks free (and straight along the
    # electrode axis): both are pure tests, so the order they run in changes only what they cost.
    # Against the exact stop (no variant taken yet) a fly-by nearly always wins (its time is below
    # the exact stop's lower bound in 9 of 10 trials on a 240-spot clamped cell), so its geometry
    # decides and is checked first: a path that fails is not timed (a TOPP-RA run, several times
    # the cost of a failing check). Against a variant already taken the time decides more often
    # (a smaller corner or a junction fly-by is often slower), so it is timed first.
    for options, corners in ((corner_options, True), (junction_options, False)):
        for radius in options:
            rj, rd = (best_rj, radius) if corners else (radius, best_rd)
            shape = shaped(rj, rd)
            if shape is None:
                continue
            trial: tuple[float, list[ChainPath], list[Segment]] | None = None
            if best is not None:
                trial = timed_shape(shape)
                if trial is None or not faster(trial):
                    continue
            free, used = _path_free(world, shape)
            checks += used
            if not free or not (rj == 0 or _straight(robot, shape, before, after)):
                continue
            if trial is None:
                trial = timed_shape(shape)
                if trial is None or not faster(trial):
                    continue
            best, best_rj, best_rd = trial, rj, rd
            if not corners:
                break                      # smaller junction radii only pass the corner more slowly
    if best is None:
        best = exact_motion()
    extension = extended if best_rj > 0 and extended is not None else Extension()
    return Junction(best[2], best_rj, best_rd, checks, extension)


def time_junction_at(
    robot: RobotModel, world: PathChecks, limits: JointLimits, q_start: FloatArray, waypoints: FloatArray,
    kind: str, label: str, before: WeldEnd | None, after: WeldEnd | None, junction_radius: float,
    corner_radius: float, *, tcp_speed: float, speed: float = 1.0, jerk_limited: bool = True,
) -> Junction | None:
    """The junction flown by with exactly these radii (rad; 0: stop), or None when that motion
    cannot be timed or leaves free space (several pieces of one transition share their radii)."""
    ext = None
    lin_cache: dict[bytes, LinPath] = {}
    if junction_radius > 0:
        ext = _extension(robot, np.asarray(q_start, dtype=float), waypoints, before, after, lin_cache)
        if ext is None:
            return None
    steps = _steps(waypoints, kind, label, before, after, tcp_speed, speed, junction_radius, corner_radius, ext)
    # Its path checked before it is timed: a path that leaves free space is not timed at all.
    try:
        shape = _chain_paths(robot, q_start, steps, lin_cache)
    except TimingError:
        return None
    free, used = _path_free(world, shape)
    if not free or (junction_radius > 0 and not _straight(robot, shape, before, after)):
        return None
    try:
        _, _, segments = _time_shape(shape, limits, jerk_limited)
    except TimingError:
        return None
    return Junction(segments, junction_radius, corner_radius, used, ext or Extension())


def _exact_lower_bound(q_start: FloatArray, steps: list[Step], paths: list[ChainPath], limits: JointLimits) -> float:
    """A lower bound (s) of the time of `steps` stopping at every target: each move takes at least
    its slowest joint's rest-to-rest time under the velocity and acceleration limits it may use.
    The targets are those of a fly-by variant's paths of the same moves (the same LIN ends, the
    same PTP targets); shrunk by EXACT_BOUND_SLACK for solver round-off."""
    targets = np.vstack([p.targets for p in paths])
    if len(targets) != len(steps):
        return 0.0
    total, prev = 0.0, np.asarray(q_start, dtype=float)
    for step, target in zip(steps, targets):
        fraction, accel = (step.speed, step.accel) if isinstance(step, PtpStep) else (1.0, 1.0)
        total += float(ptp_time_estimate(prev, target, limits, fraction, accel=accel, straight=False))
        prev = target
    return total * (1.0 - EXACT_BOUND_SLACK)


def _steps(
    waypoints: FloatArray, kind: str, label: str, before: WeldEnd | None, after: WeldEnd | None,
    tcp_speed: float, speed: float, rj: float, rd: float, ext: Extension | None = None, accel: float = 1.0,
    *, lin_targets: FloatArray | None = None, lin_speed: float = 0.0,
) -> list[Step]:
    steps: list[Step] = []
    if before is not None:
        T = ext.retract_T if ext is not None and ext.retract_T is not None else before.T_app
        steps.append(LinStep(T, tcp_speed, before.column, flyby=rj, kind="retract", label=before.label, accel=accel))
    if lin_targets is not None:
        # Lines through the detour's via points, each in the branch it starts in, stopping at each.
        steps += [LinStep(T, lin_speed, None, kind=kind, label=label, accel=accel) for T in lin_targets]
        if after is not None:
            steps.append(LinStep(after.T_spot, tcp_speed, after.column, kind="approach", label=after.label,
                                 accel=accel))
        return steps
    targets = np.asarray(waypoints, dtype=float)[1:]
    if after is not None and ext is not None and ext.approach_q is not None:
        targets = np.vstack([targets[:-1], ext.approach_q[None, :]])
    for w, q in enumerate(targets):
        last = w == len(targets) - 1
        fly = (rj if after is not None else 0.0) if last else rd
        steps.append(PtpStep(q, speed=speed, accel=accel, flyby=fly, kind=kind, label=label))
    if after is not None:
        steps.append(LinStep(after.T_spot, tcp_speed, after.column, kind="approach", label=after.label, accel=accel))
    return steps


def _extension(robot: RobotModel, q_start: FloatArray, waypoints: FloatArray, before: WeldEnd | None,
               after: WeldEnd | None, lin_cache: dict[bytes, LinPath] | None = None) -> Extension | None:
    """The lines continued to T_ext in their branches (the retract's end pose and configuration,
    the approach's start configuration, as programs state them); None when a line cannot be.
    lin_cache : the junction's `chain_path` cache: the continued retract is kept there, where the
    fly-by variants' chains find it (the same line, followed the same way)."""
    retract_T = retract_q = approach_q = None
    if before is not None and before.T_ext is not None:
        # The retract from the spot, as the chain will follow it (`chain_path`) in the column of
        # its start: the cache's entry for a line naming no column.
        key = lin_key(q_start, before.T_ext, None)
        lp = None if lin_cache is None else lin_cache.get(key)
        if lp is None:
            lp = lin_path(robot, fk_tcp(robot, q_start), before.T_ext, column_of(robot, q_start), q_start=q_start)
            if lin_cache is not None:
                lin_cache[key] = lp
        if not lp.ok:
            return None
        retract_T, retract_q = before.T_ext, np.asarray(lp.q[-1], dtype=float)
    if after is not None and after.T_ext is not None:
        q_app = np.asarray(waypoints[-1], dtype=float)
        lp = lin_path(robot, after.T_app, after.T_ext, column_of(robot, q_app))
        if not lp.ok:
            return None
        # The same turn as the approach point (the column's solution may be 2 pi away on a joint).
        q_ext = np.array(lp.q[-1], dtype=float)
        revolute = ~prismatic_mask(robot.model)
        q_ext[revolute] = q_app[revolute] + wrap_to_pi(q_ext[revolute] - q_app[revolute])
        if float(np.abs(q_ext - q_app).max()) > MAX_EXTENSION_JOINT_RAD or not bool(robot.limits.contains(q_ext)):
            return None
        approach_q = as_written_joints(q_ext, robot.prismatic)
    return Extension(retract_T, retract_q, approach_q)


def _straight(robot: RobotModel, shape: _Shape, before: WeldEnd | None, after: WeldEnd | None) -> bool:
    """Whether the TCP stays on the electrode axis, on the approach side, over the approach
    distance: from the spot the junction leaves (the start of its first chain) or reaches (the
    end of its last) until it is the approach distance up the axis (within STRAIGHT_TOL_M)."""
    last = len(shape.paths) - 1
    for end, k, reverse in ((before, 0, False), (after, last, True)):
        if end is None or last < 0:
            continue
        origin = np.asarray(end.T_spot, dtype=float)[:3, 3]
        axis = np.asarray(end.T_app, dtype=float)[:3, 3] - origin
        approach = float(np.linalg.norm(axis))
        if approach <= 0.0:
            continue
        axis /= approach
        tcp = shape.tcp(robot, k)
        for p in (tcp[::-1] if reverse else tcp):
            rel = p - origin
            along = float(rel @ axis)
            if along >= approach - STRAIGHT_TOL_M or float(np.linalg.norm(rel)) > approach:
                break
            if along < -STRAIGHT_TOL_M or float(np.linalg.norm(rel - along * axis)) > STRAIGHT_TOL_M:
                return False
    return True


def split_chains(steps: list[Step]) -> list[list[Step]]:
    """Maximal runs of steps in which every step but the last flies by."""
    chains: list[list[Step]] = [[]]
    for step in steps:
        chains[-1].append(step)
        if step.flyby <= 0.0:
            chains.append([])
    return [c for c in chains if c]


@dataclass(frozen=True, slots=True, eq=False)
class _Shape:
    """A variant's chains of steps and their geometric paths, not yet timed."""

    chains: list[list[Step]]
    paths: list[ChainPath]
    # Chain k's path sampled for the checks (CHECK_STEP_RAD apart) and the TCP positions there,
    # made on first use: the collision check and both ends' straightness check (one chain, where
    # the junction flies by all of it) read the same samples.
    _points: dict[int, FloatArray] = field(default_factory=dict)
    _tcp: dict[int, FloatArray] = field(default_factory=dict)

    def points(self, k: int) -> FloatArray:
        """(m, n) samples of chain k's path, rad."""
        if k not in self._points:
            self._points[k] = self.paths[k].path.sample(CHECK_STEP_RAD)
        return self._points[k]

    def tcp(self, robot: RobotModel, k: int) -> FloatArray:
        """(m, 3) TCP positions at `points(k)`, m (robot base frame)."""
        if k not in self._tcp:
            self._tcp[k] = fk_tcp(robot, self.points(k))[:, :3, 3]
        return self._tcp[k]


def _chain_paths(robot: RobotModel, q_start: FloatArray, steps: list[Step], lin_cache: dict[bytes, LinPath]) -> _Shape:
    """Each chain's path, each starting where the one before ends (its last target)."""
    q = np.asarray(q_start, dtype=float)
    chains = split_chains(steps)
    paths: list[ChainPath] = []
    for chain in chains:
        path = chain_path(robot, q, chain, lin_cache=lin_cache)
        paths.append(path)
        q = np.asarray(path.targets[-1], dtype=float)
    return _Shape(chains, paths)


def _time_shape(shape: _Shape, limits: JointLimits, jerk_limited: bool) -> tuple[float, list[ChainPath], list[Segment]]:
    segments: list[Segment] = []
    for chain, path in zip(shape.chains, shape.paths):
        segments.extend(time_chain(path, chain, limits, jerk_limited=jerk_limited))
    return sum(s.duration for s in segments), shape.paths, segments


def _path_free(world: PathChecks, shape: _Shape) -> tuple[bool, int]:
    """Whether every chain's geometric path is free (checked between samples CHECK_STEP_RAD apart);
    the collision checks it took."""
    checks = 0
    for k, chain in enumerate(shape.paths):
        if not np.any(chain.radii > 0):
            continue                       # an exact-stop chain is the checked polyline / line itself
        res = world.check_path(shape.points(k))
        checks += res.checks
        if not res.free:
            return False, checks
    return True, checks
