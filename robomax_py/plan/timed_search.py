"""Time-windowed A* (safe-interval path planning) over a graph whose nodes and edges are blocked
in known time windows.

The method of Kholopov, Makarov and Kladov for machine-tending cells: each node carries its time
stamps of availability (always free, or free only between a door's closings); A* ranks by
f(n) = g(n) + h(n) + w(n), with g the earliest arrival time, h a lower bound of the time still to go
and w infinite where the node or the edge into it is blocked at that time. The search may *wait*
in a node that stays free until the way on opens, or take another route, whichever arrives first.

States are (node, safe interval): a node's time line split where its blocking windows begin and
end; arriving earlier within the same interval is never worse, since one can wait there. So the
first time the goal is popped its arrival is the earliest possible (h a lower bound), and a search
without a route says why: no route at all, or only after waiting longer than `max_wait`.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

Windows = tuple[tuple[float, float], ...]
# Departures are pushed past a window's end by this much (s): windows include their end.
STEP_S = 1e-3


@dataclass(frozen=True, slots=True)
class TimedGraph:
    """What the search reads of a graph; every callable may compute lazily and cache.

    neighbours(u) : (v, duration s) of the edges out of u (free of static obstacles, or to be checked
        by `edge_windows`, which returns None for an edge that is blocked for good).
    node_windows(u) : windows in which node u is blocked (sorted, disjoint).
    edge_windows(u, v) : windows in which traversing u -> v collides: the edge is taken at t only if
        no window meets [t, t + duration]; None: never traversable.
    heuristic(u) : a lower bound of the time from u to the goal, s.
    """

    neighbours: Callable[[int], Sequence[tuple[int, float]]]
    node_windows: Callable[[int], Windows]
    edge_windows: Callable[[int, int], Windows | None]
    heuristic: Callable[[int], float]


@dataclass(frozen=True, slots=True)
class TimedStep:
    """A node of a route: reached at `arrive`, left at `depart` (the difference is a wait there)."""

    node: int
    arrive: float
    depart: float


@dataclass(frozen=True, slots=True)
class TimedRoute:
    steps: tuple[TimedStep, ...]
    expansions: int

    @property
    def arrival(self) -> float:
        return self.steps[-1].arrive

    @property
    def waits(self) -> tuple[TimedStep, ...]:
        return tuple(s for s in self.steps if s.depart - s.arrive > STEP_S / 2)


@dataclass(frozen=True, slots=True)
class NoRoute:
    reason: str                  # "start_blocked" | "no_route" | "wait_limit"
    detail: str
    expansions: int


def safe_intervals(blocked: Windows) -> list[tuple[float, float]]:
    """The complement of sorted disjoint closed windows on [0, inf), kept `STEP_S` clear of them."""
    out: list[tuple[float, float]] = []
    t = 0.0
    for w0, w1 in blocked:
        if w0 - STEP_S >= t:
            out.append((t, w0 - STEP_S))
        t = max(t, w1 + STEP_S)
    out.append((t, math.inf))
    return out


def merge_windows(windows: Sequence[tuple[float, float]]) -> Windows:
    """Windows sorted and joined where they overlap or touch."""
    out: list[list[float]] = []
    for w0, w1 in sorted(windows):
        if out and w0 <= out[-1][1]:
            out[-1][1] = max(out[-1][1], w1)
        else:
            out.append([w0, w1])
    return tuple((a, b) for a, b in out)


def earliest_departure(t: float, duration: float, blocked: Windows) -> float:
    """The earliest t' >= t at which [t', t' + duration] meets no window (windows closed)."""
    for w0, w1 in blocked:
        if w1 < t:
            continue
        if w0 > t + duration:
            break
        t = w1 + STEP_S
    return t


