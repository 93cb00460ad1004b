"""plan.roadmap: lazy PRM queries on a joint space with a ball-shaped obstacle.

The world is a stand-in: a configuration is blocked inside a ball of radius 0.5 rad about a point in
joint space; a straight move is checked at 41 states. Every detour found must be free by that rule,
and the first path the lazy search checks must be the shortest one (an independent heap Dijkstra
over the same graph and weights).
"""

from __future__ import annotations

import heapq
import itertools

import numpy as np
import pytest

from robomax_py.plan.roadmap import Roadmap
from robomax_py.robot import JointLimits
from robomax_py.timing import ptp_time_estimate
from robomax_py.world.collision import SegmentCheck

CENTRE = np.zeros(6)
RADIUS = 0.5
LIMITS = JointLimits(lower=np.full(6, -3.0), upper=np.full(6, 3.0), velocity=np.array([2.0, 2.0, 2.5, 4.0, 4.0, 5.0]),
                     acceleration=np.full(6, 8.0), jerk=np.full(6, 80.0))


class BallWorld:
    def __init__(self) -> None:
        self.segments = 0

    def are_free(self, qs: np.ndarray, t: float | None = None) -> np.ndarray:
        return np.linalg.norm(qs - CENTRE, axis=1) > RADIUS

    def check_segment(self, q0: np.ndarray, q1: np.ndarray, *args: object, **kwargs: object) -> SegmentCheck:
        self.segments += 1
        states = q0 + np.linspace(0, 1, 41)[:, None] * (q1 - q0)
        free = bool(self.are_free(states).all())
        return SegmentCheck(free, 41, 41, 0, None if free else 0.5)


def _path_free(path: np.ndarray) -> bool:
    world = BallWorld()
    return all(world.check_segment(a, b).free for a, b in itertools.pairwise(path))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_detours_avoid_the_ball(seed: int) -> None:
    rng = np.random.default_rng(seed)
    start, goal = np.full(6, -0.9), np.full(6, 0.9)
    start[1:] = rng.uniform(-0.2, 0.2, 5)
    goal[1:] = rng.uniform(-0.2, 0.2, 5)
    start[0], goal[0] = -0.9, 0.9
    world = BallWorld()
    assert not world.check_segment(start, goal).free
    roadmap = Roadmap(world, LIMITS, np.array([start, goal]), rng, n_nodes=400, k=10)  # type: ignore[arg-type]
    det = roadmap.query(start, goal)
    assert det is not None
    assert np.array_equal(det.waypoints[0], start) and np.array_equal(det.waypoints[-1], goal)
    assert _path_free(det.waypoints)


def test_first_checked_path_is_the_shortest() -> None:
    rng = np.random.default_rng(5)
    start, goal = np.full(6, -1.5), np.full(6, 1.5)
    world = BallWorld()
    roadmap = Roadmap(world, LIMITS, np.array([start, goal]), rng, n_nodes=300, k=8)  # type: ignore[arg-type]
    kk = min(8, len(roadmap.nodes))
    start_links = [int(v) for v in roadmap._tree.query(start * roadmap._scale, k=kk)[1]]
    goal_links = [int(v) for v in roadmap._tree.query(goal * roadmap._scale, k=kk)[1]]
    start_w = ptp_time_estimate(start[None], roadmap.nodes[start_links], LIMITS)
    goal_w = ptp_time_estimate(roadmap.nodes[goal_links], goal[None], LIMITS)
    path = roadmap._shortest(start_links, start_w, goal_links, goal_w, {})
    assert path is not None and path[0] == -1 and path[-1] == -2

    def point(u: int) -> np.ndarray:
        return start if u == -1 else (goal if u == -2 else roadmap.nodes[u])

    def length(p: list[int]) -> float:
        return float(sum(ptp_time_estimate(point(a), point(b), LIMITS) for a, b in itertools.pairwise(p)))

    # Reference: a plain heap Dijkstra over the same graph.
    adj: dict[int, list[tuple[int, float]]] = {-1: [(v, float(w)) for v, w in zip(start_links, start_w)]}
    for (u, v), w in zip(roadmap._pairs.tolist(), roadmap._pair_weight.tolist()):
        adj.setdefault(u, []).append((v, w))
        adj.setdefault(v, []).append((u, w))
    for v, w in zip(goal_links, goal_w):
        adj.setdefault(v, []).append((-2, float(w)))
    dist = {-1: 0.0}
    heap = [(0.0, -1)]
    while heap:
        d, u = heapq.heappop(heap)
        if d > dist.get(u, np.inf) or u == -2:
            continue
        for v, w in adj.get(u, []):
            if d + w < dist.get(v, np.inf):
                dist[v] = d + w
                heapq.heappush(heap, (d + w, v))
    assert length(path) == pytest.approx(dist[-2], rel=1e-12)


