"""What the sequencer (`plan.graph.Sequencer`) knows and what it costs: straight moves found free or
blocked, detour-only and unconnected spot pairs, detours found and their legs checked, and the
estimated move-time matrices the order search and the exact DP read, cached per spot pair."""

from __future__ import annotations

import copy
from collections import Counter

import numpy as np

from robomax_py._typing import FloatArray, IntArray
from robomax_py.plan.candidates import SpotCandidates
from robomax_py.plan.choice_memo import ChoiceMemo
from robomax_py.plan.learned_detour import LearnedDetours
from robomax_py.plan.loads import Loads
from robomax_py.plan.min_plus import min_plus_product
from robomax_py.plan.results import Progress, ResolvedOptions, _no_progress
from robomax_py.plan.roadmap import Detour, Roadmap
from robomax_py.plan.sequence import (
    HOME,
)
from robomax_py.plan.thinning import representatives
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.timing import (
    polyline_time_estimate,
    ptp_time_estimate,
)
from robomax_py.world.collision import CollisionWorld

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
# A detour of TCP lines starts and ends in the configurations it was found between: another
# candidate this close (rad, any joint) is that configuration (`plan.tcp_detour.GOAL_TOL_RAD`).
JOIN_TOL_RAD = 1e-6


def _same(a: FloatArray, b: FloatArray) -> np.ndarray:
    """Whether configurations (broadcast over all but the last axis) are the same, to JOIN_TOL_RAD."""
    return np.asarray(np.max(np.abs(a - b), axis=-1) <= JOIN_TOL_RAD)


