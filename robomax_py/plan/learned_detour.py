"""Detours searched in the learned C-space map (`planner.detours: learned`): the configuration space
synthesised by an RBF network (Pashkevich & Kozhevnikov, 2003; `cspace.learned`) used as the paper
uses it, to find the configurations of a collision-free move between two locations, from which the
program is then written.

The map
-------
One map per plan, over A1-A3 with the wrist held fixed (the model holds for one wrist):

- the wrist W is the median over the spots of the approach wrist of each spot's nominal candidate
  (nearest the nominal orientation, first IK branch), rounded to WRIST_STEP_DEG so that cells with
  alike spots share one trained model;
- the grid spans the A1-A3 box of home and every candidate's approach configuration, widened by
  BOX_MARGIN_RAD within the joint limits, `resolution` samples per axis;
- a cell is blocked where the learned model puts an object within its sphere radius (clearance +
  the points' cover radius + inflation), or where the arm touches itself (checked exactly: that
  depends on the robot and tool alone, and the paper's model is of obstacles).

A detour from qa to qb
----------------------
1. Into the map and out of it: an approach configuration lies ~30 mm from the part, where the map is
   blocked (the tips and the inflation count), so qa is joined to a free cell by a straight joint
   move (its wrist turning to W) that the exact swept check passes: free cells nearest in A1-A3
   time, ENTRY_TRIES of them at least 3 cells apart, then ENTRY_TRIES more at least 6 apart
   (ENTRY_SPREADS), so that they leave in different directions; the same at qb.
2. Dijkstra over the 26-connected free cells from the entry cell to the exit cell, each edge
   weighted by its move's time estimate.
3. Every segment of the path is checked by the exact swept check. One it refuses is the map's error:
   a cell the map calls free whose centre is not (the cell is blocked), or a gap between two free
   centres (the edge is removed); the repair is kept for the rest of the plan, counted, and the
   search repeated, at most MAX_REPAIRS times. A refused path is never offered.
4. The checked path is shortened greedily (each shortcut swept-checked) and offered as a Detour.
"""

from __future__ import annotations

import itertools
import math
import time
from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.cspace import (
    CSpaceError,
    CSpaceGrid,
    cover_radius,
    learned_map,
    learned_model,
    surface_points,
)
from robomax_py.cspace.exact import BLOCK
from robomax_py.cspace.grid import check_arm, neighbour_moves
from robomax_py.cspace.learned import COARSE_TRAINING, LearnedModel, TrainingSettings
from robomax_py.plan.candidates import SpotCandidates
from robomax_py.plan.results import LearnedMapReport
from robomax_py.plan.roadmap import Detour
from robomax_py.plan.shortcut import swept_shortcut
from robomax_py.robot import JointLimits, RobotModel
from robomax_py.spec import CellSpec, LearnedMapSpec
from robomax_py.timing import polyline_time_estimate, ptp_time_estimate
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

WRIST_STEP_DEG = 10.0       # the map's wrist is rounded to this (a model per 10 deg of wrist)
BOX_MARGIN_RAD = 0.6        # the map's A1-A3 box beyond home and every candidate
ENTRY_TRIES = 16            # free cells tried per spread as a stop's way into (or out of) the map
# Cells (Chebyshev) between two entries tried, so that they leave in different directions: first
# near the stop, then farther out. Measured on the blocked moves of the file's order of the reference
# cell, cells/cabin_flange.yaml and cells/frame.yaml (18 moves, nominal candidates, 40^3 cells): 16
# tries at (3, 6) find a detour for all 18 in the learned map and in the exact map of the same grid;
# 24 tries at 3 alone find 17 and 14, 12 tries at (3, 6) 14 and 17.
ENTRY_SPREADS = (3, 6)
ENTRY_POOL = 3000           # nearest free cells the entries are chosen from
MAX_REPAIRS = 12            # refused path segments repaired per search before it gives up
_BANNED = 1e9               # an edge's weight once the exact check refused it (no path uses it)


