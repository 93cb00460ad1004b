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
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.candidates import SpotCandidates, seam_candidates
from robomax_py.collision import CollisionWorld
from robomax_py.ik import config_text, solve_all
from robomax_py.ik.turns import wrap_to_pi
from robomax_py.robot import JointLimits, RobotModel, fk_tcp
from robomax_py.roadmap import Detour, Roadmap
from robomax_py.scene import build_scene
from robomax_py.seams import OrientationGrid, approach_poses, orientation_grid, spot_poses
from robomax_py.sequence import HOME, SeamBlock, Tour, choice_for_order, optimise
from robomax_py.spec import CellSpec
from robomax_py.junction import WeldEnd, time_junction
from robomax_py.program import as_written_joints, as_written_pose_in, written_seconds, written_speed, written_tcp_speed
from robomax_py.timing import Segment, TimingError, Trajectory, concatenate, dwell, ptp_time_estimate, resample
from robomax_py.transforms import invert
from robomax_py.waiting import WaitingError, WaitPlan, schedule_waits

log = logging.getLogger(__name__)

Progress = Callable[[str, int, int], None]
"""progress(stage, done, total): called as a long stage advances ("candidates", "sequencing",
"timing", "verify"); the CLI draws progress bars from it. total may grow (sequencing rounds)."""


def _no_progress(stage: str, done: int, total: int) -> None:
    pass


# Heights (m, world z) tried for up-across-down detours over clamps, lowest first.
LIFT_HEIGHTS_M = (0.08, 0.15, 0.25, 0.4)
# Cost of a detour not yet found, as a multiple of the straight move's estimate.
DETOUR_PRIOR = 1.6
# Blocked detour legs between two spots after which only verified legs are offered for that pair:
# each blocked leg bans one (candidate, candidate, detour) triple, and two spots with hundreds of
# candidates each would otherwise let the optimiser try a fresh unverified triple every round.
MAX_BLOCKED_LEGS = 4
# The planner's own check allows this relative velocity slack (toppra's output is within ~1e-5).
PLAN_VELOCITY_RTOL = 1e-3
# Placeholder keeping detour indices stable for pairs a detour cannot serve.
_UNUSABLE = Detour(np.zeros((0, 0)), float("inf"), 0)


@dataclass(frozen=True, slots=True)
class PlanOptions:
    """How to plan; every field has a production default."""

    baseline: bool = False           # the published method: given order, nominal orientation, first branch
    # Speeds; None takes the cell's `planner` values (defaults 1.0, 0.5 m/s, 1.0).
    speed: float | None = None       # global override in (0, 1] of every programmed speed
    tcp_speed: float | None = None   # m/s on approach and retract lines (before the override)
    detour_speed: float | None = None  # speed fraction of detour moves (before the override)
    roadmap_nodes: int = 600
    roadmap_k: int = 12
    straight_tries: int = 12         # blocked straight moves between two spots before detours only
    max_rounds: int = 80             # sequencing rounds (optimise, verify, repair)
    max_evaluations: int = 400       # DP evaluations per sequencing round
    jerk_limited: bool = True        # PTP moves and detour legs with ruckig; False: toppra (vel/acc only)
    blend: bool = True               # fly by detour corners and approach points on checked G2 blends where faster


@dataclass(frozen=True, slots=True, eq=False)
class SpotPlan:
    """One welded spot: where and how."""

    seam: str
    name: str
    angles: FloatArray               # (3,) alpha, beta, gamma, rad
    config: str                      # the controller brand's configuration data at the spot
    q_spot: FloatArray
    q_app: FloatArray
    t_arrive: float
    t_leave: float
    T_spot: FloatArray               # (4, 4) TCP at the spot, robot base frame
    T_app: FloatArray                # (4, 4) TCP at the approach point, robot base frame
    config_app: str = ""             # configuration data at the approach point (where the retract ends)


@dataclass(frozen=True, slots=True)
class SpotFailure:
    seam: str
    name: str
    reason: str                      # unreachable | joint_limit | collision | approach_blocked
    detail: str


