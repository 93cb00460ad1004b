"""A cell -> a collision-free, cycle-time-optimised spot-welding trajectory (no file I/O, no printing).

Stages: candidates per spot (orientation grid x IK branch, pruned) -> sequencing (spot order and
candidates by DP and local search on estimated motion times, straight moves verified lazily, detours
through a roadmap where they are blocked) -> timing (jerk-limited PTP moves, detours, LIN
approach/retract, dwells) -> a dense re-check of the timed trajectory, which is only returned when
every sample pair is collision-free and within limits.
"""

from __future__ import annotations

import logging
import time
from collections import Counter
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from robomax_py.plan.associative import pin_transfer_ends
from robomax_py.plan.candidates import SpotCandidates, check_ik_work, seam_candidates
from robomax_py.plan.checked_tour import Timed, time_and_check
from robomax_py.plan.graph import Sequencer
from robomax_py.plan.learned_detour import LearnedDetours
from robomax_py.plan.loads import Loads
from robomax_py.plan.reach import always_touching_text
from robomax_py.plan.results import (
    FailureReason,
    OrderChoice,
    PlanOptions,
    PlanResult,
    PlanStats,
    Progress,
    ResolvedOptions,
    SpotFailure,
    _no_progress,
    resolved_options,
)
from robomax_py.plan.roadmap import Roadmap
from robomax_py.plan.sequence import Tour, choice_for_order
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.world.cell_cache import keep_decisions
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.collision_results import Contact
from robomax_py.world.motion import min_clearance
from robomax_py.world.scene import build_scene

log = logging.getLogger(__name__)



def plan_cell(
    cell: CellSpec, robot: RobotModel, options: PlanOptions = PlanOptions(), progress: Progress = _no_progress,
    known: Mapping[tuple[str, str], SpotCandidates] | None = None,
) -> PlanResult:
    """Plan a cell whose robot (with its tool mounted) is given; `progress` hears of each stage's advance.
    `known`: candidates already found for spots of this cell (by seam and spot name) against this
    cell's objects with the same robot, home and process, as `seam_candidates` finds them (a station
    finds every robot's once for all the spots it may weld); a seam with a spot missing from it, or
    carrying a load, is found here."""
    result = _plan(cell, robot, resolved_options(cell, options), progress, known or {})
    keep_decisions()                        # the cells its worlds decided, for the next run
    return result


def _in_collision(what: str, contact: Contact, world: CollisionWorld, robot: RobotModel) -> str:
    """'<what> is in collision: a vs b', saying so when the pair touches in every one of the world's
    samples (no posture is free of it: robot.yaml must exempt it, `plan.reach.always_touching_text`)."""
    text = f"{what} is in collision: {contact.describe()}"
    pieces = {(contact.piece_a, contact.piece_b), (contact.piece_b, contact.piece_a)}
    if pieces & set(world.acm.always_in_contact):
        text += f"; {always_touching_text(robot, contact.body_a, contact.body_b, world.acm.samples)}"
    return text


def home_collision(cell: CellSpec, robot: RobotModel, world: CollisionWorld | None = None) -> str | None:
    """Why the robot cannot stand at its home ('home is in collision: a vs b'), None where it can:
    every program starts and ends there, so `plan` refuses such a cell, and `check` tells it first.
    `world`: the cell's world without its dynamic objects (built here when not given)."""
    if world is None:
        world = CollisionWorld(robot, build_scene(replace(cell, dynamic=()), robot), cell.process.clearance)
    contact = world.first_contact(cell.home)
    return None if contact is None else _in_collision("home", contact, world, robot)


