"""Shortest paths in a graph (Dijkstra, compiled) that stop as soon as their goal is settled.

The detour searches run many searches on one graph that loses nodes and edges between them and
want the path to one goal only, where scipy's `dijkstra` settles every node it can reach (about
4 ms on a 24³ local map of 26-connected cells, 7 ms on a 240-spot cell's roadmap):

- `shortest_path`: between two cells of a local C-space map (`plan.cspace_detour`), the closed
  cells and moves read from masks, so the graph is built once;
- `shortest_path_to_any`: from a roadmap's start to whichever of the goal's links ends the
  shortest way (`plan.roadmap`), the goal's own cost added per link.

Each keeps a heap of (distance, node) pairs: of equal distances the lower node is settled first.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robomax_py.jit import helper, kernel


@helper
def _before(d1: float, u1: int, d2: float, u2: int) -> bool:
    """Heap order: the nearer first, of equal distances the lower node."""
    return d1 < d2 or (d1 == d2 and u1 < u2)


@helper
def _pop(heap_d: Any, heap_u: Any, size: int) -> int:
    """Remove the heap's first entry (read heap_d[0], heap_u[0] before): the last entry sifted down
    from the root. Returns the new size."""
    size -= 1
    last_d, last_u = heap_d[size], heap_u[size]
    i = 0
    while True:
        c = 2 * i + 1
        if c >= size:
            break
        if c + 1 < size and _before(heap_d[c + 1], heap_u[c + 1], heap_d[c], heap_u[c]):
            c += 1
        if not _before(heap_d[c], heap_u[c], last_d, last_u):
            break
        heap_d[i], heap_u[i] = heap_d[c], heap_u[c]
        i = c
    if size > 0:
        heap_d[i], heap_u[i] = last_d, last_u
    return size


@helper
def _push(heap_d: Any, heap_u: Any, size: Any, d: float, u: int) -> Any:
    """Add (d, u), sifted up from the end. Returns the new size. size: an int64, never a literal
    (numba compiles a function again for each literal it is called with)."""
    i = size
    while i > 0:
        p = (i - 1) // 2
        if not _before(d, u, heap_d[p], heap_u[p]):
            break
        heap_d[i], heap_u[i] = heap_d[p], heap_u[p]
        i = p
    heap_d[i], heap_u[i] = d, u
    return size + 1


@helper
def _relax(dist: Any, pred: Any, heap_d: Any, heap_u: Any, size: Any, u: int, v: int, nd: float) -> Any:
    """Node v reached from u at distance nd: kept, and pushed, where nearer than known. Returns the
    heap's size."""
    if nd < dist[v]:
        dist[v] = nd
        pred[v] = u
        return _push(heap_d, heap_u, size, nd, v)
    return size


@helper
def _traced(pred: Any, start: int, end: Any) -> Any:
    """The nodes from start to end along the predecessors (start first); end as `_push`'s size."""
    length = 1
    u = end
    while u != start:
        u = pred[u]
        length += 1
    path = np.empty(length, dtype=np.int64)
    u = end
    for k in range(length - 1, -1, -1):
        path[k] = u
        u = pred[u]
    return path


@kernel
def shortest_path(indptr: Any, indices: Any, weight: Any, usable: Any, cut: Any, start: int, goal: int) -> Any:
    """The cells of a shortest path from start to goal (start first), empty when there is none.

    indptr, indices, weight: the graph in CSR form (the moves out of cell u are
    indices[indptr[u]:indptr[u + 1]], each of cost weight[...] >= 0); usable (n,) bool: the cells
    a path may pass (start and goal are taken as given); cut (m,) bool: moves closed. Of equal
    distances the lower cell is settled first (a heap of (distance, cell) pairs), so the path does
    not depend on the order moves were pushed in."""
    n = indptr.shape[0] - 1
    dist = np.empty(n)
    pred = np.empty(n, dtype=np.int64)
    done = np.empty(n, dtype=np.bool_)
    for u in range(n):
        dist[u] = np.inf
        pred[u] = -1
        done[u] = False
    heap_d = np.empty(indices.shape[0] + 1)     # an entry per relaxation at most, and the start's
    heap_u = np.empty(indices.shape[0] + 1, dtype=np.int64)
    size = _push(heap_d, heap_u, np.int64(0), 0.0, start)
    dist[start] = 0.0
    while size > 0:
        d, u = heap_d[0], heap_u[0]
        size = _pop(heap_d, heap_u, size)
        if done[u] or d > dist[u]:
            continue                            # an entry left behind by a shorter one
        done[u] = True
        if u == goal:
            return _traced(pred, start, goal)
        for e in range(indptr[u], indptr[u + 1]):
            v = indices[e]
            if not (cut[e] or done[v] or not (usable[v] or v == goal)):
                size = _relax(dist, pred, heap_d, heap_u, size, u, v, d + weight[e])
    return np.empty(0, dtype=np.int64)


@kernel
def shortest_path_to_any(indptr: Any, indices: Any, weight: Any, start: int, goals: Any, goal_cost: Any) -> Any:
    """The nodes of a shortest path from start to one of `goals` (start first, the goal last), the
    goal chosen as scipy's `dijkstra` distances and `np.argmin` over dist[goals] + goal_cost choose
    it (the first of equal totals in `goals`' order); empty when no goal is reached. The graph in CSR
    form as for `shortest_path`; an edge of infinite weight is never taken; goal_cost (g,) >= 0,
    inf for a goal not to be used. The search stops once every node nearer than the best total so
    far is settled: a goal not settled then is at least that far, its total no less."""
    n = indptr.shape[0] - 1
    dist = np.empty(n)
    pred = np.empty(n, dtype=np.int64)
    done = np.empty(n, dtype=np.bool_)
    ends = np.empty(n)                          # the least goal cost of each node (inf: not a goal)
    for u in range(n):
        dist[u] = np.inf
        pred[u] = -1
        done[u] = False
        ends[u] = np.inf
    for k in range(goals.shape[0]):
        ends[goals[k]] = min(ends[goals[k]], goal_cost[k])
    heap_d = np.empty(indices.shape[0] + 1)
    heap_u = np.empty(indices.shape[0] + 1, dtype=np.int64)
    size = _push(heap_d, heap_u, np.int64(0), 0.0, start)
    dist[start] = 0.0
    best = np.inf
    while size > 0:
        d, u = heap_d[0], heap_u[0]
        if d > best:
            break                               # every node at most `best` away is settled
        size = _pop(heap_d, heap_u, size)
        if done[u] or d > dist[u]:
            continue
        done[u] = True
        best = min(best, d + ends[u])
        for e in range(indptr[u], indptr[u + 1]):
            v = indices[e]
            if not done[v]:
                size = _relax(dist, pred, heap_d, heap_u, size, u, v, d + weight[e])
    chosen = np.int64(-1)                       # not a literal (`_push`)
    least = np.inf
    for k in range(goals.shape[0]):
        g = goals[k]
        total = dist[g] + goal_cost[k] if done[g] else np.inf
        if total < least:
            least = total
            chosen = g
    if chosen < 0:
        return np.empty(0, dtype=np.int64)
    return _traced(pred, start, chosen)