def training_settings(spec: LearnedMapSpec) -> TrainingSettings:
    """The model's training settings for the cell's `planner.learned`."""
    base = COARSE_TRAINING if spec.training == "coarse" else TrainingSettings()
    return replace(base, max_neurons=spec.neurons)


def map_wrist(spots: list[SpotCandidates], limits: JointLimits) -> FloatArray:
    """A4-A6 (rad) of the plan's map: the median over the spots of their nominal candidates'
    approach wrists, rounded to WRIST_STEP_DEG and kept within the limits."""
    wrists = []
    for c in spots:
        nominal = int(np.lexsort((c.column, c.orient))[0])   # orientations are ordered nearest nominal first
        wrists.append(c.q_app[nominal, 3:6])
    step = math.radians(WRIST_STEP_DEG)
    w = np.round(np.median(np.array(wrists), axis=0) / step) * step
    return np.clip(w, np.asarray(limits.lower)[3:6], np.asarray(limits.upper)[3:6])


def map_grid(home: FloatArray, spots: list[SpotCandidates], limits: JointLimits, wrist: FloatArray,
             resolution: int) -> CSpaceGrid:
    """The A1-A3 grid over the box of home and every candidate's approach configuration, widened
    by BOX_MARGIN_RAD within the limits, with the wrist fixed."""
    anchors = np.vstack([np.asarray(home)[None, :3], *[c.q_app[:, :3] for c in spots]])
    lo = np.maximum(anchors.min(axis=0) - BOX_MARGIN_RAD, np.asarray(limits.lower)[:3])
    hi = np.minimum(anchors.max(axis=0) + BOX_MARGIN_RAD, np.asarray(limits.upper)[:3])
    axes = tuple(np.linspace(lo[k], hi[k], resolution) for k in range(3))
    return CSpaceGrid(axes=axes, wrist=np.asarray(wrist, dtype=float))  # type: ignore[arg-type]


@dataclass(frozen=True, slots=True)
class MapFigures:
    """How the plan's map was made."""

    points: int                  # surface points of the cell's objects
    in_reach: int                # of them, within the model's reach (the paper's N')
    radius: float                # m, the training sphere's
    cached: bool                 # the model came from the cache
    map_cpu_seconds: float       # the learned map and the exact self-contact mask


def self_contact(world: CollisionWorld, grid: CSpaceGrid) -> BoolArray:
    """(r, r, r) bool: the cells where the arm or its tool touches itself, checked exactly."""
    itself = world.restricted(obstacles=False, self_pairs=True)
    touching = np.zeros(grid.size, dtype=bool)
    for a in range(0, grid.size, BLOCK):
        b = min(a + BLOCK, grid.size)
        touching[a:b] = ~itself.are_free(grid.configs(a, b))
    r = grid.resolution
    return touching.reshape(r, r, r)


