"""Voxel free space of a cell's static objects, refined adaptively (an octree), for the TCP's
route through the work space (`plan.tcp_route`) and the preview (`preview --voxels`).

The root is a cube over the given bounds. A node whose cube, grown by `inflation` on every side,
meets no object is a free leaf; any other node is split into its eight octants until its edge
would fall below `precision`, and is then a blocked leaf. So free space near the objects is
resolved to `precision` and far from them in large boxes. The test is compiled
(`voxel_kernels`: the grown cube against the objects' triangles, separating axes): a grown cube
holds every point within `inflation` of the cube, so a free leaf is provably farther than
`inflation` from every object (tested against coal's distance). A node inside a convex piece (a
box, a convex part) is a blocked leaf at once, so the inside of a table is not refined; cylinders,
spheres and capsules count as their bounding boxes. Blocked leaves are conservative: a leaf at the
precision limit that touches the grown object counts as blocked even where most of it is free.
Dynamic objects are left out (their time windows are for the search to weigh).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import coal
import numpy as np
from scipy.spatial import ConvexHull

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.world.bounds import support_points, triangles
from robomax_py.world.scene import Scene
from robomax_py.world.voxel_kernels import TriangleGrid


@dataclass(frozen=True, slots=True)
class VoxelMap:
    """Leaves of the octree: lower corners (L, 3) m, edges (L,) m and whether each is free."""

    corner: FloatArray
    edge: FloatArray
    free: BoolArray
    level: np.ndarray            # (L,) depth of each leaf: its edge is the root's / 2**level
    root_corner: FloatArray      # (3,) m
    root_edge: float             # m
    precision: float
    inflation: float
    tests: int                   # triangle-cube tests made
    # Per depth: (cells per axis, sorted integer keys, leaf index of each key); built on first use.
    _index: list[tuple[int, np.ndarray, np.ndarray]] = field(default_factory=list, repr=False, compare=False)

    def leaf_of(self, points: FloatArray) -> np.ndarray:
        """(P,) index of the leaf holding each point (base frame, m); -1 outside the root.

        Per depth, the point's cell at that depth is looked up among that depth's leaves (sorted
        integer keys): a few binary searches a point, not a scan of every leaf."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        out = np.full(len(p), -1, dtype=np.int64)
        rel = (p - self.root_corner) / self.root_edge                    # in [0, 1) inside the root
        inside = np.all((rel >= 0.0) & (rel < 1.0), axis=1)
        if not self._index:
            for depth in np.unique(self.level):
                n = 1 << int(depth)
                leaves = np.flatnonzero(self.level == depth)
                cells = np.round((self.corner[leaves] - self.root_corner) / self.root_edge * n).astype(np.int64)
                keys = (cells[:, 0] * n + cells[:, 1]) * n + cells[:, 2]
                order = np.argsort(keys)
                self._index.append((n, keys[order], leaves[order]))
        for n, keys, leaves in self._index:
            at = np.minimum((rel * n).astype(np.int64), n - 1)
            want = (at[:, 0] * n + at[:, 1]) * n + at[:, 2]
            pos = np.clip(np.searchsorted(keys, want), 0, len(keys) - 1)
            hit = inside & (out < 0) & (keys[pos] == want)
            out[hit] = leaves[pos[hit]]
        return out

    def is_free(self, points: FloatArray) -> BoolArray:
        """Whether each point lies in a free leaf (outside the root: not free)."""
        leaf = self.leaf_of(points)
        return np.where(leaf >= 0, self.free[np.maximum(leaf, 0)], False)


def build_voxels(scene: Scene, lo: FloatArray, hi: FloatArray, precision: float, inflation: float = 0.0) -> VoxelMap:
    """The octree over the cube that holds the box lo..hi (base frame, m)."""
    if not (math.isfinite(precision) and precision > 0):
        raise ValueError(f"precision must be a finite length > 0 m, got {precision}")
    if not (math.isfinite(inflation) and inflation >= 0):
        raise ValueError(f"inflation must be a finite length >= 0 m, got {inflation}")
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all() and (hi > lo).all()):
        raise ValueError("the bounds must be finite with hi > lo on every axis")
    tris = []
    solids = []                                # (AABB lo, hi, plane normals (f, 3), offsets (f,)) of convex pieces
    for obj in scene.obstacles:
        T = np.asarray(obj.T_base_object, dtype=float)
        for geom in obj.pieces:
            pts = support_points(geom, T)
            if isinstance(geom, coal.BVHModelBase):
                tris.append(pts[triangles(geom)])
                continue
            # A convex piece is exactly the hull of these points (any other primitive lies inside
            # the hull of its bounding box): a node inside it is blocked whole.
            hull = ConvexHull(pts)
            tris.append(pts[hull.simplices])
            solids.append((pts.min(axis=0), pts.max(axis=0), hull.equations[:, :3], -hull.equations[:, 3]))
    grid = TriangleGrid(np.concatenate(tris) if tris else np.zeros((0, 3, 3)), precision)

    size = float((hi - lo).max())
    corners = lo[None, :].copy()
    edges = np.array([size])
    out_corner, out_edge, out_free, out_level = [], [], [], []
    tests = 0
    depth = 0
    octants = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=float)
    while len(corners):
        # The cube grown by the inflation against the triangles (compiled), then the solids' insides.
        touching, used = grid.touching(corners + edges[:, None] / 2, edges / 2 + inflation)
        tests += used
        inside = _inside_a_solid(corners, edges, solids, octants)
        touching |= inside
        split = touching & ~inside & (edges / 2 >= precision)
        leaf = ~split
        out_corner.append(corners[leaf])
        out_edge.append(edges[leaf])
        out_free.append(~touching[leaf])
        out_level.append(np.full(int(leaf.sum()), depth, dtype=np.int64))
        depth += 1
        corners = (corners[split][:, None, :] + octants[None] * (edges[split] / 2)[:, None, None]).reshape(-1, 3)
        edges = np.repeat(edges[split] / 2, 8)
    return VoxelMap(corner=np.concatenate(out_corner), edge=np.concatenate(out_edge), free=np.concatenate(out_free),
                    level=np.concatenate(out_level), root_corner=lo, root_edge=size, precision=precision,
                    inflation=inflation, tests=tests)


def _inside_a_solid(corners: FloatArray, edges: FloatArray, solids: list[tuple[FloatArray, FloatArray, FloatArray, FloatArray]],
                    octants: FloatArray) -> BoolArray:
    """Whether each node box lies inside one convex piece (all eight corners within its planes)."""
    out = np.zeros(len(corners), dtype=bool)
    if not solids or not len(corners):
        return out
    for lo, hi, normals, offsets in solids:
        # Only a node inside the solid's bounding box can be inside the solid.
        todo = np.flatnonzero(~out & np.all(corners >= lo, axis=1) & np.all(corners + edges[:, None] <= hi, axis=1))
        if not len(todo):
            continue
        pts = corners[todo, None, :] + octants[None] * edges[todo, None, None]   # (n, 8, 3)
        side = pts @ normals.T                                                    # (n, 8, f)
        out[todo[np.all(side <= offsets - 1e-12, axis=(1, 2))]] = True
    return out
