"""Greedy shortcutting of a path: from each kept point, the farthest later one reachable straight.

Shared by the roadmap's detours, the local C-space detours, the time-aware junctions and the TCP's
voxel routes, which differ only in what "reachable" means (a swept collision check, a line through
free voxels, no new dynamic obstacle touched).
"""

from __future__ import annotations

from collections.abc import Callable


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
