"""Chains of PTP and LIN moves flying by their intermediate targets: one path, one timing.

A robot program is a list of moves. A move marked fly-by with radius r is not stopped at: the
path leaves the programmed one within r (Euclidean joint-space distance, rad) of that move's
target and joins the next move's path with a quintic matching position, first and second
derivative (`blend.blend_chain`). A *chain* is a maximal run of moves in which every move but the
last flies by; it starts and ends at rest.

- A chain of one PTP move is a jerk-limited synchronised joint move (ruckig), unless jerk
  limiting is off (then toppra on the straight line).
- Every other chain (a LIN move; fly-by through several moves) is timed time-optimally by toppra
  on the blended path under the joint velocity and acceleration limits (no jerk limit), moving at
  the lowest `speed` of its PTP moves and the lowest `accel` of all its moves; LIN moves, and the joins next to them, also
  keep their TCP speed.

The planner and `robomax verify` both build motion with `chain_path` and `time_chain`, so a
program rebuilt from its statements follows the path that was planned and checked.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Hashable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.robot import JointLimits, RobotModel, fk_tcp, prismatic_mask
from robomax_py.spec import frozen_array
from robomax_py.timing._common import DEFAULT_DT_S, ZERO_MOVE, TimingError
from robomax_py.timing.blend import blend_chain
from robomax_py.timing.lin import IkSolver, LinPath, lin_path
from robomax_py.timing.paths import GeometricPath, line_path
from robomax_py.timing.ptp import ptp_move
from robomax_py.timing.topp import time_path_phases
from robomax_py.timing.trajectory import Segment

# Samples per join for the TCP speed bound next to a LIN move; the bound is their largest finite
# difference speed times this safety factor (the joins are short quintics, smooth on this scale).
JOIN_TCP_SAMPLES = 41
JOIN_TCP_SAFETY = 1.05
# A TCP-distance fly-by needs a move that displaces the TCP at least this much (m).
MIN_TCP_CHORD_M = 1e-3
# Stands for "no limit" in the path speed limit toppra receives (it needs finite values).
UNLIMITED_PATH_SPEED = 1e9
# Chains kept built and timed (`chain_path`, `time_chain`), each; the oldest go first.
CHAIN_MEMO_SIZE = 256


@dataclass(frozen=True, slots=True, eq=False)
class PtpStep:
    """A joint move to q (rad); speed and accel are fractions of the robot's limits."""

    q: FloatArray
    speed: float = 1.0
    accel: float = 1.0
    flyby: float = 0.0               # rad; 0: stop exactly at q
    kind: str = "move"
    label: str = ""
    flyby_tcp: float = 0.0           # m: the fly-by as a TCP distance (`tcp_flyby_radius`)


@dataclass(frozen=True, slots=True, eq=False)
class LinStep:
    """A Cartesian straight line of the TCP to T (4, 4, robot base frame) at up to tcp_speed m/s.

    column : the IK table column (`robomax_py.robot.ik.solve_all`) to follow; None: the one whose
    solution at the line's start is the configuration the line starts from.
    """

    T: FloatArray
    tcp_speed: float
    column: int | None = None
    flyby: float = 0.0
    kind: str = "approach"
    label: str = ""
    flyby_tcp: float = 0.0
    accel: float = 1.0               # fraction of the joint acceleration and jerk limits, as a PTP's


Step = PtpStep | LinStep


@dataclass(frozen=True, slots=True, eq=False)
class ChainPath:
    """The geometric path of a chain.

    path : GeometricPath
    ranges : (m, 2) float
        s range of each step's own (unblended) part of `path`.
    radii : (m - 1,) float
        Fly-by radius used after each step but the last, rad (0: the path stops there).
    targets : (m, n) float
        Configuration at each step's programmed target (the end of its unblended path), rad.
    cuts : (m + 1,) float
        Where one step's share of the motion ends and the next begins: the middle of each join.
    """

    path: GeometricPath
    ranges: FloatArray
    radii: FloatArray
    targets: FloatArray
    cuts: FloatArray
    tcp_limits: tuple[tuple[float, float, float], ...]   # (s0, s1, largest ds/dt) where a TCP speed applies


