"""Cartesian straight-line (LIN) moves: TCP position linear, orientation slerp, in one IK branch.

`lin_path` samples the line (every `step` metres of travel, `rot_step` radians of rotation), solves
the IK in one branch column and follows it continuously:

* at each sample the branch column's solution is taken, shifted by whole turns (2 pi) to the
  value nearest the previous sample for revolute joints (IK solvers wrap angles, and a column may
  hold a turn variant that stops being valid when the wrapped angle crosses pi);
* if that column is invalid or jumps, the nearest valid solution of any column is accepted when it
  is within `max_joint_step` of the previous sample (a continuous continuation of the motion);
* otherwise the step is bisected (new IK calls) down to `MIN_REFINE_M` of TCP travel; a jump that
  survives is a discontinuity (branch change, singularity), reported with its position;
* finally the joint path (a C2 cubic spline through the samples) is checked by forward kinematics
  halfway between samples and refined until the TCP is within `path_tol` of the line.

`lin_move` then times that joint path with toppra under the joint velocity/acceleration limits and
a TCP speed limit, from rest to rest. The path parameter s is TCP travel in metres (for a pure
re-orientation: ROT_LENGTH_M per radian), so the TCP speed limit is a constant bound on ds/dt.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.robot import JointLimits, RobotModel
from robomax_py.spec import frozen_array
from robomax_py.timing._common import DEFAULT_DT_S, LIMIT_TOL, LinMoveError, TimingError
from robomax_py.timing._lin_track import (
    ROT_LENGTH_M,
    ZERO_LENGTH_M,
    IkSolver,
    Line,
    Tracker,
    off_line,
)
from robomax_py.timing.paths import GeometricPath, spline_path
from robomax_py.timing.topp import time_path
from robomax_py.timing.trajectory import Segment
from robomax_py.tolerances import DEFAULT as TOL

# Sampling of the line: metres of TCP travel and radians of TCP rotation between IK samples.
LIN_STEP_M = 0.001
LIN_ROT_STEP_RAD = 0.002
# Consecutive samples further apart than this (rad, any joint) are bisected; a jump this large
# that survives bisection down to MIN_REFINE_M of travel is a discontinuity.
LIN_MAX_JOINT_STEP_RAD = 0.02
MIN_REFINE_M = 1e-6
# The joint path is refined until the TCP is this close to the line halfway between samples (m),
# in at most this many rounds.
LIN_PATH_TOL_M = TOL.lin_path_tol_m
LIN_REFINE_ROUNDS = 8
# q_start must be an IK solution of T_start within this (rad, any joint).
START_TOL_RAD = TOL.start_tol_rad
# Below this the line has no rotation (rad).
ZERO_ANGLE_RAD = 1e-9

__all__ = ["ROT_LENGTH_M", "IkSolver", "LinPath", "lin_move", "lin_path", "time_lin_path"]


@dataclass(frozen=True, slots=True, eq=False)
class LinPath:
    """The joint path of a Cartesian line in one IK branch, or why there is none.

    ok : bool
    reason : str
        "" when ok; else "unreachable", "discontinuous", "joint_limit" or "start_mismatch".
    detail : str
        A sentence for messages.
    index : int
        First failing sample (-1 when ok); fraction : its position along the line, 0..1.
    s : (k,) float
        Path parameter of the samples: metres of TCP travel (see ROT_LENGTH_M), from 0.
    q : (k, n) float
        Joint values at the samples, rad; up to the failure when not ok.
    tcp_length : float
        Distance between the end positions, m.
    tcp_angle : float
        Rotation between the end orientations, rad.
    """

    ok: bool
    reason: str
    detail: str
    index: int
    fraction: float
    s: FloatArray
    q: FloatArray
    tcp_length: float
    tcp_angle: float
    # The joint path, built on first use and kept: a line in a junction's LIN cache joins the
    # chains of several fly-by variants, and the spline (and its polynomial, `GeometricPath`)
    # cost more than the lookups. Derived from `s` and `q` only.
    _path: GeometricPath | None = field(default=None, init=False, repr=False, compare=False)

    @property
    def length(self) -> float:
        """Path parameter length (metres of TCP travel, or ROT_LENGTH_M per radian without travel)."""
        return float(self.s[-1])

    @property
    def path(self) -> GeometricPath:
        """The joint path q(s) as a C2 cubic spline through the samples (needs ok and two samples)."""
        if not self.ok:
            raise self.error()
        if len(self.s) < 2:
            raise TimingError("a LIN path without motion has no geometric path")
        if self._path is None:
            object.__setattr__(self, "_path", spline_path(self.s, self.q))
        assert self._path is not None
        return self._path

    def error(self) -> LinMoveError:
        """The failure as an exception (for ok paths: a TimingError saying so)."""
        if self.ok:
            raise TimingError("the LIN path is fine; there is no error")
        return LinMoveError(self.reason, self.index, self.fraction, self.detail)


# Samples of one LIN move at most (1 mm steps: a 20 m line; no arm reaches that far): a target in
# the wrong unit (a program in m read as mm) fails here instead of sampling kilometres.
MAX_LIN_SAMPLES = 20_000


def lin_path(
    robot: RobotModel,
    T_start: FloatArray,
    T_end: FloatArray,
    branch_index: int,
    *,
    q_start: FloatArray | None = None,
    step: float = LIN_STEP_M,
    rot_step: float = LIN_ROT_STEP_RAD,
    max_joint_step: float = LIN_MAX_JOINT_STEP_RAD,
    path_tol: float = LIN_PATH_TOL_M,
    ik: IkSolver | None = None,
) -> LinPath:
    """Follow the straight line T_start -> T_end continuously in IK branch column `branch_index`.

    Parameters
    ----------
    T_start, T_end : (4, 4) float
        TCP poses in the robot base frame, m.
    branch_index : int
        Column k of the IK table (`robomax_py.robot.ik.solve_all`) to start in.
    q_start : (n,) float, optional
        The configuration the move starts from, rad (e.g. the end of the previous move); it must
        solve T_start. Default: column k's solution at T_start.
    step, rot_step : float
        Sample spacing, m of travel and rad of rotation.
    max_joint_step : float
        rad; see the module docstring.
    path_tol : float
        m; largest TCP distance from the line between samples after refinement.
    ik : callable, optional
        IK solver with `solve_all`'s signature (default `robomax_py.robot.ik.solve_all`).

    Returns
    -------
    LinPath
        Never raises for an infeasible line: `ok` and `reason` say what happened.
    """
    line = Line.between(T_start, T_end)
    tracker = Tracker(robot, ik if ik is not None else _default_ik(), line, branch_index, max_joint_step)
    seed = np.asarray(q_start, dtype=float).reshape(-1) if q_start is not None and tracker.seeded else None
    first = tracker.solve(np.zeros(1), seed)
    if q_start is not None:
        q0 = np.asarray(q_start, dtype=float).reshape(-1)
        near = tracker.nearest(first, 0, q0)
        if near is None or float(np.max(np.abs(near - q0))) > START_TOL_RAD:
            return _failed(line, "start_mismatch", "q_start does not solve T_start", 0.0, [0.0], [q0])
    else:
        own = tracker.column(first, 0)
        if own is None:
            reason = "joint_limit" if tracker.reachable(first, 0) else "unreachable"
            detail = f"no solution in branch {branch_index} at the start"
            return _failed(line, reason, detail, 0.0, [0.0], [np.full(robot.dof, np.nan)])
        q0 = own
    if line.length <= 0.0:
        return LinPath(True, "", "", -1, 0.0, frozen_array([0.0]), frozen_array(q0[None]), line.tcp_length, line.tcp_angle)

    count = 1 + max(1, int(np.ceil(line.tcp_length / step)), int(np.ceil(line.tcp_angle / rot_step)))
    if count > MAX_LIN_SAMPLES:
        detail = f"the line is {line.tcp_length:.1f} m long, longer than any arm can follow in one move"
        return _failed(line, "unreachable", detail, 0.0, [0.0], [q0])
    followed = _follow(tracker, np.linspace(0.0, 1.0, count), q0)
    if isinstance(followed, LinPath):
        return followed
    refined = refine(tracker, *followed, path_tol)
    if isinstance(refined, Unrefined):
        detail = "the joint path cannot be refined to follow the line"
        return _failed(line, "discontinuous", detail, refined.fraction, list(refined.u), list(refined.q))
    u, q = refined
    return LinPath(True, "", "", -1, 1.0, frozen_array(u * line.length), frozen_array(q), line.tcp_length, line.tcp_angle)


@dataclass(frozen=True, slots=True, eq=False)
class Unrefined:
    """Where refining found no joint step in the branch: the path's fraction between samples
    `index` and `index + 1`, and the samples (fractions `u`, configurations `q`) up to `index`."""

    index: int
    fraction: float
    u: FloatArray
    q: FloatArray


def refine(tracker: Tracker, u: FloatArray, q: FloatArray, path_tol: float) -> tuple[FloatArray, FloatArray] | Unrefined:
    """Samples (u, q) of a followed path with a sample added midway wherever the TCP leaves the
    path by more than `path_tol` between two (up to LIN_REFINE_ROUNDS times), or where that fails."""
    for _ in range(LIN_REFINE_ROUNDS):
        bad = off_line(tracker.robot, tracker.line, u, q, path_tol)
        if not np.any(bad):
            break
        mids = 0.5 * (u[:-1][bad] + u[1:][bad])
        table = None if tracker.redundant else tracker.solve(mids)
        new_q = []
        for j, i in enumerate(np.nonzero(bad)[0]):
            q_mid = tracker.step(table, j, float(mids[j]), q[i])
            if q_mid is None:
                return Unrefined(int(i), float(mids[j]), u[: i + 1], q[: i + 1])
            new_q.append(q_mid)
        order = np.argsort(np.concatenate([u, mids]), kind="stable")
        u = np.concatenate([u, mids])[order]
        q = np.concatenate([q, np.array(new_q)])[order]
    return u, q


def _follow(tracker: Tracker, grid: FloatArray, q0: FloatArray) -> tuple[FloatArray, FloatArray] | LinPath:
    """Samples (u, q) following the branch from q0 over the grid of line fractions, or the failure."""
    robot, line = tracker.robot, tracker.line
    lower = np.asarray(robot.limits.lower) - LIMIT_TOL
    upper = np.asarray(robot.limits.upper) + LIMIT_TOL
    # A redundant arm continues from its last configuration alone (`Tracker.continued`): its table
    # is solved only where the line stops, to say why.
    table = None if tracker.redundant else tracker.solve(grid)
    us: list[float] = [0.0]
    qs: list[FloatArray] = [q0]
    todo: deque[tuple[float, int]] = deque((float(u), i) for i, u in enumerate(grid) if i > 0)
    while todo:
        u_b, row = todo[0]
        sol, r = (table, row) if table is not None and row >= 0 else (None, 0)
        if sol is None and not tracker.redundant:
            sol = tracker.solve(np.array([u_b]))
        q_b = tracker.step(sol, r, u_b, qs[-1])
        if q_b is not None:
            if np.any(q_b < lower) or np.any(q_b > upper):
                return _failed(line, "joint_limit", "the line leaves the joint limits", u_b, us, qs)
            us.append(u_b)
            qs.append(q_b)
            todo.popleft()
            continue
        if sol is None:
            sol = tracker.solve(np.array([u_b]))
        if not tracker.any_valid(sol, r):
            reason = "joint_limit" if tracker.reachable(sol, r) else "unreachable"
            return _failed(line, reason, "no IK solution on the line here", u_b, us, qs)
        u_a = us[-1]
        if (u_b - u_a) * max(line.length, ZERO_LENGTH_M) >= MIN_REFINE_M:
            todo.appendleft((0.5 * (u_a + u_b), -1))
            continue
        branch = tracker.branch
        if tracker.redundant or tracker.column(sol, r) is not None:
            reason = "discontinuous"
            detail = f"the joints jump by more than {tracker.max_step} rad (branch change or singularity)"
        elif tracker.own_reachable(sol, r):
            reason, detail = "joint_limit", f"branch {branch} continues only outside the joint limits"
        else:
            reason, detail = "unreachable", f"the line leaves the workspace of branch {branch}"
        return _failed(line, reason, detail, u_b, us, qs)
    return np.array(us), np.array(qs)


def lin_move(
    robot: RobotModel,
    T_start: FloatArray,
    T_end: FloatArray,
    branch_index: int,
    limits: JointLimits,
    tcp_speed: float,
    *,
    speed: float = 1.0,
    accel: float = 1.0,
    tcp_angular_speed: float | None = None,
    q_start: FloatArray | None = None,
    kind: str = "approach",
    label: str = "",
    dt: float = DEFAULT_DT_S,
    step: float = LIN_STEP_M,
    ik: IkSolver | None = None,
) -> Segment:
    """Time-optimal Cartesian straight line from rest to rest in one IK branch.

    Parameters
    ----------
    robot, T_start, T_end, branch_index, q_start, step, ik
        As `lin_path`.
    limits : JointLimits
        Joint velocity and acceleration limits (rad/s, rad/s^2).
    tcp_speed : float
        Largest TCP linear speed, m/s (> 0).
    speed, accel : float
        Overrides in (0, 1] of the joint velocity and acceleration limits.
    tcp_angular_speed : float, optional
        Largest TCP angular speed, rad/s.
    kind, label, dt
        As for every segment.

    Returns
    -------
    Segment
        Starts and ends at rest; the TCP follows the line within the path tolerance.

    Raises
    ------
    LinMoveError
        If the line cannot be followed in the branch (reason, sample index and position attached).
    TimingError
        For bad speeds or a toppra failure.
    """
    lp = lin_path(robot, T_start, T_end, branch_index, q_start=q_start, step=step, ik=ik)
    return time_lin_path(
        lp, limits, tcp_speed, speed=speed, accel=accel, tcp_angular_speed=tcp_angular_speed, kind=kind, label=label, dt=dt
    )


def time_lin_path(
    lp: LinPath,
    limits: JointLimits,
    tcp_speed: float,
    *,
    speed: float = 1.0,
    accel: float = 1.0,
    tcp_angular_speed: float | None = None,
    kind: str = "approach",
    label: str = "",
    dt: float = DEFAULT_DT_S,
) -> Segment:
    """Time a `lin_path` result (rest to rest); `lin_move` is lin_path + this.

    Parameters as `lin_move`. Raises LinMoveError if `lp` is not ok.
    """
    if not (np.isfinite(tcp_speed) and tcp_speed > 0):
        raise TimingError(f"tcp_speed must be > 0 m/s, got {tcp_speed}")
    if tcp_angular_speed is not None and not (np.isfinite(tcp_angular_speed) and tcp_angular_speed > 0):
        raise TimingError(f"tcp_angular_speed must be > 0 rad/s, got {tcp_angular_speed}")
    if not lp.ok:
        raise lp.error()
    if len(lp.s) < 2:
        zeros = np.zeros((1, lp.q.shape[1]))
        return Segment(t=np.zeros(1), q=np.asarray(lp.q), qd=zeros, qdd=zeros.copy(), kind=kind, label=label)
    sd_max = np.inf
    if lp.tcp_length > ZERO_LENGTH_M:
        sd_max = tcp_speed * lp.length / lp.tcp_length
    if tcp_angular_speed is not None and lp.tcp_angle > ZERO_ANGLE_RAD:
        sd_max = min(sd_max, tcp_angular_speed * lp.length / lp.tcp_angle)
    limit = None if not np.isfinite(sd_max) else (lambda s: np.full(np.shape(s), sd_max))
    return time_path(lp.path, limits, speed, accel=accel, path_speed_limit=limit, kind=kind, label=label, dt=dt)


def _failed(line: Line, reason: str, detail: str, fraction: float, us: list[float], qs: list[FloatArray]) -> LinPath:
    return LinPath(
        ok=False, reason=reason, detail=detail, index=len(us), fraction=float(fraction),
        s=frozen_array(np.asarray(us) * line.length), q=frozen_array(np.asarray(qs)),
        tcp_length=line.tcp_length, tcp_angle=line.tcp_angle,
    )


def _default_ik() -> IkSolver:
    from robomax_py.robot.solve import solve_all

    return solve_all
