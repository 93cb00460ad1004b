"""The scratch and the exact tests under `world.collision.CollisionWorld` (its base): Pinocchio data
and coal's broad phase attached to the shared geometry, the pre-filter's blocks of states handed to
coal pair by pair, and the pairs of dynamic obstacles switched on and off with time."""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray, IntArray
from robomax_py.world.acm import SharedGeometry, configure_requests
from robomax_py.world.chunk_reach import certified, chunks_of_pair
from robomax_py.world.collision_results import Contact, SegmentCheck
from robomax_py.world.pair_cells import CERTIFIED, UNCERTIFIED, UNKNOWN, CellTable

_FIRST_CHUNK = 8     # states the first pre-filter call of a scan covers (blocked moves stop early)
# A near scan (`_scan`) of fewer states tests every pair: finding the pairs to leave out costs about
# one state's test.
_NEAR_STATES = 8
# A near scan finds the pairs to leave out per run of this many neighbouring states (by their place
# along the path, not the scan order): a short run moves the robot little, so its grown bounds clear
# nearly what each state's own test clears, and with the finer tests (`Prefilter.near_reach`)
# the pieces close to a meshed obstacle too, which each state's test could clear only chunk by chunk.
_NEAR_RUN = 16
# A pair left by a run's pre-filter whose coal distance at the run's centre exceeds its margin by
# more than the distance can shrink over the run (`Prefilter.near_reach`) is free at every state of
# the run, and skips coal's test at each: the arm's neighbouring links (UR10: base and upper arm,
# forearm and wrist) are a few cm apart at every state, so no bound on spheres or boxes clears them.
# The margin is grown by CERTIFY_SLACK_M, far above GJK's tolerance (1e-6) and the residual coal may return
# for touching shapes, so that no pair coal could call colliding is left out.
CERTIFY_SLACK_M = 1e-4


