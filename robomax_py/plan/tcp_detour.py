"""Detours of straight TCP lines through via points, as paper 003 builds them (`planner.detour_moves: lin`).

Kozhevnikov, Ilyushin, Starovoitov and Kosyrev join the configurations of consecutive spots by
"simple" paths, straight lines of the gun's working point; where none is free they go through
intermediate configurations near the two spots (their Fig. 3: round a clamp through two via
points, the program then written in SRCL). Here the via points are the two approach points
lifted by the same height h, straight up (world z), back along each spot's approach line, or both
at once, as the joint-space lift of `graph_detours` lifts them: the gun moves A -> A' -> B' -> B in
straight lines, with A's orientation on the first line, B's on the last and the orientation turned
from one to the other (slerp) on the line across. The single line A -> B is tried first.

Every line is followed by IK in the IK branch it starts in (`timing.lin.lin_path`: continuous, no
joint jumps), keeps the configuration status (shoulder, elbow, wrist bits) at every sample (no flip
through a singularity), and is collision-checked along the joint path the program follows (the
line's spline, sampled as `junction` samples paths). The last line must end in the goal
configuration itself, the same branch and turns: a straight line cannot change the arm's
configuration, so two candidates of different status are never joined this way.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray, IntArray
from robomax_py.plan.junction import CHECK_STEP_RAD, PathChecks
from robomax_py.plan.roadmap import Detour
from robomax_py.robot import JointLimits, RobotModel, fk_tcp
from robomax_py.robot.ik.config import status_generic, status_opw
from robomax_py.robot.ik.opw import OpwParams
from robomax_py.timing import TimingError, ptp_time_estimate
from robomax_py.timing.chain import column_of
from robomax_py.timing.lin import lin_path

__all__ = ["GOAL_TOL_RAD", "LineLegs", "TcpDetourSearch", "follow_lines", "lift_poses", "lines_time_estimate",
           "status_of", "tcp_detour"]

# The last line ends in the goal configuration within this (rad, any joint): the line's own end
# tolerance (IK samples every millimetre, refined to the line), far below another branch or turn.
GOAL_TOL_RAD = 1e-6


def status_of(robot: RobotModel, q: FloatArray) -> IntArray:
    """(k,) configuration status bits (0..7: shoulder, elbow, wrist) of configurations (k, n)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    if robot.ik_solver == "opw" and isinstance(robot.ik_params, OpwParams):
        return status_opw(robot.ik_params, q)
    return status_generic(robot.model, robot.flange_frame_id, q)


@dataclass(frozen=True, slots=True, eq=False)
class LineLegs:
    """A polyline of straight TCP lines followed from a configuration, or why it cannot be.

    ok : every line followed, within the limits, in one status, collision-free (and, where a goal
        was given, ending in it).
    q : (m, n) the configuration at the start and at the end of each line followed (rad).
    checks : collision checks spent.
    reason : "" when ok; else "unreachable", "discontinuous", "joint_limit", "start_mismatch"
        (`lin_path`'s), "flip" (the status changes along a line), "blocked" or "goal".
    """

    ok: bool
    q: FloatArray
    checks: int
    reason: str = ""


def follow_lines(robot: RobotModel, world: PathChecks, q_start: FloatArray, poses: Sequence[FloatArray],
                 q_goal: FloatArray | None = None) -> LineLegs:
    """Follow straight TCP lines from q_start through `poses` ((4, 4) each, robot base frame), each
    in the IK branch it starts in, checking each as it is followed (stops at the first failure)."""
    q = np.asarray(q_start, dtype=float)
    status = int(status_of(robot, q)[0])
    ends = [q]
    checks = 0
    for T in poses:
        try:
            column = column_of(robot, q)
        except TimingError:
            return LineLegs(False, np.array(ends), checks, "start_mismatch")
        lp = lin_path(robot, fk_tcp(robot, q), np.asarray(T, dtype=float), column, q_start=q)
        if not lp.ok:
            return LineLegs(False, np.array(ends), checks, lp.reason)
        if len(lp.s) >= 2:
            if np.any(status_of(robot, lp.q) != status):
                return LineLegs(False, np.array(ends), checks, "flip")
            res = world.check_path(lp.path.sample(CHECK_STEP_RAD))
            checks += res.checks
            if not res.free:
                return LineLegs(False, np.array(ends), checks, "blocked")
        q = np.asarray(lp.q[-1], dtype=float)
        ends.append(q)
    if q_goal is not None and float(np.max(np.abs(q - np.asarray(q_goal, dtype=float)))) > GOAL_TOL_RAD:
        return LineLegs(False, np.array(ends), checks, "goal")
    return LineLegs(True, np.array(ends), checks)


