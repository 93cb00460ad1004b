"""The shortest path between two cells of a map's graph (Dijkstra, compiled), stopping as soon as
the goal is reached, over the cells and moves still open.

The local maps' searches (`plan.cspace_detour`) run many times on one graph that loses cells and
moves between searches, and want only the path to one goal. scipy's `dijkstra` settles every cell
it can reach (about 4 ms on a 24³ map of 26-connected cells) and takes a new sparse matrix for
every removal; this one stops when the goal is settled and reads which cells and moves are open
from two masks, so the graph is built once.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robomax_py.jit import kernel


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
    capacity = indices.shape[0] + 1
    heap_d = np.empty(capacity)
    heap_u = np.empty(capacity, dtype=np.int64)
    heap_d[0], heap_u[0] = 0.0, start
    size = 1
    dist[start] = 0.0
    found = False
    while size > 0:
        d, u = heap_d[0], heap_u[0]
        size -= 1                               # pop: the last entry sifted down from the root
        last_d, last_u = heap_d[size], heap_u[size]
        i = 0
        while True:
            c = 2 * i + 1
            if c >= size:
                break
            if c + 1 < size and (heap_d[c + 1] < heap_d[c] or (heap_d[c + 1] == heap_d[c] and heap_u[c + 1] < heap_u[c])):
                c += 1
            if heap_d[c] < last_d or (heap_d[c] == last_d and heap_u[c] < last_u):
                heap_d[i], heap_u[i] = heap_d[c], heap_u[c]
                i = c
            else:
                break
        if size > 0:
            heap_d[i], heap_u[i] = last_d, last_u
        if done[u] or d > dist[u]:
            continue                            # an entry left behind by a shorter one
        done[u] = True
        if u == goal:
            found = True
            break
        for e in range(indptr[u], indptr[u + 1]):
            v = indices[e]
            if cut[e] or done[v] or not (usable[v] or v == goal):
                continue
            nd = d + weight[e]
            if nd < dist[v]:
                dist[v] = nd
                pred[v] = u
                i = size                        # push: sifted up from the end
                size += 1
                while i > 0:
                    p = (i - 1) // 2
                    if heap_d[p] < nd or (heap_d[p] == nd and heap_u[p] < v):
                        break
                    heap_d[i], heap_u[i] = heap_d[p], heap_u[p]
                    i = p
                heap_d[i], heap_u[i] = nd, v
    if not found:
        return np.empty(0, dtype=np.int64)
    length = 1
    u = goal
    while u != start:
        u = pred[u]
        length += 1
    path = np.empty(length, dtype=np.int64)
    u = goal
    for k in range(length - 1, -1, -1):
        path[k] = u
        u = pred[u]
    return path
