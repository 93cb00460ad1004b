"""The compiled descent of the robot-pair collision diagram (`bodies.clash_map`, numba): from
spheres around each link over a block of consecutive samples, to each sample pair's link spheres,
to its piece spheres. Only the piece pairs whose spheres come within the margin are left for coal.

Every test is of two spheres that hold what they stand for (a block's link sphere holds that link's
sphere at every sample of the block, grown by the sample's slack; a link's sphere holds its pieces'
spheres; a piece's sphere holds the piece), so a pair culled here cannot touch."""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _grow(buf: Any, n: int) -> Any:
    """`buf` with room for twice its rows, its first n rows kept."""
    out = np.empty((2 * buf.shape[0], buf.shape[1]), dtype=buf.dtype)
    out[:n] = buf[:n]
    return out


@njit(cache=True, nogil=True)
def near_pieces(block: int, block_a: Any, block_ra: Any, block_b: Any, block_rb: Any,
                link_a: Any, link_ra: Any, link_b: Any, link_rb: Any,
                ca: Any, ra: Any, start_a: Any, pieces_a: Any,
                cb: Any, rb: Any, start_b: Any, pieces_b: Any,
                sa: Any, sb: Any, margin: float) -> tuple[Any, Any]:
    """The piece pairs whose spheres come within the margin, per sample pair.

    block : samples per block. block_a (na, La, 3), block_ra (na, La): each block's link spheres,
        grown by the block's slacks and the margin's rounding allowance (b alike).
    link_a (ka, La, 3), link_ra (ka, La): each sample's link spheres; ca (ka, pa, 3), ra (pa,): its
        piece spheres; the pieces of link u are pieces_a[start_a[u]:start_a[u + 1]].
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
            for i in range(I * block, min((I + 1) * block, ka)):
                for j in range(J * block, min((J + 1) * block, kb)):
                    slack = margin + sa[i] + sb[j]
                    for t in range(m):
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
                                if gap < 0.0:
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
