"""Detours through a configuration-space map of A1-A3 (the published ROBOMAX way), as an alternative
or a complement to the roadmap (`planner.detours: roadmap | cspace | both`).

Between two configurations qa and qb: a grid of A1-A3 over the box they span, widened by
`MARGIN_RAD` (within the joint limits), with the wrist interpolated along the way (each cell takes
the wrist at its projection onto the straight A1-A3 line from qa to qb); every cell is checked
exactly (the exact map, with the pre-filter: a 24³ grid costs ~14,000 checks); the shortest
26-connected path of free cells in a time metric (Dijkstra, scipy) joins the cells nearest qa and
qb; it is shortened greedily and every segment of the result, qa and qb included, is checked
exactly by the swept check before the detour is offered. A learned map is not used here: it holds
for one fixed wrist, and training one per detour (minutes) costs far more than the exact local map;
`planner.detours: learned` searches one learned map per plan instead (`plan.learned_detour`).
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from robomax_py._typing import FloatArray
from robomax_py.cspace.grid import nearest_cell
from robomax_py.plan.roadmap import Detour
from robomax_py.plan.shortcut import swept_shortcut
from robomax_py.robot import JointLimits
from robomax_py.timing import polyline_time_estimate, ptp_time_estimate
from robomax_py.world.collision import CollisionWorld

RESOLUTION = 24             # samples per axis of the local grid
MARGIN_RAD = 0.5            # the grid box beyond qa and qb on A1-A3
_STEPS = np.array([d for d in itertools.product((-1, 0, 1), repeat=3) if d != (0, 0, 0)], dtype=np.int64)


def grid_detour(world: CollisionWorld, limits: JointLimits, qa: FloatArray, qb: FloatArray,
                resolution: int = RESOLUTION, margin: float = MARGIN_RAD) -> tuple[Detour | None, int]:
    """A swept-checked detour from qa to qb through the local A1-A3 map (None when the map has no
    free way or its path does not survive the swept check), and the collision checks spent."""
    qa, qb = np.asarray(qa, dtype=float), np.asarray(qb, dtype=float)
    axes, configs = local_grid(qa, qb, limits.lower, limits.upper, resolution, margin)
    start, goal = (nearest_cell(axes, q) for q in (qa, qb))
    r = resolution

    def flat(ijk: tuple[int, ...]) -> int:
        return (ijk[0] * r + ijk[1]) * r + ijk[2]

    # The cells the path starts and ends in first: next to a clamp one of them is often blocked
    # (a third of the searches on a 240-spot clamped cell), and then the map has no way whatever
    # the other cells hold.
    ends = world.are_free(configs[[flat(start), flat(goal)]])
    if not ends.all():
        return None, len(ends)
    free = world.are_free(configs)
    checks = len(ends) + len(configs)
    # Edges between free neighbouring cells, weighted by the straight move's time estimate.
    idx = np.arange(r ** 3).reshape(r, r, r)
    src, dst = [], []
    for step in _STEPS:
        a = idx[tuple(slice(max(0, -s), r - max(0, s)) for s in step)]
        b = idx[tuple(slice(max(0, s), r - max(0, -s)) for s in step)]
        ok = free[a.ravel()] & free[b.ravel()]
        src.append(a.ravel()[ok])
        dst.append(b.ravel()[ok])
    src_a, dst_a = np.concatenate(src), np.concatenate(dst)
    weight = ptp_time_estimate(configs[src_a], configs[dst_a], limits) + 1e-9
    graph = coo_matrix((weight, (src_a, dst_a)), shape=(r ** 3, r ** 3)).tocsr()
    dist, pred = dijkstra(graph, directed=True, indices=flat(start), return_predecessors=True)
    if not np.isfinite(dist[flat(goal)]):
        return None, checks
    path = [flat(goal)]
    while path[-1] != flat(start):
        path.append(int(pred[path[-1]]))
    waypoints = np.vstack([qa, configs[path[::-1]], qb])
    # The map checked only cell centres: every consecutive pair is checked too.
    short, spent = swept_shortcut(world, waypoints, check_neighbours=True)
    checks += spent
    if short is None:
        return None, checks
    return Detour(short, polyline_time_estimate(short, limits), checks), checks


def local_grid(qa: FloatArray, qb: FloatArray, lower: FloatArray, upper: FloatArray, resolution: int,
               margin: float) -> tuple[list[FloatArray], FloatArray]:
    """The A1-A3 sample values over the box qa and qb span, widened by `margin` within the limits,
    and every cell's configuration (C order) with the wrist at the cell's projection onto the
    straight A1-A3 line from qa to qb."""
    lo = np.maximum(np.minimum(qa[:3], qb[:3]) - margin, np.asarray(lower)[:3])
    hi = np.minimum(np.maximum(qa[:3], qb[:3]) + margin, np.asarray(upper)[:3])
    axes = [np.linspace(lo[k], hi[k], resolution) for k in range(3)]
    cells = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    span = qb[:3] - qa[:3]
    denom = float(span @ span)
    frac = np.clip((cells - qa[:3]) @ span / denom, 0.0, 1.0) if denom > 1e-12 else np.zeros(len(cells))
    return axes, np.hstack([cells, qa[3:] + frac[:, None] * (qb[3:] - qa[3:])])
