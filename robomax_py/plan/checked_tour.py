"""A sequenced tour timed and checked: timed with fly-by blends (best first, with dynamic objects
also waiting at rest), each timing checked sample by sample as `robomax verify` checks a
trajectory, a junction whose blend fails the check timed again stopping at its corners, and the
first clean timing returned (`time_and_check`)."""

from __future__ import annotations

import bisect
import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from robomax_py.plan.associative import associative_moves
from robomax_py.plan.candidates import SpotCandidates
from robomax_py.plan.lead_in import LeadInError, lead_in
from robomax_py.plan.loads import Loads, check_carried_motion
from robomax_py.plan.results import Progress, ResolvedOptions, SpotPlan, Transition
from robomax_py.plan.roadmap import Roadmap
from robomax_py.plan.sequence import Tour
from robomax_py.plan.tour_timing import JunctionMemo, time_tour
from robomax_py.plan.waiting import WaitingError
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.timing import TimingError, Trajectory
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.motion import MotionCheck, check_motion

log = logging.getLogger(__name__)

# The planner's own check allows this relative velocity slack (toppra's output is within ~1e-5).
PLAN_VELOCITY_RTOL = TOL.plan_velocity_rtol

# Rounds of timing again, stopping at every corner, the junctions a blended timing's violations
# fall in, before the whole tour is timed without blends.
EXACT_JUNCTION_ROUNDS = 3


@dataclass(frozen=True, slots=True, eq=False)
class Timed:
    """A tour timed and checked: the first clean timing, or why none is."""

    trajectory: Trajectory | None
    plans: list[SpotPlan]
    transitions: list[Transition]
    options: ResolvedOptions
    verify_checks: int
    verify_seconds: float
    failure: str | None = None
    transfer_seconds: float = 0.0     # planning the carried moves again (`planner.transfers: associative`)


def time_and_check(cell: CellSpec, robot: RobotModel, world: CollisionWorld, full_world: CollisionWorld,
                    spots: list[SpotCandidates], tour: Tour, found: Sequence[Transition], options: ResolvedOptions,
                    progress: Progress, roadmap: Roadmap, loads: Loads | None) -> Timed:
    """The tour timed (fly-by blends, else stopping at every corner where a blend fails the check)
    and the first timing that passes the plan's own check. With `transfers: associative` the
    carried moves are first planned again by that method (`plan.associative`)."""
    transfer_seconds = 0.0
    if options.transfers == "associative" and loads is not None:
        t_start = time.perf_counter()
        moves = associative_moves(robot, loads, tour, found)
        transfer_seconds = time.perf_counter() - t_start
        if moves.failure is not None:
            return Timed(None, [], [], options, 0, 0.0, f"associative transfer: {moves.failure}",
                          transfer_seconds)
        found = moves.transitions
    timed = _checked_timing(cell, robot, world, full_world, spots, tour, found, options, progress, roadmap, loads)
    return replace(timed, transfer_seconds=transfer_seconds)


