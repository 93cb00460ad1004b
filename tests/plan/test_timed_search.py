"""Time-windowed A* (plan.timed_search) on small graphs: waiting in front of a closed node, going
round it when that is sooner, edge windows, the wait limit, and random graphs against a brute-force
search over a whole-second time grid (every discrete route is a continuous one, so the continuous
search may only be as fast or faster)."""

from __future__ import annotations

import math
from collections.abc import Sequence

from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.plan.timed_search import (
    STEP_S,
    NoRoute,
    TimedGraph,
    TimedRoute,
    Windows,
    merge_windows,
    safe_intervals,
    timed_astar,
)


def _graph(edges: dict[tuple[int, int], float], nodes: dict[int, Windows] | None = None,
           edge_windows: dict[tuple[int, int], Windows] | None = None, goal: int = 0) -> TimedGraph:
    adjacent: dict[int, list[tuple[int, float]]] = {}
    for (a, b), d in edges.items():
        adjacent.setdefault(a, []).append((b, d))
        adjacent.setdefault(b, []).append((a, d))
    nodes = nodes or {}
    edge_windows = edge_windows or {}
    return TimedGraph(
        neighbours=lambda u: adjacent.get(u, []),
        node_windows=lambda u: nodes.get(u, ()),
        edge_windows=lambda u, v: edge_windows.get((min(u, v), max(u, v)), ()),
        heuristic=lambda u: 0.0,
    )


def test_waits_in_the_node_before_the_closed_one() -> None:
    g = _graph({(0, 1): 1.0, (1, 2): 1.0}, nodes={2: ((0.0, 10.0),)})
    route = timed_astar(g, 0, 2, 0.0, max_wait=60.0)
    assert isinstance(route, TimedRoute)
    assert [s.node for s in route.steps] == [0, 1, 2]
    assert route.arrival == 10.0 + STEP_S            # windows include their end
    (wait,) = route.waits
    assert wait.node == 1 and wait.arrive == 1.0 and wait.depart == 9.0 + STEP_S


def test_goes_round_when_that_is_sooner_and_waits_when_that_is() -> None:
    edges = {(0, 1): 1.0, (1, 3): 1.0, (0, 2): 3.0, (2, 3): 3.0}
    closed_long = timed_astar(_graph(edges, nodes={1: ((0.0, 20.0),)}), 0, 3, 0.0, 60.0)
    assert isinstance(closed_long, TimedRoute)
    assert [s.node for s in closed_long.steps] == [0, 2, 3] and closed_long.arrival == 6.0
    closed_short = timed_astar(_graph(edges, nodes={1: ((0.0, 3.0),)}), 0, 3, 0.0, 60.0)
    assert isinstance(closed_short, TimedRoute)
    assert [s.node for s in closed_short.steps] == [0, 1, 3] and closed_short.arrival == 3.0 + STEP_S + 1.0


def test_an_edge_window_delays_the_departure() -> None:
    g = _graph({(0, 1): 2.0}, edge_windows={(0, 1): ((1.0, 4.0),)})
    route = timed_astar(g, 0, 1, 0.0, 60.0)
    assert isinstance(route, TimedRoute)
    assert route.steps[0].depart == 4.0 + STEP_S and route.arrival == 6.0 + STEP_S


def test_the_wait_limit_and_a_blocked_start_are_reported() -> None:
    g = _graph({(0, 1): 1.0}, nodes={1: ((0.0, 100.0),)})
    limited = timed_astar(g, 0, 1, 0.0, max_wait=10.0)
    assert isinstance(limited, NoRoute) and limited.reason == "wait_limit"
    assert isinstance(timed_astar(g, 0, 1, 0.0, max_wait=200.0), TimedRoute)
    blocked = timed_astar(_graph({(0, 1): 1.0}, nodes={0: ((0.0, 5.0),)}), 0, 1, 1.0, 60.0)
    assert isinstance(blocked, NoRoute) and blocked.reason == "start_blocked"
    walled = timed_astar(_graph({(0, 1): 1.0}, edge_windows={(0, 1): ((0.0, math.inf),)}), 0, 1, 0.0, 60.0)
    assert isinstance(walled, NoRoute) and walled.reason == "no_route"