class CollisionWorldCore:
    """Scratch, pair activation and exact tests of one collision world (the base of `CollisionWorld`)."""

    __slots__ = ("_active", "_active_before", "_allowed", "_callback", "_data", "_first_window", "_gdata", "_manager",
                 "_pf", "_present", "_s", "_segments", "_windows")

    # ----------------------------------------------------------------------------------- set-up

    def _attach(self, shared: SharedGeometry) -> None:
        self._s = shared
        self._data = shared.model.createData()
        self._gdata = shared.geom_model.createData()
        configure_requests(self._gdata, shared.pair_margin)
        self._manager: Any = None
        self._callback: Any = None
        if shared.options.broad_phase:
            self._manager = pin.BroadPhaseManager_NaiveCollisionManager(shared.model, shared.geom_model, self._gdata)
            self._callback = pin.CollisionCallBackDefault(shared.geom_model, self._gdata, True)
        self._present = np.ones(len(shared.dynamic_ids), dtype=bool)
        # Every window of every dynamic obstacle, flat: (start, end, index into dynamic_ids), so the
        # presence of hundreds of them (a moving object's spans) is one vectorised test.
        spans = [(float(w0), float(w1), k) for k, i in enumerate(shared.dynamic_ids)
                 for w0, w1 in (shared.obstacles[int(i)].present or ((-np.inf, np.inf),))]
        self._windows = np.array(spans, dtype=float).reshape(-1, 3)
        self._first_window = np.searchsorted(self._windows[:, 2], np.arange(len(shared.dynamic_ids)))
        self._active_before = np.arange(len(shared.pair_a) + 1, dtype=np.int64)
        self._active = np.ones(len(shared.pair_a), dtype=bool)
        self._allowed = np.ones(len(shared.pair_a), dtype=bool)     # pairs this world checks at all
        self._pf = shared.prefilter if shared.options.broad_phase and shared.options.prefilter else None
        # Verdicts of untimed swept checks by their exact ends and step (`SweptChecks.check_segment`).
        self._segments: dict[tuple[bytes, bytes, float], SegmentCheck] = {}

    def _restrict(self, allowed: np.ndarray) -> None:
        self._allowed = allowed.copy()
        for p in np.flatnonzero(~allowed):
            self._gdata.deactivateCollisionPair(int(p))
        self._refresh_active()

    # ------------------------------------------------------------------------------- internals

    def _exact(self, q: FloatArray, pairs: list[int], undecided: bool) -> tuple[bool, int]:
        """coal's verdict on the pairs the pre-filter left (in pair order): (free, pairs tested).
        undecided: one of them lies in a cell (`pair_cells`) not decided when the filter ran; such
        cells are decided first, and a pair in a cell certified free is left out.

        pairs is a list, not an array: the scans convert a block's pairs once and slice the list per
        state (slicing the array by its offsets and converting each slice took about five times as
        long, over a million states of a 30-spot plan)."""
        if undecided:
            pairs = self._uncertified(q, pairs)
        if not pairs:
            return True, 0
        s, gd = self._s, self._gdata
        gm = s.geom_model
        pin.updateGeometryPlacements(s.model, self._data, gm, gd, q)
        for n, p in enumerate(pairs):
            if pin.computeCollision(gm, gd, p):
                return False, n + 1
        return True, len(pairs)

    def _uncertified(self, q: FloatArray, pairs: list[int]) -> list[int]:
        """`pairs` less those whose cell holding q is certified free, each undecided cell decided
        now (the filter cleared the pairs of cells certified before)."""
        assert self._pf is not None
        cells = self._pf.cells
        tables, decided = cells.tables, cells.decided
        left = []
        for p in pairs:
            table = tables[p]
            if table is not None:
                c = table.cell(q)
                if c >= 0 and decided[c] == UNKNOWN:
                    decided[c] = self._decide(q, p, table, c)
                if c >= 0 and decided[c] == CERTIFIED:
                    continue
            left.append(p)
        return left

    def _decide(self, q: FloatArray, p: int, table: CellTable, cell: int) -> int:
        """Whether pair p is free at every configuration of its cell `cell` (the other joints at
        q's values: the pair's distance does not depend on them), by the near runs' test over the
        cell's box (`_run_pairs`): CERTIFIED or UNCERTIFIED."""
        only = np.zeros(len(self._active), dtype=bool)
        only[p] = True
        lo, hi = table.box(q, cell)
        _, live = self._run_pairs(np.stack((lo, hi)), only)
        if not live[p]:
            return CERTIFIED
        # Left live, the pair was measured by coal at the cell's centre just now (`_run_pairs`).
        distance = float(self._gdata.distanceResults[p].min_distance)
        return CERTIFIED if self._certified_by_slabs(p, lo, hi, distance) else UNCERTIFIED

    def _certified_by_slabs(self, p: int, lo: FloatArray, hi: FloatArray, distance: float) -> bool:
        """The finer test of a cell the first one could not certify (`chunk_reach`): the moving
        piece's slabs each grown by their own motion over the cell [lo, hi], the pieces `distance`
        apart at its centre."""
        s = self._s
        pair = s.geom_model.collisionPairs[p]
        chunks = chunks_of_pair(s.model, s.geom_model, int(pair.first), int(pair.second))
        bar = s.pair_margin[p] + CERTIFY_SLACK_M
        if chunks is None or not distance > bar:
            return False
        pin.computeJointJacobians(s.model, self._data, (lo + hi) / 2)     # the centre, as `_run_pairs` takes it
        return certified(chunks, self._data, distance, (hi - lo) / 2, bar)

    def _scan_timed(self, states: FloatArray, fractions: FloatArray, order: IntArray, m: int, start: float,
                    span: float) -> SegmentCheck:
        """`_scan` where dynamic obstacles come and go: state k (of `order`) counts the obstacles
        present during the time between its neighbouring steps, so the states are scanned in runs
        that share one presence, each with the pairs active then, stopping at the first collision."""
        lo, hi = step_windows(np.asarray(order, dtype=np.int64), m, start, span)
        return self._scan_in_time(states, fractions, lo, hi, m + 1)

    def _scan_in_time(self, states: FloatArray, fractions: FloatArray, lo: FloatArray, hi: FloatArray,
                      n_states: int, near: bool = False) -> SegmentCheck:
        """`_scan` with state k against the dynamic obstacles present at some time in [lo[k], hi[k]]:
        in runs of neighbouring states of one presence, in order, stopping at the first collision."""
        presence = self._presences(lo, hi)
        tests = 0
        for k0, k1 in _presence_runs(presence):
            self._apply_presence(presence[k0])
            res = self._scan(states[k0:k1], fractions[k0:k1], n_states, near)
            tests += res.narrow_phase_tests
            if not res.free:
                return SegmentCheck(False, k0 + res.checks, n_states, tests, res.s_contact)
        return SegmentCheck(True, len(states), n_states, tests, None)

    def _scan(self, states: FloatArray, fractions: FloatArray, n_states: int, near: bool = False,
              place: IntArray | None = None) -> SegmentCheck:
        """Check `states` in the given order, stopping at the first collision (pre-filter on).

        near: the states lie close together (a short path); the pre-filter's pairs cleared at every
        state of a run of `_NEAR_RUN` neighbours are then found once per run and left out of each
        state's test. place: each state's place along the path (default: the given order)."""
        assert self._pf is not None
        tests = 0
        start, chunk = 0, _FIRST_CHUNK
        blocks: np.ndarray | None = None
        active: np.ndarray = self._active
        rows: IntArray | None = None
        if near and len(states) >= _NEAR_STATES:
            run = (np.arange(len(states)) if place is None else np.asarray(place)) // _NEAR_RUN
            # Each run's states as `states[run == r]` picks them (in the given order), from one
            # stable sort instead of a comparison over every state per run.
            order = np.argsort(run, kind="stable")
            ends = np.searchsorted(run[order], np.arange(int(run.max()) + 2)).tolist()
            found = [self._run_pairs(states[order[a:b]]) for a, b in itertools.pairwise(ends)]
            blocks = np.array([b for b, _ in found])
            active = np.array([a for _, a in found])
            rows = run.astype(np.int64)
        while start < len(states):
            block = states[start:start + chunk]
            offsets, pairs, undecided = self._pf.left_for_coal(block, active, blocks,
                                                               None if rows is None else rows[start:start + chunk])
            at, left, pending = offsets.tolist(), pairs.tolist(), undecided.tolist()
            for i in np.flatnonzero(np.diff(offsets)).tolist():
                free, n = self._exact(block[i], left[at[i]:at[i + 1]], pending[i])
                tests += n
                if not free:
                    k = start + i
                    return SegmentCheck(False, k + 1, n_states, tests, float(fractions[k]))
            start += len(block)
            chunk *= 4
        return SegmentCheck(True, len(states), n_states, tests, None)

    def _run_pairs(self, states: FloatArray, active: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(blocks, pairs) a run of neighbouring states must still test, of the `active` pairs (None:
        the world's): `Prefilter.near_reach`'s, less those proven free at every configuration of the
        run's joint-space box (coal's distance at its centre, less how much the distance can shrink
        within the box, above the pair's margin by CERTIFY_SLACK_M)."""
        assert self._pf is not None
        blocks, live, reach = self._pf.near_reach(states, self._active if active is None else active)
        left = np.flatnonzero(live)
        if not left.size:
            return blocks, live
        s, gd = self._s, self._gdata
        gm = s.geom_model
        centre = (states.min(axis=0) + states.max(axis=0)) / 2     # as `_near` takes it
        pin.updateGeometryPlacements(s.model, self._data, gm, gd, centre)
        bar = s.pair_margin + CERTIFY_SLACK_M
        for p in left.tolist():
            if pin.computeDistance(gm, gd, p).min_distance - reach[p] > bar[p]:
                live[p] = False
        return blocks, live

    def _collides(self, q: FloatArray) -> bool:
        s = self._s
        if self._manager is not None:
            return bool(pin.computeCollisions(s.model, self._data, self._manager, self._callback, q))
        return bool(pin.computeCollisions(s.model, self._data, s.geom_model, self._gdata, q, True))

    def _hit_pair(self) -> int:
        """Index of the pair that stopped the last colliding query."""
        if self._manager is not None:
            return int(self._callback.collisionPairIndex)
        # Exhaustive mode stops at the first colliding active pair, in order; later results are stale.
        results, active = self._gdata.collisionResults, self._gdata.activeCollisionPairs
        for p in range(len(self._s.pair_a)):
            if active[p] and results[p].isCollision():
                return p
        raise RuntimeError("collision reported but no colliding pair found")  # pragma: no cover

    def _tests(self, hit_pair: int) -> int:
        """Narrow-phase tests of the last query."""
        if self._manager is not None:
            return int(self._callback.count)
        return int(self._active_before[hit_pair + 1] if hit_pair >= 0 else self._active_before[-1])

    def _set_presence(self, ta: float | None, tb: float | None) -> None:
        """Activate the pairs of dynamic obstacles present at some time in [ta, tb] (None: present)."""
        if self._s.dynamic_ids.size:
            self._apply_presence(self._presence(ta, tb))

    def _apply_presence(self, present: np.ndarray) -> None:
        """Activate the pairs of the dynamic obstacles `present` (d,) marks, deactivate the others'."""
        s = self._s
        changed = np.flatnonzero(present != self._present)
        if not changed.size:
            return
        for k in changed.tolist():
            on_now, pairs = bool(present[k]), s.dynamic_pairs[k]
            for p in pairs.tolist():
                if on_now and self._allowed[p]:
                    self._gdata.activateCollisionPair(p)
                else:
                    self._gdata.deactivateCollisionPair(p)
            self._active[pairs] = on_now & self._allowed[pairs]
        self._present = present
        self._active_before = np.concatenate([[0], np.cumsum(self._active)]).astype(np.int64)

    def _presence(self, ta: float | None, tb: float | None) -> np.ndarray:
        """(d,) bool: which dynamic obstacles are present at some time in [ta, tb] (None: all)."""
        if ta is None or tb is None:
            return np.ones(len(self._s.dynamic_ids), dtype=bool)
        row: np.ndarray = self._presences(np.array([ta]), np.array([tb]))[0]
        return row

    def _presences(self, lo: FloatArray, hi: FloatArray) -> np.ndarray:
        """(k, d) bool: row i marks the dynamic obstacles present at some time in [lo[i], hi[i]]."""
        w = self._windows
        meets = (w[None, :, 0] <= hi[:, None]) & (w[None, :, 1] >= lo[:, None])
        # Every obstacle has at least one window, and its windows are consecutive in `_windows`.
        return np.logical_or.reduceat(meets, self._first_window, axis=1)

    def _refresh_active(self) -> None:
        active = np.fromiter(self._gdata.activeCollisionPairs, dtype=bool, count=len(self._s.pair_a))
        self._active = active
        self._active_before = np.concatenate([[0], np.cumsum(active)]).astype(np.int64)

    def _contact(self, pair: int) -> Contact:
        s = self._s
        a, b = s.pieces[int(s.pair_a[pair])], s.pieces[int(s.pair_b[pair])]
        return Contact(body_a=a.body, kind_a=a.kind, body_b=b.body, kind_b=b.kind, piece_a=a.name, piece_b=b.name)


def step_windows(steps: IntArray, m: IntArray | int, start: FloatArray | float,
                 span: FloatArray | float) -> tuple[FloatArray, FloatArray]:
    """(lo, hi): the time each state of a timed swept check stands for, state k (of m steps from
    `start`, `span` seconds long) the time from its previous step to its next; m = 0: one state at
    one instant. m, start and span are one move's, or each state's own."""
    m, start, span = np.asarray(m, dtype=np.int64), np.asarray(start, dtype=float), np.asarray(span, dtype=float)
    whole = np.maximum(m, 1)
    a = start + np.maximum(steps - 1, 0) / whole * span
    b = start + np.minimum(steps + 1, m) / whole * span
    a, b = np.where(m > 0, a, start), np.where(m > 0, b, start)
    return np.minimum(a, b), np.maximum(a, b)


def _presence_runs(presence: np.ndarray) -> list[tuple[int, int]]:
    """[k0, k1) of each run of consecutive rows of `presence` (k, d) that are equal."""
    breaks = (np.flatnonzero(np.any(presence[1:] != presence[:-1], axis=1)) + 1).tolist()
    return list(zip([0, *breaks], [*breaks, len(presence)]))
