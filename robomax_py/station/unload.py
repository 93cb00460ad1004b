"""Spots moved away from the robot whose own cycle is the makespan, where no robot waits.

After the assignment and the order change a station can end at one robot's own cycle with nothing
waiting: interlocks are then no part of the makespan and the re-assignment with the waits as
costs has nothing to charge. The assignment balanced estimated tours, and a robot's real cycle can
overrun its estimate more than the others' do (the shipped example's UR10 r3: 38.69 s, the
KR 125-class arms 31-32 s). Here spots of that robot are moved, one at a time, to a robot that
reaches them, while the longest predicted own cycle shortens: each robot's cycle predicted as its
planned own cycle plus the change of its estimated tour (`reach.tour_legs`, welds and approach
lines, and the side prior) scaled by how far its planned cycle overran the estimate of its tour.
The giver keeps its planned order less the spots it gives, a taker welds a spot where the estimate
inserts it most cheaply; both are planned in those orders (`PlanOptions.given_order`, as an order
change is: one robot's plan each, not a new sequencing) and the station coordinated again.

A prediction knows nothing of the interlocks the new tours may need, so each trial is judged by its
coordinated makespan and kept only when that is shorter; trials are the greedy's prefixes, the
predicted shortest first, at most UNLOAD_TRIALS of them, and the first that shortens the makespan
ends the search (a trial costs two or three robots' plans).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from robomax_py._typing import FloatArray
from robomax_py.spec_station import SpotKey
from robomax_py.station.reach import RobotReach, cost_matrix, tour_estimate

log = logging.getLogger(__name__)

Order = tuple[SpotKey, ...]

# Trials planned (each: the giver and its takers planned in given orders, the station coordinated).
UNLOAD_TRIALS = 2
# Spots moved at most in one trial.
MAX_MOVES = 6
# A move is made when it shortens the longest predicted own cycle by more than this, s.
PREDICT_EPS_S = 1e-3


@dataclass(frozen=True, slots=True)
class Unload:
    """One trial: the robots whose spots change, each with its new order; the moves made
    (`why`, one per robot changed); the longest own cycle the estimate predicts, s."""

    orders: Mapping[str, Order]
    why: Mapping[str, str]
    predicted: float


def bottleneck(own: Mapping[str, float], ends: Mapping[str, float], tol: float = 1e-6) -> str | None:
    """The robot that ends last when it ends at its own cycle (it waited for nobody), else None."""
    if not ends:
        return None
    last = max(ends, key=lambda r: (ends[r], r))
    return last if ends[last] <= own.get(last, 0.0) + tol else None


def cycle_scales(orders: Mapping[str, Order], own: Mapping[str, float],
                 tour_time: Callable[[str, Order], float]) -> dict[str, float]:
    """Each robot's planned own cycle over its estimated tour in its planned order (1 where either is
    0): what turns a change of its estimated tour into a predicted change of its cycle."""
    return {r: (own[r] / t if (t := tour_time(r, o)) > 0 and own.get(r, 0.0) > 0 else 1.0)
            for r, o in orders.items()}


def unloads(orders: Mapping[str, Order], own: Mapping[str, float], giver: str,
            able: Mapping[SpotKey, Sequence[str]], tour_time: Callable[[str, Order], float],
            fixed: frozenset[SpotKey] = frozenset()) -> list[Unload]:
    """The trials of moving spots away from `giver`, the predicted shortest first.

    orders : each robot's spots in its planned order. own : each robot's own planned cycle, s.
    able : the robots that reach each spot. tour_time : a robot's estimated tour in an order, s.
    fixed : spots that may not move (an ordered seam's: it goes to one robot whole)."""
    scale = cycle_scales(orders, own, tour_time)
    now = dict(orders)
    pred = {r: own.get(r, 0.0) for r in orders}
    steps: list[Unload] = []
    why: dict[str, list[str]] = {}
    for _ in range(MAX_MOVES):
        base_g = tour_time(giver, now[giver])
        best: tuple[float, float, SpotKey, str, Order, Order] | None = None
        for i, spot in enumerate(now[giver]):
            if spot in fixed:
                continue
            rest = now[giver][:i] + now[giver][i + 1:]
            p_giver = pred[giver] + scale[giver] * (tour_time(giver, rest) - base_g)
            for taker in able.get(spot, ()):
                if taker == giver or taker not in now:
                    continue
                mine = now[taker]
                base_t = tour_time(taker, mine)
                into = min((mine[:j] + (spot,) + mine[j:] for j in range(len(mine) + 1)),
                           key=lambda o: tour_time(taker, o))
                p_taker = pred[taker] + scale[taker] * (tour_time(taker, into) - base_t)
                others = max((p for r, p in pred.items() if r not in (giver, taker)), default=0.0)
                score = (max(p_giver, p_taker, others), p_giver + p_taker)
                if best is None or score < best[:2]:
                    best = (*score, spot, taker, rest, into)
        if best is None or best[0] >= max(pred.values()) - PREDICT_EPS_S:
            break
        top, _, spot, taker, rest, into = best
        pred[giver] += scale[giver] * (tour_time(giver, rest) - base_g)
        pred[taker] += scale[taker] * (tour_time(taker, into) - tour_time(taker, now[taker]))
        now[giver], now[taker] = rest, into
        why.setdefault(taker, []).append(spot[1])
        log.debug("unload: %s gives %s to %s, predicted longest own cycle %.3f s", giver, spot[1], taker, top)
        changed = {r: o for r, o in now.items() if o != orders[r]}
        steps.append(Unload(changed, _why(giver, why), top))
    steps.sort(key=lambda u: u.predicted)
    return steps[:UNLOAD_TRIALS]


def tour_estimator(reaches: Mapping[str, RobotReach], penalty: Mapping[tuple[str, SpotKey], float],
                   costs: dict[str, FloatArray]) -> Callable[[str, Order], float]:
    """A robot's estimated tour in an order, s, as the assignment counts it (`reach.tour_estimate`;
    `costs` holds each robot's `reach.cost_matrix`, made once)."""
    def tour_time(robot: str, order: Order) -> float:
        if robot not in costs:
            costs[robot] = cost_matrix(reaches[robot])
        return tour_estimate(reaches[robot], costs[robot], order, penalty)
    return tour_time


def _why(giver: str, given: Mapping[str, Sequence[str]]) -> dict[str, str]:
    """Per robot changed, what it gives or takes."""
    gives = ", ".join(f"{', '.join(spots)} to {taker}" for taker, spots in given.items())
    return {giver: f"{giver} gives {gives}",
            **{taker: f"{taker} takes {', '.join(spots)} from {giver}" for taker, spots in given.items()}}