@dataclass(frozen=True, slots=True, eq=False)
class Transition:
    """The joint path between two stops (home or an approach point); kind 'move' or 'detour'."""

    kind: str
    waypoints: FloatArray            # (m, n), both ends included
    label: str
    checks: int = 0                  # collision checks spent finding this detour (0 for a straight move)
    blend_radius: float = 0.0        # rad: detour corners passed on G2 blends of this radius; 0: stops at each
    flyby_radius: float = 0.0        # rad: the retract -> move and move -> approach joins flown by; 0: stops
    wait: WaitPlan | None = None     # a wait at rest before it, for a dynamic obstacle to clear


@dataclass(frozen=True, slots=True)
class PlanStats:
    candidates: int
    candidate_checks: int
    sequencing_checks: int
    roadmap_checks: int
    verify_checks: int
    detours: int
    rounds: int
    dp_evaluations: int
    seconds: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True, slots=True, eq=False)
class PlanResult:
    cell: str
    robot: str
    status: str                      # "planned" | "infeasible"
    message: str
    spots: tuple[SpotPlan, ...] = ()
    failures: tuple[SpotFailure, ...] = ()
    transitions: tuple[Transition, ...] = ()
    trajectory: Trajectory | None = None
    stats: PlanStats | None = None
    baseline: bool = False
    joint_names: tuple[str, ...] = ()
    tool: str = ""
    T_flange_tcp: FloatArray | None = None   # (4, 4)
    T_world_base: FloatArray | None = None   # (4, 4)
    T_root_controller: FloatArray | None = None   # (4, 4) the controller's base in the URDF root frame
    home: FloatArray | None = None
    options: PlanOptions = PlanOptions()
    weld_time: float = 0.0

    @property
    def cycle_time(self) -> float:
        return float("nan") if self.trajectory is None else self.trajectory.duration


def resolved_options(cell: CellSpec, options: PlanOptions) -> PlanOptions:
    """The options with every speed left None taken from the cell's `planner` section."""
    p = cell.planner
    return replace(
        options,
        speed=p.speed if options.speed is None else options.speed,
        tcp_speed=p.tcp_speed if options.tcp_speed is None else options.tcp_speed,
        detour_speed=p.detour_speed if options.detour_speed is None else options.detour_speed,
    )