def chain_path(
    robot: RobotModel, q_start: FloatArray, steps: Sequence[Step], *, ik: IkSolver | None = None,
    lin_cache: dict[bytes, LinPath] | None = None,
) -> ChainPath:
    """The blended path of a chain of moves starting (at rest) at q_start.

    lin_cache : optional dict reused across calls: LIN joint paths by start configuration, target
        and column (the same line in variants that differ only in their fly-by radii).

    Raises LinMoveError when a LIN move cannot be followed in its branch, TimingError for a chain
    without motion.
    """
    if not steps:
        raise TimingError("a chain needs at least one move")
    q = np.asarray(q_start, dtype=float).reshape(-1)
    if _PATHS and next(iter(_PATHS.values()))[0] is not robot:
        # One robot's chains at a time: a robot model holds its meshes, and a batch worker plans
        # cell after cell, each loading its own.
        _PATHS.clear()
        _TIMED.clear()
    key = (id(robot), id(ik), q.tobytes(), tuple(_step_key(step) for step in steps))
    hit = _PATHS.get(key)
    if hit is not None and hit[0] is robot and hit[1] is ik:
        _PATHS.move_to_end(key)
        return hit[2]
    chain = _build_chain_path(robot, q, steps, ik, lin_cache)
    _remember(_PATHS, key, (robot, ik, chain))
    return chain


# Chains built and timed in this process, by everything each depends on. Both are pure functions
# of those inputs, and the same chain comes back: the planner builds and times a junction's
# exact-stop lines again in every fly-by variant it tries, and the proof of a written program
# rebuilds and times each chain from the joint values, poses and radii the planner used (the
# program states them exactly), so each distinct chain is built and timed once. A chain that
# differs in any bit (a writer's mistake) is a new entry, built and timed afresh. Entries hold the
# robot, solver and chain whose ids their keys use, so no other object takes that id while they
# live. Bounded (CHAIN_MEMO_SIZE); the oldest go first, and all of them when another robot's
# chain is built.
_PATHS: OrderedDict[tuple[Hashable, ...], tuple[RobotModel, IkSolver | None, ChainPath]] = OrderedDict()
_TIMED: OrderedDict[tuple[Hashable, ...], tuple[ChainPath, tuple[Segment, ...]]] = OrderedDict()


def _remember(memo: OrderedDict[tuple[Hashable, ...], Any], key: tuple[Hashable, ...], value: Any) -> None:
    memo[key] = value
    if len(memo) > CHAIN_MEMO_SIZE:
        memo.popitem(last=False)


def _step_key(step: Step) -> tuple[Hashable, ...]:
    """Everything of a step that its chain's path depends on."""
    if isinstance(step, PtpStep):
        return ("ptp", np.asarray(step.q, dtype=float).tobytes(), step.flyby, step.flyby_tcp)
    return ("lin", np.asarray(step.T, dtype=float).tobytes(), step.tcp_speed, step.column, step.flyby, step.flyby_tcp)


