"""The configuration graph and detour learner: spot order and candidates by DP and local search on
estimated motion times; straight moves verified lazily, blocked ones replaced by detours (a lift over
the obstacle, else a path through the roadmap), rounds repeated until every move of the best tour is
known free."""

from __future__ import annotations

import copy
import itertools
import logging
from collections import Counter
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray, IntArray
from robomax_py.plan.candidates import SpotCandidates
from robomax_py.plan.cspace_detour import grid_detour
from robomax_py.plan.loads import Loads
from robomax_py.plan.results import Progress, ResolvedOptions, Transition, _no_progress
from robomax_py.plan.roadmap import Detour, Roadmap
from robomax_py.plan.rrt_detour import rrt_detour
from robomax_py.plan.sequence import (
    EXACT_ORDERS,
    HOME,
    SeamBlock,
    Tour,
    choice_for_order,
    optimise,
    order_count,
)
from robomax_py.plan.thinning import representatives
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.robot.ik.turns import wrap_to_pi
from robomax_py.robot.solve import solve_all
from robomax_py.spec import CellSpec
from robomax_py.timing import (
    ptp_time_estimate,
)
from robomax_py.transforms import invert
from robomax_py.world.collision import CollisionWorld, bisection_order

log = logging.getLogger(__name__)

LIFT_HEIGHTS_M = (0.08, 0.15, 0.25, 0.4)
# Cost of a detour not yet found, as a multiple of the straight move's estimate.
DETOUR_PRIOR = 1.6
# Blocked detour legs between two spots after which only verified legs are offered for that pair:
# each blocked leg bans one (candidate, candidate, detour) triple, and two spots with hundreds of
# candidates each would otherwise let the optimiser try a fresh unverified triple every round.
MAX_BLOCKED_LEGS = 4
# Placeholder keeping detour indices stable for pairs a detour cannot serve.
_UNUSABLE = Detour(np.zeros((0, 0)), float("inf"), 0)
_ONE = np.zeros(1, dtype=np.int64)   # home's only candidate
# Blocked straight moves between two spots after which only straight moves known to be free are
# offered between them (a `straight_tries` batch is checked after each blocked one).
MAX_BLOCKED_STRAIGHT = 24
# Failed detour searches between two spots after which they count as unconnected (but for
# detours found at their ends).
MAX_FAILED_DETOURS = 6
# Re-choices of the candidates of one order per round (`Sequencer._repair`).
REPAIRS_PER_ROUND = 40
# States of the coarse probe of a move between two stops that are not near neighbours.
PROBE_STATES = 9
# Withdrawing the gun off a flange (`Sequencer._withdrawn_detour`): directions perpendicular to the
# electrode axis, distances (m; spots lie ~20 mm from the edge the C wraps round, and its jaws
# reach a little past the electrodes), and exit pairs tried per detour.
WITHDRAW_DIRECTIONS = 8
WITHDRAW_M = (0.06, 0.12)
WITHDRAW_PAIRS = 6
# An order whose best tour has a move no reached candidate can make (`Sequencer._open_dead_end`):
# straight moves checked from the reached candidates of that move, then detour searches (the
# random trees of `rrt_detour` the last resort), before the cell is called disconnected.
DEAD_END_STRAIGHT = 48
DEAD_END_DETOURS = 3


def _distinct(path: FloatArray) -> FloatArray:
    """The polyline without repeated waypoints."""
    keep = [0] + [k for k in range(1, len(path)) if not np.allclose(path[k], path[k - 1])]
    return path[keep]


def _moves_of(order: tuple[int, ...]) -> set[tuple[int, int]]:
    stops = (HOME, *order, HOME)
    return set(zip(stops[:-1], stops[1:]))




@dataclass(frozen=True, slots=True)
class SequencingOutcome:
    """What `Sequencer.run` found.

    status : "found" (tour and transitions set, every leg known free), "disconnected" (some spots
    have no collision-free connection) or "not_converged" (rounds ran out); `message` says why.
    """

    status: Literal["found", "disconnected", "not_converged"]
    tour: Tour | None = None
    transitions: tuple[Transition, ...] = ()
    message: str = ""


@dataclass(frozen=True, slots=True)
class _TourCheck:
    complete: bool                         # every leg of the tour is known free
    transitions: tuple[Transition, ...]    # the legs known free so far, in tour order


