"""Another spot order instead of waiting: where the robot that ends last waits for another, its
spots in the shared zone welded at another time of its tour (or the leader's earlier), each robot
re-planned with that order fixed and the station coordinated again; a change is kept only when the
makespan shortens.

Letting each robot take its own best tour and then waiting where the tours cross can cost far more
than changing a tour so that two robots are not in the shared zone at the same time (Åblad et al.,
IEEE T-ASE 2022, "Continuous-time multi-robot coordination", on spot-welding stations; Spensieri et
al., IEEE T-ASE 2016). Here the candidates are few and found from the interlocks themselves: the
zone's spot of the waiting robot welded last, first, or the tour reversed (the zone then comes at
the other end), and the leader's zone spot welded first (it leaves the zone sooner). Each one is
planned as the published method plans a given order (`PlanOptions.given_order`: the same
candidates, detours and timing), so the cost of a candidate is one robot's plan and the diagrams.

That plan can cost more than the change can gain: a candidate re-plans one robot and keeps every
other robot's plan, so the station cannot end before the longest own cycle among the others, nor
before the re-planned robot's new own cycle, at least its tour's lower bound (`most_gain`). A candidate whose most gain is below
MIN_GAIN_SHARE of the makespan is not planned, the rest are planned the most gain first, and a
round stops once the best trial reaches what every candidate left could reach.

Candidates of one robot often could gain the same: the other robots' own cycles bound them all
(the robot's tour bound does not depend on the order). Among those the one whose tour is estimated
to grow least is planned first (a reversed tour keeps its legs; a spot moved to the other end adds
a detour): it is the likelier to keep the robot's own cycle and reach the bound, and once one
reaches it the round plans none of the others.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Generic, TypeVar

from robomax_py.spec import CellSpec, SeamSpec
from robomax_py.spec_station import SpotKey
from robomax_py.station.coordinate import Interlock

log = logging.getLogger(__name__)

Plan = TypeVar("Plan")
Order = tuple[SpotKey, ...]

# Rounds of order changes (each from the best station so far) and candidates planned per round.
ORDER_ROUNDS = 2
ORDER_CANDIDATES = 3
# A change is kept when the makespan shortens by more than this, s.
MAKESPAN_EPS_S = 1e-3
# A candidate is planned only when it could shorten the makespan by at least this share of it. A
# candidate costs one robot's plan (about 1 s of CPU for a KR 125 with 10 spots, 5-10 s for a robot
# of 30-50 spots); each change kept on the generated stations and the crossing station gained
# 1.4-23 % (docs/stations.md), so this stays well below what the order change is for.
MIN_GAIN_SHARE = 0.005


@dataclass(frozen=True, slots=True)
class OrderChange:
    """One candidate: `robot`'s spots welded in `order` (`why` says which move made it)."""

    robot: str
    order: tuple[SpotKey, ...]
    why: str


def ordered_view(cell: CellSpec, order: Sequence[SpotKey]) -> CellSpec:
    """`cell` narrowed to `order`'s spots in that order: each seam cut into runs of consecutive
    spots of the order (a run keeps its seam's name, tolerance and grid), so that the published
    method's file order is `order`."""
    by_key = {(seam.name, s.name): (seam, s) for seam in cell.seams for s in seam.spots}
    runs: list[SeamSpec] = []
    for key in order:
        seam, spot = by_key[key]
        if runs and runs[-1].name == seam.name:
            runs[-1] = dataclasses.replace(runs[-1], spots=(*runs[-1].spots, spot))
        else:
            runs.append(dataclasses.replace(seam, spots=(spot,)))
    return dataclasses.replace(cell, seams=tuple(runs))


def candidates(order: Mapping[str, tuple[SpotKey, ...]], ends: Mapping[str, float],
               waits: Mapping[str, Sequence[tuple[float, float]]], interlocks: Sequence[Interlock],
               ordered: Sequence[Sequence[SpotKey]]) -> list[OrderChange]:
    """Order changes worth planning for a coordinated station, best bets first: none unless the
    robot that ends last waits (its waits are then part of the makespan).

    order : each robot's spots in its planned order. ends : each robot's end on the shared clock, s.
    waits : each robot's (own time of the wait point, seconds waited). ordered : an ordered seam's
    spots, in their order (a candidate that breaks one is left out)."""
    if not ends:
        return []
    last = max(ends, key=lambda r: (ends[r], r))
    waited = dict(waits.get(last, ()))
    locks = sorted((x for x in interlocks if x.waiter == last and waited.get(x.wait_at, 0.0) > 0),
                   key=lambda x: -waited[x.wait_at])
    out: list[OrderChange] = []
    for lock in locks:
        mine = order[last]
        k = _segment_spot(lock, last, mine)
        if k is not None:
            rest = mine[:k] + mine[k + 1:]
            out.append(OrderChange(last, (*rest, mine[k]), f"{last} welds {mine[k][1]} last"))
        out.append(OrderChange(last, mine[::-1], f"{last}'s tour reversed"))
        theirs = order[lock.leader]
        j = _segment_spot(lock, lock.leader, theirs)
        if j is not None:
            rest = theirs[:j] + theirs[j + 1:]
            out.append(OrderChange(lock.leader, (theirs[j], *rest), f"{lock.leader} welds {theirs[j][1]} first"))
        if k is not None:
            rest = mine[:k] + mine[k + 1:]
            out.append(OrderChange(last, (mine[k], *rest), f"{last} welds {mine[k][1]} first"))
    seen = {(r, o) for r, o in order.items()}
    kept: list[OrderChange] = []
    for c in out:
        if (c.robot, c.order) not in seen and _keeps_seams(c.order, ordered):
            seen.add((c.robot, c.order))
            kept.append(c)
    return kept


