"""Detours around obstacles: a lazy probabilistic roadmap of free configurations, built once per cell.

Nodes are collision-free configurations sampled (seeded) in a joint-space box around the work —
the spread of the spot candidates and home, widened by a margin — and joined to their k nearest
neighbours in a time-scaled joint metric. Edges are checked only when a shortest path wants them
(Lazy PRM): a blocked edge is removed and the search repeated. A found detour is shortened by
greedy shortcutting (join each waypoint to the farthest later one reachable in a straight free
move). Every collision check is counted.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from robomax_py._typing import FloatArray
from robomax_py.robot import JointLimits
from robomax_py.timing import ptp_time_estimate
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
            for u, row in enumerate(idx):
                for v in row[1:]:
                    self._adjacent[u].add(int(v))
                    self._adjacent[int(v)].add(u)
        # Edge weights (s, estimated) computed once, vectorised.
        self._weight: dict[tuple[int, int], float] = {}
        pairs = np.array([(u, v) for u, adj in enumerate(self._adjacent) for v in adj if u < v], dtype=np.int64)
        if len(pairs):
            w = ptp_time_estimate(self.nodes[pairs[:, 0]], self.nodes[pairs[:, 1]], limits)
            self._weight = {(int(u), int(v)): float(x) for (u, v), x in zip(pairs, w)}
        self._edge_free: dict[tuple[int, int], bool] = {}
        self.edge_checks = 0

    def __len__(self) -> int:
        return len(self.nodes)

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

        def neighbours(u: int) -> list[int]:
            if u == S:
                return start_links
            if u == G:
                return []
            out = list(self._adjacent[u])
            if u in goal_links:
                out.append(G)
            return out

        blocked = 0
        while blocked < MAX_BLOCKED_PER_QUERY:
            path = self._shortest(S, G, point, neighbours, extra_free)
            if path is None:
                return None
            bad = None
            for u, v in zip(path[:-1], path[1:]):
                key = (min(u, v), max(u, v))
                table = extra_free if u < 0 or v < 0 else self._edge_free
                known = table.get(key)
                if known is None:
                    res = self._world.check_segment(point(u), point(v))
                    checks += res.checks
                    known = table[key] = res.free
                if not known:
                    bad = key
                    break
            if bad is None:
                waypoints = np.array([point(u) for u in path])
                waypoints, used = self._shortcut(waypoints)
                checks += used
                self.edge_checks += checks
                return Detour(waypoints, _polyline_time(waypoints, self._limits), checks)
            blocked += 1
        self.edge_checks += checks
        return None

    def _shortest(self, S: int, G: int, point, neighbours, extra_free) -> list[int] | None:  # type: ignore[no-untyped-def]
        """Dijkstra on time estimates, skipping edges known to be blocked."""
        dist: dict[int, float] = {S: 0.0}
        prev: dict[int, int] = {}
        heap = [(0.0, S)]
        done: set[int] = set()
        while heap:
            d, u = heapq.heappop(heap)
            if u in done:
                continue
            if u == G:
                path = [G]
                while path[-1] != S:
                    path.append(prev[path[-1]])
                return path[::-1]
            done.add(u)
            pu = point(u)
            for v in neighbours(u):
                key = (min(u, v), max(u, v))
                table = extra_free if u < 0 or v < 0 else self._edge_free
                if table.get(key) is False:
                    continue
                w = self._weight.get(key)
                if w is None:
                    w = float(ptp_time_estimate(pu, point(v), self._limits))
                nd = d + w
                if nd < dist.get(v, np.inf):
                    dist[v] = nd
                    prev[v] = u
                    heapq.heappush(heap, (nd, v))
        return None

    def _shortcut(self, waypoints: FloatArray) -> tuple[FloatArray, int]:
        """Greedy: from each kept waypoint jump to the farthest later one reachable straight."""
        checks = 0
        kept = [0]
        i = 0
        last = len(waypoints) - 1
        while i < last:
            j = last
            while j > i + 1:
                res = self._world.check_segment(waypoints[i], waypoints[j])
                checks += res.checks
                if res.free:
                    break
                j -= 1
            kept.append(j)
            i = j
        return waypoints[kept], checks


def _polyline_time(waypoints: FloatArray, limits: JointLimits) -> float:
    return float(np.sum(ptp_time_estimate(waypoints[:-1], waypoints[1:], limits)))