def _build_chain_path(robot: RobotModel, q: FloatArray, steps: Sequence[Step], ik: IkSolver | None,
                      lin_cache: dict[bytes, LinPath] | None) -> ChainPath:
    pieces: list[GeometricPath | None] = []
    tcp_rate: list[float | None] = []             # per step: largest ds/dt from its TCP speed
    targets = []
    radii_by_step: list[float] = []
    for step in steps:
        q_before = q
        if isinstance(step, PtpStep):
            target = np.asarray(step.q, dtype=float).reshape(-1)
            moved = float(np.linalg.norm(target - q)) > ZERO_MOVE
            pieces.append(line_path(q, target) if moved else None)
            tcp_rate.append(None)
            q = target
        else:
            key = lin_key(q, step.T, step.column)
            lp = None if lin_cache is None else lin_cache.get(key)
            if lp is None:
                column = step.column if step.column is not None else column_of(robot, q, ik)
                lp = lin_path(robot, fk_tcp(robot, q), step.T, column, q_start=q, ik=ik)
                if lin_cache is not None:
                    lin_cache[key] = lp
            if not lp.ok:
                raise lp.error()
            if len(lp.s) < 2:
                pieces.append(None)
                tcp_rate.append(None)
            else:
                pieces.append(lp.path)
                per_m = lp.length / lp.tcp_length if lp.tcp_length > 0 else 1.0
                tcp_rate.append(step.tcp_speed * per_m)
            q = np.asarray(lp.q[-1], dtype=float)
        targets.append(q.copy())
        radii_by_step.append(step.flyby if step.flyby_tcp <= 0 else tcp_flyby_radius(robot, q_before, q, step.flyby_tcp))
    moving = [k for k, p in enumerate(pieces) if p is not None]
    if not moving:
        raise TimingError("the chain does not move")
    radii_in = [radii_by_step[k] for k in moving[:-1]]
    blended = blend_chain([p for p in pieces if p is not None], radii_in)
    m = len(steps)
    ranges = np.zeros((m, 2))
    radii = np.zeros(max(m - 1, 0))
    last_end = 0.0
    for idx, k in enumerate(moving):
        ranges[k] = blended.piece_ranges[idx]
        if idx < len(moving) - 1:
            radii[k] = blended.radii[idx]
    for k in range(m):                             # steps without motion sit where the path is then
        if pieces[k] is None:
            ranges[k] = (last_end, last_end)
        last_end = ranges[k][1]
    cuts = np.concatenate([[0.0], 0.5 * (ranges[:-1, 1] + ranges[1:, 0]), [blended.path.length]])
    cuts = np.maximum.accumulate(cuts)
    limits: list[tuple[float, float, float]] = []
    pr = blended.piece_ranges
    for idx, k in enumerate(moving):
        rate = tcp_rate[k]
        if rate is None:
            continue
        limits.append((float(pr[idx][0]), float(pr[idx][1]), rate))
        # The joins on either side of a LIN move keep its TCP speed too.
        joins = []
        if idx > 0:
            joins.append((float(pr[idx - 1][1]), float(pr[idx][0])))
        if idx < len(moving) - 1:
            joins.append((float(pr[idx][1]), float(pr[idx + 1][0])))
        for lo, hi in joins:
            if hi > lo:
                limits.append((lo, hi, _tcp_rate_bound(robot, blended.path, lo, hi, steps[k])))
    return ChainPath(blended.path, frozen_array(ranges), frozen_array(radii), frozen_array(np.array(targets)),
                     frozen_array(cuts), tuple(limits))


def lin_key(q_start: FloatArray, T: FloatArray, column: int | None) -> bytes:
    """A LIN move's key in a `chain_path` lin_cache: where it starts, its target and the column asked for
    (None: the start's own, `column_of`)."""
    return np.asarray(q_start, dtype=float).tobytes() + np.asarray(T, dtype=float).tobytes() + str(column).encode()


def tcp_flyby_radius(robot: RobotModel, q_from: FloatArray, q_to: FloatArray, distance_m: float) -> float:
    """The joint-space fly-by radius (rad) of a move q_from -> q_to whose fly-by is stated as a TCP
    distance (KRL `C_DIS`, RAPID zones, URScript `r`): the distance times the move's ratio of
    joint-space chord to TCP chord. Writers state distance = radius / ratio with the same ratio,
    so the radius comes back as planned. A move that does not displace the TCP has no such
    ratio; its fly-by cannot be stated this way (radius 0: it stops).
    """
    q_from = np.asarray(q_from, dtype=float)
    q_to = np.asarray(q_to, dtype=float)
    tcp = float(np.linalg.norm(fk_tcp(robot, q_to)[:3, 3] - fk_tcp(robot, q_from)[:3, 3]))
    if tcp < MIN_TCP_CHORD_M:
        return 0.0
    return distance_m * float(np.linalg.norm(q_to - q_from)) / tcp


def flyby_tcp_distance(robot: RobotModel, q_from: FloatArray, q_to: FloatArray, radius_rad: float) -> float:
    """Inverse of `tcp_flyby_radius`: the TCP distance (m) that states a joint-space radius;
    raises TimingError for a move that does not displace the TCP."""
    q_from = np.asarray(q_from, dtype=float)
    q_to = np.asarray(q_to, dtype=float)
    tcp = float(np.linalg.norm(fk_tcp(robot, q_to)[:3, 3] - fk_tcp(robot, q_from)[:3, 3]))
    joint = float(np.linalg.norm(q_to - q_from))
    if tcp < MIN_TCP_CHORD_M or joint <= 0.0:
        raise TimingError(f"the move displaces the TCP by {tcp * 1000:.3f} mm only: its fly-by cannot be "
                          "stated as a TCP distance")
    return radius_rad * tcp / joint