def most_gain(makespan: float, own: Mapping[str, float], robot: str, floor: float) -> float:
    """The most an order change of `robot` can shorten `makespan`, s (0 when it cannot).

    own : each robot's own cycle (its program alone, no waits), s. floor : a lower bound on
    `robot`'s own cycle in the new order, s.

    The other robots keep their plans, so each ends no sooner than its own cycle (a wait only adds
    to it), whatever the new interlocks; their ends themselves are no bound (a robot that waited
    for `robot` may wait less). `robot`, planned anew, ends no sooner than its new own cycle, which
    is at least `floor`. That holds for the robot that ends last re-ordered, and for a leader
    re-ordered (the robot that ends last then keeps its own cycle, counted among the others)."""
    others = max((c for r, c in own.items() if r != robot), default=0.0)
    return max(0.0, makespan - max(others, floor))


def _segment_spot(lock: Interlock, robot: str, order: Sequence[SpotKey]) -> int | None:
    """The spot (index into `order`) the robot's program segment in the interlock moves to and
    welds; None for the segment back home."""
    segment = lock.zone[0] if robot == lock.pair[0] else lock.zone[1]
    return segment if segment < len(order) else None


def _keeps_seams(order: Sequence[SpotKey], ordered: Sequence[Sequence[SpotKey]]) -> bool:
    at = {k: i for i, k in enumerate(order)}
    for seam in ordered:
        pos = [at[k] for k in seam if k in at]
        if pos != sorted(pos):
            return False
    return True


@dataclass(frozen=True, slots=True)
class OrderSearch(Generic[Plan]):
    """What `improve_orders` did: the best plan, the candidates planned (`tried`) and those passed
    over for what they could gain at most (`skipped`), the changes kept, in order."""

    best: Plan
    tried: int
    skipped: int
    kept: tuple[OrderChange, ...]


def improve_orders(start: Plan, makespan: Callable[[Plan], float], orders: Callable[[Plan], Mapping[str, Order]],
                   propose: Callable[[Plan], list[OrderChange]], trial: Callable[[Plan, OrderChange], Plan | None],
                   gain: Callable[[Plan, OrderChange], float] | None = None,
                   growth: Callable[[Plan, OrderChange], float] | None = None) -> OrderSearch[Plan]:
    """ORDER_ROUNDS rounds, each planning up to ORDER_CANDIDATES of `propose`'s changes to the best
    plan so far by `trial` (None where the change does not plan) and keeping the one with the
    shortest makespan when it is shorter. A station whose robots' orders (`orders`) were all
    planned before is not planned again.

    `gain`: the most a change can shorten the makespan (`most_gain`; none given: no limit). A
    change that could gain less than MIN_GAIN_SHARE of the makespan is not planned; the others are
    planned the most gain first, and a round stops once its best trial is as short as the change
    left could make the station.

    `growth`: how much a change is estimated to lengthen its robot's tour, s; among changes of equal
    most gain, the least growth first (none given, or equal: `propose`'s order)."""
    best, tried, skipped = start, 0, 0
    kept: list[OrderChange] = []
    seen = {_state(orders(start))}
    for _ in range(ORDER_ROUNDS):
        found: tuple[Plan, OrderChange] | None = None
        now = dict(orders(best))
        span = makespan(best)
        fresh = [c for c in propose(best) if _state({**now, c.robot: c.order}) not in seen]
        worth: list[tuple[float, float, OrderChange]] = []
        for change in fresh:
            g = math.inf if gain is None else gain(best, change)
            if g >= MIN_GAIN_SHARE * span:
                worth.append((g, 0.0 if growth is None else growth(best, change), change))
            else:
                skipped += 1
                log.debug("order change %s not planned: it could gain %.3f s at most", change.why, g)
        for g, grown, change in worth:
            log.debug("order change %s: could gain %.3f s at most, tour estimated %+.3f s", change.why, g, grown)
        worth.sort(key=lambda gc: (-gc[0], gc[1]))
        for g, _, change in worth[:ORDER_CANDIDATES]:
            if found is not None and makespan(found[0]) <= span - g + MAKESPAN_EPS_S:
                # No change left (the most gain first) could end sooner than the one found.
                skipped += 1
                continue
            tried += 1
            seen.add(_state({**now, change.robot: change.order}))
            got = trial(best, change)
            log.debug("order change %s: makespan %s (best %.3f s, at best %.3f s)", change.why,
                      "not planned" if got is None else f"{makespan(got):.3f} s", span, span - g)
            if got is None or makespan(got) >= span - MAKESPAN_EPS_S:
                continue
            if found is None or makespan(got) < makespan(found[0]):
                found = (got, change)
        if found is None:
            break
        best = found[0]
        kept.append(found[1])
    return OrderSearch(best, tried, skipped, tuple(kept))


def _state(orders: Mapping[str, Order]) -> frozenset[tuple[str, Order]]:
    return frozenset(orders.items())
