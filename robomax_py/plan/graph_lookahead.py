"""What the sequencer (`plan.graph.Sequencer`) learns beyond the tour it verifies: the straight moves
of the orders its search ranked next (the runners-up), checked before the next round searches again.

On a cell with a field of clamps each round's best tour leans on moves nobody has checked yet
(a skip over a clamp, another candidate pair across it); verifying it finds a few dozen of them
blocked, and the next search turns to the runners-up, which lean on the next few dozen. Checking
the straight moves those orders would use, at the candidates the search sees, takes what the next
rounds would have found one round at a time. Only straight moves are checked here, never a detour
searched: a detour is searched when a verified tour needs it, as before.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import Literal

import numpy as np

from robomax_py.plan.graph_detours import SequencerDetours
from robomax_py.plan.sequence import HOME, choice_for_order
from robomax_py.timing import ptp_time_estimate

# Runners-up of each round's order search whose straight moves are checked (`Sequencer.run`).
LOOKAHEAD_ORDERS = 8
# The round from which they are: a cell that has not found its tour in this many rounds is one
# where each round finds a new batch of blocked moves; one that does (every shipped cell) never
# pays for the extra checks, and plans as it did.
LOOKAHEAD_FROM_ROUND = 6

StraightVerdict = Literal["free", "other_free", "detour_only"]


class SequencerLookahead(SequencerDetours):
    """Straight moves learnt in batches (the base of `Sequencer`)."""

    def _learn_straight(self, i: int, a: int, j: int, b: int) -> StraightVerdict:
        """Check the straight move from candidate a of i to b of j and record it. Blocked: the
        cheapest other straight moves between the two spots are checked at once (up to
        `straight_tries` found blocked); "other_free" if one is free, else the pair becomes
        detour-only ("detour_only"; no detour is searched here)."""
        res = self.world_from(i).check_segment(self.q(i)[a], self.q(j)[b])
        self.checks += res.checks
        self._record_straight(i, a, j, b, res.free)
        if res.free:
            return "free"
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
                return "other_free"       # a free alternative exists; let the optimiser weigh it
            tried += 1
        self.detour_only.add((min(i, j), max(i, j)))
        self._forget(i, j)
        return "detour_only"

    def _look_ahead(self, orders: Sequence[tuple[int, ...]]) -> int:
        """Check the unchecked straight moves of each order's best tour over the candidates the
        order search sees (its representatives, costed with what is known now), where that tour
        takes a straight move rather than a known detour. Returns how many were found blocked."""
        blocked = 0
        for order in orders:
            choice, cost = choice_for_order(order, self.cost, self.node_reps)
            if not np.isfinite(cost):
                continue
            stops = [(HOME, 0), *((s, int(self._rows(s)[c])) for s, c in zip(order, choice)), (HOME, 0)]
            for (i, a), (j, b) in itertools.pairwise(stops):
                if (min(i, j), max(i, j)) in self.detour_only or self._verified_straight_only(i, j):
                    continue
                if (a, b) in self.straight.get((i, j), {}):
                    continue
                qa, qb = self.q(i)[a], self.q(j)[b]
                straight = float(ptp_time_estimate(qa, qb, self.limits, self.options.speed))
                pa, pb = self._positions(i, self._rows(i))[a], self._positions(j, self._rows(j))[b]
                if self.cost(i, j)[pa, pb] < straight - 1e-12:
                    continue              # the tour goes round by a known detour there
                if self._learn_straight(i, a, j, b) != "free":
                    blocked += 1
        return blocked
