"""The configuration graph and detour learner: spot order and candidates by DP and local search on
estimated motion times; straight moves verified lazily, blocked ones replaced by detours (a lift over
the obstacle, else a path through the roadmap), rounds repeated until every move of the best tour is
known free, or (from the sixth round) until a tour known free is within KNOWN_TOUR_MARGIN of it.
What the sequencer knows and its costs are in `graph_knowledge`, its detour searches in
`graph_detours`, the moves round those a round left open (checked from the sixth round on) in
`graph_lookahead`."""

from __future__ import annotations

import copy
import itertools
import logging
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray, IntArray
from robomax_py.plan.graph_detours import (
    LIFT_HEIGHTS_M,
    WITHDRAW_DIRECTIONS,
    WITHDRAW_M,
    WITHDRAW_PAIRS,
)
from robomax_py.plan.graph_knowledge import (
    DETOUR_PRIOR,
    MAX_BLOCKED_LEGS,
    MAX_BLOCKED_STRAIGHT,
    MAX_FAILED_DETOURS,
)
from robomax_py.plan.graph_lookahead import (
    LOOKAHEAD_FROM_ROUND,
    SequencerLookahead,
)
from robomax_py.plan.results import Transition
from robomax_py.plan.sequence import (
    EXACT_ORDERS,
    HOME,
    SeamBlock,
    Tour,
    optimise,
    order_count,
)
from robomax_py.timing import (
    ptp_time_estimate,
)
from robomax_py.world.collision import bisection_order

# The tuning constants of the knowledge and detour modules stay importable from here.
__all__ = [
    "DEAD_END_DETOURS", "DEAD_END_STRAIGHT", "DETOUR_PRIOR", "KNOWN_TOUR_MARGIN", "LIFT_HEIGHTS_M", "LOOKAHEAD_FROM_ROUND", "MAX_BLOCKED_LEGS",
    "MAX_BLOCKED_STRAIGHT", "MAX_FAILED_DETOURS", "PROBE_STATES", "REPAIRS_PER_ROUND", "WITHDRAW_DIRECTIONS",
    "WITHDRAW_M", "WITHDRAW_PAIRS", "Sequencer", "SequencingOutcome",
]

log = logging.getLogger(__name__)

# Re-choices of the candidates of one order per round (`Sequencer._repair`).
REPAIRS_PER_ROUND = 40
# States of the coarse probe of a move between two stops that are not near neighbours.
PROBE_STATES = 9
# An order whose best tour has a move no reached candidate can make (`Sequencer._open_dead_end`):
# straight moves checked from the reached candidates of that move, then detour searches (the
# random trees of `rrt_detour` the last resort), before the cell is called disconnected.
DEAD_END_STRAIGHT = 48
DEAD_END_DETOURS = 3
# From LOOKAHEAD_FROM_ROUND on, the cheapest tour found known free (by `_repair`) ends the rounds
# once its estimated cost is at most this fraction above the round's best tour, whose unchecked moves
# are priced as if free. Estimates this close are not trusted to rank two tours (the file's order
# estimated 0.5-4.2 % below the searched tour timed shorter on seven cells, 2.9 % above timed 3.1 %
# longer on another, `pipeline.GIVEN_ORDER_MARGIN`); on four panels of 60 spots each further round found one more
# unchecked move between two panels blocked while the tour known free stayed about 1 % dearer.
KNOWN_TOUR_MARGIN = 0.01


def _moves_of(order: tuple[int, ...]) -> set[tuple[int, int]]:
    stops = (HOME, *order, HOME)
    return set(itertools.pairwise(stops))



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


@dataclass(frozen=True, slots=True)
class _KnownTour:
    """A tour whose every leg was found free, and those legs (what `_repair` may find)."""

    tour: Tour
    transitions: tuple[Transition, ...]




