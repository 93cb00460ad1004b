"""Detours around obstacles: a lazy probabilistic roadmap of free configurations, built once per cell.

Nodes are collision-free configurations sampled (seeded) in a joint-space box around the work —
the spread of the spot candidates and home, widened by a margin — and joined to their k nearest
neighbours in a time-scaled joint metric. Edges are checked only when a shortest path wants them
(Lazy PRM): a blocked edge is removed and the search repeated. A found detour is shortened by
greedy shortcutting (join each waypoint to the farthest later one reachable in a straight free
move). Every collision check is counted.
"""

from __future__ import annotations

import copy
import itertools
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.cspace.dijkstra import shortest_path_to_any
from robomax_py.plan.shortcut import swept_shortcut
from robomax_py.robot import JointLimits
from robomax_py.timing import polyline_time_estimate, ptp_time_estimate
from robomax_py.world.collision import CollisionWorld

# Sampling box margin around the work's joint-space spread, rad (or m), per joint.
BOX_MARGIN = 0.6
# Share of samples drawn near the anchors (Gaussian, this sigma per joint) rather than uniformly:
# detours leave and rejoin the work, where uniform samples in a 6-D box are sparse.
NEAR_FRACTION = 0.5
NEAR_SIGMA = 0.25
# Lazy search gives up after this many blocked edges in one query.
MAX_BLOCKED_PER_QUERY = 60


@dataclass(frozen=True, slots=True)
class Detour:
    """A collision-free joint path from start to goal: waypoints (m, n) including both ends."""

    waypoints: FloatArray
    time_estimate: float          # s, stopping at every waypoint (an upper bound for blended timing)
    checks: int                   # collision checks this query spent (roadmap sampling not included)
    # A detour of straight TCP lines (`plan.tcp_detour`): the TCP pose at every waypoint (m, 4, 4),
    # robot base frame; the moves between waypoints are then lines, not joint moves. None: joint moves.
    poses: FloatArray | None = None

    def reversed(self) -> Detour:
        """The same detour travelled the other way."""
        poses = None if self.poses is None else self.poses[::-1].copy()
        return Detour(self.waypoints[::-1].copy(), self.time_estimate, self.checks, poses)


