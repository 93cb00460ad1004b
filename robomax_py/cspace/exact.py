"""The exact configuration-space map: every grid cell checked by the collision world.

Two masks over the same grid: cells where the robot or its tool is within the clearance of a cell
object, and cells where it touches itself. The learned model (cspace.learned) predicts the first; the
second depends on the robot, tool and wrist alone. Cells are checked in blocks, optionally in
several processes (forked, each with its own copy of the world's scratch); the answer is the same
for any number of processes.
"""

from __future__ import annotations

import itertools
import multiprocessing
import os
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np

from robomax_py._typing import BoolArray
from robomax_py.cspace.grid import CSpaceGrid
from robomax_py.world.collision import CollisionWorld

BLOCK = 8192                  # configurations per are_free call


@dataclass(frozen=True, slots=True)
class CSpaceMap:
    """A map over a CSpaceGrid: blocked cells (r, r, r) by obstacles and by the robot itself."""

    grid: CSpaceGrid
    obstacle: BoolArray
    self_contact: BoolArray
    method: Literal["exact", "learned"]
    cpu_seconds: float           # summed over the processes that built it
    wall_seconds: float
    checks: int                  # configurations checked exactly

    @property
    def blocked(self) -> BoolArray:
        return self.obstacle | self.self_contact


# The world a forked worker inherits (set just before the pool starts, read only by the workers).
_SHARED: dict[str, object] = {}


def _check_range(args: tuple[int, int]) -> tuple[bytes, bytes, float]:
    start, stop = args
    t0 = time.process_time()
    grid: CSpaceGrid = _SHARED["grid"]  # type: ignore[assignment]
    obstacles: CollisionWorld = _SHARED["obstacles"]  # type: ignore[assignment]
    itself: CollisionWorld = _SHARED["self"]  # type: ignore[assignment]
    obstacles, itself = obstacles.copy(), itself.copy()   # own scratch in this process
    hit_obs = np.zeros(stop - start, dtype=bool)
    hit_self = np.zeros(stop - start, dtype=bool)
    for a in range(start, stop, BLOCK):
        b = min(a + BLOCK, stop)
        qs = grid.configs(a, b)
        hit_obs[a - start:b - start] = ~obstacles.are_free(qs)
        hit_self[a - start:b - start] = ~itself.are_free(qs)
    return hit_obs.tobytes(), hit_self.tobytes(), time.process_time() - t0


def exact_map(world: CollisionWorld, grid: CSpaceGrid, workers: int = 1) -> CSpaceMap:
    """Check every cell of `grid` in `world` (its clearance applies to obstacles; every dynamic
    obstacle counts as present), split over `workers` processes (1: in this process)."""
    if workers < 1:
        raise ValueError("workers must be >= 1")
    w0, c0 = time.perf_counter(), time.process_time()
    obstacles = world.restricted(obstacles=True, self_pairs=False)
    itself = world.restricted(obstacles=False, self_pairs=True)
    n = grid.size
    workers = min(workers, max(1, n // BLOCK))
    bounds = np.linspace(0, n, workers + 1).astype(int)
    ranges = [(int(a), int(b)) for a, b in itertools.pairwise(bounds)]
    _SHARED.update(grid=grid, obstacles=obstacles, self=itself)
    try:
        if workers == 1 or "fork" not in multiprocessing.get_all_start_methods():
            parts = [_check_range(r) for r in ranges]
            child_cpu = 0.0
        else:
            with multiprocessing.get_context("fork").Pool(workers) as pool:
                parts = pool.map(_check_range, ranges)
            child_cpu = sum(p[2] for p in parts)
    finally:
        _SHARED.clear()
    r = grid.resolution
    hit_obs = np.concatenate([np.frombuffer(p[0], dtype=bool) for p in parts]).reshape(r, r, r)
    hit_self = np.concatenate([np.frombuffer(p[1], dtype=bool) for p in parts]).reshape(r, r, r)
    return CSpaceMap(
        grid=grid, obstacle=hit_obs.copy(), self_contact=hit_self.copy(), method="exact",
        cpu_seconds=time.process_time() - c0 + child_cpu, wall_seconds=time.perf_counter() - w0, checks=2 * n,
    )


def default_workers() -> int:
    """The cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)