def _tcp_rate_bound(robot: RobotModel, path: GeometricPath, s0: float, s1: float, step: Step) -> float:
    """Largest ds/dt on [s0, s1] keeping the TCP at or below the step's TCP speed."""
    assert isinstance(step, LinStep)
    s = np.linspace(s0, s1, JOIN_TCP_SAMPLES)
    p = fk_tcp(robot, path(s))[:, :3, 3]
    rate = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(s)
    worst = float(np.max(rate)) * JOIN_TCP_SAFETY
    return step.tcp_speed / worst if worst > 0 else UNLIMITED_PATH_SPEED


def time_chain(
    chain: ChainPath,
    steps: Sequence[Step],
    limits: JointLimits,
    *,
    speed: float = 1.0,
    jerk_limited: bool = True,
    dt: float = DEFAULT_DT_S,
) -> list[Segment]:
    """One segment per step (kind and label from the step), at rest at both ends of the chain.

    speed : global override in (0, 1] applied on top of each move's own speed.
    """
    # The steps' kinds and labels only name the segments: a chain timed under other names (the
    # proof reads a detour's moves back as plain moves) takes the timing and is named anew.
    key = (id(chain), speed, jerk_limited, dt, *(np.asarray(a, dtype=float).tobytes() for a in (
        limits.lower, limits.upper, limits.velocity, limits.acceleration, limits.jerk)),
        tuple((isinstance(s, PtpStep), s.speed if isinstance(s, PtpStep) else 1.0, s.accel) for s in steps))
    hit = _TIMED.get(key)
    if hit is not None and hit[0] is chain:
        _TIMED.move_to_end(key)
        return [seg if (seg.kind, seg.label) == (step.kind, step.label) else
                replace(seg, kind=step.kind, label=step.label) for seg, step in zip(hit[1], steps)]
    segments = _time_chain(chain, steps, limits, speed, jerk_limited, dt)
    if len(segments) == len(steps):
        _remember(_TIMED, key, (chain, tuple(segments)))
    return segments


def _time_chain(chain: ChainPath, steps: Sequence[Step], limits: JointLimits, speed: float, jerk_limited: bool,
                dt: float) -> list[Segment]:
    ptp = [s for s in steps if isinstance(s, PtpStep)]
    if len(steps) == 1 and ptp and jerk_limited:
        step = ptp[0]
        return [ptp_move(chain.path.start, chain.path.end, limits, speed * step.speed, accel=step.accel,
                         kind=step.kind, label=step.label, dt=dt)]
    chain_speed = speed * min((s.speed for s in ptp), default=1.0)
    chain_accel = min((s.accel for s in steps), default=1.0)
    bounds = chain.tcp_limits

    def path_speed_limit(s: FloatArray) -> FloatArray:
        s = np.asarray(s, dtype=float)
        out = np.full(s.shape, UNLIMITED_PATH_SPEED)
        for lo, hi, rate in bounds:
            inside = (s >= lo - 1e-12) & (s <= hi + 1e-12)
            out[inside] = np.minimum(out[inside], rate)
        return out

    names = [(s.kind, s.label) for s in steps]
    return time_path_phases(chain.path, limits, chain.cuts, names, chain_speed, accel=chain_accel,
                            path_speed_limit=path_speed_limit if bounds else None, dt=dt)


def column_of(robot: RobotModel, q: FloatArray, ik: IkSolver | None = None) -> int:
    """The IK table column whose solution at FK(q) is q (up to whole turns)."""
    from robomax_py.timing.lin import _default_ik

    solve = ik if ik is not None else _default_ik()
    q = np.asarray(q, dtype=float).reshape(-1)
    # A seeded solver (numeric, table) holds the solutions its seeds reached: seeded at q itself,
    # q is found (its solution comes first); a closed form finds every branch without it.
    seeded = robot.ik_solver in ("numeric", "table")
    table = solve(robot, fk_tcp(robot, q)[None], q) if seeded else solve(robot, fk_tcp(robot, q)[None])
    sols = np.asarray(table.q)[0]
    valid = np.asarray(table.valid)[0]
    revolute = ~prismatic_mask(robot.model)
    delta = sols - q
    delta[:, revolute] = (delta[:, revolute] + np.pi) % (2 * np.pi) - np.pi
    diff = np.abs(delta).max(axis=1)
    diff[~valid] = np.inf
    k = int(np.argmin(diff))
    if not np.isfinite(diff[k]) or diff[k] > 1e-6:
        raise TimingError("the configuration is not among the IK solutions of its own pose")
    return k