class Sequencer(SequencerLookahead):
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
        return self._probe_row(i, [j])[0]

    def _probe_row(self, i: int, others: list[int]) -> list[tuple[int, int]]:
        """`probe_pair(i, j)` for every j of `others`, from one estimate of i's representatives
        against all of theirs: one call per pair cost numpy's overhead N^2 / 2 times. The estimate
        is element-wise, so each pair's block and its first least entry are those of its own call."""
        ri = self._rows(i)
        cols = [self._rows(j) for j in others]
        qs = np.concatenate([self.q(j)[c] for j, c in zip(others, cols, strict=True)])
        est = ptp_time_estimate(self.q(i)[ri][:, None, :], qs[None, :, :], self.limits, self.options.speed)
        out: list[tuple[int, int]] = []
        start = 0
        for c in cols:
            block = est[:, start:start + len(c)]
            start += len(c)
            a, b = np.unravel_index(int(np.argmin(block)), block.shape)
            out.append((int(ri[a]), int(c[b])))
        return out

    def _coarse_blocked(self, i: int, starts: FloatArray, goals: FloatArray) -> IntArray:
        """For the coarse probes of moves leaving stop i (k starts and goals, (k, n)): the index of
        the first blocked state of each (PROBE_STATES states in bisection order), -1 where all are
        free. Checked state by state over all moves at once, each state only where the states
        before it were free: the same configurations, checks and verdicts as one move at a time."""
        fractions = bisection_order(PROBE_STATES - 1) / (PROBE_STATES - 1)
        first = np.full(len(starts), -1, dtype=np.int64)
        alive = np.arange(len(starts))
        world = self.world_from(i)
        for k, f in enumerate(fractions):
            if not len(alive):
                break
            qa, qb = starts[alive], goals[alive]
            free = world.are_free(qa + f * (qb - qa))
            self.checks += len(alive)
            first[alive[~free]] = k
            alive = alive[free]
        return first

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
        for x, i in enumerate(ids):
            others = ids[x + 1:]
            if not others:
                continue
            pairs = self._probe_row(i, others)
            far = [y for y, j in enumerate(others) if (i, j) not in near]
            blocked_far: set[int] = set()
            if far:
                starts = np.array([self.q(i)[pairs[y][0]] for y in far])
                goals = np.array([self.q(others[y])[pairs[y][1]] for y in far])
                first = self._coarse_blocked(i, starts, goals)
                blocked_far = {y for y, state in zip(far, first.tolist(), strict=True) if state >= 0}
            # Recorded pair by pair in the order they were always learnt.
            for y, j in enumerate(others):
                a, b = pairs[y]
                if (i, j) in near:
                    res = self.world_from(i).check_segment(self.q(i)[a], self.q(j)[b])
                    self.checks += res.checks
                    free = res.free
                    self._record_straight(i, a, j, b, free)
                else:
                    free = y not in blocked_far
                    if not free:
                        self._record_straight(i, a, j, b, False)
                if not free:
                    self.detour_only.add((i, j))
                    self._forget(i, j)

    def run(self) -> SequencingOutcome:
        """The best tour whose every leg is known free, or why there is none (a status, not None)."""
        blocks = self._blocks()
        given = tuple(s for b in blocks for s in b.spots)          # the cell file's order
        if self._probed is None:
            self._probe_pairs()
            self._probed = ({k: dict(v) for k, v in self.straight.items()}, set(self.detour_only), self.checks)
        previous: tuple[tuple[int, ...], ...] = ()
        known: _KnownTour | None = None          # the cheapest tour the repairs found known free
        for _ in range(self.options.max_rounds):
            self.rounds += 1
            self.left_open = ()
            # Rounds end when a tour's legs are all known free; the bar shows rounds so far.
            self.progress("sequencing", self.rounds - 1, self.rounds)
            if self.options.baseline or self.options.given_order:
                choice, cost = self.choose(given)
                tour = Tour(given, choice, cost)
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
                self._full_straight = {key: e for key, e in self._full_straight.items() if key in moves}
                choice, cost = self.choose(found.order)
                tour = Tour(found.order, choice, cost)
            if not np.isfinite(tour.cost) and self._open_dead_end(tour.order):
                continue
            # Else the file's order's own dead end, which every order may then use: a spot under a
            # clamp (tests/data/pocket_spot), every straight move from it blocked, was joined by
            # RRT-Connect to home, its next stop in the file, not to the best order's next spot.
            if not np.isfinite(tour.cost) and tour.order != given and self._open_dead_end(given):
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
            repaired = self._repair(tour.order)
            if repaired is not None and (known is None or repaired.tour.cost < known.tour.cost):
                known = repaired
            if self.rounds >= LOOKAHEAD_FROM_ROUND:
                if known is not None and known.tour.cost <= tour.cost * (1.0 + KNOWN_TOUR_MARGIN):
                    log.debug("sequencing: the tour known free (%.3f s) is within %.0f %% of round %d's (%.3f s)",
                              known.tour.cost, 100 * KNOWN_TOUR_MARGIN, self.rounds, tour.cost)
                    self.progress("sequencing", self.rounds, self.rounds)
                    return SequencingOutcome("found", known.tour, known.transitions)
                self._look_around(self.left_open)
                if repaired is not None and not (self.options.baseline or self.options.given_order):
                    self._show_to_search(repaired.tour.order, repaired.tour.choice)
        if known is not None:
            # Out of rounds: each found another unchecked move blocked; the best tour known free stands.
            log.debug("sequencing: out of rounds, the tour known free (%.3f s) taken", known.tour.cost)
            return SequencingOutcome("found", known.tour, known.transitions)
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
                          loads=self.loads, learned=None if self.learned is None else self.learned.fresh())
        straight, detour_only, _ = self._probed
        other.straight = {k: dict(v) for k, v in straight.items()}
        other.detour_only = set(detour_only)
        other._probed = (straight, detour_only, 0)
        # Roadmaps built for held parts are seeded by the cell alone; their checked edges are shared.
        other._roadmaps.update({part: r.fresh() for part, r in self._roadmaps.items() if part is not None})
        return other

    def _repair(self, order: tuple[int, ...]) -> _KnownTour | None:
        """The candidates of one order re-chosen (the exact DP, cheap next to an order search) and
        checked again, up to REPAIRS_PER_ROUND times, until every leg is known free or the order
        has no finite tour. A blocked move between two spots with many near-equal candidates
        (other wrist turns of one pose, of the same joint time where a big axis sets it) otherwise
        costs a round per candidate pair: the order search proposes the same order with the next
        unchecked pair. Returns the tour whose every leg it found free, if it found one: the next
        round's order search weighs what was learnt, and that tour is taken only when no round finds
        one cheaper by more than KNOWN_TOUR_MARGIN (`run`)."""
        for _ in range(REPAIRS_PER_ROUND):
            choice, cost = self.choose(order)
            if not np.isfinite(cost):
                return None
            tour = Tour(order, choice, cost)
            checked = self._verify(tour)
            if checked.complete:
                return _KnownTour(tour, checked.transitions)
        return None

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
        for (i, a), (j, b) in itertools.pairwise(stops):
            qa, qb = self.q(i)[a], self.q(j)[b]
            label = f"{self._name(i)} -> {self._name(j)}"
            straight, best_v, via_costs = self._way(i, a, j, b)
            if straight:
                if self._check_straight(i, a, j, b):
                    out.append(Transition("move", np.array([qa, qb]), label))
                else:
                    complete = False
                    self.unresolved[label] += 1
                    self.left_open += ((i, j),)
                continue
            if best_v < 0 or not np.isfinite(via_costs[best_v]):
                self._new_detour(i, a, j, b)
                complete = False
                self.unresolved[label] += 1
                self.left_open += ((i, j),)
                continue
            path = self._check_via(i, a, j, b, best_v)
            if path is None:
                complete = False
                self.unresolved[label] += 1
                self.left_open += ((i, j),)
                continue
            via = self.vias_for(i, j)[best_v]
            if via.poses is not None:
                # Lines join exactly their own ends (`_via_costs`): the path is the detour's, each
                # waypoint after the first reached by a line to its pose.
                out.append(Transition("detour", via.waypoints, label, via.checks, lin_targets=via.poses[1:]))
                continue
            out.append(Transition("detour", path, label, via.checks))
        return _TourCheck(complete, tuple(out))

    def _check_straight(self, i: int, a: int, j: int, b: int) -> bool:
        known = self.straight.get((i, j), {}).get((a, b))
        if known is not None:
            return known
        # Blocked: the cheapest other straight moves between these two spots are tried right away;
        # all blocked, a detour is searched.
        verdict = self._learn_straight(i, a, j, b)
        if verdict == "detour_only":
            self._new_detour(i, a, j, b)
        return verdict == "free"

    def _check_via(self, i: int, a: int, j: int, b: int, v: int) -> FloatArray | None:
        wp = self.vias_for(i, j)[v].waypoints
        qa, qb = self.q(i)[a], self.q(j)[b]
        if (a, b, v) not in self.legs_ok.get((i, j), set()) and not self._legs_free(i, a, j, b, v):
            # A pair given up (MAX_FAILED_DETOURS searches found nothing) is not searched again for
            # every blocked leg: it keeps the legs known free.
            if (min(i, j), max(i, j)) not in self.unconnected:
                self._new_detour(i, a, j, b)
            return None
        path = np.vstack([qa[None, :], wp, qb[None, :]])
        keep = [0] + [k for k in range(1, len(path)) if not np.allclose(path[k], path[k - 1])]
        return path[keep]

    def _name(self, i: int) -> str:
        return "home" if i == HOME else self.spots[i].name
