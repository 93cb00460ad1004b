"""The compiled descent of the robot-pair collision diagram (`bodies.clash_map`, numba): from
spheres around each link over a block of consecutive samples, to each sample pair's link spheres,
to its piece spheres, to its pieces' boxes. Only the piece pairs whose boxes come within the margin
are left for coal.

Every test is of two volumes that hold what they stand for (a block's link sphere holds that link's
sphere at every sample of the block, grown by the sample's slack; a link's sphere holds its pieces'
spheres; a piece's sphere and its box, coal's local AABB placed with the piece, hold the piece), so
a pair culled here cannot touch."""

from __future__ import annotations

from typing import Any

import numpy as np

from robomax_py.jit import kernel
from robomax_py.world.box_separation import separated


@kernel
def _grow(buf: Any, n: int) -> Any:
    """`buf` with room for twice its rows, its first n rows kept."""
    out = np.empty((2 * buf.shape[0], buf.shape[1]), dtype=buf.dtype)
    out[:n] = buf[:n]
    return out


@kernel
def _boxes_apart(Ta: Any, ca: Any, ha: Any, Tb: Any, cb: Any, hb: Any, margin: float) -> bool:
    """Whether two boxes are farther apart than `margin` along a separating axis
    (`world.box_separation.separated`). Ta, Tb: (4, 4) poses whose rotation columns are the boxes'
    axes; ca, cb: (3,) box centres in the world; ha, hb: (3,) half extents, m."""
    R = np.empty((3, 3))
    t = np.empty(3)
    for i in range(3):
        t[i] = (cb[0] - ca[0]) * Ta[0, i] + (cb[1] - ca[1]) * Ta[1, i] + (cb[2] - ca[2]) * Ta[2, i]
        for j in range(3):
            R[i, j] = Ta[0, i] * Tb[0, j] + Ta[1, i] * Tb[1, j] + Ta[2, i] * Tb[2, j]
    return separated(R, t, ha, hb, margin)


@kernel
def near_pieces(block: int, block_a: Any, block_ra: Any, block_b: Any, block_rb: Any,
                link_a: Any, link_ra: Any, link_b: Any, link_rb: Any,
                ca: Any, ra: Any, start_a: Any, pieces_a: Any, poses_a: Any, half_a: Any,
                cb: Any, rb: Any, start_b: Any, pieces_b: Any, poses_b: Any, half_b: Any,
                sa: Any, sb: Any, margin: float) -> tuple[Any, Any]:
    """The piece pairs whose spheres and boxes come within the margin, per sample pair.

    block : samples per block. block_a (na, La, 3), block_ra (na, La): each block's link spheres,
        grown by the block's slacks and the margin's rounding allowance (b alike).
    link_a (ka, La, 3), link_ra (ka, La): each sample's link spheres; ca (ka, pa, 3), ra (pa,): its
        piece spheres (the centres its boxes' centres too); the pieces of link u are
        pieces_a[start_a[u]:start_a[u + 1]]; poses_a (ka, pa, 4, 4) the pieces' poses, half_a (pa, 3)
        their boxes' half extents along the piece's axes.
    sa (ka,), sb (kb,): each sample's slack, m; margin, m (the allowance included).

    Returns (n, 4) int rows (sample of a, sample of b, piece of a, piece of b) and (n,) float, the
    squared centre distance less the squared reach (the most negative the nearest)."""
    na, nb = block_a.shape[0], block_b.shape[0]
    La, Lb = block_a.shape[1], block_b.shape[1]
    ka, kb = link_a.shape[0], link_b.shape[0]
    rows = np.empty((1024, 4), dtype=np.int64)
    keys = np.empty((1024, 1), dtype=np.float64)
    n = 0
    pu = np.empty(La * Lb, dtype=np.int64)
    pv = np.empty(La * Lb, dtype=np.int64)
    ok_a = np.empty((block, La * Lb), dtype=np.bool_)
    ok_b = np.empty((block, La * Lb), dtype=np.bool_)
    for I in range(na):
        for J in range(nb):
            m = 0
            for u in range(La):
                for v in range(Lb):
                    d0 = block_a[I, u, 0] - block_b[J, v, 0]
                    d1 = block_a[I, u, 1] - block_b[J, v, 1]
                    d2 = block_a[I, u, 2] - block_b[J, v, 2]
                    r = block_ra[I, u] + block_rb[J, v] + margin
                    if d0 * d0 + d1 * d1 + d2 * d2 < r * r:
                        pu[m] = u
                        pv[m] = v
                        m += 1
            if m == 0:
                continue
            # Each sample's link spheres against the other block's: most link pairs drop here.
            for i in range(I * block, min((I + 1) * block, ka)):
                for t in range(m):
                    u, v = pu[t], pv[t]
                    d0 = link_a[i, u, 0] - block_b[J, v, 0]
                    d1 = link_a[i, u, 1] - block_b[J, v, 1]
                    d2 = link_a[i, u, 2] - block_b[J, v, 2]
                    r = link_ra[i, u] + sa[i] + block_rb[J, v] + margin
                    ok_a[i - I * block, t] = d0 * d0 + d1 * d1 + d2 * d2 < r * r
            for j in range(J * block, min((J + 1) * block, kb)):
                for t in range(m):
                    u, v = pu[t], pv[t]
                    d0 = block_a[I, u, 0] - link_b[j, v, 0]
                    d1 = block_a[I, u, 1] - link_b[j, v, 1]
                    d2 = block_a[I, u, 2] - link_b[j, v, 2]
                    r = block_ra[I, u] + link_rb[j, v] + sb[j] + margin
                    ok_b[j - J * block, t] = d0 * d0 + d1 * d1 + d2 * d2 < r * r
            for i in range(I * block, min((I + 1) * block, ka)):
                if not ok_a[i - I * block, :m].any():
                    continue
                for j in range(J * block, min((J + 1) * block, kb)):
                    slack = margin + sa[i] + sb[j]
                    for t in range(m):
                        if not (ok_a[i - I * block, t] and ok_b[j - J * block, t]):
                            continue
                        u, v = pu[t], pv[t]
                        d0 = link_a[i, u, 0] - link_b[j, v, 0]
                        d1 = link_a[i, u, 1] - link_b[j, v, 1]
                        d2 = link_a[i, u, 2] - link_b[j, v, 2]
                        r = link_ra[i, u] + link_rb[j, v] + slack
                        if d0 * d0 + d1 * d1 + d2 * d2 >= r * r:
                            continue
                        for x in range(start_a[u], start_a[u + 1]):
                            p = pieces_a[x]
                            for y in range(start_b[v], start_b[v + 1]):
                                q = pieces_b[y]
                                e0 = ca[i, p, 0] - cb[j, q, 0]
                                e1 = ca[i, p, 1] - cb[j, q, 1]
                                e2 = ca[i, p, 2] - cb[j, q, 2]
                                reach = ra[p] + rb[q] + slack
                                gap = e0 * e0 + e1 * e1 + e2 * e2 - reach * reach
                                if gap < 0.0 and not _boxes_apart(poses_a[i, p], ca[i, p], half_a[p],
                                                                  poses_b[j, q], cb[j, q], half_b[q], slack):
                                    if n == rows.shape[0]:
                                        rows = _grow(rows, n)
                                        keys = _grow(keys, n)
                                    rows[n, 0] = i
                                    rows[n, 1] = j
                                    rows[n, 2] = p
                                    rows[n, 3] = q
                                    keys[n, 0] = gap
                                    n += 1
    return rows[:n], keys[:n, 0]
