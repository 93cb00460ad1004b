"""Inverse kinematics as a table (Diane and Anikina's associative memory), for any arm.

Every joint is sampled on its own grid, `q_i(j) = q_start + j (q_end - q_start) / (J_i - 1)`, forward
kinematics fills the rows `Q -> X` of the table, and rows in collision are dropped (once without and
once with the held part, which gives two tables). The inverse lookup returns the stored
configuration whose point is nearest the target (`argmin |x - x*|`, a k-d tree), with the distance
as the lookup's error. The stored points are also the nodes of a k-nearest-neighbour graph over
which a route between two configurations is found by Dijkstra (edges checked only when a route
uses them), and a route is followed by damped Jacobian interpolation, `q += J+ (p(t+dt) - p(t))`,
which keeps the point on the straight line between two nodes within a stated error (`follow_edge`:
an edge is usable where that interpolation arrives at the far node's configuration).

The module knows nothing of the robot: forward kinematics, the Jacobian and the collision test are
functions handed in, so the same table serves a 6-axis arm, a planar test arm or anything else.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.jit import kernel

Forward = Callable[[FloatArray], FloatArray]          # (m, n) joint rows -> (m, d) points
FreeTest = Callable[[FloatArray], BoolArray]          # (m, n) joint rows -> (m,) collision-free
Jacobian = Callable[[FloatArray], FloatArray]         # (n,) joints -> (d, n) d point / d joints

# Rows filled per call of the forward kinematics and the collision test.
BATCH = 65_536
# A step of `follow_edge` turning a joint by more than this (rad) jumped through a singular
# configuration: a step of a few millimetres of the point turns a well-conditioned arm's joints by
# hundredths of a radian.
MAX_JOINT_STEP = 0.2
# `TableIk.nearest` scans tables of up to this many stored numbers (rows x point dimension).
SCAN_MAX_VALUES = 50_000


@kernel
def _scan_nearest(points: FloatArray, target: FloatArray) -> tuple[int, float]:
    best, best_i = np.inf, 0
    for i in range(points.shape[0]):
        d = 0.0
        for j in range(points.shape[1]):
            e = points[i, j] - target[j]
            d += e * e
        if d < best:
            best, best_i = d, i
    return best_i, math.sqrt(best)


@dataclass(frozen=True, slots=True)
class JointGrid:
    """Per joint: the first and last value (rad, or m) and the number of samples J_i >= 2."""

    start: tuple[float, ...]
    end: tuple[float, ...]
    counts: tuple[int, ...]

    def __post_init__(self) -> None:
        if not (len(self.start) == len(self.end) == len(self.counts)) or not self.counts:
            raise ValueError("start, end and counts need one entry per joint")
        if any(c < 2 for c in self.counts):
            raise ValueError(f"every joint needs at least 2 samples, got {self.counts}")

    @staticmethod
    def stepped(start: tuple[float, ...], end: tuple[float, ...], counts: int | tuple[int, ...]) -> JointGrid:
        n = len(start)
        return JointGrid(tuple(start), tuple(end), (counts,) * n if isinstance(counts, int) else tuple(counts))

    def values(self, i: int) -> FloatArray:
        j = np.arange(self.counts[i])
        return self.start[i] + j * (self.end[i] - self.start[i]) / (self.counts[i] - 1)

    @property
    def size(self) -> int:
        return int(np.prod(self.counts))

    def rows(self, first: int, count: int) -> FloatArray:
        """Configurations first .. first + count - 1 of the grid (the last joint fastest)."""
        idx = np.unravel_index(np.arange(first, min(first + count, self.size)), self.counts)
        return np.stack([self.values(i)[k] for i, k in enumerate(idx)], axis=1)


@dataclass(frozen=True, slots=True, eq=False)
class TableIk:
    """The collision-free rows of a joint grid: configurations q (K, n) and their points x (K, d)."""

    q: FloatArray
    x: FloatArray
    grid_size: int                    # rows before collision filtering
    tree: cKDTree = field(repr=False)

    def __len__(self) -> int:
        return len(self.q)

    def lookup(self, targets: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(configurations (m, n), errors (m,)) of the stored points nearest each target (m, d)."""
        t = np.atleast_2d(np.asarray(targets, dtype=float))
        dist, idx = self.tree.query(t, k=1)
        return self.q[idx], np.asarray(dist, dtype=float)

    def nearest(self, target: FloatArray) -> tuple[FloatArray, float]:
        """(configuration (n,), error) of the stored point nearest one target (d,): a compiled scan
        of every stored point for tables up to SCAN_MAX_VALUES numbers (no per-call k-d tree set-up,
        which costs more than the scan there), else the k-d tree."""
        x = np.asarray(target, dtype=float)
        if self.x.size <= SCAN_MAX_VALUES:
            i, d = _scan_nearest(self.x, x)
        else:
            d, i = self.tree.query(x, k=1)
        return self.q[int(i)], float(d)