class LearnedDetours:
    """The plan's learned map and the searches in it (see the module docstring; not thread-safe).

    `query` keeps what the exact check taught (blocked cells, removed edges) for later searches;
    `fresh` gives a map without those repairs that counts into the same report."""

    def __init__(self, grid: CSpaceGrid, obstacle: BoolArray, self_contact: BoolArray, limits: JointLimits,
                 model: LearnedModel, figures: MapFigures, counts: Counter[str] | None = None,
                 base: csr_matrix | None = None) -> None:
        self.grid, self.obstacle, self.self_contact, self.limits = grid, obstacle, self_contact, limits
        self.model, self.figures = model, figures
        self.counts: Counter[str] = Counter() if counts is None else counts
        self.configs = grid.configs(0, grid.size)
        self.free = ~(obstacle | self_contact).reshape(-1)          # this map's own copy, repairs included
        self._base = base                                            # the graph before any repair
        self._graph: csr_matrix | None = None
        self._entries: dict[tuple[int, bytes], int] = {}

    @staticmethod
    def build(cell: CellSpec, robot: RobotModel, world: CollisionWorld, spots: list[SpotCandidates],
              spec: LearnedMapSpec, folder: Path | None = None) -> LearnedDetours:
        """The plan's map: the model for the robot, tool and map wrist (from the cache, else trained
        and stored in `folder`, default `cspace.cache_dir()`), the cell's objects (dynamic ones
        left out, as the plan leaves them) as surface points, and the exact self-contact mask.
        A robot the method cannot map is a CSpaceError naming the cell's key."""
        try:
            check_arm(robot)
        except CSpaceError as exc:
            raise CSpaceError(f"{cell.source}: planner.detours: learned: {exc}") from None
        wrist = map_wrist(spots, robot.limits)
        grid = map_grid(np.asarray(cell.home), spots, robot.limits, wrist, spec.resolution)
        radius = cell.process.clearance + cover_radius(spec.spacing) + spec.inflation
        model, cached = learned_model(cell, robot, wrist, radius, training_settings(spec), folder)
        c0 = time.process_time()
        points = surface_points(build_scene(replace(cell, dynamic=()), robot), spec.spacing)
        learned = learned_map(model, points, grid)
        touching = self_contact(world, grid)
        figures = MapFigures(points=len(points), in_reach=int((model.base.coordinates(points)[0] <= model.d_max).sum()),
                             radius=radius, cached=cached, map_cpu_seconds=time.process_time() - c0)
        return LearnedDetours(grid, learned.obstacle, touching, robot.limits, model, figures)

    def fresh(self) -> LearnedDetours:
        """The same map without this one's repairs; its searches count into the same report."""
        return LearnedDetours(self.grid, self.obstacle, self.self_contact, self.limits, self.model, self.figures,
                              self.counts, self._base)

    def report(self) -> LearnedMapReport:
        m, f, n = self.model, self.figures, self.counts
        return LearnedMapReport(
            wrist=tuple(float(v) for v in self.grid.wrist), resolution=self.grid.resolution,
            blocked_by_objects=int(self.obstacle.sum()), blocked_by_itself=int((self.self_contact & ~self.obstacle).sum()),
            points=f.points, points_in_reach=f.in_reach, sphere_radius=f.radius,
            neurons=len(m.centres), weights=int(m.weights.size), training_cached=f.cached,
            training_cpu_seconds=m.train_cpu_seconds, training_checks=m.train_checks, map_cpu_seconds=f.map_cpu_seconds,
            searches=n["searches"], found=n["found"], refused_segments=n["refused_segments"],
            refused_entries=n["refused_entries"], no_entry=n["no_entry"], no_path=n["no_path"], gave_up=n["gave_up"],
        )

    # ------------------------------------------------------------------------------ searching

    def query(self, world: CollisionWorld, qa: FloatArray, qb: FloatArray) -> tuple[Detour | None, int]:
        """A detour from qa to qb through the map whose every segment the exact swept check in
        `world` passed (None when there is none), and the collision checks spent."""
        self.counts["searches"] += 1
        qa, qb = np.asarray(qa, dtype=float), np.asarray(qb, dtype=float)
        start, checks = self.entry(world, qa)
        goal, spent = self.entry(world, qb)
        checks += spent
        if start is None or goal is None:
            self.counts["no_entry"] += 1
            return None, checks
        for _ in range(MAX_REPAIRS + 1):
            cells = self.path(start, goal)
            if cells is None:
                self.counts["no_path"] += 1
                return None, checks
            refused, spent = self._refused(world, cells)
            checks += spent
            if not refused:
                break
            self.counts["refused_segments"] += 1
        else:
            self.counts["gave_up"] += 1
            return None, checks
        waypoints = np.vstack([qa, self.configs[cells], qb])
        # Consecutive waypoints are known free (each segment was checked): only shortcuts are.
        short, spent = swept_shortcut(world, waypoints)
        assert short is not None             # neighbours are not re-checked, so never None
        checks += spent
        self.counts["found"] += 1
        return Detour(short, polyline_time_estimate(short, self.limits), checks), checks

    def path(self, start: int, goal: int) -> list[int] | None:
        """Flat cells from start to goal along the shortest free way in the map, or None."""
        if start == goal:
            return [start]
        dist, pred = dijkstra(self._edges(), directed=True, indices=start, return_predecessors=True)
        if not dist[goal] < _BANNED:
            return None
        cells = [goal]
        while cells[-1] != start:
            cells.append(int(pred[cells[-1]]))
        return cells[::-1]

    def _edges(self) -> csr_matrix:
        """Moves between free neighbouring cells, weighted by their time estimates (built once per
        map and copied for each fresh one), with this map's repairs."""
        if self._graph is None:
            if self._base is None:
                self._base = self._unrepaired()
            self._graph = self._base.copy()
        return self._graph

    def _unrepaired(self) -> csr_matrix:
        """The 26-connected moves between the map's free cells (before any repair)."""
        r = self.grid.resolution
        free = ~(self.obstacle | self.self_contact).reshape(-1)
        src, dst = neighbour_moves((r, r, r))
        ok = free[src] & free[dst]
        s, d = src[ok], dst[ok]
        weight = ptp_time_estimate(self.configs[s], self.configs[d], self.limits) + 1e-9
        graph: csr_matrix = coo_matrix((weight, (s, d)), shape=(r ** 3, r ** 3)).tocsr()
        return graph

    def _ban(self, a: int, b: int) -> None:
        """No path through the move a -> b (both ways) from now on."""
        graph = self._edges()
        for u, v in ((a, b), (b, a)):
            row = slice(graph.indptr[u], graph.indptr[u + 1])
            hit = np.flatnonzero(graph.indices[row] == v)
            graph.data[row][hit] = _BANNED

    def _block(self, cell: int) -> None:
        """The cell taken out of the map: every move into and out of it banned."""
        self.free[cell] = False
        graph = self._edges()
        for v in graph.indices[graph.indptr[cell]:graph.indptr[cell + 1]].tolist():
            self._ban(cell, int(v))

    def _refused(self, world: CollisionWorld, cells: list[int]) -> tuple[bool, int]:
        """Whether the exact check refuses a segment of the path, the first one repaired (its
        blocked end cell taken out, else the move between the two removed), and the checks spent."""
        checks = 0
        for u, v in itertools.pairwise(cells):
            res = world.check_segment(self.configs[u], self.configs[v])
            checks += res.checks
            if res.free:
                continue
            if res.s_contact == 0.0:
                self._block(u)
            elif res.s_contact == 1.0:
                self._block(v)
            else:
                self._ban(u, v)
            return True, checks
        return False, checks

    def entry(self, world: CollisionWorld, q: FloatArray) -> tuple[int | None, int]:
        """The free cell q joins the map at by a straight move the exact check passes (see the
        module docstring), and the checks spent; remembered per configuration while it stays free."""
        key = (id(world), q.tobytes())          # a held part makes another world (pick and place)
        known = self._entries.get(key)
        if known is not None and self.free[known]:
            return known, 0
        free = np.flatnonzero(self.free)
        if not len(free):
            return None, 0
        # Nearest in A1-A3 time: every entry turns the wrist to W, which costs the same for all.
        vel = np.asarray(self.limits.velocity)[:3]
        cost = np.max(np.abs(self.configs[free, :3] - q[:3]) / vel, axis=1)
        pool = min(ENTRY_POOL, len(free))
        near = np.argpartition(cost, pool - 1)[:pool]
        near = near[np.argsort(cost[near], kind="stable")]
        cells = free[near]
        r = self.grid.resolution
        ijk = np.stack(np.unravel_index(cells, (r, r, r)), axis=1)
        checks = 0
        tried: set[int] = set()
        for spread in ENTRY_SPREADS:               # near first, then farther out and more spread
            shell: list[int] = []
            for n in range(len(cells)):
                if len(shell) >= ENTRY_TRIES:
                    break
                if n in tried or (shell and (np.abs(ijk[shell] - ijk[n]).max(axis=1) < spread).any()):
                    continue
                shell.append(n)
                tried.add(n)
                res = world.check_segment(q, self.configs[cells[n]])
                checks += res.checks
                if res.free:
                    self._entries[key] = int(cells[n])
                    return int(cells[n]), checks
                self.counts["refused_entries"] += 1
        return None, checks