def plan_cell(
    cell: CellSpec, robot: RobotModel, options: PlanOptions = PlanOptions(), progress: Progress = _no_progress,
) -> PlanResult:
    """Plan a cell whose robot (with its tool mounted) is given; `progress` hears of each stage's advance."""
    options = resolved_options(cell, options)
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

    home_contact = world.first_contact(cell.home)
    if home_contact is not None:
        return PlanResult(cell.name, robot.name, "infeasible", f"home is in collision: {home_contact.describe()}")

    t0 = time.perf_counter()
    spots: list[SpotCandidates] = []
    candidate_checks = 0
    n_spots = sum(len(seam.spots) for seam in cell.seams)
    done = iter(range(1, n_spots + 1))
    progress("candidates", 0, n_spots)
    for s in range(len(cell.seams)):
        found, stats = seam_candidates(cell, robot, world, s,
                                       on_spot=lambda: progress("candidates", next(done), n_spots))
        spots.extend(found)
        candidate_checks += stats.collision_checks
    clock["candidates"] = time.perf_counter() - t0
    for c in spots:
        log.debug("spot %s/%s: %d candidates; rejected %s", cell.seams[c.seam_index].name, c.name, len(c),
                  dict(c.rejected.most_common()) or "none")
    failures = tuple(_failure(cell, c) for c in spots if len(c) == 0)
    if failures:
        names = ", ".join(f"{f.seam}/{f.name} ({f.reason})" for f in failures)
        return PlanResult(cell.name, robot.name, "infeasible", f"{len(failures)} spot(s) cannot be welded: {names}",
                          failures=failures)
    if options.baseline:
        spots = [_baseline_candidate(c) for c in spots]

    t0 = time.perf_counter()
    rng = np.random.default_rng(cell.planner.seed)
    anchors = np.vstack([cell.home[None, :], *[c.q_app for c in spots]])
    roadmap = Roadmap(world, robot.limits, anchors, rng, options.roadmap_nodes, options.roadmap_k, seeds=anchors)
    clock["roadmap"] = time.perf_counter() - t0
    log.debug("roadmap: %d nodes in %.2f s", len(roadmap.nodes), clock["roadmap"])

    t0 = time.perf_counter()
    sequencer = _Sequencer(cell, robot, world, roadmap, spots, options, rng, progress)
    outcome = sequencer.run()
    clock["sequencing"] = time.perf_counter() - t0
    log.debug("sequencing: %d rounds, %d DP evaluations, %d collision checks in %.2f s", sequencer.rounds,
              sequencer.dp_evaluations, sequencer.checks, clock["sequencing"])
    if isinstance(outcome, str):
        return PlanResult(cell.name, robot.name, "infeasible", outcome)
    tour, transitions = outcome

    t0 = time.perf_counter()
    try:
        trajectory, plans, transitions = _time_tour(cell, robot, world, spots, tour, transitions, options, progress)
    except TimingError as exc:
        return PlanResult(cell.name, robot.name, "infeasible", f"timing failed: {exc}")
    except WaitingError as exc:
        return PlanResult(cell.name, robot.name, "infeasible", f"dynamic obstacles: {exc}")
    clock["timing"] = time.perf_counter() - t0
    log.debug("timing: cycle %.3f s, %d samples in %.2f s", trajectory.duration, len(trajectory.t), clock["timing"])

    t0 = time.perf_counter()
    progress("verify", 0, 1)
    problem, verify_checks = verify_trajectory(full_world, robot, trajectory)
    progress("verify", 1, 1)
    clock["verify"] = time.perf_counter() - t0
    log.debug("verify: %d collision checks in %.2f s: %s", verify_checks, clock["verify"], problem or "clean")
    if problem:
        return PlanResult(cell.name, robot.name, "infeasible", f"the timed program failed its own check: {problem}")

    stats = PlanStats(
        candidates=sum(len(c) for c in spots), candidate_checks=candidate_checks,
        sequencing_checks=sequencer.checks, roadmap_checks=roadmap.sampling_checks + roadmap.edge_checks,
        verify_checks=verify_checks, detours=sum(1 for t in transitions if t.kind == "detour"),
        rounds=sequencer.rounds, dp_evaluations=sequencer.dp_evaluations, seconds=clock,
    )
    return PlanResult(cell.name, robot.name, "planned", "planned", spots=tuple(plans), transitions=tuple(transitions),
                      trajectory=trajectory, stats=stats, baseline=options.baseline, joint_names=robot.joint_names,
                      tool=cell.tool.name, T_flange_tcp=np.asarray(robot.T_flange_tcp),
                      T_world_base=np.asarray(cell.T_world_base),
                      T_root_controller=np.asarray(cell.robot.controller.T_root_base), home=np.asarray(cell.home), options=options,
                      weld_time=cell.process.weld_time)


def verify_trajectory(world: CollisionWorld, robot: RobotModel, traj: Trajectory) -> tuple[str, int]:
    """'' if every sample is within limits and every straight step between samples is free, else why.

    The same check `robomax verify` runs (`verify.check_motion`), stopping at the first problem.
    """
    from robomax_py.verify import check_motion

    found, checks = check_motion(world, robot, traj.t, traj.q, stop_at_first=True, velocity_rtol=PLAN_VELOCITY_RTOL)
    if not found:
        return "", checks
    v = found[0]
    return f"{v.kind}: {v.detail} at t = {v.t:.3f} s", checks


def _failure(cell: CellSpec, c: SpotCandidates) -> SpotFailure:
    """The dominant reason a spot has no candidate."""
    seam = cell.seams[c.seam_index].name
    if not c.rejected:
        return SpotFailure(seam, c.name, "unreachable", "no IK solution at any orientation")
    groups: Counter[str] = Counter()
    for reason, n in c.rejected.items():
        groups[reason.split(":")[0]] += n
    order = ("approach_blocked", "collision", "approach_branch", "approach_joint_limit", "joint_limit", "unreachable")
    for reason in order:
        if groups.get(reason):
            detail = ", ".join(f"{k} x{v}" for k, v in c.rejected.most_common(4))
            label = {"approach_branch": "approach_blocked", "approach_joint_limit": "joint_limit"}.get(reason, reason)
            return SpotFailure(seam, c.name, label, detail)
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