class Roadmap:
    """A lazily checked k-nearest-neighbour roadmap over free configurations (not thread-safe)."""

    def __init__(
        self,
        world: CollisionWorld,
        limits: JointLimits,
        anchors: FloatArray,
        rng: np.random.Generator,
        n_nodes: int = 800,
        k: int = 12,
        max_samples: int = 40000,
        seeds: FloatArray | None = None,
    ) -> None:
        """Sample `n_nodes` free configurations in the box spanned by `anchors` (+ margin).

        anchors : (a, n) float — configurations the detours will connect (candidates, home).
        seeds : (s, n) float, optional — known free configurations added as nodes as well (the
            spot candidates: they give the graph nodes right where detours start and end).
        """
        self._world = world
        self._limits = limits
        self._k = k
        lo = np.maximum(np.min(anchors, axis=0) - BOX_MARGIN, limits.lower)
        hi = np.minimum(np.max(anchors, axis=0) + BOX_MARGIN, limits.upper)
        self.sampling_checks = 0
        nodes: list[FloatArray] = []
        anchors = np.asarray(anchors, dtype=float)
        while len(nodes) < n_nodes and self.sampling_checks < max_samples:
            uniform = rng.uniform(lo, hi, size=(256, len(lo)))
            near = anchors[rng.integers(len(anchors), size=256)] + rng.normal(0.0, NEAR_SIGMA, size=(256, len(lo)))
            batch = np.where((rng.random(256) < NEAR_FRACTION)[:, None], np.clip(near, lo, hi), uniform)
            free = world.are_free(batch)
            self.sampling_checks += len(batch)
            nodes.extend(batch[free])
        sampled = np.array(nodes[:n_nodes]).reshape(-1, len(lo))
        self.nodes = sampled if seeds is None else np.vstack([sampled, np.asarray(seeds, dtype=float)])
        # Time-scaled coordinates: Euclidean distance ~ joint-time at full speed.
        self._scale = 1.0 / np.asarray(limits.velocity)
        self._tree = cKDTree(self.nodes * self._scale) if len(self.nodes) else None
        self._adjacent: list[set[int]] = [set() for _ in range(len(self.nodes))]
        if self._tree is not None and len(self.nodes) > 1:
            kk = min(k + 1, len(self.nodes))
            _, idx = self._tree.query(self.nodes * self._scale, k=kk)
            for u, row in enumerate(idx.tolist()):          # Python ints: numpy's cost a call each
                for v in row[1:]:
                    self._adjacent[u].add(v)
                    self._adjacent[v].add(u)
        # Edge weights (s, estimated) computed once, vectorised.
        pairs = np.array([(u, v) for u, adj in enumerate(self._adjacent) for v in adj if u < v], dtype=np.int64)
        self._pairs = pairs.reshape(-1, 2)
        self._pair_weight = np.zeros(len(self._pairs))
        if len(pairs):
            self._pair_weight = np.asarray(ptp_time_estimate(self.nodes[pairs[:, 0]], self.nodes[pairs[:, 1]], limits),
                                           dtype=float)
        self._edge_index = {(u, v): e for e, (u, v) in enumerate(self._pairs.tolist())}
        self._edge_blocked = np.zeros(len(self._pairs), dtype=bool)
        self._edge_free: dict[tuple[int, int], bool] = {}
        # Every edge's check result, shared with `fresh` copies (which do not know them yet).
        self._checked: dict[tuple[int, int], bool] = {}
        self.edge_checks = 0
        self._csr: tuple[IntArray, IntArray, FloatArray, IntArray] | None = None   # `_both_ways`
        self._search: tuple[FloatArray, IntArray, IntArray] | None = None         # `_search_arrays`

    def fresh(self) -> Roadmap:
        """This roadmap as it was built, before any edge was known: its queries find what a new
        roadmap's would (a query gives up after MAX_BLOCKED_PER_QUERY blocked edges it meets, so what
        is known changes what is found). Edges checked by either are not checked again."""
        other = copy.copy(self)
        other._edge_blocked = np.zeros(len(self._pairs), dtype=bool)
        other._edge_free = {}
        other._search = None
        other.edge_checks = 0
        return other

    def __len__(self) -> int:
        return len(self.nodes)

    def neighbours(self, u: int) -> list[tuple[int, float]]:
        """(v, estimated move time s) of node u's edges, blocked ones included (`edge_free` says)."""
        return [(v, float(self._pair_weight[self._edge_index[(min(u, v), max(u, v))]])) for v in sorted(self._adjacent[u])
                if v != u]

    def edge_free(self, u: int, v: int) -> bool:
        """Is the straight move between nodes u and v free? Checked once, shared with `query`."""
        free, used = self._edge(u, v)
        self.edge_checks += used
        return free

    def _edge(self, u: int, v: int) -> tuple[bool, int]:
        """Whether the edge between nodes u and v is free (checked once, a blocked one dropped from
        the graph), and the collision checks this call took."""
        key = (min(u, v), max(u, v))
        known = self._edge_free.get(key)
        if known is not None:
            return known, 0
        checked = self._checked.get(key)
        used = 0
        if checked is None:
            res = self._world.check_segment(self.nodes[u], self.nodes[v])
            checked = self._checked[key] = res.free
            used = res.checks
        self._edge_free[key] = checked
        if not checked:
            self._edge_blocked[self._edge_index[key]] = True
        return checked, used

    def nearest(self, q: FloatArray, k: int | None = None) -> list[int]:
        """The k (default: the roadmap's k) nodes nearest q in the time-scaled metric."""
        if self._tree is None:
            return []
        kk = min(k or self._k, len(self.nodes))
        return [int(v) for v in np.atleast_1d(self._tree.query(np.asarray(q) * self._scale, k=kk)[1])]

    def query(self, q_start: FloatArray, q_goal: FloatArray) -> Detour | None:
        """A free path from q_start to q_goal through the roadmap, shortcut; None if none is found."""
        checks = 0
        if self._tree is None:
            return None
        kk = min(self._k, len(self.nodes))
        start_links = [int(v) for v in np.atleast_1d(self._tree.query(q_start * self._scale, k=kk)[1])]
        goal_links = [int(v) for v in np.atleast_1d(self._tree.query(q_goal * self._scale, k=kk)[1])]
        S, G = -1, -2
        extra_free: dict[tuple[int, int], bool] = {}

        def point(u: int) -> FloatArray:
            return q_start if u == S else (q_goal if u == G else self.nodes[u])

        blocked = 0
        start_w = ptp_time_estimate(q_start[None, :], self.nodes[start_links], self._limits)
        goal_w = ptp_time_estimate(self.nodes[goal_links], q_goal[None, :], self._limits)
        while blocked < MAX_BLOCKED_PER_QUERY:
            path = self._shortest(start_links, start_w, goal_links, goal_w, extra_free)
            if path is None:
                return None
            bad = None
            known: bool | None
            for u, v in itertools.pairwise(path):
                key = (min(u, v), max(u, v))
                if u >= 0 and v >= 0:
                    known, used = self._edge(u, v)
                    checks += used
                elif (known := extra_free.get(key)) is None:
                    res = self._world.check_segment(point(u), point(v))
                    checks += res.checks
                    known = extra_free[key] = res.free
                if not known:
                    bad = key
                    break
            if bad is None:
                waypoints = np.array([point(u) for u in path])
                waypoints, used = self._shortcut(waypoints)
                checks += used
                self.edge_checks += checks
                return Detour(waypoints, polyline_time_estimate(waypoints, self._limits), checks)
            blocked += 1
        self.edge_checks += checks
        return None

    def _shortest(self, start_links: list[int], start_w: FloatArray, goal_links: list[int], goal_w: FloatArray,
                  extra_free: dict[tuple[int, int], bool]) -> list[int] | None:
        """Dijkstra (compiled, `cspace.dijkstra.shortest_path_to_any`) on time estimates from the
        start S = -1 through the roadmap to the goal G = -2, skipping edges known to be blocked;
        the path as node indices, S and G included (None: no way).

        The roadmap holds every spot candidate as a node (tens of thousands on a large cell), and a
        lazy query searches again after each blocked edge it meets: the graph's arrays are made
        once (`_both_ways`), a blocked edge weighs infinity (never taken), the start is one row
        appended, and the goal is reached through whichever of its links ends the shortest way (no
        node of its own). The search stops once no node nearer than the best way found so far is
        left, instead of settling every node of the roadmap for a detour between two neighbouring
        spots (scipy's `dijkstra` did, bounded by a reach it grew until the way fitted; 2.8 s of a
        240-spot clamped cell's plan).
        """
        n = len(self.nodes)
        slots = self._both_ways()[3]
        data, indices, indptr = self._search_arrays(len(start_links))
        # Blocked edges weigh infinity (idempotent: an edge once blocked stays blocked).
        blocked = np.flatnonzero(self._edge_blocked)
        data[slots[blocked]] = np.inf
        data[slots[blocked + len(self._pairs)]] = np.inf

        def usable(links: list[int], label: int) -> BoolArray:
            return np.array([extra_free.get((min(label, v), max(label, v))) is not False for v in links], dtype=bool)

        s_ok = usable(start_links, -1)
        s_links = np.asarray(start_links, dtype=np.int64)[s_ok]
        # The roadmap's own edges weigh at least the least positive float (`_both_ways`); the
        # start's links alike, so that every edge of the search has a positive weight.
        s_w = np.maximum(np.asarray(start_w, dtype=float)[s_ok], np.finfo(float).tiny)
        # The start's row overwrites the end of the buffers.
        edges = int(indptr[n])
        end = edges + len(s_links)
        data[edges:end] = s_w
        indices[edges:end] = s_links
        indptr[n + 1] = end
        if not goal_links:
            return None
        goal_at = np.asarray(goal_links, dtype=np.int64)
        cost = np.where(usable(goal_links, -2), np.asarray(goal_w, dtype=float), np.inf)
        found = shortest_path_to_any(indptr, indices[:end], data[:end], n, goal_at, cost)
        if not len(found):
            return None
        return [-1 if u == n else int(u) for u in found] + [-2]

    def _both_ways(self) -> tuple[IntArray, IntArray, FloatArray, IntArray]:
        """The roadmap's edges stored both ways as CSR arrays of its n rows (the start's row is
        appended by `_shortest`): indptr (n + 1,), indices, weights, and where each direction of edge e is stored
        (slots[e] from the lower node, slots[e + edges] from the higher). Made once per roadmap."""
        if self._csr is None:
            n, m = len(self.nodes), len(self._pairs)
            rows = np.concatenate([self._pairs[:, 0], self._pairs[:, 1]])
            cols = np.concatenate([self._pairs[:, 1], self._pairs[:, 0]])
            order = np.lexsort((cols, rows))
            slots = np.empty(2 * m, dtype=np.int64)
            slots[order] = np.arange(2 * m)
            indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=n))]).astype(np.int64)
            weight = np.maximum(np.concatenate([self._pair_weight, self._pair_weight]), np.finfo(float).tiny)
            self._csr = (indptr, cols[order].astype(np.int64), weight[order], slots)
        return self._csr

    def _search_arrays(self, room: int) -> tuple[FloatArray, IntArray, IntArray]:
        """This roadmap's graph for `_shortest` in buffers kept between its searches: data (its
        blocked edges at infinity) and indices with room for a start row of `room` links after the
        edges, indptr (n + 2,). Made once per roadmap and per `fresh` copy (whose blocked edges
        differ)."""
        edges = len(self._both_ways()[2])
        if self._search is None or len(self._search[0]) < edges + room:
            indptr, indices, weights, _ = self._both_ways()
            n, room = len(self.nodes), max(room, self._k)
            data = np.empty(edges + room)
            data[:edges] = weights
            idx = np.empty(edges + room, dtype=np.int64)
            idx[:edges] = indices
            ptr = np.empty(n + 2, dtype=np.int64)
            ptr[:n + 1] = indptr
            self._search = (data, idx, ptr)
        return self._search

    def _shortcut(self, waypoints: FloatArray) -> tuple[FloatArray, int]:
        """Greedy (`swept_shortcut`): each kept waypoint joined to the farthest later one reachable
        straight; the collision checks it took."""
        kept, checks = swept_shortcut(self._world, waypoints)
        assert kept is not None                       # neighbours are not checked: always a path
        return kept, checks