def build_table(grid: JointGrid, forward: Forward, free: FreeTest) -> TableIk:
    """The table of a grid: forward kinematics of every row, the rows in collision dropped;
    ValueError when none is left."""
    qs, xs = [], []
    for first in range(0, grid.size, BATCH):
        rows = grid.rows(first, BATCH)
        keep = np.asarray(free(rows), dtype=bool)
        qs.append(rows[keep])
        xs.append(np.asarray(forward(rows[keep]), dtype=float))
    q, x = np.concatenate(qs), np.concatenate(xs)
    if not len(q):
        # A table without rows answers no lookup; say so here rather than on the first one.
        raise ValueError(f"every one of the grid's {grid.size} rows is in collision")
    return TableIk(q, x, grid.size, cKDTree(x))


@dataclass(frozen=True, slots=True, eq=False)
class KnnGraph:
    """The undirected k-nearest-neighbour graph of stored points: each point joined to its k
    nearest others (so a node may have more than k edges, never fewer), every edge once, a < b,
    its length the distance between the points (point units; zero lengths raised to the smallest
    positive float, for a graph library that reads 0 as no edge)."""

    a: IntArray
    b: IntArray
    length: FloatArray
    n: int


def knn_graph(x: FloatArray, k: int, tree: cKDTree | None = None) -> KnnGraph:
    """The k-NN graph (`KnnGraph`) of points x (m, d); k >= 3 as the paper asks."""
    if k < 3:
        raise ValueError(f"k must be at least 3, got {k}")
    x = np.asarray(x, dtype=float)
    n = len(x)
    kk = min(k + 1, n)
    dist, idx = (tree if tree is not None else cKDTree(x)).query(x, k=kk)
    src = np.repeat(np.arange(n), kk - 1)
    dst = np.asarray(idx)[:, 1:].reshape(-1)
    w = np.maximum(np.asarray(dist)[:, 1:].reshape(-1), np.finfo(float).tiny)
    lo, hi = np.minimum(src, dst), np.maximum(src, dst)
    keep = lo != hi
    key = lo[keep].astype(np.int64) * n + hi[keep]
    _, first = np.unique(key, return_index=True)
    return KnnGraph(lo[keep][first], hi[keep][first], w[keep][first], n)


RouteStatus = Literal["found", "no_route", "too_many_blocked"]


@dataclass(frozen=True, slots=True)
class TableRoute:
    """A route over the k-NN graph: `status` "found" (nodes from the start's to the goal's,
    indices into the table), "no_route" (the graph, less its blocked edges, does not join them) or
    "too_many_blocked" (max_blocked edges found blocked); the edge checks spent, the route's length
    (point units) and the edges found blocked (a < b), dropped from the graph."""

    status: RouteStatus
    nodes: tuple[int, ...] = ()
    edge_checks: int = 0
    length: float = math.inf
    blocked: tuple[tuple[int, int], ...] = ()

    @property
    def found(self) -> bool:
        return self.status == "found"