class _Sequencer:
    """Spot order and candidates with lazily verified straight moves and roadmap detours.

    Knowledge grows round by round: straight moves found blocked, detours found between two spots
    (offered to every candidate pair of those spots as enter-leg + detour + leave-leg), and detour
    legs found blocked. Cost matrices are cached per spot pair and recomputed only when what is
    known about that pair changes. When a straight move between two spots is blocked, the cheapest
    few other straight moves between them are checked at once; if all are blocked the spot pair is
    treated as detour-only (this may miss a rare free straight move, never admits a blocked one).
    A detour-only pair for which no detour is found gets a bounded number of further straight checks
    (`_retry_straight`); a free one lifts the detour-only mark, so one unlucky probe cannot leave the
    optimiser banning candidate pairs one round at a time.
    """

    def __init__(
        self, cell: CellSpec, robot: RobotModel, world: CollisionWorld, roadmap: Roadmap,
        spots: list[SpotCandidates], options: PlanOptions, rng: np.random.Generator,
        progress: Progress = _no_progress,
    ) -> None:
        self.cell, self.robot, self.world, self.roadmap = cell, robot, world, roadmap
        self.progress = progress
        self.spots, self.options, self.rng = spots, options, rng
        self.limits = robot.limits
        self.home = np.asarray(cell.home)[None, :]
        self.checks = 0
        self.rounds = 0
        self.dp_evaluations = 0
        # Per spot: time of approach + weld + retract (joint-time estimate of the short LIN moves).
        weld = cell.process.weld_time
        self.node = [2 * ptp_time_estimate(c.q_app, c.q_spot, self.limits, options.speed) + weld for c in spots]
        self.straight: dict[tuple[int, int], dict[tuple[int, int], bool]] = {}   # (i, j) -> (a, b) -> free
        self.detour_only: set[tuple[int, int]] = set()                           # unordered spot pairs
        self.no_way: dict[tuple[int, int], set[tuple[int, int]]] = {}            # (i, j) -> {(a, b)} unconnectable
        self.detours: list[tuple[int, int, Detour]] = []                          # (from spot, to spot, path)
        self.legs_bad: dict[tuple[int, int], set[tuple[int, int, int]]] = {}      # (i, j) -> {(a, b, v)}
        self.legs_ok: dict[tuple[int, int], set[tuple[int, int, int]]] = {}
        self._matrices: dict[tuple[int, int], FloatArray] = {}
        self._estimates: dict[tuple[int, int], FloatArray] = {}
        self.unresolved: Counter[str] = Counter()                                 # move label -> rounds left open

    # ------------------------------------------------------------------ knowledge and costs

    def q(self, i: int) -> FloatArray:
        return self.home if i == HOME else self.spots[i].q_app

    def _forget(self, i: int, j: int) -> None:
        self._matrices.pop((i, j), None)
        self._matrices.pop((j, i), None)

    def estimate(self, i: int, j: int) -> FloatArray:
        key = (i, j)
        if key not in self._estimates:
            back = self._estimates.get((j, i))
            if back is not None:        # |qb - qa| = |qa - qb| bit for bit: the estimate is symmetric
                self._estimates[key] = back.T
            else:
                qa, qb = self.q(i), self.q(j)
                self._estimates[key] = ptp_time_estimate(qa[:, None, :], qb[None, :, :], self.limits,
                                                         self.options.speed)
        return self._estimates[key]

    def vias_for(self, i: int, j: int) -> list[Detour]:
        """Known detours usable from spot i to spot j, oriented i -> j: those found between i and j,
        and those leaving i or reaching j (another leg then joins their far end to the other spot).
        Indices are stable: new detours are only appended."""
        out: list[Detour] = []
        for di, dj, det in self.detours:
            if di == i or dj == j:
                out.append(det)
            elif dj == i or di == j:
                out.append(Detour(det.waypoints[::-1].copy(), det.time_estimate, det.checks))
            else:
                out.append(_UNUSABLE)
        return out

    def _via_costs(self, i: int, j: int, v: int) -> FloatArray:
        det = self.vias_for(i, j)[v]
        if det is _UNUSABLE:
            return np.full((len(self.q(i)), len(self.q(j))), np.inf)
        wp, sp = det.waypoints, self.options.speed * self.options.detour_speed
        enter = ptp_time_estimate(self.q(i), wp[0][None, :], self.limits, sp)
        leave = ptp_time_estimate(wp[-1][None, :], self.q(j), self.limits, sp)
        inner = float(np.sum(ptp_time_estimate(wp[:-1], wp[1:], self.limits, sp)))
        via = enter[:, None] + inner + leave[None, :]
        bad = self.legs_bad.get((i, j), set())
        if len(bad) >= MAX_BLOCKED_LEGS:
            verified = np.full_like(via, np.inf)
            for a, b, vv in self.legs_ok.get((i, j), ()):
                if vv == v:
                    verified[a, b] = via[a, b]
            return verified
        for a, b, vv in bad:
            if vv == v:
                via[a, b] = np.inf
        return via

    def cost(self, i: int, j: int) -> FloatArray:
        """Estimated move time between every candidate pair, using what is known about blockages."""
        key = (i, j)
        if key in self._matrices:
            return self._matrices[key]
        est = self.estimate(i, j).copy()
        if (min(i, j), max(i, j)) in self.detour_only:
            # Until a detour is known, price one at a multiple of the straight move: optimistic
            # enough to be explored, costly enough not to be preferred.
            usable = any(d is not _UNUSABLE for d in self.vias_for(i, j))
            est = np.full_like(est, np.inf) if usable else est * DETOUR_PRIOR
        else:
            for (a, b), free in self.straight.get(key, {}).items():
                if not free:
                    est[a, b] = np.inf
        for v in range(len(self.vias_for(i, j))):
            est = np.minimum(est, self._via_costs(i, j, v))
        for a, b in self.no_way.get(key, ()):
            est[a, b] = np.inf
        self._matrices[key] = est
        return est

    def _record_straight(self, i: int, a: int, j: int, b: int, free: bool) -> None:
        self.straight.setdefault((i, j), {})[(a, b)] = free
        self.straight.setdefault((j, i), {})[(b, a)] = free
        self._forget(i, j)

    def _record_leg(self, i: int, a: int, j: int, b: int, v: int, ok: bool) -> None:
        table = self.legs_ok if ok else self.legs_bad
        table.setdefault((i, j), set()).add((a, b, v))
        table.setdefault((j, i), set()).add((b, a, v))
        self._forget(i, j)

    # ------------------------------------------------------------------ the loop

    def _blocks(self) -> list[SeamBlock]:
        blocks = []
        start = 0
        for seam in self.cell.seams:
            ids = tuple(range(start, start + len(seam.spots)))
            start += len(seam.spots)
            blocks.append(SeamBlock(ids, seam.ordered or self.options.baseline))
        return blocks

    def _probe_pairs(self) -> None:
        """One straight check per spot pair (its cheapest candidate pair): blocked pairs start detour-only."""
        ids = [HOME, *range(len(self.spots))]
        for x, i in enumerate(ids):
            for j in ids[x + 1:]:
                est = self.estimate(i, j)
                a, b = np.unravel_index(int(np.argmin(est)), est.shape)
                res = self.world.check_segment(self.q(i)[a], self.q(j)[b])
                self.checks += res.checks
                self._record_straight(i, int(a), j, int(b), res.free)
                if not res.free:
                    self.detour_only.add((min(i, j), max(i, j)))

    def run(self) -> tuple[Tour, list[Transition]] | str:
        blocks = self._blocks()
        self._probe_pairs()
        previous: tuple[tuple[int, ...], ...] = ()
        for _ in range(self.options.max_rounds):
            self.rounds += 1
            # Rounds end when a tour's legs are all known free; the bar shows rounds so far.
            self.progress("sequencing", self.rounds - 1, self.rounds)
            if self.options.baseline:
                order = tuple(s for b in blocks for s in b.spots)
                choice, cost = choice_for_order(order, self.cost, self.node)
                tour = Tour(order, choice, cost)
            else:
                budget = self.options.max_evaluations if self.rounds == 1 else max(50, self.options.max_evaluations // 4)
                tour, stats = optimise(blocks, self.cost, self.node, rng=self.rng, max_evaluations=budget,
                                       starts=previous)
                self.dp_evaluations += stats.dp_evaluations
                previous = (tour.order,)
            if not np.isfinite(tour.cost):
                return "no collision-free connection found between some spots (roadmap exhausted)"
            transitions = self._verify(tour)
            if transitions is not None:
                self.progress("sequencing", self.rounds, self.rounds)
                return tour, transitions
        worst = ", ".join(f"{label} ({n} rounds)" for label, n in self.unresolved.most_common(5))
        return (f"sequencing did not converge in {self.options.max_rounds} rounds; moves left without a "
                f"verified connection most often: {worst}")

    def _verify(self, tour: Tour) -> list[Transition] | None:
        """Transitions of the tour if every leg is known free; else learn from every leg, return None."""
        stops = [(HOME, 0), *zip(tour.order, tour.choice), (HOME, 0)]
        out: list[Transition] = []
        complete = True
        for (i, a), (j, b) in zip(stops[:-1], stops[1:]):
            qa, qb = self.q(i)[a], self.q(j)[b]
            label = f"{self._name(i)} -> {self._name(j)}"
            straight_ok = (min(i, j), max(i, j)) not in self.detour_only and \
                self.straight.get((i, j), {}).get((a, b), True)
            straight_cost = float(self.estimate(i, j)[a, b]) if straight_ok else np.inf
            via_costs = [float(self._via_costs(i, j, v)[a, b]) for v in range(len(self.vias_for(i, j)))]
            best_v = int(np.argmin(via_costs)) if via_costs else -1
            if straight_ok and (best_v < 0 or straight_cost <= via_costs[best_v]):
                if self._check_straight(i, a, j, b):
                    out.append(Transition("move", np.array([qa, qb]), label))
                else:
                    complete = False
                    self.unresolved[label] += 1
                continue
            if best_v < 0 or not np.isfinite(via_costs[best_v]):
                self._new_detour(i, a, j, b)
                complete = False
                self.unresolved[label] += 1
                continue
            path = self._check_via(i, a, j, b, best_v)
            if path is None:
                complete = False
                self.unresolved[label] += 1
                continue
            out.append(Transition("detour", path, label, self.vias_for(i, j)[best_v].checks))
        return out if complete else None

    def _check_straight(self, i: int, a: int, j: int, b: int) -> bool:
        known = self.straight.get((i, j), {}).get((a, b))
        if known is not None:
            return known
        res = self.world.check_segment(self.q(i)[a], self.q(j)[b])
        self.checks += res.checks
        self._record_straight(i, a, j, b, res.free)
        if res.free:
            return True
        # Blocked: try the cheapest other straight moves between these two spots right away.
        est = self.estimate(i, j)
        known_pairs = self.straight.get((i, j), {})
        tried = sum(1 for free in known_pairs.values() if not free)
        for flat in np.argsort(est, axis=None, kind="stable"):
            if tried >= self.options.straight_tries:
                break
            aa, bb = np.unravel_index(int(flat), est.shape)
            if (int(aa), int(bb)) in known_pairs:
                continue
            r = self.world.check_segment(self.q(i)[aa], self.q(j)[bb])
            self.checks += r.checks
            self._record_straight(i, int(aa), j, int(bb), r.free)
            if r.free:
                return False          # a free alternative exists; let the optimiser weigh it
            tried += 1
        self.detour_only.add((min(i, j), max(i, j)))
        self._forget(i, j)
        self._new_detour(i, a, j, b)
        return False

    def _lift_detour(self, i: int, a: int, j: int, b: int) -> Detour | None:
        """Up, across, down: the TCP raised by h at both ends in the same IK branch, for clamps.

        The cheapest kind of detour an operator would teach; tried for rising h before the roadmap.
        """
        qa, qb = self.q(i)[a], self.q(j)[b]
        up = invert(np.asarray(self.cell.T_world_base))[:3, :3] @ np.array([0.0, 0.0, 1.0])
        checks = 0
        for h in LIFT_HEIGHTS_M:
            ends = []
            for q, idx, col in ((qa, i, a), (qb, j, b)):
                if idx == HOME:
                    ends.append(q)
                    continue
                T = fk_tcp(self.robot, q)
                T[:3, 3] += h * up
                table = solve_all(self.robot, T[None], q_hint=q)
                column = int(self.spots[idx].column[col])
                if not table.valid[0, column]:
                    break
                lifted = table.q[0, column].copy()
                ends.append(q + wrap_to_pi(lifted - q))
            if len(ends) < 2 or not self.limits.contains(np.array(ends)).all():
                continue
            path = np.array([qa, ends[0], ends[1], qb])
            ok = True
            for p0, p1 in zip(path[:-1], path[1:]):
                if np.allclose(p0, p1):
                    continue
                res = self.world.check_segment(p0, p1)
                checks += res.checks
                if not res.free:
                    ok = False
                    break
            if ok:
                keep = [0] + [k for k in range(1, 4) if not np.allclose(path[k], path[k - 1])]
                wp = path[keep]
                return Detour(wp, float(np.sum(ptp_time_estimate(wp[:-1], wp[1:], self.limits))), checks)
        self.checks += checks
        return None

    def _new_detour(self, i: int, a: int, j: int, b: int) -> None:
        # Lift first: on clamp cells it is found in ~1,000 checks; the roadmap is the general fallback.
        det = self._lift_detour(i, a, j, b) or self.roadmap.query(self.q(i)[a], self.q(j)[b])
        if det is None:
            # No way found for this exact pair: make sure the optimiser stops choosing it.
            self.no_way.setdefault((i, j), set()).add((a, b))
            self.no_way.setdefault((j, i), set()).add((b, a))
            self._forget(i, j)
            if (min(i, j), max(i, j)) in self.detour_only:
                self._retry_straight(i, j)
            return
        self.checks += det.checks
        self.detours.append((i, j, det))
        # Every pair sharing an end spot with this detour may now use it.
        self._matrices.clear()
        self._record_leg(i, a, j, b, len(self.detours) - 1, True)   # its ends are this pair's configurations

    def _retry_straight(self, i: int, j: int) -> bool:
        """A detour-only spot pair without a detour: check up to `straight_tries` straight moves between
        candidate pairs not yet checked, cheapest first; a free one lifts the detour-only mark.

        The pair may have been marked detour-only after a single blocked probe (`_probe_pairs`) while
        other candidate pairs of the same two spots move freely (a clamp beside one orientation only).
        """
        est = self.estimate(i, j)
        known = self.straight.get((i, j), {})
        banned = self.no_way.get((i, j), set())
        tried = 0
        for flat in np.argsort(est, axis=None, kind="stable"):
            if tried >= self.options.straight_tries:
                break
            a, b = (int(x) for x in np.unravel_index(int(flat), est.shape))
            if (a, b) in known or (a, b) in banned or not np.isfinite(est[a, b]):
                continue
            res = self.world.check_segment(self.q(i)[a], self.q(j)[b])
            self.checks += res.checks
            self._record_straight(i, a, j, b, res.free)
            tried += 1
            if res.free:
                self.detour_only.discard((min(i, j), max(i, j)))
                self._forget(i, j)
                return True
        return False

    def _check_via(self, i: int, a: int, j: int, b: int, v: int) -> FloatArray | None:
        wp = self.vias_for(i, j)[v].waypoints
        qa, qb = self.q(i)[a], self.q(j)[b]
        if (a, b, v) not in self.legs_ok.get((i, j), set()):
            for p, r in ((qa, wp[0]), (wp[-1], qb)):
                if np.allclose(p, r):
                    continue
                res = self.world.check_segment(p, r)
                self.checks += res.checks
                if not res.free:
                    self._record_leg(i, a, j, b, v, False)
                    self._new_detour(i, a, j, b)
                    return None
            self._record_leg(i, a, j, b, v, True)
        path = np.vstack([qa[None, :], wp, qb[None, :]])
        keep = [0] + [k for k in range(1, len(path)) if not np.allclose(path[k], path[k - 1])]
        return path[keep]

    def _name(self, i: int) -> str:
        return "home" if i == HOME else self.spots[i].name


def _time_tour(
    cell: CellSpec, robot: RobotModel, world: CollisionWorld, spots: list[SpotCandidates], tour: Tour,
    transitions: list[Transition], options: PlanOptions, progress: Progress = _no_progress,
) -> tuple[Trajectory, list[SpotPlan], list[Transition]]:
    """Junction by junction (retract, move or detour, approach; `junction.time_junction`) and dwells."""
    grids = [orientation_grid(seam) for seam in cell.seams]
    ends: list[WeldEnd] = []
    welded: list[tuple[int, int, FloatArray, FloatArray]] = []
    for i, a in zip(tour.order, tour.choice):
        end = weld_end(cell, spots[i], a, grids)
        ends.append(end)
        welded.append((i, a, end.T_spot, end.T_app))
    blocks: list[list[Segment]] = []
    timed: list[Transition] = []
    q_now = as_written_joints(cell.home)
    weld_time = written_seconds(cell.process.weld_time)
    for k, trans in enumerate(transitions):
        progress("timing", k, len(transitions))
        before = ends[k - 1] if k > 0 else None
        after = ends[k] if k < len(ends) else None
        waypoints = as_written_joints(trans.waypoints)      # the first row: where the retract ends
        trans = replace(trans, waypoints=waypoints)
        junction = time_junction(
            robot, world, robot.limits, q_now, waypoints, trans.kind, trans.label, before, after,
            tcp_speed=written_tcp_speed(options.tcp_speed * options.speed),
            speed=written_speed(options.speed * (options.detour_speed if trans.kind == "detour" else 1.0)),
            jerk_limited=options.jerk_limited, flyby=options.blend,
        )
        block = list(junction.segments)
        timed.append(replace(trans, blend_radius=junction.corner_radius, flyby_radius=junction.junction_radius))
        q_now = block[-1].q[-1]
        if after is not None:
            block.append(dwell(q_now, weld_time, kind="weld", label=after.label))
        blocks.append(block)
    segments: list[Segment] = []
    waits = {w.index: w for w in _waits(cell, robot, blocks)}
    for k, block in enumerate(blocks):
        if k in waits:
            w = waits[k]
            segments.append(dwell(block[0].q[0], w.seconds, kind="wait", label=f"wait for {w.obstacle}"))
            timed[k] = replace(timed[k], wait=w)
        segments.extend(block)
    progress("timing", len(transitions), len(transitions))
    traj = resample(concatenate(segments))
    plans = []
    for i, a, T_spot, T_app in welded:
        c = spots[i]
        seam = cell.seams[c.seam_index]
        label = f"{seam.name}/{c.name}"
        phase = traj.phases_of("weld", label)[0]
        q_spot = np.asarray(traj.q[phase.i_start], dtype=float)
        # Each target states its own configuration: on ABB and FANUC arms J2 is often near 0 at
        # the spot and changes sign over the approach line (issue 14).
        plans.append(SpotPlan(seam.name, c.name, c.angles[a], config_text(robot, c.q_spot[a]), q_spot,
                              as_written_joints(c.q_app[a]), float(phase.t_start), float(phase.t_end), T_spot, T_app,
                              config_text(robot, c.q_app[a])))
    return traj, plans, timed


def weld_end(cell: CellSpec, c: SpotCandidates, a: int, grids: list[OrientationGrid]) -> WeldEnd:
    """Candidate a of spot c as a junction end: its TCP poses at the spot and the approach point
    (robot base frame) as the program states them. Timed and checked rounded to the program's
    decimals, so the written program is exactly the motion checked (`rebuild` gives it back).
    grids: `orientation_grid` of every seam of the cell."""
    seam = cell.seams[c.seam_index]
    T_world = spot_poses((seam.spots[c.spot_index],), grids[c.seam_index])[0, c.orient[a]]
    # Rounded as the program states them: in the controller's base frame (SPEC §6).
    C = cell.robot.controller.T_root_base
    T_spot = as_written_pose_in(invert(np.asarray(cell.T_world_base)) @ T_world, C)
    T_app = as_written_pose_in(approach_poses(T_spot, cell.process.approach), C)
    return WeldEnd(T_spot, T_app, None, f"{seam.name}/{c.name}")


def _waits(cell: CellSpec, robot: RobotModel, blocks: list[list[Segment]]) -> list[WaitPlan]:
    """Where the robot waits for dynamic obstacles (`waiting`), checked against them alone."""
    if not cell.dynamic:
        return []
    world = CollisionWorld(robot, build_scene(replace(cell, objects=()), robot), cell.process.clearance)
    windows = {d.name: d.present if d.present is not None else ((0.0, float("inf")),) for d in cell.dynamic}
    return schedule_waits(world, blocks, windows)