class SequencerKnowledge:
    """The state of a `Sequencer` and the costs read from it (the base of `SequencerDetours`)."""

    def __init__(
        self, cell: CellSpec, robot: RobotModel, world: CollisionWorld, roadmap: Roadmap,
        spots: list[SpotCandidates], options: ResolvedOptions, rng: np.random.Generator,
        progress: Progress = _no_progress, loads: Loads | None = None, learned: LearnedDetours | None = None,
    ) -> None:
        self.cell, self.robot, self.world, self.roadmap = cell, robot, world, roadmap
        # `planner.detours: learned`: the plan's learned C-space map, where every detour is searched.
        self.learned = learned
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
        # The straight-move estimates under the matrices above, (rows, cols, estimate) per spot pair:
        # a matrix is recomputed whenever what is known about its moves changes, its estimate
        # (of the configurations alone) is not. Kept for the same pairs as the matrices.
        self._matrices_straight: dict[tuple[int, int], tuple[IntArray, IntArray, FloatArray]] = {}
        self._full_straight: dict[tuple[int, int], tuple[IntArray, IntArray, FloatArray]] = {}
        self.unresolved: Counter[str] = Counter()                                 # move label -> rounds left open
        self.failed_detours: Counter[tuple[int, int]] = Counter()                 # unordered spot pair -> searches
        self.unconnected: set[tuple[int, int]] = set()                            # unordered spot pairs given up
        self._exit_cache: dict[tuple[int, int], list[FloatArray]] = {}            # (spot, candidate) -> exits
        self._raised_cache: dict[tuple[int, int, int, float], FloatArray] = {}   # (spot, candidate, exit, h) -> q
        self._lift_cache: dict[tuple[int, int, str, float], FloatArray | None] = {}  # (spot, candidate, kind, h) -> q
        self._inner: dict[tuple[int, bool], float] = {}                           # (detour, reversed) -> time
        self.tcp_detour_searches = 0          # `planner.detour_moves: lin`: searches for TCP lines
        self.tcp_detours_found = 0            # ... and those that found them
        # What `_probe_pairs` learnt (straight moves, detour-only pairs, checks) and the generator as
        # it was before any round: a sequencer of the given order starts from them (`given_order`).
        self._probed: tuple[dict[tuple[int, int], dict[tuple[int, int], bool]], set[tuple[int, int]], int] | None = None
        self._rng_at_start = copy.deepcopy(rng)
        # The exact DP of one order over every candidate (`full_cost`), its layers kept between calls.
        self.choose = ChoiceMemo(self.full_cost, self.node)
        # `vias_for` per spot pair: (detours seen, the list), extended as detours are appended.
        self._vias: dict[tuple[int, int], tuple[int, list[Detour]]] = {}

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
        Indices are stable: new detours are only appended, so the list is kept per spot pair and
        only extended by the detours found since (it was rebuilt over every detour for every matrix
        and every leg checked: detours x legs grows with the square of the spots). Callers read it,
        never change it."""
        seen, out = self._vias.get((i, j), (0, []))
        if seen == len(self.detours):
            return out
        out = list(out)
        for di, dj, det in self.detours[seen:]:
            if self._load(di) != self._load(i):
                out.append(_UNUSABLE)            # found for another load: not checked for this one
            elif di == i or dj == j:
                out.append(det)
            elif dj == i or di == j:
                out.append(det.reversed())
            else:
                out.append(_UNUSABLE)
        self._vias[(i, j)] = (len(self.detours), out)
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
        lines = np.array([vias[v].poses is not None for v in usable])
        if lines.any():
            # A detour of TCP lines joins only the configurations it starts and ends in: a joint
            # move onto it from another candidate would not be a line.
            enter = np.where(lines[None, :] & ~_same(self.q(i)[rows][:, None, :], starts[None, :, :]), np.inf, enter)
            leave = np.where(lines[:, None] & ~_same(ends[:, None, :], self.q(j)[cols][None, :, :]), np.inf, leave)
        bad = self.legs_bad.get((i, j), set())
        verified_only = len(bad) >= MAX_BLOCKED_LEGS
        column = {v: k for k, v in enumerate(usable)}
        # (row, col) -> the detours (columns of `enter`) its mark names: banned, or the only ones
        # offered once verified_only. A handful: fewer than MAX_BLOCKED_LEGS banned, a few verified.
        marks: dict[tuple[int, int], set[int]] = {}
        for a, b, vv in (self.legs_ok.get((i, j), ()) if verified_only else bad):
            if pi[a] >= 0 and pj[b] >= 0 and vv in column:
                marks.setdefault((int(pi[a]), int(pj[b])), set()).add(column[vv])
        inner = np.array([self._inner_time(v, vias[v]) for v in usable])
        # The sum of a detour's three parts is (enter + inner) + leave, so numpy's first addition
        # feeds the (min, +) product its rows: every sum and every least as priced one detour at a
        # time. The product reads the legs once: numpy's broadcast wrote out the rows x detours x
        # cols sums first, tens of megabytes for two spots of 800 candidates and a dozen detours.
        enter_inner = enter + inner[None, :]
        if verified_only:
            for (r, c), ks in marks.items():
                out[r, c] = min(enter_inner[r, k] + leave[k, c] for k in ks)
        else:
            out = min_plus_product(enter_inner, np.ascontiguousarray(leave))
            for (r, c), ks in marks.items():
                out[r, c] = min((enter_inner[r, k] + leave[k, c] for k in range(len(usable)) if k not in ks),
                                default=np.inf)
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
        if det.poses is not None:
            return det.time_estimate             # lines: estimated where found, the same both ways
        key = (v, not np.array_equal(wp[0], self.detours[v][2].waypoints[0]))
        got = self._inner.get(key)
        if got is None:
            sp = self._detour_speed()
            got = self._inner[key] = polyline_time_estimate(wp, self.limits, sp)
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
        starts = np.array([vias[v].waypoints[0] for v in usable])
        ends = np.array([vias[v].waypoints[-1] for v in usable])
        enter = ptp_time_estimate(self.q(i)[a][None, :], starts, self.limits, sp)
        leave = ptp_time_estimate(ends, self.q(j)[b][None, :], self.limits, sp)
        via = enter + np.array([self._inner_time(v, vias[v]) for v in usable]) + leave
        lines = np.array([vias[v].poses is not None for v in usable])
        joined = _same(self.q(i)[a][None, :], starts) & _same(ends, self.q(j)[b][None, :])
        via = np.where(lines & ~joined, np.inf, via)      # as `_via_costs`: lines join their own ends only
        bad = self.legs_bad.get((i, j), set())
        if len(bad) >= MAX_BLOCKED_LEGS:
            ok = self.legs_ok.get((i, j), set())
            keep = np.array([(a, b, v) in ok for v in usable])
        else:
            keep = np.array([(a, b, v) not in bad for v in usable])
        out[usable] = np.where(keep, via, np.inf)
        return out

    def _straight_estimate(self, i: int, j: int, rows: IntArray, cols: IntArray,
                           kept: dict[tuple[int, int], tuple[IntArray, IntArray, FloatArray]] | None) -> FloatArray:
        """Estimated straight-move time between candidates `rows` of i and `cols` of j (a fresh
        array), taken from `kept` where it holds these rows and columns, else computed and kept."""
        got = None if kept is None else kept.get((i, j))
        if got is not None and np.array_equal(got[0], rows) and np.array_equal(got[1], cols):
            return got[2].copy()
        est = ptp_time_estimate(self.q(i)[rows][:, None, :], self.q(j)[cols][None, :, :], self.limits,
                                self.options.speed)
        if kept is not None:
            kept[(i, j)] = (rows.copy(), cols.copy(), est.copy())
        return est

    def _costs(self, i: int, j: int, rows: IntArray, cols: IntArray,
               kept: dict[tuple[int, int], tuple[IntArray, IntArray, FloatArray]] | None = None) -> FloatArray:
        """Estimated move time between candidates `rows` of i and `cols` of j, using what is known
        about blockages; `kept`: where the straight-move estimate is kept between calls."""
        key = (i, j)
        est = self._straight_estimate(i, j, rows, cols, kept)
        pi, pj = self._positions(i, rows), self._positions(j, cols)
        vias = self.vias_for(i, j)
        if (min(i, j), max(i, j)) in self.detour_only:
            # Until a detour is known, price one at a multiple of the straight move: optimistic
            # enough to be explored, costly enough not to be preferred.
            # A detour of TCP lines joins only its own two candidates (`_via_costs`): the others
            # keep the prior, so that lines are sought between them too.
            usable = any(d is not _UNUSABLE and d.poses is None for d in vias)
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

    def _show_to_search(self, order: tuple[int, ...], choice: tuple[int, ...]) -> None:
        """The candidates of a tour known free (`choice`, one per spot of `order`) joined to the
        representatives the order search sees, so that the search can find that tour again: where
        its free moves join candidates the thinning left out, the search prices its order by the
        representatives' moves, found blocked, and keeps turning to orders whose unchecked moves
        look cheaper. Matrices of the spots whose representatives grew are recomputed when asked."""
        grown: set[int] = set()
        for i, a in zip(order, choice):
            rows = self.reps[i]
            k = int(np.searchsorted(rows, a))
            if k < len(rows) and rows[k] == a:
                continue
            self.reps[i] = np.insert(rows, k, a)            # ascending, as `representatives` gives them
            self.node_reps[i] = self.node[i][self.reps[i]]
            grown.add(i)
        for key in [key for key in self._matrices if key[0] in grown or key[1] in grown]:
            del self._matrices[key]

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
            got = self._matrices[key] = self._costs(i, j, self._rows(i), self._rows(j), self._matrices_straight)
        return got

    def full_cost(self, i: int, j: int) -> FloatArray:
        """`_costs` between every candidate of two spots (for the exact DP of one order), cached."""
        key = (i, j)
        got = self._full.get(key)
        if got is None:
            got = self._full[key] = self._costs(i, j, np.arange(len(self.q(i))), np.arange(len(self.q(j))),
                                                 self._full_straight)
        return got

    def _try_straight(self, i: int, a: int, j: int, b: int) -> bool:
        """Check the straight move from candidate a of i to b of j, count and record it; a free one
        takes the pair off the detour-only list."""
        res = self.world_from(i).check_segment(self.q(i)[a], self.q(j)[b])
        self.checks += res.checks
        self._record_straight(i, a, j, b, res.free)
        pair = (min(i, j), max(i, j))
        if res.free and pair in self.detour_only:
            self.detour_only.discard(pair)
            self._forget(i, j)                   # the pair's costs are no longer a detour's
        return bool(res.free)

    def _record_straight(self, i: int, a: int, j: int, b: int, free: bool) -> None:
        keys = [(i, j, a, b)]
        if self._load(i) == self._load(j):       # else the way back is checked in another world
            keys.append((j, i, b, a))
        # The cost matrices are dropped only where this verdict can change them (`_costs`): every
        # move a tour verifies free was recorded, and the next choice of that order then built
        # the full matrices of all those moves again, equal to the last.
        changes = any(self._straight_changes_costs(x, y, c, d, free) for x, y, c, d in keys)
        for x, y, c, d in keys:
            self.straight.setdefault((x, y), {})[(c, d)] = free
        if changes:
            self._forget(i, j)

    def _straight_changes_costs(self, i: int, j: int, a: int, b: int, free: bool) -> bool:
        """Whether recording the straight move a of i -> b of j as `free` can change `_costs(i, j)`:
        a blocked verdict, a changed one, or any where only moves known free are offered (before or
        after it); not a new free move where blocked ones are priced and free ones are estimated,
        nor any between a detour-only pair (priced by its detours)."""
        known = self.straight.get((i, j), {})
        before = known.get((a, b))
        if before is not None and before == free:
            return False
        if not free or before is not None:
            return True
        if (min(i, j), max(i, j)) in self.detour_only:
            return False
        blocked = sum(1 for f in known.values() if not f)
        unconnected = (min(i, j), max(i, j)) in self.unconnected
        verified_after = blocked >= MAX_BLOCKED_STRAIGHT or (unconnected and blocked >= len(known) + 1 - blocked)
        return self._verified_straight_only(i, j) or verified_after

    def _record_leg(self, i: int, a: int, j: int, b: int, v: int, ok: bool) -> None:
        table = self.legs_ok if ok else self.legs_bad
        keys = [(i, j, (a, b, v))]
        if self._load(i) == self._load(j):
            keys.append((j, i, (b, a, v)))
        # A leg known free changes `_via_costs` only where verified legs alone are offered.
        changes = any(not ok or len(self.legs_bad.get((x, y), ())) >= MAX_BLOCKED_LEGS for x, y, _ in keys)
        changes = changes and any(leg not in table.get((x, y), ()) for x, y, leg in keys)
        for x, y, leg in keys:
            table.setdefault((x, y), set()).add(leg)
        if changes:
            self._forget(i, j)