class Sequencer:
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
        spots: list[SpotCandidates], options: ResolvedOptions, rng: np.random.Generator,
        progress: Progress = _no_progress, loads: Loads | None = None,
    ) -> None:
        self.cell, self.robot, self.world, self.roadmap = cell, robot, world, roadmap
        # Pick and place: the moves leaving a grip carry the part (their own world and roadmap).
        self.loads = loads
        self._roadmaps: dict[str | None, Roadmap] = {None: roadmap}
        self.progress = progress
        self.spots, self.options, self.rng = spots, options, rng
        self.limits = robot.limits
        self.home = np.asarray(cell.home)[None, :]
        self.checks = 0
        self.rounds = 0
        self.dp_evaluations = 0
        # Per spot: time of approach + weld + retract (joint-time estimate of the short LIN moves).
        weld = [cell.process.weld_time_of(cell.seams[c.seam_index].spots[c.spot_index]) for c in spots]
        self.node = [2 * ptp_time_estimate(c.q_app, c.q_spot, self.limits, options.speed) + w for c, w in zip(spots, weld)]
        self.straight: dict[tuple[int, int], dict[tuple[int, int], bool]] = {}   # (i, j) -> (a, b) -> free
        self.detour_only: set[tuple[int, int]] = set()                           # unordered spot pairs
        self.no_way: dict[tuple[int, int], set[tuple[int, int]]] = {}            # (i, j) -> {(a, b)} unconnectable
        self.detours: list[tuple[int, int, Detour]] = []                          # (from spot, to spot, path)
        self.legs_bad: dict[tuple[int, int], set[tuple[int, int, int]]] = {}      # (i, j) -> {(a, b, v)}
        self.legs_ok: dict[tuple[int, int], set[tuple[int, int, int]]] = {}
        # The order search sees a few representatives per spot; the exact DP then uses every candidate.
        self.reps = [representatives(c.q_app, n, self.limits.velocity, options.order_candidates)
                     for c, n in zip(spots, self.node)]
        self.node_reps = [n[r] for n, r in zip(self.node, self.reps)]
        self._matrices: dict[tuple[int, int], FloatArray] = {}   # representatives x representatives
        self._full: dict[tuple[int, int], FloatArray] = {}       # every candidate, pairs of the last order only
        self.unresolved: Counter[str] = Counter()                                 # move label -> rounds left open
        self.failed_detours: Counter[tuple[int, int]] = Counter()                 # unordered spot pair -> searches
        self.unconnected: set[tuple[int, int]] = set()                            # unordered spot pairs given up
        self._exit_cache: dict[tuple[int, int], list[FloatArray]] = {}            # (spot, candidate) -> exits
        self._inner: dict[tuple[int, bool], float] = {}                           # (detour, reversed) -> time
        # What `_probe_pairs` learnt (straight moves, detour-only pairs, checks) and the generator as
        # it was before any round: a sequencer of the given order starts from them (`given_order`).
        self._probed: tuple[dict[tuple[int, int], dict[tuple[int, int], bool]], set[tuple[int, int]], int] | None = None
        self._rng_at_start = copy.deepcopy(rng)

    # ------------------------------------------------------------------ knowledge and costs

    def q(self, i: int) -> FloatArray:
        return self.home if i == HOME else self.spots[i].q_app

    def _load(self, i: int) -> str | None:
        return None if self.loads is None else self.loads.part_after(i)

    def world_from(self, i: int) -> CollisionWorld:
        """The collision world of the moves leaving stop i (with the part it grips, if any)."""
        return self.world if self.loads is None else self.loads.world_after(i, self.world)

    def roadmap_from(self, i: int) -> Roadmap:
        """The roadmap of the moves leaving stop i, built for a held part when first needed."""
        part = self._load(i)
        if part not in self._roadmaps:
            assert self.loads is not None and part is not None
            rng = np.random.default_rng([self.cell.planner.seed, 1 + sorted(self.loads.worlds).index(part)])
            anchors = np.vstack([self.home, *[c.q_app for c in self.spots]])
            self._roadmaps[part] = Roadmap(self.world_from(i), self.limits, anchors, rng, self.options.roadmap_nodes,
                                           self.options.roadmap_k, seeds=anchors)
        return self._roadmaps[part]

    def _forget(self, i: int, j: int) -> None:
        for table in (self._matrices, self._full):
            table.pop((i, j), None)
            table.pop((j, i), None)

    def _rows(self, i: int) -> IntArray:
        """The candidates of spot i the order search sees."""
        return _ONE if i == HOME else self.reps[i]

    def _positions(self, i: int, rows: IntArray) -> IntArray:
        """Candidate index -> position in `rows` (-1 where absent)."""
        pos = np.full(len(self.q(i)), -1, dtype=np.int64)
        pos[rows] = np.arange(len(rows))
        return pos

    def estimate(self, i: int, j: int) -> FloatArray:
        """Estimated straight-move time between every candidate of spot i and every one of spot j
        (not cached: only asked for when a move was found blocked)."""
        return ptp_time_estimate(self.q(i)[:, None, :], self.q(j)[None, :, :], self.limits, self.options.speed)

    def vias_for(self, i: int, j: int) -> list[Detour]:
        """Known detours usable from spot i to spot j, oriented i -> j: those found between i and j,
        and those leaving i or reaching j (another leg then joins their far end to the other spot).
        Indices are stable: new detours are only appended."""
        out: list[Detour] = []
        for di, dj, det in self.detours:
            if self._load(di) != self._load(i):
                out.append(_UNUSABLE)            # found for another load: not checked for this one
            elif di == i or dj == j:
                out.append(det)
            elif dj == i or di == j:
                out.append(Detour(det.waypoints[::-1].copy(), det.time_estimate, det.checks))
            else:
                out.append(_UNUSABLE)
        return out

    def _via_costs(self, i: int, j: int, vias: list[Detour], rows: IntArray, cols: IntArray, pi: IntArray,
                   pj: IntArray) -> FloatArray:
        """Least time of enter leg + detour + leave leg over the usable detours `vias` (from
        `vias_for`) between candidates `rows` of i and `cols` of j (positions `pi`, `pj`), inf where
        none. The enter and leave legs of every detour are estimated in one call each: per detour,
        two calls on a few rows cost numpy's overhead many times the arithmetic, and a spot beside
        clamps collects dozens of detours."""
        out = np.full((len(rows), len(cols)), np.inf)
        usable = [v for v, det in enumerate(vias) if det is not _UNUSABLE]
        if not usable:
            return out
        sp = self._detour_speed()
        starts = np.array([vias[v].waypoints[0] for v in usable])
        ends = np.array([vias[v].waypoints[-1] for v in usable])
        enter = ptp_time_estimate(self.q(i)[rows][:, None, :], starts[None, :, :], self.limits, sp)   # rows x vias
        leave = ptp_time_estimate(ends[:, None, :], self.q(j)[cols][None, :, :], self.limits, sp)     # vias x cols
        bad = self.legs_bad.get((i, j), set())
        verified_only = len(bad) >= MAX_BLOCKED_LEGS
        marks: dict[int, list[tuple[int, int]]] = {}
        for a, b, vv in (self.legs_ok.get((i, j), ()) if verified_only else bad):
            if pi[a] >= 0 and pj[b] >= 0:
                marks.setdefault(vv, []).append((int(pi[a]), int(pj[b])))
        for k, v in enumerate(usable):
            via = enter[:, k, None] + self._inner_time(v, vias[v]) + leave[k][None, :]
            cells = marks.get(v, ())
            if verified_only:
                verified = np.full_like(via, np.inf)
                for r, c in cells:
                    verified[r, c] = via[r, c]
                via = verified
            else:
                for r, c in cells:
                    via[r, c] = np.inf
            out = np.minimum(out, via)
        return out

    def _detour_speed(self) -> float:
        """The speed fraction detour moves are estimated at (options resolved from the cell)."""
        speed, detour = self.options.speed, self.options.detour_speed
        assert speed is not None and detour is not None
        return speed * detour

    def _inner_time(self, v: int, det: Detour) -> float:
        """Estimated time along detour v oriented as `det` (from `vias_for`), cached per direction
        (the sum taken in the order travelled, as it always was)."""
        wp = det.waypoints
        key = (v, not np.array_equal(wp[0], self.detours[v][2].waypoints[0]))
        got = self._inner.get(key)
        if got is None:
            sp = self._detour_speed()
            got = self._inner[key] = float(np.sum(ptp_time_estimate(wp[:-1], wp[1:], self.limits, sp)))
        return got

    def _pair_via_costs(self, i: int, a: int, j: int, b: int) -> FloatArray:
        """`_via_costs` of every known detour for one candidate pair (a of i, b of j), at once:
        `_verify` asks this for every leg of every tour checked."""
        vias = self.vias_for(i, j)
        out = np.full(len(vias), np.inf)
        usable = [v for v, det in enumerate(vias) if det is not _UNUSABLE]
        if not usable:
            return out
        sp = self._detour_speed()
        enter = ptp_time_estimate(self.q(i)[a][None, :], np.array([vias[v].waypoints[0] for v in usable]),
                                  self.limits, sp)
        leave = ptp_time_estimate(np.array([vias[v].waypoints[-1] for v in usable]), self.q(j)[b][None, :],
                                  self.limits, sp)
        via = enter + np.array([self._inner_time(v, vias[v]) for v in usable]) + leave
        bad = self.legs_bad.get((i, j), set())
        if len(bad) >= MAX_BLOCKED_LEGS:
            ok = self.legs_ok.get((i, j), set())
            keep = np.array([(a, b, v) in ok for v in usable])
        else:
            keep = np.array([(a, b, v) not in bad for v in usable])
        out[usable] = np.where(keep, via, np.inf)
        return out

    def _costs(self, i: int, j: int, rows: IntArray, cols: IntArray) -> FloatArray:
        """Estimated move time between candidates `rows` of i and `cols` of j, using what is known
        about blockages."""
        key = (i, j)
        est = ptp_time_estimate(self.q(i)[rows][:, None, :], self.q(j)[cols][None, :, :], self.limits,
                                self.options.speed)
        pi, pj = self._positions(i, rows), self._positions(j, cols)
        vias = self.vias_for(i, j)
        if (min(i, j), max(i, j)) in self.detour_only:
            # Until a detour is known, price one at a multiple of the straight move: optimistic
            # enough to be explored, costly enough not to be preferred.
            usable = any(d is not _UNUSABLE for d in vias)
            unconnected = (min(i, j), max(i, j)) in self.unconnected
            est = np.full_like(est, np.inf) if usable or unconnected else est * DETOUR_PRIOR
        else:
            known = self.straight.get(key, {})
            if self._verified_straight_only(i, j):
                # Mostly blocked between these spots: only straight moves known to be free are
                # offered, or the DP picks a fresh unchecked pair of candidates every round.
                verified = np.full_like(est, np.inf)
                for (a, b), free in known.items():
                    if free and pi[a] >= 0 and pj[b] >= 0:
                        verified[pi[a], pj[b]] = est[pi[a], pj[b]]
                est = verified
            else:
                for (a, b), free in known.items():
                    if not free and pi[a] >= 0 and pj[b] >= 0:
                        est[pi[a], pj[b]] = np.inf
        est = np.minimum(est, self._via_costs(i, j, vias, rows, cols, pi, pj))
        for a, b in self.no_way.get(key, ()):
            if pi[a] >= 0 and pj[b] >= 0:
                est[pi[a], pj[b]] = np.inf
        return est

    def _verified_straight_only(self, i: int, j: int) -> bool:
        """Whether only straight moves known to be free are offered between spots i and j: many
        found blocked, or the pair given up (no detour found MAX_FAILED_DETOURS times), where
        every fresh candidate pair tried would cost another detour search."""
        known = self.straight.get((i, j), {})
        blocked = sum(1 for free in known.values() if not free)
        # Given up on detours, yet most straight moves checked are free: the failed searches were
        # for candidate pairs the gun cannot join without turning (two spins on one flange), not a
        # wall between the spots, and the next unchecked straight move is as likely free as not.
        return (blocked >= MAX_BLOCKED_STRAIGHT
                or ((min(i, j), max(i, j)) in self.unconnected and blocked >= len(known) - blocked))

    def cost(self, i: int, j: int) -> FloatArray:
        """`_costs` between the representatives of two spots (what the order search sees), cached."""
        key = (i, j)
        got = self._matrices.get(key)
        if got is None:
            got = self._matrices[key] = self._costs(i, j, self._rows(i), self._rows(j))
        return got

    def full_cost(self, i: int, j: int) -> FloatArray:
        """`_costs` between every candidate of two spots (for the exact DP of one order), cached."""
        key = (i, j)
        got = self._full.get(key)
        if got is None:
            got = self._full[key] = self._costs(i, j, np.arange(len(self.q(i))), np.arange(len(self.q(j))))
        return got

    def _try_straight(self, i: int, a: int, j: int, b: int) -> bool:
        """Check the straight move from candidate a of i to b of j, count and record it; a free one
        takes the pair off the detour-only list."""
        res = self.world_from(i).check_segment(self.q(i)[a], self.q(j)[b])
        self.checks += res.checks
        self._record_straight(i, a, j, b, res.free)
        if res.free:
            self.detour_only.discard((min(i, j), max(i, j)))
        return bool(res.free)

    def _record_straight(self, i: int, a: int, j: int, b: int, free: bool) -> None:
        self.straight.setdefault((i, j), {})[(a, b)] = free
        if self._load(i) == self._load(j):       # else the way back is checked in another world
            self.straight.setdefault((j, i), {})[(b, a)] = free
        self._forget(i, j)

    def _record_leg(self, i: int, a: int, j: int, b: int, v: int, ok: bool) -> None:
        table = self.legs_ok if ok else self.legs_bad
        table.setdefault((i, j), set()).add((a, b, v))
        if self._load(i) == self._load(j):
            table.setdefault((j, i), set()).add((b, a, v))
        self._forget(i, j)

    # ------------------------------------------------------------------ the loop

    def _blocks(self) -> list[SeamBlock]:
        blocks = []
        start = 0
        for seam in self.cell.seams:
            ids = tuple(range(start, start + len(seam.spots)))
            start += len(seam.spots)
            blocks.append(SeamBlock(ids, seam.ordered or self.options.baseline or self.options.given_order))
        return blocks

    def probe_pair(self, i: int, j: int) -> tuple[int, int]:
        """The candidate pair whose straight move `_probe_pairs` checks: the cheapest straight move
        between the two spots' representatives. Not cached: the probe asks for every pair once, and
        the search later needs only a few of those matrices."""
        ri, rj = self._rows(i), self._rows(j)
        est = ptp_time_estimate(self.q(i)[ri][:, None, :], self.q(j)[rj][None, :, :], self.limits, self.options.speed)
        a, b = np.unravel_index(int(np.argmin(est)), est.shape)
        return int(ri[a]), int(rj[b])

    def _probe_pairs(self) -> None:
        """What is blocked, learnt before the first round: a straight move (the cheapest
        representative pair) from every spot to its `probe_neighbours` nearest spots, checked in
        full; and between every other pair of stops (home included) a coarse probe of
        PROBE_STATES states of that move. A blocked probe makes the pair detour-only; a free coarse
        probe proves nothing and teaches nothing (the move is checked in full when a tour uses it).

        Checking every pair in full cost N^2 checks of moves whose length grows with the distance:
        N^3 states in all (2.8 M at 60 spots). Far pairs are rarely in a tour but, unprobed, each
        blocked one the search reaches costs a round (35 instead of 3 on the reference cell).
        """
        ids = [HOME, *range(len(self.spots))]
        k = min(self.options.probe_neighbours, len(self.spots) - 1)
        near: set[tuple[int, int]] = set()
        if k > 0:
            xyz = np.array([self.cell.seams[c.seam_index].spots[c.spot_index].xyz for c in self.spots])
            gap = np.linalg.norm(xyz[:, None, :] - xyz[None, :, :], axis=2)
            np.fill_diagonal(gap, np.inf)
            nearest = np.argsort(gap, axis=1, kind="stable")[:, :k]
            near = {(min(i, int(j)), max(i, int(j))) for i in range(len(self.spots)) for j in nearest[i]}
        fractions = bisection_order(PROBE_STATES - 1) / (PROBE_STATES - 1)
        for x, i in enumerate(ids):
            for j in ids[x + 1:]:
                a, b = self.probe_pair(i, j)
                qa, qb = self.q(i)[a], self.q(j)[b]
                if (i, j) in near:
                    res = self.world_from(i).check_segment(qa, qb)
                    self.checks += res.checks
                    free = res.free
                    self._record_straight(i, a, j, b, free)
                else:
                    free = True
                    for f in fractions:
                        self.checks += 1
                        if not self.world_from(i).is_free(qa + f * (qb - qa)):
                            free = False
                            break
                    if not free:
                        self._record_straight(i, a, j, b, False)
                if not free:
                    self.detour_only.add((i, j))
                    self._forget(i, j)

    def run(self) -> SequencingOutcome:
        """The best tour whose every leg is known free, or why there is none (a status, not None)."""
        blocks = self._blocks()
        if self._probed is None:
            self._probe_pairs()
            self._probed = ({k: dict(v) for k, v in self.straight.items()}, set(self.detour_only), self.checks)
        previous: tuple[tuple[int, ...], ...] = ()
        for _ in range(self.options.max_rounds):
            self.rounds += 1
            # Rounds end when a tour's legs are all known free; the bar shows rounds so far.
            self.progress("sequencing", self.rounds - 1, self.rounds)
            if self.options.baseline or self.options.given_order:
                order = tuple(s for b in blocks for s in b.spots)
                choice, cost = choice_for_order(order, self.full_cost, self.node)
                tour = Tour(order, choice, cost)
            else:
                budget = self.options.max_evaluations if self.rounds == 1 else max(50, self.options.max_evaluations // 4)
                # Few orders are enumerated exactly over every candidate; else the search sees representatives.
                exact = order_count(blocks) <= EXACT_ORDERS
                found, stats = optimise(blocks, self.full_cost if exact else self.cost,
                                        self.node if exact else self.node_reps, rng=self.rng,
                                        max_evaluations=budget, exact_limit=EXACT_ORDERS, starts=previous)
                self.dp_evaluations += stats.dp_evaluations
                previous = (found.order,)
                # Every candidate for the order found; full matrices only of this order's moves.
                moves = _moves_of(found.order)
                self._full = {key: m for key, m in self._full.items() if key in moves}
                choice, cost = choice_for_order(found.order, self.full_cost, self.node)
                tour = Tour(found.order, choice, cost)
            if not np.isfinite(tour.cost) and self._open_dead_end(tour.order):
                continue
            if not np.isfinite(tour.cost):
                given_up = ", ".join(f"{self._name(i)} - {self._name(j)}" for i, j in sorted(self.unconnected)[:6])
                return SequencingOutcome("disconnected", message="no collision-free connection found between some "
                                         f"spots (roadmap exhausted): {self._dead_end(tour.order)}"
                                         + (f"; no detour found {MAX_FAILED_DETOURS} times between {given_up}"
                                            if given_up else ""))
            verified = self._verify(tour)
            if verified.complete:
                self.progress("sequencing", self.rounds, self.rounds)
                return SequencingOutcome("found", tour, verified.transitions)
            self._repair(tour.order)
        worst = ", ".join(f"{label} ({n} rounds)" for label, n in self.unresolved.most_common(5))
        return SequencingOutcome("not_converged", message=f"sequencing did not converge in {self.options.max_rounds} "
                                 f"rounds; moves left without a verified connection most often: {worst}")

    def given_order(self) -> Sequencer:
        """A sequencer of the cell file's order (the published method, `PlanOptions.given_order`)
        that starts where a fresh one would after its probe, so that its tour is the one the
        published method plans: the probe is a function of the candidates alone and is copied, not
        repeated; the random generator starts as this sequencer's did. Call after `run`."""
        assert self._probed is not None, "run() first"
        other = Sequencer(self.cell, self.robot, self.world, self.roadmap.fresh(), self.spots,
                          replace(self.options, given_order=True), copy.deepcopy(self._rng_at_start),
                          loads=self.loads)
        straight, detour_only, _ = self._probed
        other.straight = {k: dict(v) for k, v in straight.items()}
        other.detour_only = set(detour_only)
        other._probed = (straight, detour_only, 0)
        # Roadmaps built for held parts are seeded by the cell alone; their checked edges are shared.
        other._roadmaps.update({part: r.fresh() for part, r in self._roadmaps.items() if part is not None})
        return other

    def _repair(self, order: tuple[int, ...]) -> None:
        """The candidates of one order re-chosen (the exact DP, cheap next to an order search) and
        checked again, up to REPAIRS_PER_ROUND times, until every leg is known free or the order
        has no finite tour. A blocked move between two spots with many near-equal candidates
        (other wrist turns of one pose, of the same joint time where a big axis sets it) otherwise
        costs a round per candidate pair: the order search proposes the same order with the next
        unchecked pair. Nothing is returned from here: the next round's order search weighs what
        was learnt, and a tour is taken only as a round's optimum."""
        for _ in range(REPAIRS_PER_ROUND):
            choice, cost = choice_for_order(order, self.full_cost, self.node)
            if not np.isfinite(cost) or self._verify(Tour(order, choice, cost)).complete:
                return

    def _open_dead_end(self, order: tuple[int, ...]) -> bool:
        """Whether something new joins the first move of `order` that no reached candidate can make
        (the tour's cost is infinite there): a free straight move from a candidate the tour reaches
        before that move, else a detour found from one (cheapest reached first).

        What is known can leave such a move with no offer at all while the two spots do connect:
        candidate pairs whose detours all failed (two spins of the gun on one flange, where it must
        slide off to turn) mark the spots unconnected, after which only straight moves known free
        are offered, and those join candidates the rest of the tour does not reach; or detours found
        for neighbouring pairs whose legs are blocked stand in for the detour this pair never got.
        The moves checked here start where the tour actually is, as a forward chain would."""
        stops = (HOME, *order, HOME)
        value = np.zeros(1)
        for prev, nxt in itertools.pairwise(stops):
            step = np.min(value[:, None] + self.full_cost(prev, nxt), axis=0)
            if np.isfinite(step).any():
                value = step
                continue
            reached = np.flatnonzero(np.isfinite(value))
            est = self.estimate(prev, nxt)[reached] + value[reached][:, None]
            ranked = [(int(reached[r]), int(b)) for r, b in
                      zip(*np.unravel_index(np.argsort(est, axis=None, kind="stable"), est.shape))]
            known = self.straight.get((prev, nxt), {})
            banned = self.no_way.get((prev, nxt), set())
            tried = 0
            for a, b in ranked:
                if tried >= DEAD_END_STRAIGHT:
                    break
                if (a, b) in known or (a, b) in banned:
                    continue
                tried += 1
                if self._try_straight(prev, a, nxt, b):
                    log.debug("dead end %s -> %s opened by a straight move", self._name(prev), self._name(nxt))
                    return True
            found = len(self.detours)
            searched = 0
            for a, b in ranked:
                if searched >= DEAD_END_DETOURS:
                    break
                if (a, b) in banned:
                    continue
                self._new_detour(prev, a, nxt, b, last_resort=True)
                searched += 1
                if len(self.detours) > found:
                    log.debug("dead end %s -> %s opened by a detour", self._name(prev), self._name(nxt))
                    return True
            log.debug("dead end %s -> %s: %d reached candidates, %d straight moves and %d detour searches "
                      "found nothing", self._name(prev), self._name(nxt), len(reached), tried, searched)
            return False
        return False

    def _dead_end(self, order: tuple[int, ...]) -> str:
        """The first move of an order that no candidate reached so far can make (what an infinite
        tour cost means), named for the report."""
        stops = (HOME, *order, HOME)
        value = np.zeros(1)
        for prev, nxt in itertools.pairwise(stops):
            value = np.min(value[:, None] + self.full_cost(prev, nxt), axis=0)
            if not np.isfinite(value).any():
                return f"nothing known joins {self._name(prev)} -> {self._name(nxt)} in the best order found"
        return "every order found has a move without a known connection"

    def _verify(self, tour: Tour) -> _TourCheck:
        """Transitions of the tour, complete when every leg is known free; else learn from every leg."""
        stops = [(HOME, 0), *zip(tour.order, tour.choice), (HOME, 0)]
        out: list[Transition] = []
        complete = True
        for (i, a), (j, b) in zip(stops[:-1], stops[1:]):
            qa, qb = self.q(i)[a], self.q(j)[b]
            label = f"{self._name(i)} -> {self._name(j)}"
            # As `_costs` offers it: an unchecked straight move is tried only where it is offered.
            straight_ok = (min(i, j), max(i, j)) not in self.detour_only and \
                self.straight.get((i, j), {}).get((a, b), not self._verified_straight_only(i, j))
            straight_cost = float(ptp_time_estimate(qa, qb, self.limits, self.options.speed)) if straight_ok else np.inf
            via_costs = self._pair_via_costs(i, a, j, b)
            best_v = int(np.argmin(via_costs)) if len(via_costs) else -1
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
        return _TourCheck(complete, tuple(out))

    def _check_straight(self, i: int, a: int, j: int, b: int) -> bool:
        known = self.straight.get((i, j), {}).get((a, b))
        if known is not None:
            return known
        res = self.world_from(i).check_segment(self.q(i)[a], self.q(j)[b])
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
            r = self.world_from(i).check_segment(self.q(i)[aa], self.q(j)[bb])
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
        """Up, across, down: the TCP moved away by h at both ends in the same IK branch, for clamps.

        The cheapest kind of detour an operator would teach, tried for rising h before the roadmap:
        first straight up; then backed off along each spot's approach line (away from the part,
        where the clamps of the row above block the way up on a stacked flange); then both at once.
        """
        qa, qb = self.q(i)[a], self.q(j)[b]
        up = self._up()
        checks = 0
        ends_at = [(qa, i, a), (qb, j, b)]
        back = {idx: self._back_direction(idx, col) for _, idx, col in ends_at if idx != HOME}
        tcp = {idx: fk_tcp(self.robot, q) for q, idx, _ in ends_at if idx != HOME}
        for kind in ("up", "back", "up_back"):
            for h in LIFT_HEIGHTS_M:
                ends = []
                for q, idx, col in ends_at:
                    if idx == HOME:
                        ends.append(q)
                        continue
                    away = up if kind == "up" else back[idx] if kind == "back" else (up + back[idx]) / np.sqrt(2.0)
                    T = tcp[idx].copy()
                    T[:3, 3] += h * away
                    table = solve_all(self.robot, T[None], q_hint=q)
                    column = int(self.spots[idx].column[col])
                    if not table.valid[0, column]:
                        break
                    lifted = table.q[0, column].copy()
                    ends.append(q + wrap_to_pi(lifted - q))
                if len(ends) < 2 or not self.limits.contains(np.array(ends)).all():
                    continue
                path = np.array([qa, ends[0], ends[1], qb])
                free, used = self._path_free(i, path)
                checks += used
                if free:
                    wp = _distinct(path)
                    return Detour(wp, float(np.sum(ptp_time_estimate(wp[:-1], wp[1:], self.limits))), checks)
        self.checks += checks
        return None

    def _up(self) -> FloatArray:
        """World up in the robot base frame."""
        up: FloatArray = invert(np.asarray(self.cell.T_world_base))[:3, :3] @ np.array([0.0, 0.0, 1.0])
        return up

    def _path_free(self, i: int, path: FloatArray) -> tuple[bool, int]:
        """Whether every leg of a joint polyline leaving stop i is free (stops at the first blocked
        one), and the collision checks spent."""
        checks = 0
        for p0, p1 in itertools.pairwise(path):
            if np.allclose(p0, p1):
                continue
            res = self.world_from(i).check_segment(p0, p1)
            checks += res.checks
            if not res.free:
                return False, checks
        return True, checks

    def _moved(self, idx: int, col: int, q: FloatArray, offsets: FloatArray) -> FloatArray:
        """(k, n) configurations of spot idx's candidate col with its TCP (at q) moved by each of
        `offsets` (k, 3), base frame, in the candidate's IK column, wrapped towards q; NaN rows
        where that column has no solution within the limits."""
        T = np.repeat(fk_tcp(self.robot, q)[None], len(offsets), axis=0)
        T[:, :3, 3] += offsets
        table = solve_all(self.robot, T, q_hint=q)
        column = int(self.spots[idx].column[col])
        out = q[None, :] + wrap_to_pi(table.q[:, column] - q[None, :])
        out[~table.valid[:, column]] = np.nan
        out[~self.limits.contains(out)] = np.nan
        return out

    def _exits(self, idx: int, col: int) -> list[FloatArray]:
        """Where the gun can leave spot idx's approach point (candidate col) by a free straight
        move that takes it off the flange: the TCP moved perpendicular to the electrode axis in
        WITHDRAW_DIRECTIONS directions by each of WITHDRAW_M (the sheet leaves the C through its
        mouth only one way; which depends on the tool and the candidate's spin, so every direction
        is tried), nearest first. Cached per candidate: a spot's candidate joins many pairs."""
        key = (idx, col)
        got = self._exit_cache.get(key)
        if got is not None:
            return got
        if idx == HOME:
            self._exit_cache[key] = [self.home[0]]
            return self._exit_cache[key]
        q = self.q(idx)[col]
        R = fk_tcp(self.robot, q)[:3, :3]
        angles = 2 * np.pi * np.arange(WITHDRAW_DIRECTIONS) / WITHDRAW_DIRECTIONS
        dirs = np.cos(angles)[:, None] * R[:, 0][None, :] + np.sin(angles)[:, None] * R[:, 1][None, :]
        offsets = np.concatenate([w * dirs for w in WITHDRAW_M])
        moved = self._moved(idx, col, q, offsets)
        out: list[FloatArray] = []
        for row in moved:
            if np.isnan(row).any():
                continue
            res = self.world_from(idx).check_segment(q, row)
            self.checks += res.checks
            if res.free:
                out.append(row)
        self._exit_cache[key] = out
        return out

    def _withdrawn_detour(self, i: int, a: int, j: int, b: int) -> Detour | None:
        """Off the flange, (up,) across, (down,) onto the flange: each end leaves its approach point
        perpendicular to the electrode axis (`_exits`), then the straight move between the two exits,
        else both exits raised by h (world up) for rising h. This is how the gun is turned over a
        flange between two faces of a part: the C slid off one edge, turned clear of the part, slid
        onto the other edge. At most WITHDRAW_PAIRS exit pairs are tried, fastest first."""
        qa, qb = self.q(i)[a], self.q(j)[b]
        starts, goals = self._exits(i, a), self._exits(j, b)
        if not starts or not goals:
            return None
        sa, sb = np.array(starts), np.array(goals)
        sp = 1.0 if self.options.speed is None else self.options.speed
        leave = np.asarray(ptp_time_estimate(qa[None, :], sa, self.limits, sp))
        across = np.asarray(ptp_time_estimate(sa[:, None, :], sb[None, :, :], self.limits, sp))
        arrive = np.asarray(ptp_time_estimate(sb, qb[None, :], self.limits, sp))
        est = leave[:, None] + across + arrive[None, :]
        up = self._up()
        checks = 0
        pairs = np.argsort(est, axis=None, kind="stable")[:WITHDRAW_PAIRS]
        for heights in ((0.0,), LIFT_HEIGHTS_M):
            for flat in pairs:
                x, y = np.unravel_index(int(flat), est.shape)
                ea, eb = sa[x], sb[y]
                for h in heights:
                    if h == 0.0:
                        path = np.array([qa, ea, eb, qb])
                    else:
                        ra = ea if i == HOME else self._moved(i, a, ea, (h * up)[None])[0]
                        rb = eb if j == HOME else self._moved(j, b, eb, (h * up)[None])[0]
                        if np.isnan(ra).any() or np.isnan(rb).any():
                            continue
                        path = np.array([qa, ea, ra, rb, eb, qb])
                    free, used = self._path_free(i, path)
                    checks += used
                    if free:
                        wp = _distinct(path)
                        return Detour(wp, float(np.sum(ptp_time_estimate(wp[:-1], wp[1:], self.limits))), checks)
        self.checks += checks
        return None

    def _searched_detour(self, i: int, qa: FloatArray, qb: FloatArray) -> Detour | None:
        """The roadmap's detour, the local C-space map's, or the faster of both (`planner.detours`)."""
        kind = self.options.detours                   # resolved from the cell (`resolved_options`)
        if kind not in ("roadmap", "cspace", "both"):
            raise ValueError(f"planner.detours must be roadmap, cspace or both, got {kind!r}")
        found: list[Detour] = []
        if kind in ("roadmap", "both"):
            det = self.roadmap_from(i).query(qa, qb)
            if det is not None:
                found.append(det)
        if kind in ("cspace", "both"):
            det, spent = grid_detour(self.world_from(i), self.limits, qa, qb)
            if det is None:
                self.checks += spent           # a found detour's checks are counted with it
            else:
                found.append(det)
        if not found:
            return None
        best = min(found, key=lambda d: d.time_estimate)
        self.checks += sum(d.checks for d in found if d is not best)
        return best

    def _back_direction(self, idx: int, col: int) -> FloatArray:
        """Unit vector (base frame) from the spot to its approach point: away from the part."""
        c = self.spots[idx]
        d = fk_tcp(self.robot, c.q_app[col])[:3, 3] - fk_tcp(self.robot, c.q_spot[col])[:3, 3]
        norm = float(np.linalg.norm(d))
        return d / norm if norm > 0 else np.zeros(3)

    def _new_detour(self, i: int, a: int, j: int, b: int, last_resort: bool = False) -> None:
        # Lift first: on clamp cells it is found in ~1,000 checks; the roadmap is the general fallback.
        # Where neither finds a way, the gun's C may still hold the sheet at both approach points
        # (moves between two faces of a part): off the flange first (`_withdrawn_detour`).
        det = (self._lift_detour(i, a, j, b) or self._searched_detour(i, self.q(i)[a], self.q(j)[b])
               or self._withdrawn_detour(i, a, j, b))
        if det is None and last_resort:
            # A tour with no other way on (`_open_dead_end`): trees grown between the two ends find
            # narrow ways out that the shared roadmap samples too thinly (a few CPU seconds at most).
            det, spent = rrt_detour(self.world_from(i), self.limits, self.q(i)[a], self.q(j)[b], self.rng)
            if det is None:
                self.checks += spent
        if det is None:
            # No way found for this exact pair: make sure the optimiser stops choosing it.
            self.no_way.setdefault((i, j), set()).add((a, b))
            self.no_way.setdefault((j, i), set()).add((b, a))
            pair = (min(i, j), max(i, j))
            self.failed_detours[pair] += 1
            if self.failed_detours[pair] >= MAX_FAILED_DETOURS:
                # Two spots with hundreds of candidates each would otherwise cost a round per
                # banned candidate pair: the spots are taken to be unconnected except through
                # detours known at their ends.
                self.unconnected.add(pair)
            self._forget(i, j)
            if (min(i, j), max(i, j)) in self.detour_only:
                self._retry_straight(i, j)
            return
        self.checks += det.checks
        self.detours.append((i, j, det))
        # Every pair sharing an end spot with this detour may now use it (`vias_for`).
        for table in (self._matrices, self._full):
            for key in [key for key in table if not {i, j}.isdisjoint(key)]:
                del table[key]
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
            tried += 1
            if self._try_straight(i, a, j, b):
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
                res = self.world_from(i).check_segment(p, r)
                self.checks += res.checks
                if not res.free:
                    self._record_leg(i, a, j, b, v, False)
                    # A pair given up (MAX_FAILED_DETOURS searches found nothing) is not searched
                    # again for every blocked leg: it keeps the legs known free.
                    if (min(i, j), max(i, j)) not in self.unconnected:
                        self._new_detour(i, a, j, b)
                    return None
            self._record_leg(i, a, j, b, v, True)
        path = np.vstack([qa[None, :], wp, qb[None, :]])
        keep = [0] + [k for k in range(1, len(path)) if not np.allclose(path[k], path[k - 1])]
        return path[keep]

    def _name(self, i: int) -> str:
        return "home" if i == HOME else self.spots[i].name


