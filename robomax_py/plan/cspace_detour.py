"""Detours through a configuration-space map of A1-A3 (the published ROBOMAX way), as an alternative
or a complement to the roadmap (`planner.detours: roadmap | cspace | both`).

Between two configurations qa and qb: a grid of A1-A3 over the box they span, widened by
`MARGIN_RAD` (within the joint limits), with the wrist interpolated along the way (each cell takes
the wrist at its projection onto the straight A1-A3 line from qa to qb); the shortest 26-connected
path of free cells in a time metric (Dijkstra, `cspace.dijkstra`) joins the cells nearest qa and
qb. The cells round each end are checked first: an end walled in there (an approach point in a
pocket of the part) ends the search before the rest of the map is checked. The others are checked
exactly (with the pre-filter) where the search's paths pass, not all 24³ of them: the path found
is the one the fully checked map gives (`_repaired_path`). The published method
finds its path over the map's nodes alone (Pashkevich & Kozhevnikov, the A1-A3 map of ROBOMAX) and
tests the program afterwards; here every consecutive segment of the path, qa and qb included, is
checked exactly by the swept check, a blocked move between two free cells is removed from the
map's graph and the map searched again (the lazy way of Lazy PRM, Bohlin & Kavraki, ICRA 2000;
bounded), and the path whose segments are all free is shortened greedily by the swept check
before the detour is offered. A learned map is not used here: it holds for one fixed wrist, and
training one per detour (minutes) costs far more than the exact local map; `planner.detours:
learned` searches one learned map per plan instead (`plan.learned_detour`).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.cspace.dijkstra import shortest_path
from robomax_py.cspace.grid import (
    nearest_cell,
    neighbour_graph,
    neighbour_moves,
    reverse_moves,
)
from robomax_py.plan.roadmap import Detour
from robomax_py.plan.shortcut import swept_shortcut
from robomax_py.robot import JointLimits
from robomax_py.timing import polyline_time_estimate, ptp_time_estimate
from robomax_py.world.collision import CollisionWorld

RESOLUTION = 24             # samples per axis of the local grid
MARGIN_RAD = 0.5            # the grid box beyond qa and qb on A1-A3
# Repairing the map's path (`_repaired_path`): at most MAX_REPAIR_ROUNDS searches of the map, and
# swept checks of its paths' segments worth at most REPAIR_BUDGET times the map's own point checks
# (the checks are the cost: a search of the 24³ map takes ~1-2 ms CPU, 64 of them ~0.1 s). Measured:
# the detours found on generated UR10 and KR16 cells needed up to 23 searches and 1.5x the map's
# checks, the one between s5 and s6 of the reference cell (tests/bench/bench_plan.py) 46 searches;
# past the bounds a narrow passage the map's samples straddle is more likely than a way through.
MAX_REPAIR_ROUNDS = 64
REPAIR_BUDGET = 2.0
# The grid box keeps this far inside the joint limits: the timed motion through the map's cells is
# a smooth path that overshoots a cell lying on a limit (by 1e-6 rad on a generated IRB 2400-class
# cell, whose repaired detour ran along A3's upper limit and could not be timed), and the timing
# refuses any sample past a limit. 1e-3 rad is a thousand times that and 2 % of a 24-cell step.
LIMIT_INSET_RAD = 1e-3
# Before the rest of the map, the cells within this many steps of each end are checked (a box of
# 9³ of the 24³ cells, checked once either way): where the free cells joined to an end there stay
# inside that box, the end is walled in and the map has no way whatever the rest holds. On a
# generated KR 16 bracket cell (corpus c114, an approach point in a pocket of the part) 8 of the 21
# maps without a way were so, the end's free cells 3 to 9 of them; 2 steps told 1 of the 8, 4 all.
ENCLOSURE_STEPS = 4
# Searches of the map through cells not checked yet (`_repaired_path`), each checking the cells
# round its path, before the cells left are all checked at once.
LAZY_ROUNDS = 8


def grid_detour(world: CollisionWorld, limits: JointLimits, qa: FloatArray, qb: FloatArray,
                resolution: int = RESOLUTION, margin: float = MARGIN_RAD) -> tuple[Detour | None, int]:
    """A swept-checked detour from qa to qb through the local A1-A3 map (None when the map has no
    free way whose segments all pass the swept check within the repair bounds), and the collision
    checks spent."""
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
    checked = np.zeros(r ** 3, dtype=bool)
    free = np.zeros(r ** 3, dtype=bool)
    checked[[flat(start), flat(goal)]] = free[[flat(start), flat(goal)]] = True
    checks = len(ends)
    # Then the cells round each end (ENCLOSURE_STEPS): an end walled in there has no way out.
    for end, other in ((start, goal), (goal, start)):
        box = tuple(slice(max(0, e - ENCLOSURE_STEPS), min(r, e + ENCLOSURE_STEPS + 1)) for e in end)
        near = np.arange(r ** 3).reshape(r, r, r)[box].ravel()
        near = near[~checked[near]]
        free[near] = world.are_free(configs[near])
        checked[near] = True
        checks += len(near)
        if _walled_in(free.reshape(r, r, r), box, end, other, r):
            return None, checks
    # The rest of the map is checked where a way is looked for (`_repaired_path`): its shortest
    # way through free cells costs the same whether every cell was checked first or not.
    weight = move_times(configs, (r, r, r), limits) + 1e-9
    cells = _LazyCells(world, configs, free, checked)
    path, spent = _repaired_path(world, cells, r, weight, qa, qb, flat(start), flat(goal),
                                 max_checks=int(REPAIR_BUDGET * len(configs)))
    checks += cells.checks
    checks += spent
    if path is None:
        return None, checks
    # Every consecutive pair is free by the swept check now: the shortcut takes them as they are.
    short, spent = swept_shortcut(world, path)
    checks += spent
    assert short is not None                            # without check_neighbours it keeps a path
    return Detour(short, polyline_time_estimate(short, limits), checks), checks


def move_times(configs: FloatArray, shape: tuple[int, int, int], limits: JointLimits) -> FloatArray:
    """`ptp_time_estimate` of every move of `neighbour_moves(shape)` between the cells' configurations
    (C order), the same floats. A move's estimate is its opposite's (|q1 - q0| is the same float
    either way), so each pair of opposite moves is estimated once; the configurations are gathered
    joint by joint, the layout the estimate's compiled pass reads (it then copies nothing)."""
    src, dst = neighbour_moves(shape)
    one, reverse = reverse_moves(shape)
    columns = configs.T
    times = ptp_time_estimate(columns[:, src[one]].T, columns[:, dst[one]].T, limits)
    out = np.empty(len(src))
    out[one] = times
    out[reverse[one]] = times
    return out


