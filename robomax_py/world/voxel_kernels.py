"""Compiled box-against-triangles tests for the voxel map (numba): which cubes meet the objects.

Every object piece is handed over as triangles in the base frame: a mesh piece its own, a convex
piece (a box, a convex part) its hull's, and any other primitive the hull of its bounding box (it
holds the primitive, so the answer stays on the safe side). The triangles are sorted into a uniform
grid; a cube is tested against the triangles of the grid cells it overlaps, by the separating-axis
test of Akenine-Möller ("Fast 3D triangle-box overlap testing", 2001: the three box axes, the
triangle's normal and the nine edge cross products). A cube grown by the inflation on every side
holds the cube's inflation neighbourhood, so "the grown cube meets a triangle" is never false when
the cube comes within the inflation of the surface: a cube found clear is clear. A cube wholly
inside a convex solid meets none of its triangles; `voxels` finds those with the solids' planes.
"""

from __future__ import annotations

import numpy as np

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.jit import kernel

# Cells per axis of the triangle grid at most, and the cell edge in precision limits at least.
MAX_GRID_CELLS = 160
MIN_CELL_PRECISIONS = 4.0
# Slack (m) on every separating-axis comparison: touching within it counts as meeting.
SAT_SLACK_M = 1e-12


class TriangleGrid:
    """Triangles (T, 3, 3) in the base frame, bucketed by a uniform grid over their bounds."""

    def __init__(self, tris: FloatArray, precision: float) -> None:
        self.tris = np.ascontiguousarray(tris, dtype=np.float64).reshape(-1, 3, 3)
        if len(self.tris) == 0:
            self.lo = np.zeros(3)
            self.cell = 1.0
            self.dims = np.ones(3, dtype=np.int64)
            self.start = np.zeros(2, dtype=np.int64)
            self.items = np.zeros(0, dtype=np.int64)
            return
        t_lo, t_hi = self.tris.min(axis=1), self.tris.max(axis=1)
        self.lo = t_lo.min(axis=0)
        extent = float((t_hi.max(axis=0) - self.lo).max())
        self.cell = max(MIN_CELL_PRECISIONS * precision, extent / MAX_GRID_CELLS, 1e-6)
        self.dims = (np.floor((t_hi.max(axis=0) - self.lo) / self.cell).astype(np.int64) + 1)
        i0 = np.clip(np.floor((t_lo - self.lo) / self.cell).astype(np.int64), 0, self.dims - 1)
        i1 = np.clip(np.floor((t_hi - self.lo) / self.cell).astype(np.int64), 0, self.dims - 1)
        self.start, self.items = _bucket(i0, i1, self.dims)

    def touching(self, centres: FloatArray, half: FloatArray) -> tuple[BoolArray, int]:
        """Whether each cube (centre (N, 3), half edge (N,)) meets a triangle; the tests made."""
        out = np.zeros(len(centres), dtype=np.bool_)
        if len(self.tris) == 0 or len(centres) == 0:
            return out, 0
        tests = _touching(np.ascontiguousarray(centres, dtype=np.float64), np.ascontiguousarray(half, dtype=np.float64),
                          self.lo, self.cell, self.dims, self.start, self.items, self.tris, out)
        return out, int(tests)


def _bucket(i0: np.ndarray, i1: np.ndarray, dims: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """CSR lists of the triangles of each grid cell (cells in x-major order)."""
    counts = np.prod(i1 - i0 + 1, axis=1)
    tri = np.repeat(np.arange(len(i0)), counts)
    # The k-th cell of each triangle's range, unravelled within the range.
    offset = np.arange(len(tri)) - np.repeat(np.cumsum(counts) - counts, counts)
    span = (i1 - i0 + 1)[tri]
    ix = i0[tri, 0] + offset // (span[:, 1] * span[:, 2])
    iy = i0[tri, 1] + (offset // span[:, 2]) % span[:, 1]
    iz = i0[tri, 2] + offset % span[:, 2]
    cell = (ix * dims[1] + iy) * dims[2] + iz
    order = np.argsort(cell, kind="stable")
    start = np.zeros(int(np.prod(dims)) + 1, dtype=np.int64)
    np.add.at(start, cell + 1, 1)
    return np.cumsum(start), tri[order].astype(np.int64)


@kernel
def _touching(centres: np.ndarray, half: np.ndarray, lo: np.ndarray, cell: float, dims: np.ndarray,
              start: np.ndarray, items: np.ndarray, tris: np.ndarray, out: np.ndarray) -> int:
    tests = 0
    for n in range(len(centres)):
        h = half[n]
        c = centres[n]
        ranges = np.empty((3, 2), dtype=np.int64)
        outside = False
        for a in range(3):
            r0 = int(np.floor((c[a] - h - lo[a]) / cell))
            r1 = int(np.floor((c[a] + h - lo[a]) / cell))
            if r1 < 0 or r0 >= dims[a]:
                outside = True
                break
            ranges[a, 0] = max(r0, 0)
            ranges[a, 1] = min(r1, dims[a] - 1)
        if outside:
            continue
        hit = False
        for ix in range(ranges[0, 0], ranges[0, 1] + 1):
            for iy in range(ranges[1, 0], ranges[1, 1] + 1):
                for iz in range(ranges[2, 0], ranges[2, 1] + 1):
                    k = (ix * dims[1] + iy) * dims[2] + iz
                    for m in range(start[k], start[k + 1]):
                        tests += 1
                        if _tri_box(c, h, tris[items[m]]):
                            hit = True
                            break
                    if hit:
                        break
                if hit:
                    break
            if hit:
                break
        out[n] = hit
    return tests


@kernel
def _tri_box(c: np.ndarray, h: float, tri: np.ndarray) -> bool:
    """Whether the cube (centre c, half edge h) and the triangle overlap (separating axes)."""
    v0 = tri[0] - c
    v1 = tri[1] - c
    v2 = tri[2] - c
    lim = h + SAT_SLACK_M
    # The box's axes: the triangle's bounds against the box.
    for a in range(3):
        if min(v0[a], v1[a], v2[a]) > lim or max(v0[a], v1[a], v2[a]) < -lim:
            return False
    e0 = v1 - v0
    e1 = v2 - v1
    e2 = v0 - v2
    # The nine cross products of the box's axes with the edges.
    for e in (e0, e1, e2):
        for a in range(3):
            # axis = unit_a x e
            ax = np.zeros(3)
            if a == 0:
                ax[1], ax[2] = -e[2], e[1]
            elif a == 1:
                ax[0], ax[2] = e[2], -e[0]
            else:
                ax[0], ax[1] = -e[1], e[0]
            p0 = ax[0] * v0[0] + ax[1] * v0[1] + ax[2] * v0[2]
            p1 = ax[0] * v1[0] + ax[1] * v1[1] + ax[2] * v1[2]
            p2 = ax[0] * v2[0] + ax[1] * v2[1] + ax[2] * v2[2]
            r = h * (abs(ax[0]) + abs(ax[1]) + abs(ax[2])) + SAT_SLACK_M
            if min(p0, p1, p2) > r or max(p0, p1, p2) < -r:
                return False
    # The triangle's plane.
    nx = e0[1] * e1[2] - e0[2] * e1[1]
    ny = e0[2] * e1[0] - e0[0] * e1[2]
    nz = e0[0] * e1[1] - e0[1] * e1[0]
    d = nx * v0[0] + ny * v0[1] + nz * v0[2]
    r = h * (abs(nx) + abs(ny) + abs(nz)) + SAT_SLACK_M
    return bool(abs(d) <= r)
