"""robomax_py.cspace.dijkstra: the compiled shortest path that stops at its goal.

What must hold, against scipy's `dijkstra` over the same graph with the closed cells and moves left
out (a second implementation): a path exactly where scipy reaches the goal, of scipy's distance
(relative 1e-12: the two add the same costs, perhaps in another order along equal paths), that
starts and ends where asked and takes only open moves between open cells; and the CSR form of the
map's moves (`neighbour_graph`) holds the moves `neighbour_moves` lists.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from robomax_py.cspace.dijkstra import shortest_path, shortest_path_to_any
from robomax_py.cspace.grid import neighbour_graph, neighbour_moves

DIST_RTOL = 1e-12


def test_the_graph_form_holds_every_move_once() -> None:
    shape = (4, 3, 5)
    src, dst = neighbour_moves(shape)
    indptr, indices, order = neighbour_graph(shape)
    rows = np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))
    np.testing.assert_array_equal(src[order], rows)
    np.testing.assert_array_equal(dst[order], indices)
    assert sorted(order.tolist()) == list(range(len(src)))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31), r=st.integers(2, 9), closed=st.floats(0.0, 0.6), cut_share=st.floats(0.0, 0.5),
       ties=st.booleans())
def test_the_path_is_scipys_shortest(seed: int, r: int, closed: float, cut_share: float, ties: bool) -> None:
    rng = np.random.default_rng(seed)
    shape = (r, r, r)
    n = r ** 3
    indptr, indices, _ = neighbour_graph(shape)
    # Costs in whole steps (many equal paths) or continuous ones.
    cost = rng.integers(1, 3, size=len(indices)).astype(float) if ties else rng.uniform(0.01, 1.0, size=len(indices))
    usable = rng.uniform(size=n) >= closed
    cut = rng.uniform(size=len(indices)) < cut_share
    start, goal = (int(x) for x in rng.choice(n, size=2, replace=False))
    path = shortest_path(indptr, indices, cost, usable, cut, start, goal)

    rows = np.repeat(np.arange(n), np.diff(indptr))
    open_ = ~cut & (usable | (np.arange(n) == start))[rows] & (usable | (np.arange(n) == goal))[indices]
    # A zero cost would drop out of scipy's sparse matrix: costs here are >= 0.01.
    graph = coo_matrix((cost[open_], (rows[open_], indices[open_])), shape=(n, n)).tocsr()
    expected = dijkstra(graph, directed=True, indices=start)[goal]

    if not np.isfinite(expected):
        assert path.size == 0
        return
    assert path[0] == start and path[-1] == goal
    total = 0.0
    for u, v in zip(path[:-1].tolist(), path[1:].tolist()):
        e = indptr[u] + np.flatnonzero(indices[indptr[u]:indptr[u + 1]] == v)
        assert e.size == 1 and not cut[e[0]]
        assert v == goal or usable[v]
        total += cost[e[0]]
    assert abs(total - expected) <= DIST_RTOL * expected


def test_start_is_goal_is_a_path_of_one_cell() -> None:
    indptr, indices, _ = neighbour_graph((3, 3, 3))
    path = shortest_path(indptr, indices, np.ones(len(indices)), np.zeros(27, dtype=bool),
                         np.zeros(len(indices), dtype=bool), 13, 13)
    assert path.tolist() == [13]


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(2, 300), degree=st.integers(1, 8), n_goals=st.integers(1, 8),
       blocked_share=st.floats(0.0, 0.5), ties=st.booleans())
def test_the_path_to_any_goal_is_scipys_shortest_and_argmin(seed: int, n: int, degree: int, n_goals: int,
                                                            blocked_share: float, ties: bool) -> None:
    """A roadmap-like graph (random edges both ways, some at infinity: blocked) and a goal reached
    through one of several links, each with its own cost (some unusable: inf): the path ends at the
    link scipy's distances and `np.argmin` over dist + cost choose, and costs that total."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, n, size=n * degree)
    b = rng.integers(0, n, size=n * degree)
    # Each pair once, as a roadmap holds its edges (scipy would add parallel entries up).
    pairs = np.unique(np.sort(np.stack([a, b], axis=1), axis=1), axis=0)
    a, b = pairs[pairs[:, 0] != pairs[:, 1]].T
    w = rng.integers(1, 4, size=len(a)).astype(float) if ties else rng.uniform(0.01, 1.0, size=len(a))
    w[rng.uniform(size=len(a)) < blocked_share] = np.inf
    rows, cols, weight = np.concatenate([a, b]), np.concatenate([b, a]), np.concatenate([w, w])
    order = np.lexsort((cols, rows))
    rows, cols, weight = rows[order], cols[order], weight[order]
    indptr = np.searchsorted(rows, np.arange(n + 1)).astype(np.int64)
    start = int(rng.integers(n))
    goals = rng.choice(n, size=min(n_goals, n), replace=False).astype(np.int64)
    cost = rng.integers(0, 3, size=len(goals)).astype(float) if ties else rng.uniform(0.0, 1.0, size=len(goals))
    cost[rng.uniform(size=len(goals)) < 0.2] = np.inf
    path = shortest_path_to_any(indptr, cols.astype(np.int64), weight, start, goals, cost)

    finite = np.isfinite(weight)
    graph = coo_matrix((weight[finite], (rows[finite], cols[finite])), shape=(n, n)).tocsr()
    dist = dijkstra(graph, directed=True, indices=start)
    total = dist[goals] + cost
    if not np.isfinite(total.min()):
        assert path.size == 0
        return
    assert path[0] == start and path[-1] == goals[int(np.argmin(total))]
    length = 0.0
    for u, v in zip(path[:-1].tolist(), path[1:].tolist()):
        row = slice(indptr[u], indptr[u + 1])
        length += float(weight[row][cols[row] == v].min())
    assert abs(length - dist[path[-1]]) <= DIST_RTOL * max(dist[path[-1]], 1.0)


def test_a_goal_as_far_as_the_best_total_is_still_settled_and_taken_first_in_order() -> None:
    """start -> 1 (1.0) and start -> 2 (2.0); goals [2, 1] with costs [0, 1]: both total 2.0, and
    np.argmin takes the first, goal 2, which lies exactly as far as the best total found through
    goal 1: the search must settle it before stopping."""
    indptr = np.array([0, 2, 3, 4], dtype=np.int64)
    indices = np.array([1, 2, 0, 0], dtype=np.int64)
    weight = np.array([1.0, 2.0, 1.0, 2.0])
    path = shortest_path_to_any(indptr, indices, weight, 0, np.array([2, 1], dtype=np.int64), np.array([0.0, 1.0]))
    assert path.tolist() == [0, 2]