def _plan(cell: CellSpec, robot: RobotModel, options: ResolvedOptions, progress: Progress,
          known: Mapping[tuple[str, str], SpotCandidates]) -> PlanResult:
    check_ik_work(cell, robot)              # before anything large is built
    clock: dict[str, float] = {}
    t0 = time.perf_counter()
    full_world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    # Planned as if the dynamic obstacles were absent; `waiting` then holds the robot where one is
    # in the way. The final check is against everything, at its time.
    world = CollisionWorld(robot, build_scene(replace(cell, dynamic=()), robot), cell.process.clearance) \
        if cell.dynamic else full_world
    clock["world"] = time.perf_counter() - t0
    log.debug("%s: collision world of %d pieces, %d pairs in %.2f s", cell.name, world.geometry_model.ngeoms,
              world.n_pairs, clock["world"])

    at_home = home_collision(cell, robot, world)
    if at_home is not None:
        return PlanResult(cell.name, robot.name, "infeasible", at_home)
    if cell.start is not None:
        start_contact = full_world.first_contact(cell.start, 0.0)
        if start_contact is not None:
            return PlanResult(cell.name, robot.name, "infeasible",
                              _in_collision("the stop configuration", start_contact, full_world, robot))

    t0 = time.perf_counter()
    spots: list[SpotCandidates] = []
    candidate_checks = 0
    n_spots = sum(len(seam.spots) for seam in cell.seams)
    done = iter(range(1, n_spots + 1))
    progress("candidates", 0, n_spots)
    loads = Loads.of(cell, robot)
    for s in range(len(cell.seams)):
        had = [known.get((cell.seams[s].name, spot.name)) for spot in cell.seams[s].spots]
        if loads is None and not cell.dynamic and all(c is not None for c in had):
            for j, c in enumerate(had):
                assert c is not None
                spots.append(replace(c, seam_index=s, spot_index=j))
                progress("candidates", next(done), n_spots)
            continue
        offset = sum(len(seam.spots) for seam in cell.seams[:s])
        line_world = None if loads is None else (lambda j, offset=offset: loads.line_world(offset + j, world))
        found, stats = seam_candidates(cell, robot, world, s,
                                       on_spot=lambda: progress("candidates", next(done), n_spots),
                                       line_world=line_world)
        spots.extend(found)
        candidate_checks += stats.collision_checks
    clock["candidates"] = time.perf_counter() - t0
    for c in spots:
        log.debug("spot %s/%s: %d candidates; rejected %s", cell.seams[c.seam_index].name, c.name, len(c),
                  dict(c.rejected.most_common()) or "none")
    failures = tuple(spot_failure(cell, c) for c in spots if len(c) == 0)
    if failures:
        names = ", ".join(f"{f.seam}/{f.name} ({f.reason})" for f in failures)
        what = "station(s) cannot be reached" if cell.tending else "spot(s) cannot be welded"
        return PlanResult(cell.name, robot.name, "infeasible",
                          f"{len(failures)} {what}: {names}{_workpiece_hint(cell, spots)}", failures=failures)
    if options.baseline:
        spots = [_baseline_candidate(c) for c in spots]
    if options.transfers == "associative" and loads is not None:
        # The Jacobian interpolation cannot change IK branch: each transfer's ends are one branch.
        spots = pin_transfer_ends(cell, spots)
    learned = None
    if options.detours == "learned":
        # The learned C-space map every detour is searched in (trained once per robot, tool and
        # wrist, then cached; docs/learned-cspace.md).
        t0 = time.perf_counter()
        learned = LearnedDetours.build(cell, robot, world, spots, cell.planner.learned)
        clock["learned map"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    rng = np.random.default_rng(cell.planner.seed)
    # A continuation's start (`cell.start`) is an anchor too: its first move may need a detour.
    starts = [] if cell.start is None else [np.asarray(cell.start)[None, :]]
    anchors = np.vstack([cell.home[None, :], *starts, *[c.q_app for c in spots]])
    roadmap = Roadmap(world, robot.limits, anchors, rng, options.roadmap_nodes, options.roadmap_k, seeds=anchors)
    clock["roadmap"] = time.perf_counter() - t0
    log.debug("roadmap: %d nodes in %.2f s", len(roadmap.nodes), clock["roadmap"])

    t0 = time.perf_counter()
    sequencer = Sequencer(cell, robot, world, roadmap, spots, options, rng, progress, loads=loads, learned=learned)
    outcome = sequencer.run()
    clock["sequencing"] = time.perf_counter() - t0
    log.debug("sequencing: %d rounds, %d DP evaluations, %d collision checks in %.2f s", sequencer.rounds,
              sequencer.dp_evaluations, sequencer.checks, clock["sequencing"])
    if outcome.status != "found" or outcome.tour is None:
        return PlanResult(cell.name, robot.name, "infeasible", outcome.message + _learned_note(learned))
    tour = outcome.tour

    t0 = time.perf_counter()
    timed = time_and_check(cell, robot, world, full_world, spots, tour, outcome.transitions, options, progress,
                            roadmap, loads)
    clock["timing"] = time.perf_counter() - t0 - timed.verify_seconds - timed.transfer_seconds
    clock["verify"] = timed.verify_seconds
    if options.transfers == "associative" and loads is not None:
        clock["transfers"] = timed.transfer_seconds
    verify_checks = timed.verify_checks
    # The optimiser also weighs the cell file's own order, planned as the published method plans it
    # (same candidates, detours and timing): the order search ranks orders on estimated leg times
    # that the final timing (fly-by blends, jerk limits) can contradict, and a user expects the
    # optimised cycle never to be longer than the file's order gives.
    order_choice: OrderChoice | None = None
    given_checks = 0
    if options.method == "optimised":
        t0 = time.perf_counter()
        order_choice, given_timed, given_checks = _given_order(sequencer, tour, timed, cell, robot, world, full_world,
                                                               spots, options, loads)
        if given_timed is not None:
            verify_checks += given_timed.verify_checks
            if order_choice.kept == "given":
                timed = given_timed
        clock["given order"] = time.perf_counter() - t0
    if timed.failure is not None:
        return PlanResult(cell.name, robot.name, "infeasible", timed.failure)
    assert timed.trajectory is not None
    trajectory, plans, transitions, options = timed.trajectory, timed.plans, timed.transitions, timed.options

    t0 = time.perf_counter()
    # The robot's and tool's clearance; a carried part rests on its supports at its ends (0 mm).
    clearance = min_clearance(full_world, trajectory.t, trajectory.q)
    clock["clearance"] = time.perf_counter() - t0

    plan_stats = PlanStats(
        candidates=sum(len(c) for c in spots), candidate_checks=candidate_checks,
        sequencing_checks=sequencer.checks + given_checks, roadmap_checks=roadmap.sampling_checks + roadmap.edge_checks,
        verify_checks=verify_checks, detours=sum(1 for t in transitions if t.kind == "detour"),
        rounds=sequencer.rounds, dp_evaluations=sequencer.dp_evaluations, seconds=clock,
        tcp_detour_searches=sequencer.tcp_detour_searches, tcp_detours_found=sequencer.tcp_detours_found,
        lin_detours=sum(1 for t in transitions if t.lin_targets is not None),
        learned=None if learned is None else learned.report(),
    )
    return PlanResult(cell.name, robot.name, "planned", "planned", spots=tuple(plans), transitions=tuple(transitions),
                      trajectory=trajectory, stats=plan_stats, baseline=options.method != "optimised", joint_names=robot.joint_names,
                      prismatic=robot.prismatic,
                      tool=cell.tool.name, T_flange_tcp=np.asarray(robot.T_flange_tcp), tool_load=cell.tool.load,
                      T_world_base=np.asarray(cell.T_world_base),
                      T_root_controller=np.asarray(cell.robot.controller.T_root_base), controller=cell.controller,
                      home=np.asarray(cell.q_start), options=options,
                      weld_time=cell.process.weld_time, clearance=clearance, order=order_choice)
# The file's order is timed only when the published method's estimate of it is below the searched
# tour's by more than this fraction (rounding: a reversed tour of symmetric legs sums the same times
# in another order). Wherever the file's order timed shorter (seven cells: six of the generated
# corpus and cells/cabin_flange.yaml), that estimate was 0.5-4.2 % below the searched tour's (the
# search ranks orders on a few representative candidates per spot, the exact DP then chooses among
# all); on cells/ur10_tray.yaml one 2.9 % above timed 3.1 % longer, and on the reference cell the
# search's tour is the file's order reversed, estimated the same to the last digit and timed the
# same (20.719 s). Timing and checking a tour costs about a third of a plan (1.1 of 4.5 s there).
GIVEN_ORDER_MARGIN = -1e-9
# Before the file's order is sequenced at all, what the order search already knows prices it (the
# exact DP, no collision check) and the order is screened with this margin. That knowledge is not
# the published method's (the search has found blocked what the published sequencer routes
# round): on corpus cell 36 this estimate was 3.1 % above the searched tour's where the published
# method's was 0.7 % below it; cells/ur10_tray.yaml (8.9 %) and cells/frame.yaml (11.5 %) are
# passed over, which saves sequencing the file's order (2 s of 11 s CPU on ur10_tray).
GIVEN_ORDER_SCREEN = 0.06


def _given_order(sequencer: Sequencer, tour: Tour, searched: Timed, cell: CellSpec, robot: RobotModel,
                 world: CollisionWorld, full_world: CollisionWorld, spots: list[SpotCandidates],
                 options: ResolvedOptions, loads: Loads | None) -> tuple[OrderChoice, Timed | None, int]:
    """The cell file's order planned by the published method beside the searched tour: which of
    the two is kept (the shorter clean cycle; the searched one on a tie), the given tour's timing
    where it was timed, and the collision checks its sequencing took.

    Not timed where the search found the file's order itself, where the published method finds
    no tour for it (a seam's spots it cannot join in that order), or where its estimate is more
    than GIVEN_ORDER_SCREEN (what the search knows) or GIVEN_ORDER_MARGIN (the published method's
    own) above the searched tour's while the searched tour timed clean."""
    searched_cycle = None if searched.trajectory is None else searched.trajectory.duration
    given_order = tuple(range(len(spots)))
    if tour.order == given_order:
        return OrderChoice("searched", searched_cycle, None, "the search found the file's order"), None, 0
    # Screened on what the search already knows before it is planned again (GIVEN_ORDER_SCREEN).
    _, known = choice_for_order(given_order, sequencer.full_cost, sequencer.node)
    if searched_cycle is not None and known > tour.cost * (1.0 + GIVEN_ORDER_SCREEN):
        return OrderChoice("searched", searched_cycle, None, f"the file's order is estimated "
                           f"{100 * (known / tour.cost - 1):.1f} % longer"), None, 0
    published = sequencer.given_order()
    outcome = published.run()
    if outcome.status != "found" or outcome.tour is None:
        return OrderChoice("searched", searched_cycle, None, "the published method found no tour in the file's "
                           "order"), None, published.checks
    ratio = outcome.tour.cost / tour.cost
    log.debug("given order: estimate %.3f s against the searched tour's %.3f s (%.4f)", outcome.tour.cost, tour.cost,
              ratio)
    if searched_cycle is not None and ratio >= 1.0 + GIVEN_ORDER_MARGIN:
        longer = "the same" if ratio < 1.0 - GIVEN_ORDER_MARGIN else f"{100 * (ratio - 1):.1f} % longer"
        note = f"the file's order is estimated {longer}"
        return OrderChoice("searched", searched_cycle, None, note), None, published.checks
    # Silent: the stages' progress bars have finished for the searched tour.
    timed = time_and_check(cell, robot, world, full_world, spots, outcome.tour, outcome.transitions, options,
                            _no_progress, published.roadmap, loads)
    given_cycle = None if timed.trajectory is None else timed.trajectory.duration
    if given_cycle is None:
        return (OrderChoice("searched", searched_cycle, None, f"the file's order: {timed.failure}"), timed,
                published.checks)
    kept = "given" if searched_cycle is None or given_cycle < searched_cycle else "searched"
    return OrderChoice(kept, searched_cycle, given_cycle, ""), timed, published.checks


def _learned_note(learned: LearnedDetours | None) -> str:
    """What the learned map's searches came to, for a plan that found no tour through it."""
    if learned is None:
        return ""
    r = learned.report()
    return (f"; learned C-space map: {r.searches} detour searches, {r.found} found, {r.no_entry} without a checked "
            f"way into or out of the map, {r.no_path} without a path, {r.gave_up} given up after repairs, "
            f"{r.refused_segments} path segments refused by the exact check")


def _workpiece_hint(cell: CellSpec, spots: list[SpotCandidates]) -> str:
    """'; every spot ... mark it `workpiece: true`' when every spot of the cell failed and each had
    candidates refused for the tool's tips touching the same object that is not a workpiece: the
    part being welded, most likely, not marked as one (the tips may touch only a workpiece). A
    clamp over some spots is a real obstacle, so the hint needs every spot; '' otherwise."""
    if not spots or any(len(c) for c in spots):
        return ""
    common: set[str] | None = None
    for c in spots:
        touched = set()
        for r in c.rejected:
            a, _, b = r.detail.partition(" vs ")
            if r.kind == "collision" and "tool_tips" in (a, b):
                touched.add(b if a == "tool_tips" else a)
        common = touched if common is None else common & touched
    workpieces = {o.name for o in cell.objects if o.workpiece}
    named = sorted((common or set()) - workpieces - {"tool_tips"})
    if not named or cell.tending or cell.parts:
        return ""
    return (f"; every spot fails on 'tool_tips vs {named[0]}': the gun's tips may touch only a workpiece; if "
            f"{named[0]} is the part being welded, mark it `workpiece: true` in the cell file")


def spot_failure(cell: CellSpec, c: SpotCandidates) -> SpotFailure:
    """The dominant reason a spot has no candidate."""
    seam = cell.seams[c.seam_index].name
    if not c.rejected:
        return SpotFailure(seam, c.name, "unreachable", "no IK solution at any orientation")
    groups: Counter[str] = Counter()
    for rejection, n in c.rejected.items():
        groups[rejection.kind] += n
    # Most telling first; the approach's own kinds are reported as the spot's (`FailureReason`).
    order: tuple[tuple[str, FailureReason], ...] = (
        ("approach_blocked", "approach_blocked"), ("collision", "collision"), ("approach_branch", "approach_blocked"),
        ("approach_joint_limit", "joint_limit"), ("joint_limit", "joint_limit"), ("unreachable", "unreachable"),
        ("pinned_config", "pinned_config"), ("pinned_orientation", "pinned_orientation"))
    for kind, reason in order:
        if groups.get(kind):
            detail = ", ".join(f"{k} x{v}" for k, v in c.rejected.most_common(4))
            return SpotFailure(seam, c.name, reason, detail)
    return SpotFailure(seam, c.name, "unreachable", "no IK solution at any orientation")


def _baseline_candidate(c: SpotCandidates) -> SpotCandidates:
    """The published method's choice: nearest-to-nominal orientation, then the first branch."""
    # Grid orientations are ordered by distance from nominal, so the lowest index is the nearest.
    best = int(np.lexsort((c.column, c.orient))[0])
    sel = np.array([best])
    return replace(
        c, orient=c.orient[sel], angles=c.angles[sel], column=c.column[sel], q_spot=c.q_spot[sel],
        q_app=c.q_app[sel], app_path=c.app_path[sel], status=c.status[sel], turn=c.turn[sel],
    )


