"""What the sequencer (`plan.graph.Sequencer`) learns beyond the tour it verifies: the moves round
those a round left open, checked before the next round searches again (`_look_around`).

On a cell with a field of clamps the late rounds each find one or two moves blocked next to a clamp
(a spot's move past the clamp to another spot, or a known detour's leave leg to it), and the next
search swaps in the same spot's move to a neighbour of that other spot, unchecked and as cheap: one
round per neighbour. After a round that left moves open, the moves from each open move's first spot
to its second spot's nearest spots, and from the first spot's nearest to the second, are checked as
`_verify` would take them (at the cheapest pair of the candidates the search sees): a straight move,
or the enter and leave legs of the cheapest known detour. Nothing is searched here: a detour is
searched when a verified tour needs it, as before.

The runners-up of the order search (the cheapest other orders it evaluated) were tried first and
dropped: they differ from its best order by one move far from the open ones, and checking their
moves cut no round on the clamped scale cells (33 rounds against 37 at 240 spots, 10 against 10 at
60) while the tour got 0.2-0.5 % longer.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.cheapest_first import cheapest_first
from robomax_py.plan.graph_detours import SequencerDetours
from robomax_py.timing import ptp_time_estimate

# Nearest spots of each end of a move left open whose moves are checked (`_look_around`).
LOOKAROUND_SPOTS = 6
# The round from which they are: a cell that has not found its tour in this many rounds is one
# where each round finds a new batch of blocked moves; one that does (every shipped cell) never
# pays for the extra checks, and plans as it did.
LOOKAHEAD_FROM_ROUND = 6

StraightVerdict = Literal["free", "other_free", "detour_only"]


class SequencerLookahead(SequencerDetours):
    """Straight moves learnt in batches and the look round open moves (the base of `Sequencer`)."""

    _near: dict[int, list[int]] | None = None
    left_open: tuple[tuple[int, int], ...] = ()       # the moves `_verify` left open this round (spot pairs)

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
        for flat in cheapest_first(est):
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

    def _look_around(self, legs: Sequence[tuple[int, int]]) -> int:
        """For each move (i, j) a verified tour left open, the moves the next order search would
        swap in: from i to each of j's LOOKAROUND_SPOTS nearest spots, and from each of i's nearest
        to j, at their cheapest pair of the candidates the search sees, each checked as `_verify`
        would take it (`_learn_move`). Returns how many were found blocked."""
        near = self._nearest_spots()
        moves: dict[tuple[int, int], None] = {}
        for i, j in legs:
            for jj in near.get(j, ()):
                if jj != i:
                    moves[(i, jj)] = None
            for ii in near.get(i, ()):
                if ii != j:
                    moves[(ii, j)] = None
        blocked = 0
        for i, j in moves:
            est = self.cost(i, j)
            if not np.isfinite(est).any():
                continue
            r, c = np.unravel_index(int(np.argmin(est)), est.shape)
            if not self._learn_move(i, int(self._rows(i)[r]), j, int(self._rows(j)[c])):
                blocked += 1
        return blocked

    def _nearest_spots(self) -> dict[int, list[int]]:
        """Each spot's LOOKAROUND_SPOTS nearest spots (TCP positions of the spots), made once."""
        if self._near is None:
            xyz = np.array([self.cell.seams[c.seam_index].spots[c.spot_index].xyz for c in self.spots])
            gap = np.linalg.norm(xyz[:, None, :] - xyz[None, :, :], axis=2)
            np.fill_diagonal(gap, np.inf)
            k = min(LOOKAROUND_SPOTS, len(self.spots) - 1)
            order = np.argsort(gap, axis=1, kind="stable")[:, :k]
            self._near = {i: [int(x) for x in row] for i, row in enumerate(order)}
        return self._near

    def _way(self, i: int, a: int, j: int, b: int) -> tuple[bool, int, FloatArray]:
        """How a tour takes the move from candidate a of i to b of j, as `_costs` offers it (an
        unchecked straight move is tried only where it is offered): (straight, v, via_costs), with
        `straight` True where the straight move is offered and no dearer than the cheapest known
        detour, v that detour's index in via_costs (-1: none known)."""
        qa, qb = self.q(i)[a], self.q(j)[b]
        straight_ok = (min(i, j), max(i, j)) not in self.detour_only and \
            self.straight.get((i, j), {}).get((a, b), not self._verified_straight_only(i, j))
        straight = float(ptp_time_estimate(qa, qb, self.limits, self.options.speed)) if straight_ok else np.inf
        via_costs = self._pair_via_costs(i, a, j, b)
        v = int(np.argmin(via_costs)) if len(via_costs) else -1
        return straight_ok and (v < 0 or straight <= via_costs[v]), v, via_costs

    def _learn_move(self, i: int, a: int, j: int, b: int) -> bool:
        """The move from candidate a of i to b of j checked as `_verify` takes it: the straight move
        where it is offered and cheapest (a blocked one with its batch of alternatives), else the
        enter and leave legs of the cheapest known detour. Searches nothing; False if found blocked."""
        straight, v, via_costs = self._way(i, a, j, b)
        if straight:
            if (a, b) in self.straight.get((i, j), {}):
                return True
            return self._learn_straight(i, a, j, b) == "free"
        if v < 0 or not np.isfinite(via_costs[v]) or (a, b, v) in self.legs_ok.get((i, j), set()):
            return True
        return self._legs_free(i, a, j, b, v)

    def _legs_free(self, i: int, a: int, j: int, b: int, v: int) -> bool:
        """Check and record the enter and leave legs of known detour v from candidate a of i to b of
        j (searching nothing: the look round takes a blocked leg as it is, `Sequencer._check_via`
        searches a new detour)."""
        wp = self.vias_for(i, j)[v].waypoints
        for p, r in ((self.q(i)[a], wp[0]), (wp[-1], self.q(j)[b])):
            if np.allclose(p, r):
                continue
            res = self.world_from(i).check_segment(p, r)
            self.checks += res.checks
            if not res.free:
                self._record_leg(i, a, j, b, v, False)
                return False
        self._record_leg(i, a, j, b, v, True)
        return True