def route(table: TableIk, start: int, goal: int, k: int, edge_free: Callable[[FloatArray, FloatArray], bool],
          max_blocked: int = 200) -> TableRoute:
    """Dijkstra (scipy) over the k-nearest-neighbour graph of the stored points (k >= 3), lengths in
    the point space; an edge is checked (`edge_free` of its two configurations, in the direction
    the route takes it) only when a shortest route uses it, and a blocked one is dropped and the
    search repeated (lazily)."""
    graph = knn_graph(table.x, k, table.tree)
    n = graph.n
    # The graph is built once; a blocked edge's length becomes infinite (never on a shortest route).
    order = csr_matrix((np.arange(1, len(graph.a) + 1, dtype=float), (graph.a, graph.b)), shape=(n, n))
    edge_of = order.data.astype(np.int64) - 1
    position = np.empty(len(graph.a), dtype=np.int64)
    position[edge_of] = np.arange(len(edge_of))
    csr = order.copy()
    csr.data = graph.length[edge_of]
    keys = graph.a * n + graph.b                  # sorted: knn_graph orders its edges by (a, b)
    known: dict[int, bool] = {}
    blocked: list[tuple[int, int]] = []
    checks = 0
    while True:
        d, pred = dijkstra(csr, directed=False, indices=start, return_predecessors=True)
        if not math.isfinite(d[goal]):
            return TableRoute("no_route", (), checks, math.inf, tuple(blocked))
        path = [goal]
        while path[-1] != start:
            path.append(int(pred[path[-1]]))
        path.reverse()
        clear = True
        for u, v in itertools.pairwise(path):
            e = int(np.searchsorted(keys, min(u, v) * n + max(u, v)))
            if e not in known:
                checks += 1
                known[e] = bool(edge_free(table.q[u], table.q[v]))
            if not known[e]:
                csr.data[position[e]] = np.inf
                blocked.append((min(u, v), max(u, v)))
                clear = False
                break
        if clear:
            return TableRoute("found", tuple(path), checks, float(d[goal]), tuple(blocked))
        if len(blocked) >= max_blocked:
            return TableRoute("too_many_blocked", (), checks, math.inf, tuple(blocked))


def jacobian_interpolation(q0: FloatArray, p1: FloatArray, forward: Forward, jacobian: Jacobian, step: float,
                           damping: float = 1e-3) -> tuple[FloatArray, float]:
    """Joint rows from q0 moving the point on the straight line to p1 in steps of at most `step`
    (same unit as the point): q(t + dt) = q(t) + J+ (p(t + dt) - p(t)), J+ the damped least-squares
    inverse. Returns the rows and the largest distance (point units) of the point from the line."""
    q = np.asarray(q0, dtype=float).copy()
    p0 = np.asarray(forward(q[None, :]), dtype=float)[0]
    p1 = np.asarray(p1, dtype=float)
    n_steps = max(1, math.ceil(float(np.linalg.norm(p1 - p0)) / step))
    rows = [q.copy()]
    worst = 0.0
    p = p0
    for s in range(1, n_steps + 1):
        target = p0 + (p1 - p0) * (s / n_steps)
        J = np.asarray(jacobian(q), dtype=float)
        # Damped least squares: J^T (J J^T + lambda^2 I)^-1, steady near singular configurations.
        dq = J.T @ np.linalg.solve(J @ J.T + damping ** 2 * np.eye(J.shape[0]), target - p)
        q = q + dq
        rows.append(q.copy())
        p = np.asarray(forward(q[None, :]), dtype=float)[0]
        worst = max(worst, _off_line(p, p0, p1))
    return np.array(rows), worst


@dataclass(frozen=True, slots=True, eq=False)
class EdgeFollow:
    """An edge of a route followed by `jacobian_interpolation`: the joint rows (m, n) from the
    edge's first configuration towards the second's point; `arrived` when they end within the
    tolerance of the second configuration and no step turns a joint by more than the bound (the
    last row is then that configuration exactly; else the interpolation reached the point in
    another branch, not at all, or by a jump through a singular configuration); `off_line` the
    largest distance (point units) of the point from the edge's straight line."""

    rows: FloatArray
    arrived: bool
    off_line: float


def follow_edge(q_a: FloatArray, q_b: FloatArray, forward: Forward, jacobian: Jacobian, step: float,
                arrival_tol: float, max_joint_step: float = MAX_JOINT_STEP) -> EdgeFollow:
    """The edge from configuration q_a to q_b by Jacobian interpolation (formula (15) of the paper)."""
    q_b = np.asarray(q_b, dtype=float)
    rows, off_line = jacobian_interpolation(q_a, np.asarray(forward(q_b[None, :]), dtype=float)[0], forward, jacobian,
                                            step)
    arrived = float(np.max(np.abs(rows[-1] - q_b))) <= arrival_tol and \
        float(np.max(np.abs(np.diff(rows, axis=0)))) <= max_joint_step
    if arrived:
        rows[-1] = q_b
    return EdgeFollow(rows, arrived, off_line)


def _off_line(p: FloatArray, a: FloatArray, b: FloatArray) -> float:
    ab = b - a
    t = 0.0 if not ab.any() else float(np.clip((p - a) @ ab / (ab @ ab), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))