def test_intervals_and_merging() -> None:
    assert merge_windows([(5.0, 6.0), (1.0, 2.0), (1.5, 3.0)]) == ((1.0, 3.0), (5.0, 6.0))
    assert safe_intervals(((1.0, 3.0),)) == [(0.0, 1.0 - STEP_S), (3.0 + STEP_S, math.inf)]
    assert safe_intervals(((0.0, 3.0),)) == [(3.0 + STEP_S, math.inf)]


# ------------------------------------------------------------------ random graphs, brute force

HORIZON = 60


def _blocked(windows: Sequence[tuple[float, float]], a: float, b: float) -> bool:
    return any(w0 <= b and w1 >= a for w0, w1 in windows)


def _brute_force(n: int, edges: dict[tuple[int, int], int], nodes: dict[int, Windows],
                 edge_windows: dict[tuple[int, int], Windows], goal: int) -> float:
    """Earliest arrival over whole-second times: wait a second, or take an edge."""
    reach = {(0, 0)}
    frontier = [(0, 0)]
    best = math.inf
    while frontier:
        nxt = []
        for u, t in frontier:
            if u == goal:
                best = min(best, t)
                continue
            moves = [(u, t + 1, 1, ())]
            moves += [(b if a == u else a, t + d, d, edge_windows.get((a, b), ())) for (a, b), d in edges.items() if u in (a, b)]
            for v, t2, d, ew in moves:
                if t2 > HORIZON or (v, t2) in reach:
                    continue
                if v == u and _blocked(nodes.get(u, ()), t, t2):
                    continue
                if v != u and (_blocked(ew, t, t2) or _blocked(nodes.get(v, ()), t2, t2)):
                    continue
                reach.add((v, t2))
                nxt.append((v, t2))
        frontier = nxt
    return best


def _valid(route: TimedRoute, edges: dict[tuple[int, int], int], nodes: dict[int, Windows],
           edge_windows: dict[tuple[int, int], Windows]) -> bool:
    for a, b in zip(route.steps[:-1], route.steps[1:]):
        key = (min(a.node, b.node), max(a.node, b.node))
        if _blocked(nodes.get(a.node, ()), a.arrive, a.depart) or _blocked(nodes.get(b.node, ()), b.arrive, b.arrive):
            return False
        if abs(b.arrive - a.depart - edges[key]) > 1e-9 or _blocked(edge_windows.get(key, ()), a.depart, b.arrive):
            return False
    return True


@st.composite
def _cases(draw: st.DrawFn) -> tuple[int, dict[tuple[int, int], int], dict[int, Windows], dict[tuple[int, int], Windows]]:
    n = draw(st.integers(3, 7))
    pairs = draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), min_size=n, max_size=3 * n))
    edges = {(min(a, b), max(a, b)): draw(st.integers(1, 4)) for a, b in pairs if a != b}

    def windows() -> Windows:
        starts = draw(st.lists(st.integers(0, 40), max_size=2))
        return merge_windows([(s + 0.5, s + 0.5 + draw(st.integers(1, 8))) for s in starts])

    nodes = {u: windows() for u in range(1, n)}
    edge_windows = {e: windows() for e in edges}
    return n, edges, nodes, edge_windows


@settings(max_examples=150, deadline=None)
@given(_cases())
def test_random_graphs_against_brute_force(case: tuple[int, dict[tuple[int, int], int], dict[int, Windows],
                                                       dict[tuple[int, int], Windows]]) -> None:
    n, edges, nodes, edge_windows = case
    goal = n - 1
    graph = _graph({e: float(d) for e, d in edges.items()}, nodes, edge_windows)
    found = timed_astar(graph, 0, goal, 0.0, max_wait=1e9)
    discrete = _brute_force(n, edges, nodes, edge_windows, goal)
    if isinstance(found, NoRoute):
        assert math.isinf(discrete)
        return
    assert _valid(found, edges, nodes, edge_windows)
    assert found.arrival <= discrete + 1e-9