def timed_astar(graph: TimedGraph, start: int, goal: int, t0: float, max_wait: float,
                max_expansions: int = 200_000) -> TimedRoute | NoRoute:
    """The earliest arrival at `goal` leaving `start` at t0, waiting in nodes where that helps.

    A wait of more than `max_wait` at one node is not taken; when only such waits would lead on,
    the answer is NoRoute("wait_limit").
    """
    start_iv = _interval_at(safe_intervals(graph.node_windows(start)), t0)
    if start_iv is None:
        return NoRoute("start_blocked", f"the start is blocked at t = {t0:.3f} s", 0)
    goal_free = safe_intervals(graph.node_windows(goal))

    heuristics: dict[int, float] = {}                 # a node is queued again and again: h once each

    def rank(t: float, u: int) -> tuple[float, float]:
        """f = the goal's first free time from g + h on (still a lower bound of the arrival), then h:
        while a window holds the goal shut, the states nearest it go first instead of every state
        that could arrive before it opens."""
        h = heuristics.get(u)
        if h is None:
            h = heuristics[u] = graph.heuristic(u)
        return _free_from(goal_free, t + h), h

    # Edges are checked lazily (Lazy A*): a successor is queued on the time it would have if its
    # edge were free, and the edge is checked when that entry comes first; a later true arrival is
    # queued again. Checking an edge is a swept collision test per obstacle, the search's main cost.
    State = tuple[int, int]
    best: dict[State, float] = {}                     # arrivals of the states closed
    parent: dict[State, tuple[State, float] | None] = {}
    heap: list[tuple[float, float, float, int, int, int, State | None, float, bool]] = []
    seq = 0
    intervals: dict[int, list[tuple[float, float]]] = {}
    expansions = 0
    wait_limited = False

    def node_intervals(u: int) -> list[tuple[float, float]]:
        if u not in intervals:
            intervals[u] = safe_intervals(graph.node_windows(u))
        return intervals[u]

    def push(t: float, v: int, j: int, par: State | None, dep: float, checked: bool) -> None:
        nonlocal seq
        seq += 1
        heapq.heappush(heap, (*rank(t, v), t, seq, v, j, par, dep, checked))

    push(t0, start, start_iv, None, t0, True)
    while heap and expansions < max_expansions:
        _, _, t, _, u, iv, par, dep, checked = heapq.heappop(heap)
        if (u, iv) in best:
            continue
        if not checked and par is not None:
            blocked = graph.edge_windows(par[0], u)
            if blocked is None:
                continue
            d = t - dep
            dep_true = earliest_departure(dep, d, blocked)
            if dep_true > dep:
                if math.isinf(dep_true) or dep_true > node_intervals(par[0])[par[1]][1]:
                    continue                # the node before is blocked before the edge opens
                if dep_true - best[par] > max_wait:
                    wait_limited = True
                    continue
                if dep_true + d <= node_intervals(u)[iv][1]:
                    push(dep_true + d, u, iv, par, dep_true, True)
                continue
        best[(u, iv)] = t
        parent[(u, iv)] = None if par is None else (par, dep)
        if u == goal:
            return TimedRoute(_route((u, iv), best, parent), expansions)
        expansions += 1
        iv_end = node_intervals(u)[iv][1]
        for v, d in graph.neighbours(u):
            for j, (c, e) in enumerate(node_intervals(v)):
                if e < t + d or (v, j) in best:
                    continue
                dep = max(t, c - d)
                if dep > iv_end:
                    break                   # u is blocked before the way on opens
                if dep - t > max_wait:
                    wait_limited = True
                    break
                push(dep + d, v, j, (u, iv), dep, False)
    if wait_limited:
        return NoRoute("wait_limit", f"only a wait of more than {max_wait:g} s at one place leads on", expansions)
    return NoRoute("no_route", "no route through the free nodes at any time", expansions)


def _free_from(intervals: list[tuple[float, float]], t: float) -> float:
    """The first time >= t inside one of the intervals."""
    for a, b in intervals:
        if t <= b:
            return max(a, t)
    return math.inf


def _interval_at(intervals: list[tuple[float, float]], t: float) -> int | None:
    for i, (a, b) in enumerate(intervals):
        if a <= t <= b:
            return i
    return None


def _route(end: tuple[int, int], best: dict[tuple[int, int], float],
           parent: dict[tuple[int, int], tuple[tuple[int, int], float] | None]) -> tuple[TimedStep, ...]:
    """Steps from the start: each node's arrival and departure (the goal's departure is its arrival)."""
    steps = [TimedStep(end[0], best[end], best[end])]
    key = end
    while (link := parent[key]) is not None:
        prev, dep = link
        steps.append(TimedStep(prev[0], best[prev], dep))
        key = prev
    return tuple(reversed(steps))
