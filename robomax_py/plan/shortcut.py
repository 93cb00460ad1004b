"""Greedy shortcutting of a path: from each kept point, the farthest later one reachable straight.

Shared by the roadmap's detours, the local C-space detours, the time-aware junctions and the TCP's
voxel routes, which differ only in what "reachable" means (a swept collision check, a line through
free voxels, no new dynamic obstacle touched).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from robomax_py._typing import FloatArray
    from robomax_py.world.collision import CollisionWorld


def greedy_shortcut(n: int, reachable: Callable[[int, int], bool], *, check_neighbours: bool = False) -> list[int] | None:
    """Indices of the points kept of a path of n points, first and last included.

    From each kept point i the later points are tried from the last back, and the first j with
    `reachable(i, j)` is kept. Neighbours (j = i + 1) are taken as reachable unless
    `check_neighbours`; then a neighbour that is not makes the answer None.
    """
    kept = [0]
    i = 0
    while i < n - 1:
        j = n - 1
        while j > i + 1 and not reachable(i, j):
            j -= 1
        if j == i + 1 and check_neighbours and not reachable(i, j):
            return None
        kept.append(j)
        i = j
    return kept


def swept_shortcut(world: CollisionWorld, waypoints: FloatArray, *,
                   check_neighbours: bool = False) -> tuple[FloatArray | None, int]:
    """A joint-space path shortened greedily by swept collision checks (each kept waypoint joined
    to the farthest later one a free swept move reaches), and the checks spent. Consecutive
    waypoints are taken as free unless `check_neighbours`; then a blocked pair gives None."""
    checks = 0

    def free(i: int, j: int) -> bool:
        nonlocal checks
        res = world.check_segment(waypoints[i], waypoints[j])
        checks += res.checks
        return res.free

    keep = greedy_shortcut(len(waypoints), free, check_neighbours=check_neighbours)
    return (None if keep is None else waypoints[keep]), checks