def lift_poses(T_a: FloatArray, T_b: FloatArray, away_a: FloatArray, away_b: FloatArray, h: float,
               written: Callable[[FloatArray], FloatArray]) -> list[FloatArray]:
    """The via points A' and B' (each approach point moved by h along its `away` unit vector, its
    orientation kept), as the program states them, and B itself: the targets of the three lines."""
    out = []
    for T, away in ((T_a, away_a), (T_b, away_b)):
        via = np.array(T, dtype=float)
        via[:3, 3] += h * np.asarray(away, dtype=float)
        out.append(written(via))
    out.append(np.asarray(T_b, dtype=float))
    return out


def lines_time_estimate(robot: RobotModel, limits: JointLimits, q: FloatArray, speed: float,
                        tcp_speed: float) -> float:
    """Estimated time (s) of the lines through configurations q (m, n), stopping at each: per line
    the longer of its joint move's estimate and its TCP length at `tcp_speed` (m/s)."""
    q = np.asarray(q, dtype=float)
    joint = np.atleast_1d(ptp_time_estimate(q[:-1], q[1:], limits, speed))
    p = fk_tcp(robot, q)[:, :3, 3]
    tcp = np.linalg.norm(np.diff(p, axis=0), axis=1) / tcp_speed
    return float(np.sum(np.maximum(joint, tcp)))


@dataclass(frozen=True, slots=True, eq=False)
class TcpDetourSearch:
    """What `tcp_detour` found: the detour (None: no polyline of lines joins the two) and the
    collision checks spent when none was found (a found detour carries its own)."""

    detour: Detour | None
    checks: int


def tcp_detour(robot: RobotModel, world: PathChecks, limits: JointLimits, q_a: FloatArray, q_b: FloatArray,
               aways: Sequence[tuple[FloatArray, FloatArray]], heights: Sequence[float],
               written: Callable[[FloatArray], FloatArray], speed: float, tcp_speed: float) -> TcpDetourSearch:
    """Straight TCP lines from configuration q_a to q_b: the single line, else A -> A' -> B' -> B
    for each (away_a, away_b) of `aways` (unit vectors, robot base frame) and each height of
    `heights` in turn (`lift_poses`); the first that `follow_lines` passes.

    The detour's waypoints are the configurations at the line ends, its `poses` the TCP poses
    there (the first q_a's, the others as the lines end), its time the `lines_time_estimate`.
    """
    q_a = np.asarray(q_a, dtype=float)
    q_b = np.asarray(q_b, dtype=float)
    if int(status_of(robot, q_a)[0]) != int(status_of(robot, q_b)[0]):
        return TcpDetourSearch(None, 0)
    T_a, T_b = fk_tcp(robot, q_a), fk_tcp(robot, q_b)
    tries: list[list[FloatArray]] = [[T_b]]
    tries += [lift_poses(T_a, T_b, away_a, away_b, h, written) for away_a, away_b in aways for h in heights]
    checks = 0
    for poses in tries:
        legs = follow_lines(robot, world, q_a, poses, q_goal=q_b)
        checks += legs.checks
        if legs.ok:
            wp = legs.q.copy()
            wp[-1] = q_b                          # within GOAL_TOL_RAD: the candidate itself
            all_poses = np.array([T_a, *poses])
            estimate = lines_time_estimate(robot, limits, wp, speed, tcp_speed)
            return TcpDetourSearch(Detour(wp, estimate, checks, poses=all_poses), 0)
    return TcpDetourSearch(None, checks)