def test_a_fresh_copy_finds_what_a_new_roadmap_finds_without_checking_edges_again() -> None:
    """`Roadmap.fresh`: the published method planned beside the search starts from the roadmap as
    built. Queries that another roadmap's knowledge would change (blocked edges already dropped)
    give the same detours as a newly built roadmap, and edges checked before are not checked again."""
    start, goal = np.array([-0.9, 0.1, 0, 0, 0, 0]), np.array([0.9, -0.1, 0, 0, 0, 0])
    other_start, other_goal = np.array([0, -0.9, 0.2, 0, 0, 0]), np.array([0, 0.9, -0.2, 0, 0, 0])

    def build(world: BallWorld) -> Roadmap:
        return Roadmap(world, LIMITS, np.array([start, goal, other_start, other_goal]), np.random.default_rng(5),
                       n_nodes=300, k=8)  # type: ignore[arg-type]

    used = build(BallWorld())
    first = used.query(other_start, other_goal)
    assert first is not None
    fresh_world, new_world = BallWorld(), BallWorld()
    fresh = used.fresh()
    fresh._world = fresh_world  # type: ignore[assignment]   # count what the copy checks
    new = build(new_world)
    for a, b in ((start, goal), (other_start, other_goal)):
        got, want = fresh.query(a, b), new.query(a, b)
        assert got is not None and want is not None
        assert np.array_equal(got.waypoints, want.waypoints)
    assert fresh_world.segments < new_world.segments


def test_searches_reusing_the_graph_buffers_find_what_a_rebuilt_graph_finds() -> None:
    """`Roadmap._shortest` keeps its CSR buffers between searches, marking blocked edges and
    writing the start's row in place: after each newly blocked edge and with start rows of other
    lengths, the path is that of buffers built anew, and a `fresh` copy sees none of the blocks."""
    import copy

    rng = np.random.default_rng(7)
    start, goal = np.full(6, -1.5), np.full(6, 1.5)
    roadmap = Roadmap(BallWorld(), LIMITS, np.array([start, goal]), rng, n_nodes=300, k=8)  # type: ignore[arg-type]
    links, goal_links = roadmap.nearest(start, 8), roadmap.nearest(goal, 8)
    goal_w = ptp_time_estimate(roadmap.nodes[goal_links], goal[None], LIMITS)

    def search(rm: Roadmap, n_links: int) -> list[int] | None:
        start_w = ptp_time_estimate(start[None], rm.nodes[links[:n_links]], LIMITS)
        return rm._shortest(links[:n_links], start_w, goal_links, goal_w, {})

    first = search(roadmap, 8)
    paths = []
    for n_links in (8, 3, 8, 5, 1, 8):
        path = search(roadmap, n_links)
        rebuilt = copy.copy(roadmap)
        rebuilt._search = None
        assert path is not None and path == search(rebuilt, n_links)
        paths.append(path)
        inner = [(u, v) for u, v in itertools.pairwise(path) if u >= 0 and v >= 0]
        if inner:                                   # block the path's first roadmap edge
            roadmap._edge_blocked[roadmap._edge_index[(min(inner[0]), max(inner[0]))]] = True
    assert len({tuple(p) for p in paths}) > 2       # the blocks changed the way found
    assert search(roadmap.fresh(), 8) == first