def _checked_timing(cell: CellSpec, robot: RobotModel, world: CollisionWorld, full_world: CollisionWorld,
                    spots: list[SpotCandidates], tour: Tour, found: Sequence[Transition], options: ResolvedOptions,
                    progress: Progress, roadmap: Roadmap, loads: Loads | None) -> Timed:
    """`time_and_check` once the transitions are final."""
    memo: JunctionMemo = {}
    try:
        if cell.start is not None:
            # A continuation's first move is made again from its start, once for every timing below.
            found = lead_in(world, roadmap, np.asarray(cell.start), list(found), robot,
                            np.random.default_rng(cell.planner.seed))
        timings = _timed_tours(cell, robot, world, spots, tour, list(found), options, progress, roadmap, loads,
                               memo=memo)
    except TimingError as exc:
        return Timed(None, [], [], options, 0, 0.0, f"timing failed: {exc}")
    except WaitingError as exc:
        return Timed(None, [], [], options, 0, 0.0, f"dynamic obstacles: {exc}")
    except LeadInError as exc:
        return Timed(None, [], [], options, 0, 0.0, str(exc))
    t0 = time.perf_counter()
    progress("verify", 0, 1)
    verify_checks = 0
    # The first timing that passes its own check (the next is waiting at rest, where there is one).
    for trajectory, plans, transitions in timings:
        check = verify_trajectory(full_world, robot, trajectory, cell, loads, plans)
        verify_checks += check.checks
        if check.clean:
            break
        log.debug("verify: a timing of %.3f s failed its check: %s", trajectory.duration, check.violations[0].detail)
    # A fly-by blend is checked where it is built, yet its timed samples can still graze an object
    # the check of the blend missed (seen on generated cells: the gun body against a part at a
    # detour corner; link 4 against a clamp jaw at a 6 deg corner). Each junction starts and ends at
    # rest at a spot, so only the junctions the violations fall in are timed again stopping at
    # every corner: on a 240-spot clamped cell one such corner cost 349.50 s timed all without
    # blends, against 312.80 s with that junction alone stopping.
    exact: frozenset[int] = frozenset()
    for _ in range(EXACT_JUNCTION_ROUNDS if options.blend else 0):
        if check.clean:
            break
        times = [v.t for v in check.violations]
        if any(t is None for t in times):
            break                               # not a moment of the motion: no junction to stop
        leaves = [p.t_leave for p in plans]
        exact |= {bisect.bisect_right(leaves, t) for t in times if t is not None}
        t1 = time.perf_counter()
        try:
            retimed = _timed_tours(cell, robot, world, spots, tour, list(found), options, progress, roadmap, loads,
                                   exact, memo)
        except (TimingError, WaitingError):
            break
        t0 += time.perf_counter() - t1        # timing, not checking
        trajectory, plans, transitions = retimed[0]
        check = verify_trajectory(full_world, robot, trajectory, cell, loads, plans)
        verify_checks += check.checks
        log.debug("verify: the timing with %d junctions stopping at their corners (%.3f s): %s", len(exact),
                  trajectory.duration, "clean" if check.clean else check.violations[0].detail)
    if not check.clean and options.blend:
        # Without blends the robot stops at every corner and follows the straight moves the
        # sequencer proved free, so the tour still plans, slower.
        t1 = time.perf_counter()
        try:
            unblended = _timed_tours(cell, robot, world, spots, tour, list(found),
                                     replace(options, blend=False), progress, roadmap, loads, memo=memo)
        except (TimingError, WaitingError):
            unblended = []
        t0 += time.perf_counter() - t1        # timing, not checking
        for trajectory_u, plans_u, transitions_u in unblended:
            check_u = verify_trajectory(full_world, robot, trajectory_u, cell, loads, plans_u)
            verify_checks += check_u.checks
            if check_u.clean:
                trajectory, plans, transitions, check = trajectory_u, plans_u, transitions_u, check_u
                options = replace(options, blend=False)      # what the result was timed with
                log.debug("verify: the timing without fly-by blends (%.3f s) passes", trajectory.duration)
                break
    log.debug("timing: cycle %.3f s, %d samples", trajectory.duration, len(trajectory.t))
    progress("verify", 1, 1)
    seconds = time.perf_counter() - t0
    log.debug("verify: %d collision checks in %.2f s, %d violations", verify_checks, seconds, len(check.violations))
    if not check.clean:
        v = check.violations[0]
        return Timed(None, [], [], options, verify_checks, seconds,
                      f"the timed program failed its own check: {v.kind}: {v.detail} at t = {v.t:.3f} s")
    return Timed(trajectory, plans, transitions, options, verify_checks, seconds)


def _timed_tours(cell: CellSpec, robot: RobotModel, world: CollisionWorld, spots: list[SpotCandidates], tour: Tour,
                 transitions: list[Transition], options: ResolvedOptions, progress: Progress,
                 roadmap: Roadmap, loads: Loads | None = None, exact: frozenset[int] = frozenset(),
                 memo: JunctionMemo | None = None) -> list[tuple[Trajectory, list[SpotPlan], list[Transition]]]:
    """The tour timed, best first. With dynamic objects planned in time (`planner.dynamic: timed`)
    it is also timed waiting at rest, shorter first: the time-aware choice is made junction by
    junction, and an earlier arrival can meet a door that a later one would not. `memo` keeps the
    junctions timed across calls for the same tour (`tour_timing.JunctionMemo`), without dynamic
    objects only."""
    if not cell.dynamic:
        return [time_tour(cell, robot, world, spots, tour, transitions, options, progress, roadmap, loads, exact,
                          memo)]
    if options.dynamic != "timed":
        return [time_tour(cell, robot, world, spots, tour, transitions, options, progress, roadmap, loads, exact)]
    out = []
    failure: WaitingError | None = None
    for mode in ("timed", "rest"):
        try:
            out.append(time_tour(cell, robot, world, spots, tour, transitions, replace(options, dynamic=mode),
                                 progress, roadmap, exact=exact))
        except WaitingError as exc:
            failure = failure or exc
    if not out:
        assert failure is not None
        raise failure
    return sorted(out, key=lambda timing: timing[0].duration)


def verify_trajectory(world: CollisionWorld, robot: RobotModel, traj: Trajectory, cell: CellSpec | None = None,
                      loads: Loads | None = None, plans: list[SpotPlan] | None = None) -> MotionCheck:
    """Every sample within limits and every straight step between samples free? The same check
    `robomax verify` runs (`world.motion.check_motion`; with a part held, `loads.check_carried_motion`),
    stopping at the first problem."""
    if loads is not None and cell is not None and plans is not None:
        spots = [{"seam": p.seam, "name": p.name, "t_arrive": p.t_arrive, "t_leave": p.t_leave} for p in plans]
        return check_carried_motion(cell, robot, world, loads.worlds, traj.t, traj.q, spots, stop_at_first=True,
                                    velocity_rtol=PLAN_VELOCITY_RTOL)
    return check_motion(world, robot, traj.t, traj.q, stop_at_first=True, velocity_rtol=PLAN_VELOCITY_RTOL)