def _walled_in(free: BoolArray, box: tuple[slice, ...], end: tuple[int, ...], other: tuple[int, ...], r: int) -> bool:
    """Whether the free cells 26-connected to `end` inside `box` (cells of the r x r x r map `free`,
    every one in the box checked) neither hold `other` nor reach a side of the box that lies inside
    the map: then they are all the free cells connected to `end` in the whole map, and the map has
    no way from one end to the other."""
    sub = free[box]
    src, dst = neighbour_moves(sub.shape)
    flat_free = sub.ravel()
    ok = flat_free[src] & flat_free[dst]
    links = coo_matrix((np.ones(int(ok.sum())), (src[ok], dst[ok])), shape=(sub.size, sub.size))
    _, label = connected_components(links, directed=False)
    lo = [b.start for b in box]
    region = (label == label[np.ravel_multi_index([e - l for e, l in zip(end, lo)], sub.shape)]).reshape(sub.shape)
    region &= sub
    if all(b.start <= o < b.stop for b, o in zip(box, other)) and region[tuple(o - l for o, l in zip(other, lo))]:
        return False
    for axis, b in enumerate(box):
        if (b.start > 0 and region.take(0, axis=axis).any()) or (b.stop < r and region.take(-1, axis=axis).any()):
            return False
    return True


class _LazyCells:
    """The map's cells and what is known of them: each is checked once, when a way through the map
    first looks at it (`check`), or all that are left at once (`check_rest`)."""

    def __init__(self, world: CollisionWorld, configs: FloatArray, free: BoolArray, checked: BoolArray) -> None:
        self.world, self.configs, self.free, self.checked = world, configs, free, checked
        self.checks = 0                          # cells checked here (the ends' were counted before)

    def blocked(self) -> BoolArray:
        return self.checked & ~self.free

    def check(self, cells: IntArray) -> bool:
        """Check those of `cells` not checked yet; whether one of them is blocked."""
        new = cells[~self.checked[cells]]
        if not new.size:
            return False
        ok = self.world.are_free(self.configs[new])
        self.free[new], self.checked[new] = ok, True
        self.checks += len(new)
        return not bool(ok.all())

    def check_rest(self) -> bool:
        return self.check(np.flatnonzero(~self.checked))


def _tube(cells: IntArray, r: int) -> IntArray:
    """`cells` of the r x r x r map and every cell one step (26-connected) from one of them."""
    ijk = np.stack(np.unravel_index(cells, (r, r, r)), axis=1)
    steps = np.stack(np.meshgrid(*([np.arange(-1, 2)] * 3), indexing="ij"), axis=-1).reshape(-1, 3)
    near = (ijk[:, None, :] + steps[None, :, :]).reshape(-1, 3)
    near = near[((near >= 0) & (near < r)).all(axis=1)]
    return np.unique(np.ravel_multi_index(tuple(near.T), (r, r, r)))


