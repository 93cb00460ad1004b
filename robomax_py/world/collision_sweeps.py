"""The swept checks of `world.collision.CollisionWorld` (its base): a straight joint-space move or a
polyline subdivided by a bound on how far any robot or tool point moves, its states checked
coarse-to-fine, stopping at the first collision; dynamic obstacles per the `world.collision`
module docstring."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray, IntArray
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.world.collision_core import CollisionWorldCore, step_windows
from robomax_py.world.collision_results import MovesCheck, SegmentCheck, bisection_order

# Untimed segment verdicts a world remembers (`check_segment`); past this many it forgets them all
# at once (about 200 B each). A sequencing's detour searches ask a few thousand to tens of thousands.
REMEMBERED_SEGMENTS = 200_000


class SweptChecks(CollisionWorldCore):
    """Swept-segment and polyline checks (the base of `CollisionWorld`)."""

    __slots__ = ()

    def sweep_length(self, q0: FloatArray, q1: FloatArray) -> float:
        """Upper bound (m) on how far any robot or tool point moves along the joint-space line q0 -> q1.

        Point p moves at |dp/ds| <= sum_i |dq_i| dist(p, axis_i); `lever_arms`[i] bounds dist(p, axis_i)
        over every p beyond joint i and every configuration: for pieces on joint i, the exact largest
        distance of their (hull / bounding-box) vertices from the axis; for pieces on a descendant
        joint j, dist(o_c, axis_i) + sum of the joint-origin offsets from c to j (plus the travel of
        prismatic joints on the way) + the largest vertex distance from o_j (triangle inequality;
        c is the child of i towards j).
        """
        dq = np.abs(np.asarray(q1, dtype=float) - np.asarray(q0, dtype=float))
        # A sum, not np.dot: `sweep_lengths` sums each row the same way, to the same last bit (numpy
        # adds a row of a contiguous array as it adds a vector), so a polyline checked in one call
        # has exactly the states its segments checked one by one have.
        return float((self._s.lever * dq).sum())

    def sweep_lengths(self, q0s: FloatArray, q1s: FloatArray) -> FloatArray:
        """(k,) `sweep_length` of each move q0s[i] -> q1s[i] (k, n)."""
        dq = np.abs(np.asarray(q1s, dtype=float) - np.asarray(q0s, dtype=float))
        return np.asarray((self._s.lever * dq).sum(axis=1), dtype=float)

    def _step_counts(self, q0s: FloatArray, q1s: FloatArray, max_step: float) -> IntArray:
        """(k,) the steps `_check_segment` splits each move into (before a timed move at rest gets one)."""
        return np.ceil(self.sweep_lengths(q0s, q1s) / max_step - 1e-12).astype(np.int64)

    def segment_states(self, q0: FloatArray, q1: FloatArray, max_step: float = TOL.sweep_step_m) -> FloatArray:
        """(m + 1, n): the states `check_segment` checks on q0 -> q1, in order from q0 (both ends
        where the move does not displace the robot)."""
        q0s = np.asarray(q0, dtype=np.float64)[None]
        q1s = np.asarray(q1, dtype=np.float64)[None]
        return _subdivided(q0s, q1s, np.maximum(self._step_counts(q0s, q1s, max_step), 1))[3]

    def segment_free(
        self,
        q0: FloatArray,
        q1: FloatArray,
        t0: float | None = None,
        t1: float | None = None,
        max_step: float = TOL.sweep_step_m,
    ) -> bool:
        """Whether the straight joint-space move q0 -> q1 is collision-free (see `check_segment`)."""
        return self.check_segment(q0, q1, t0, t1, max_step).free

    def check_segment(
        self,
        q0: FloatArray,
        q1: FloatArray,
        t0: float | None = None,
        t1: float | None = None,
        max_step: float = TOL.sweep_step_m,
    ) -> SegmentCheck:
        """Check the straight joint-space move q0 -> q1, both ends included.

        The move is split into m = ceil(sweep_length(q0, q1) / max_step) equal joint steps, so no
        robot or tool point moves more than `max_step` between consecutive states; states are
        checked coarse-to-fine (ends, middle, quarters, ...), stopping at the first collision.

        Parameters
        ----------
        q0, q1 : (n,) float, rad
        t0, t1 : float or None, s
            Times at q0 and q1 (both or neither); state k is at t0 + k/m (t1 - t0). Dynamic obstacles
            are included per the module docstring. None: every dynamic obstacle present.
        max_step : float, m

        An untimed check (every dynamic obstacle present) is a function of q0, q1 and max_step
        alone, the world's pairs being fixed when it is made: its answer is remembered by their
        exact bytes and given again, with the checks it took then, for the same move asked again
        (the sequencer's detour searches shortcut the same roadmap paths and try the same exit legs
        for many candidate pairs). Budgets counted in checks thus spend the same whether or not a
        verdict was remembered.
        """
        if (t0 is None) != (t1 is None):
            raise ValueError("give both t0 and t1, or neither")
        if not max_step > 0:
            raise ValueError(f"max_step must be > 0 m, got {max_step}")
        q0 = np.ascontiguousarray(q0, dtype=np.float64)
        q1 = np.ascontiguousarray(q1, dtype=np.float64)
        timed = t0 is not None and t1 is not None and self._s.dynamic_ids.size > 0
        if timed:
            return self._check_segment(q0, q1, t0, t1, max_step)
        key = (q0.tobytes(), q1.tobytes(), float(max_step))
        known = self._segments.get(key)
        if known is None:
            if len(self._segments) >= REMEMBERED_SEGMENTS:
                self._segments.clear()
            known = self._segments[key] = self._check_segment(q0, q1, None, None, max_step)
        return known

    def first_blocked(self, q0s: FloatArray, q1s: FloatArray, t0s: FloatArray, t1s: FloatArray,
                      max_step: float = TOL.sweep_step_m) -> MovesCheck:
        """The first of the moves q0s[i] -> q1s[i] (from t0s[i] to t1s[i] s) that `check_segment`
        finds blocked, with that check, and the checks the free moves before it took.

        The answer of `check_segment` on each move in turn, from fewer calls: a sampled motion is
        hundreds of moves of a few states each. Every state of every move is checked once (against
        the dynamic obstacles present around its own time, the window `check_segment` gives it), in
        time order, neighbouring states of one presence together, stopping at the first collision;
        the move that state belongs to is then checked by `check_segment` itself, for its own answer.
        """
        if not max_step > 0:
            raise ValueError(f"max_step must be > 0 m, got {max_step}")
        q0s, q1s = np.asarray(q0s, dtype=np.float64), np.asarray(q1s, dtype=np.float64)
        t0s, t1s = np.asarray(t0s, dtype=float), np.asarray(t1s, dtype=float)
        start, spent = 0, 0
        while start < len(q0s):
            if self._pf is None:
                k = start                                   # no pre-filter to batch with: each move as asked
            else:
                k, states = self._first_colliding_move(q0s[start:], q1s[start:], t0s[start:], t1s[start:], max_step)
                k += start
                spent += states                             # a free move's check takes all its states
                if k == len(q0s):
                    return MovesCheck(None, None, spent)
            res = self.check_segment(q0s[k], q1s[k], float(t0s[k]), float(t1s[k]), max_step)
            if not res.free:
                return MovesCheck(k, res, spent)
            spent += res.checks
            start = k + 1
        return MovesCheck(None, None, spent)

    def _first_colliding_move(self, q0s: FloatArray, q1s: FloatArray, t0s: FloatArray, t1s: FloatArray,
                              max_step: float) -> tuple[int, int]:
        """(the index of the first move with a state that collides, len(q0s) when none has; the
        states of the moves before it), the states and their windows as `_check_segment` builds them."""
        timed = self._s.dynamic_ids.size > 0
        m = self._step_counts(q0s, q1s, max_step)
        if timed:
            m[(m == 0) & (t0s != t1s)] = 1               # at rest over a time: both ends, as `_check_segment`
        move, step, fractions, states = _subdivided(q0s, q1s, m)
        if timed:
            lo, hi = step_windows(step, m[move], t0s[move], (t1s - t0s)[move])
            res = self._scan_in_time(states, fractions, lo, hi, len(states), near=True)
        else:
            self._set_presence(None, None)
            res = self._scan(states, fractions, len(states), near=True)
        if res.free:
            return len(q0s), int(np.sum(m + 1))
        first = int(move[res.checks - 1])
        return first, int(np.sum(m[:first] + 1))

    def _check_segment(self, q0: FloatArray, q1: FloatArray, t0: float | None, t1: float | None,
                       max_step: float) -> SegmentCheck:
        """`check_segment` of float64 ends, checked now."""
        dq = q1 - q0
        m = math.ceil(self.sweep_length(q0, q1) / max_step - 1e-12)
        timed = t0 is not None and t1 is not None and self._s.dynamic_ids.size > 0
        if m == 0:
            m = 1 if timed and t0 != t1 else 0
        order = bisection_order(m)
        fractions = order / m if m else np.zeros(1)
        states = q0 + fractions[:, None] * dq
        states[order == m] = q1                       # the end exactly, not q0 + 1.0 * dq
        checks = tests = 0
        if not timed:
            self._set_presence(None, None)
        if not timed and self._pf is not None:        # the common case: pre-filter, then coal's exact test
            return self._scan(states, fractions, m + 1)
        if not timed and self._manager is not None:
            model, data, manager, callback = self._s.model, self._data, self._manager, self._callback
            for k in range(len(order)):
                hit = pin.computeCollisions(model, data, manager, callback, states[k])
                tests += callback.count
                if hit:
                    return SegmentCheck(False, k + 1, m + 1, int(tests), float(fractions[k]))
            return SegmentCheck(True, len(order), m + 1, int(tests), None)
        start = float(t0) if t0 is not None else 0.0
        span = float(t1) - start if t1 is not None else 0.0
        if self._pf is not None:
            return self._scan_timed(states, fractions, order, m, start, span)
        for k, step in enumerate(order):
            if timed:
                ta = start + max(step - 1, 0) / m * span
                tb = start + min(step + 1, m) / m * span
                self._set_presence(min(ta, tb), max(ta, tb))
            hit = self._collides(states[k])
            checks += 1
            tests += self._tests(self._hit_pair() if hit else -1)
            if hit:
                return SegmentCheck(False, checks, m + 1, tests, float(fractions[k]))
        return SegmentCheck(True, checks, m + 1, tests, None)

    def check_path(self, points: FloatArray, max_step: float = TOL.sweep_step_m, near: bool = False) -> SegmentCheck:
        """Check the joint-space polyline through `points` (k, n), every dynamic obstacle present.

        Exactly the states `check_segment` checks on each segment, a state shared by two segments
        once, in coarse-to-fine order over the whole polyline (a blocked path is found early); the
        polyline is free iff every `check_segment` of its segments is. s_contact is the colliding
        state's fraction of the states, start to end. near: the polyline is short (an approach
        line), so the pairs clear of the whole of it are found once, beforehand (the same result).
        """
        if not max_step > 0:
            raise ValueError(f"max_step must be > 0 m, got {max_step}")
        pts = np.asarray(points, dtype=np.float64)
        if pts.ndim != 2 or len(pts) == 0:
            raise ValueError("points must be a non-empty (k, n) array")
        _, step, _, states = _subdivided(pts[:-1], pts[1:], self._step_counts(pts[:-1], pts[1:], max_step))
        # Each segment's states after its first, which is the one before's last (where m = 0,
        # check_segment checks q0 alone: already in).
        states = np.concatenate([pts[:1], states[step > 0]])
        self._set_presence(None, None)
        last = len(states) - 1
        order = bisection_order(last)
        if self._pf is not None:
            return self._scan(states[order], order / last if last else np.zeros(len(order)), len(states), near, order)
        tests = 0
        for k, idx in enumerate(order):
            hit = self._collides(states[idx])
            tests += self._tests(self._hit_pair() if hit else -1)
            if hit:
                return SegmentCheck(False, k + 1, len(states), int(tests), float(idx) / last if last else 0.0)
        return SegmentCheck(True, len(order), len(states), int(tests), None)

    def path_free(self, points: FloatArray, max_step: float = TOL.sweep_step_m) -> bool:
        """Whether the joint-space polyline through `points` is collision-free (see `check_path`)."""
        return self.check_path(points, max_step).free


def _subdivided(q0s: FloatArray, q1s: FloatArray, m: IntArray) -> tuple[IntArray, IntArray, FloatArray, FloatArray]:
    """(move, step, fraction, state) of each state k = 0..m[i] of each move q0s[i] -> q1s[i], in
    order, as `_check_segment` builds them: q0 + k / m (q1 - q0), the last exactly q1 (m = 0: q1)."""
    move = np.repeat(np.arange(len(m)), m + 1)
    step = np.arange(len(move)) - np.repeat(np.cumsum(m + 1) - (m + 1), m + 1)
    fractions = np.where(m[move] > 0, step / np.maximum(m[move], 1), 0.0)
    states = q0s[move] + fractions[:, None] * (q1s[move] - q0s[move])
    at_end = step == m[move]
    states[at_end] = q1s[move[at_end]]
    return move, step, fractions, states