def _repaired_path(world: CollisionWorld, cells: _LazyCells, r: int, weight: FloatArray, qa: FloatArray,
                   qb: FloatArray, start: int, goal: int, max_checks: int) -> tuple[FloatArray | None, int]:
    """The map's shortest path from qa to qb whose every cell is free and every consecutive segment
    free by the swept check, and the swept checks spent: None when the map has no path left, a
    segment into or out of the map is blocked, or `MAX_REPAIR_ROUNDS` searches of paths of free
    cells or `max_checks` swept checks are spent. r: the map's samples per axis; weight: the
    time estimates of its moves, in `neighbour_moves`' order.

    Cells not checked yet are taken to be free (the lazy way of Lazy PRM, Bohlin & Kavraki, "Path
    planning using lazy PRM", ICRA 2000, for the map's cells): a path through unchecked cells has
    them checked, with the cells one step round them (`_tube`: the next path mostly runs there), and
    the map is searched again without the blocked ones. A path whose cells are all free is the
    shortest over the free cells, as the fully checked map would give it: every path of free cells
    is a path of the searched map too. After `LAZY_ROUNDS` such searches the cells left are checked
    at once, which bounds the searches on a map with no way through.

    The map checked only cell centres; a move between two free neighbouring cells can still be
    blocked (an obstacle edge between the samples). The lazy way again, for the moves: check the
    path's segments, remove the blocked ones from the graph (both directions) and search again. A
    segment's answer is kept across rounds, so a later path pays only for its new segments.
    """
    indptr, indices, order = neighbour_graph((r, r, r))
    cost = np.ascontiguousarray(weight[order])
    cut = np.zeros(len(indices), dtype=bool)          # moves found blocked by the swept check
    # (cell, cell), low first -> free by the swept check (a straight move is blocked both ways)
    known: dict[tuple[int, int], bool] = {}
    checks = rounds = lazy_rounds = 0
    while True:
        path = shortest_path(indptr, indices, cost, ~cells.blocked(), cut, start, goal).tolist()
        if not path:
            return None, checks
        on_path = np.array(path)
        if not cells.checked[on_path].all():
            lazy_rounds += 1
            found_blocked = cells.check_rest() if lazy_rounds > LAZY_ROUNDS else cells.check(_tube(on_path, r))
            if found_blocked:
                continue                              # a blocked cell on the path: search again
        rounds += 1
        waypoints = np.vstack([qa, cells.configs[path], qb])
        # The segments into and out of the map (qa -> start cell, goal cell -> qb) are not edges of
        # the graph: one blocked, no other path of the map helps.
        last = len(waypoints) - 2
        blocked = []
        for k in range(last + 1):
            key = (-1, -1) if k == 0 else (-2, -2) if k == last else \
                (min(path[k - 1], path[k]), max(path[k - 1], path[k]))
            if key not in known:
                if checks >= max_checks:
                    return None, checks
                res = world.check_segment(waypoints[k], waypoints[k + 1])
                checks += res.checks
                known[key] = res.free
            if not known[key]:
                if k in (0, last):
                    return None, checks
                blocked.append(key)
        if not blocked:
            return waypoints, checks
        if rounds >= MAX_REPAIR_ROUNDS:
            return None, checks
        for u, v in blocked:                          # both directions
            for x, y in ((u, v), (v, u)):
                cut[indptr[x] + int(np.flatnonzero(indices[indptr[x]:indptr[x + 1]] == y)[0])] = True


def local_grid(qa: FloatArray, qb: FloatArray, lower: FloatArray, upper: FloatArray, resolution: int,
               margin: float) -> tuple[list[FloatArray], FloatArray]:
    """The A1-A3 sample values over the box qa and qb span, widened by `margin` within the limits,
    and every cell's configuration (C order) with the wrist at the cell's projection onto the
    straight A1-A3 line from qa to qb."""
    lo = np.maximum(np.minimum(qa[:3], qb[:3]) - margin, np.asarray(lower)[:3] + LIMIT_INSET_RAD)
    hi = np.minimum(np.maximum(qa[:3], qb[:3]) + margin, np.asarray(upper)[:3] - LIMIT_INSET_RAD)
    axes = [np.linspace(lo[k], hi[k], resolution) for k in range(3)]
    cells = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    span = qb[:3] - qa[:3]
    denom = float(span @ span)
    frac = np.clip((cells - qa[:3]) @ span / denom, 0.0, 1.0) if denom > 1e-12 else np.zeros(len(cells))
    return axes, np.hstack([cells, qa[3:] + frac[:, None] * (qb[3:] - qa[3:])])
