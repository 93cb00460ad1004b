"""The compiled loops of the bounding-volume pre-filter (`world.prefilter`, numba): forward
kinematics of the serial chain, the pieces' spheres and boxes placed, and the pair bounds of a batch
of configurations, read from the packed float and int tables `Prefilter` holds (F the scalars, R
(n, 3) the 3-vectors, M (n, 3, 3) the matrices, I the ints; where each table starts:
`prefilter_layout`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robomax_py.jit import helper, kernel
from robomax_py.world.box_separation import boxes_apart
from robomax_py.world.pair_cells import (
    CERTIFIED,
    COLUMNS,
    INV_CELL,
    UNCERTIFIED,
    UNKNOWN,
)
from robomax_py.world.prefilter_layout import (
    AXIS,
    B_A,
    B_B,
    B_END,
    B_KIND,
    B_MARGIN,
    B_PAIRS,
    BOX_HI,
    BOX_LO,
    CELL,
    CELL_LO,
    CENTRE,
    CH_BC,
    CH_BR,
    CH_C,
    CH_END,
    CH_H,
    CH_RAD,
    CH_SKIP,
    CH_START,
    G_CENTRE,
    G_RADIUS,
    GROUP_JOINT,
    JQ,
    JROT,
    JTRANS,
    KIND,
    MARGIN,
    OBB_C,
    OBB_H,
    OBB_R,
    PAIR_A,
    PAIR_B,
    PAIR_OBSTACLE,
    PARENT,
    PIECE_JOINT,
    RADIUS,
    WALK,
)
from robomax_py.world.prefilter_reach import _growth, _pair_reach


@helper
def _forward(q: Any, R: Any, M: Any, I: Any, rot: Any, trans: Any) -> None:
    """Joint frames in the base frame: oMi[j] = oMi[parent] * placement[j] * motion_j(q)."""
    parent, kind, axis, jrot, jtrans, jq = I[PARENT], I[KIND], I[AXIS], I[JROT], I[JTRANS], I[JQ]
    # Loops, not slice assignments (`rot[0, :, :] = 0.0`): numba lowers each of those through its
    # broadcasting setitem, much more code to compile for the same nine stores.
    for r in range(3):
        trans[0, r] = 0.0
        for c in range(3):
            rot[0, r, c] = 1.0 if r == c else 0.0
    m = np.empty((3, 3))
    for j in range(1, I[0]):
        p = I[parent + j]
        # placement in the base frame: R = Rp @ Rj, t = tp + Rp @ tj
        for r in range(3):
            acc = trans[p, r]
            for c in range(3):
                acc += rot[p, r, c] * R[jtrans + j, c]
                s = 0.0
                for k in range(3):
                    s += rot[p, r, k] * M[jrot + j, k, c]
                m[r, c] = s
            trans[j, r] = acc
        x = q[I[jq + j]]
        ax, ay, az = R[axis + j, 0], R[axis + j, 1], R[axis + j, 2]
        if I[kind + j] == 0:
            # Rodrigues: R = I + sin x K + (1 - cos x) K^2, K the cross-product matrix of the axis
            s, c1 = math.sin(x), 1.0 - math.cos(x)
            m00 = 1.0 - c1 * (ay * ay + az * az)
            m11 = 1.0 - c1 * (ax * ax + az * az)
            m22 = 1.0 - c1 * (ax * ax + ay * ay)
            m01 = -s * az + c1 * ax * ay
            m10 = s * az + c1 * ax * ay
            m02 = s * ay + c1 * ax * az
            m20 = -s * ay + c1 * ax * az
            m12 = -s * ax + c1 * ay * az
            m21 = s * ax + c1 * ay * az
            for r in range(3):
                a0, a1, a2 = m[r, 0], m[r, 1], m[r, 2]
                rot[j, r, 0] = a0 * m00 + a1 * m10 + a2 * m20
                rot[j, r, 1] = a0 * m01 + a1 * m11 + a2 * m21
                rot[j, r, 2] = a0 * m02 + a1 * m12 + a2 * m22
        else:
            for r in range(3):
                trans[j, r] += x * (m[r, 0] * ax + m[r, 1] * ay + m[r, 2] * az)
                rot[j, r, 0], rot[j, r, 1], rot[j, r, 2] = m[r, 0], m[r, 1], m[r, 2]


@kernel
def _placements(q: Any, F: Any, R: Any, M: Any, I: Any) -> Any:
    J = I[0]
    rot = np.empty((J, 3, 3))
    trans = np.empty((J, 3))
    _forward(q, R, M, I, rot, trans)
    return rot, trans


@kernel
def _uncleared(qs: Any, F: Any, R: Any, M: Any, I: Any, active: Any, blocks: Any, rows: Any, decided: Any) -> Any:
    """For each configuration i of qs, the pairs active in row rows[i] of `active` (r, P) it does
    not clear, in pair order; blocks whose entry in row rows[i] of `blocks` (r, NB) is False are
    known cleared (`_near`) and skipped; a pair of two robot pieces whose cell holding the
    configuration is certified free in `decided` (`pair_cells`) is cleared. Returns (offsets (k + 1,),
    pairs, undecided (k,) bool): configuration i's pairs are pairs[offsets[i]:offsets[i + 1]], and
    undecided[i] tells whether one of them lies in a cell not decided yet."""
    J, G, P, NG, NB, N = I[0], I[1], I[2], I[3], I[4], I[6]
    centre, radius, box_lo, box_hi, margin = I[CENTRE], I[RADIUS], I[BOX_LO], I[BOX_HI], I[MARGIN]
    g_centre, g_radius, b_margin, ch_c, ch_rad = I[G_CENTRE], I[G_RADIUS], I[B_MARGIN], I[CH_C], I[CH_RAD]
    piece_joint, pair_a, pair_b, pair_obstacle = I[PIECE_JOINT], I[PAIR_A], I[PAIR_B], I[PAIR_OBSTACLE]
    group_joint, b_kind, b_a, b_b, b_end, b_pairs = I[GROUP_JOINT], I[B_KIND], I[B_A], I[B_B], I[B_END], I[B_PAIRS]
    ch_start, ch_end, ch_skip, walk, cell = I[CH_START], I[CH_END], I[CH_SKIP], I[WALK], I[CELL]
    # `boxes_apart` (shared with the clash descent) takes its boxes' tables as arrays.
    obb_h = R[I[OBB_H]:I[OBB_H] + G]
    ch_bc, ch_br, ch_h = R[I[CH_BC]:], M[I[CH_BR]:], R[I[CH_H]:]

    n_cfg = qs.shape[0]
    rot = np.empty((J, 3, 3))
    trans = np.empty((J, 3))
    world = np.empty((G, 3))
    g_world = np.empty((NG, 3))
    box_c = np.empty((G, 3))
    box_r = np.empty((G, 3, 3))
    placed = np.empty(G, dtype=np.bool_)     # world box of the piece computed for this configuration
    scratch = np.empty((7, 3))               # `boxes_apart`'s, allocated once
    offsets = np.empty(n_cfg + 1, dtype=np.int64)     # configuration i's pairs: out[offsets[i]:offsets[i + 1]]
    offsets[0] = 0
    undecided = np.empty(n_cfg, dtype=np.bool_)
    out = np.empty(n_cfg * P, dtype=np.int64)
    filled = 0
    # Pieces on the base (every obstacle) are where they are at any configuration: placed once.
    for r in range(3):
        trans[0, r] = 0.0
        for c in range(3):
            rot[0, r, c] = 1.0 if r == c else 0.0
    moving = np.empty(G, dtype=np.int64)
    n_moving = 0
    for g in range(G):
        if I[piece_joint + g] == 0:
            _place(rot, trans, I[piece_joint + g], R, centre + g, world, g)
        else:
            moving[n_moving] = g
            n_moving += 1
    # Each configuration is copied to a writable row first: `_forward` then has the one
    # specialisation `_near` and `_placements` also use (a read-only row would compile it again,
    # about 0.4 s of a first plan).
    # A row of `blocks` with few blocks (`near`'s, typically a block or two of hundreds) is walked by
    # its list of blocks: the tree would test boxes over blocks the row leaves out anyway.
    listed = np.empty(blocks.shape, dtype=np.int64)
    n_listed = np.empty(blocks.shape[0], dtype=np.int64)      # -1: the row walks the tree
    for r in range(blocks.shape[0]):
        n_on = 0
        for blk in range(NB):
            if blocks[r, blk]:
                listed[r, n_on] = blk
                n_on += 1
        n_listed[r] = n_on if 4 * n_on < NB else -1
    q = np.empty(qs.shape[1])
    for i in range(n_cfg):
        for c in range(q.shape[0]):          # a loop: slice assignment compiles its shape checks
            q[c] = qs[i, c]
        _forward(q, R, M, I, rot, trans)
        row = rows[i]
        for m in range(n_moving):
            g = moving[m]
            _place(rot, trans, I[piece_joint + g], R, centre + g, world, g)
        for g in range(NG):
            _place(rot, trans, I[group_joint + g], R, g_centre + g, g_world, g)
        for g in range(G):
            placed[g] = False
        first = filled
        undecided[i] = False
        few = n_listed[row] >= 0
        end = n_listed[row] if few else N
        nd = 0
        while nd < end:                         # the row's list, or the block walk (`prefilter_tree`)
            if few:
                blk = listed[row, nd]
                nd += 1
            else:
                blk = I[walk + 3 * nd]
                if blk < 0:                     # a box over obstacles: cleared, all their blocks are
                    ga = I[walk + 3 * nd + 1]
                    cleared = _sphere_box(g_world, ga, F[g_radius + ga] + F[b_margin + NB + nd], R, box_lo + G + nd,
                                          box_hi + G + nd)
                    nd = I[walk + 3 * nd + 2] if cleared else nd + 1
                    continue
                nd += 1
                if not blocks[row, blk]:
                    continue
            begin = I[b_end + blk - 1] if blk > 0 else 0
            stop = I[b_end + blk]
            ga, gb = I[b_a + blk], I[b_b + blk]
            if I[b_kind + blk] == 0:
                cleared = _sphere_box(g_world, ga, F[g_radius + ga] + F[b_margin + blk], R, box_lo + gb, box_hi + gb)
            else:
                cleared = _sphere_point(g_world, ga, g_world, gb, F[g_radius + ga] + F[g_radius + gb] + F[b_margin + blk])
            if not cleared:
                for n in range(begin, stop):
                    k = I[b_pairs + n]
                    if not active[row, k]:
                        continue
                    a, b = I[pair_a + k], I[pair_b + k]
                    pending = False                   # left for coal with its cell not decided yet
                    if I[pair_obstacle + k]:
                        ok = _sphere_box(world, a, F[radius + a] + F[margin + k], R, box_lo + b, box_hi + b)
                        if not ok and I[ch_start + b] >= 0:   # near the obstacle's box: chunk by chunk
                            if not placed[a]:
                                _place_box(rot, trans, I[piece_joint + a], R, M, I, a, box_c, box_r)
                                placed[a] = True
                            ok = True
                            c = I[ch_start + b]
                            while c < I[ch_end + b]:          # the chunk tree, pre-order, without a stack
                                if _sphere_point(world, a, R, ch_c + c, F[radius + a] + F[ch_rad + c] + F[margin + k]) or \
                                        boxes_apart(box_c, box_r, obb_h, a, ch_bc, ch_br, ch_h, c, F[margin + k], scratch):
                                    c = I[ch_skip + c]    # cleared: past its subtree
                                elif I[ch_skip + c] == c + 1:
                                    ok = False            # a leaf it cannot clear
                                    break
                                else:
                                    c += 1                # into its first child
                    else:
                        ok = _sphere_point(world, a, world, b, F[radius + a] + F[radius + b] + F[margin + k])
                        if not ok and I[cell + COLUMNS * k] > 0:    # neighbouring pieces: their cell
                            decision = _cell_decision(q, F, I, k, decided)
                            ok = decision == CERTIFIED
                            pending = decision == UNKNOWN
                        if not ok:                # the spheres overlap: try the pieces' boxes
                            for g in (a, b):
                                if not placed[g]:
                                    _place_box(rot, trans, I[piece_joint + g], R, M, I, g, box_c, box_r)
                                    placed[g] = True
                            ok = boxes_apart(box_c, box_r, obb_h, a, box_c, box_r, obb_h, b, F[margin + k], scratch)
                    if not ok:
                        out[filled] = k
                        filled += 1
                        undecided[i] = undecided[i] or pending
        for n in range(first + 1, filled):      # into pair order: a few entries, insertion sort
            k = out[n]
            m = n - 1
            while m >= first and out[m] > k:
                out[m + 1] = out[m]
                m -= 1
            out[m + 1] = k
        offsets[i + 1] = filled
    return offsets, out[:filled], undecided


@kernel
def _near(qs: Any, F: Any, R: Any, M: Any, I: Any, active: Any, deep: bool) -> Any:
    """(blocks (NB,) bool, pairs (P,) bool): the blocks, and the active pairs, that `_uncleared`'s
    tests may fail to clear at some configuration of the joint-space box spanned by qs (k, n);
    the others are cleared at every configuration of the box.

    The tests are `_uncleared`'s sphere tests at the box's centre, each sphere grown by how far its
    centre can move within the box: a point on joint j's link moves at |dp/ds| <= sum_i |dq_i|
    |p - o_i| over the revolute joints i from j back to the base (o_i on axis i), and |p - o_i| is at
    most the joint-origin offsets from i to j plus the point's distance from o_j (rotations keep
    lengths); along the straight line from the centre to any configuration of the box its centre
    so moves at most sum_i (half range_i) * that bound. A chain with a prismatic joint, or a
    configuration with a NaN, gets no bound (every block and active pair kept).

    deep: a pair whose grown spheres meet is also tried with `_uncleared`'s finer tests at the box's
    centre (an obstacle's chunk tree, the pieces' oriented boxes), the gap grown by how far any point
    of the piece can move (`_growth` of its farthest point: the piece lies within its sphere); a pair
    so cleared is cleared at every configuration of the box, though `_uncleared` of one of them may
    not clear it (it then goes to coal's exact test, which finds it free). Also returned: reach (P,),
    for each pair left when deep, how much its distance can shrink from the box's centre
    (`_pair_reach`; inf otherwise)."""
    J, G, P, NG, NB, N = I[0], I[1], I[2], I[3], I[4], I[6]
    centre, radius, box_lo, box_hi, margin = I[CENTRE], I[RADIUS], I[BOX_LO], I[BOX_HI], I[MARGIN]
    g_centre, g_radius, b_margin, ch_c, ch_rad = I[G_CENTRE], I[G_RADIUS], I[B_MARGIN], I[CH_C], I[CH_RAD]
    piece_joint, pair_a, pair_b, pair_obstacle = I[PIECE_JOINT], I[PAIR_A], I[PAIR_B], I[PAIR_OBSTACLE]
    group_joint, b_kind, b_a, b_b, b_end, b_pairs = I[GROUP_JOINT], I[B_KIND], I[B_A], I[B_B], I[B_END], I[B_PAIRS]
    ch_start, ch_end, ch_skip, walk, kind = I[CH_START], I[CH_END], I[CH_SKIP], I[WALK], I[KIND]
    # `boxes_apart` (shared with the clash descent) takes its boxes' tables as arrays.
    obb_h = R[I[OBB_H]:I[OBB_H] + G]
    ch_bc, ch_br, ch_h = R[I[CH_BC]:], M[I[CH_BR]:], R[I[CH_H]:]
    # np.empty and loops, not np.ones, np.full or a copy: numba compiles each constructor (and each
    # dtype of it) as a function of its own, about 0.1 s apiece of a first plan.
    keep = np.empty(NB, dtype=np.bool_)
    for m in range(NB):
        keep[m] = True
    live = np.empty(P, dtype=np.bool_)
    reach = np.empty(P)
    for m in range(P):
        live[m] = active[m]
        reach[m] = np.inf
    for j in range(1, J):
        if I[kind + j] != 0:
            return keep, live, reach
    n = qs.shape[1]
    lo = np.empty(n)
    hi = np.empty(n)
    mid = np.empty(n)
    for c in range(n):
        lo[c] = hi[c] = qs[0, c]
        for i in range(qs.shape[0]):
            x = qs[i, c]
            if not math.isfinite(x):
                return keep, live, reach
            lo[c] = min(lo[c], x)
            hi[c] = max(hi[c], x)
    for c in range(n):                       # a loop: an array expression compiles a kernel of its own
        mid[c] = (lo[c] + hi[c]) / 2.0
    rot = np.empty((J, 3, 3))
    trans = np.empty((J, 3))
    _forward(mid, R, M, I, rot, trans)
    g_world = np.empty((NG, 3))
    g_grow = np.empty(NG)
    for g in range(NG):
        _place(rot, trans, I[group_joint + g], R, g_centre + g, g_world, g)
        g_grow[g] = _growth(R, I, g_centre + g, I[group_joint + g], lo, hi, 0.0, np.int64(0))
    world = np.empty((G, 3))
    grow = np.empty(G)                        # < 0: not yet computed
    box_c = np.empty((G, 3))
    box_r = np.empty((G, 3, 3))
    boxed = np.empty(G, dtype=np.bool_)       # the piece's box placed at the centre
    spread = np.empty(G)                      # how far any point of the piece can move; < 0: not yet computed
    for g in range(G):
        grow[g] = spread[g] = -1.0
        boxed[g] = False
    scratch = np.empty((7, 3))
    for m in range(NB):                       # a block or pair the walk leaves out is cleared
        keep[m] = False
    for m in range(P):
        live[m] = False
    nd = 0
    while nd < N:                             # `_uncleared`'s block walk, every test grown
        blk = I[walk + 3 * nd]
        if blk < 0:
            ga = I[walk + 3 * nd + 1]
            cleared = _sphere_box(g_world, ga, F[g_radius + ga] + F[b_margin + NB + nd] + g_grow[ga], R,
                                  box_lo + G + nd, box_hi + G + nd)
            nd = I[walk + 3 * nd + 2] if cleared else nd + 1
            continue
        nd += 1
        begin = I[b_end + blk - 1] if blk > 0 else 0
        stop = I[b_end + blk]
        ga, gb = I[b_a + blk], I[b_b + blk]
        if I[b_kind + blk] == 0:
            cleared = _sphere_box(g_world, ga, F[g_radius + ga] + F[b_margin + blk] + g_grow[ga], R, box_lo + gb,
                                  box_hi + gb)
        else:
            cleared = _sphere_point(g_world, ga, g_world, gb, F[g_radius + ga] + F[g_radius + gb] + F[b_margin + blk]
                                    + g_grow[ga] + g_grow[gb])
        if cleared:
            continue
        any_live = False
        for m in range(begin, stop):
            k = I[b_pairs + m]
            if not active[k]:
                continue
            a, b = I[pair_a + k], I[pair_b + k]
            if grow[a] < 0.0:
                _place(rot, trans, I[piece_joint + a], R, centre + a, world, a)
                grow[a] = _growth(R, I, centre + a, I[piece_joint + a], lo, hi, 0.0, np.int64(0))
            if I[pair_obstacle + k]:
                live[k] = not _sphere_box(world, a, F[radius + a] + F[margin + k] + grow[a], R, box_lo + b, box_hi + b)
                if live[k] and deep and I[ch_start + b] >= 0:
                    # The box and the spread are kept apart: `_pair_reach` may have computed the
                    # spread (for an obstacle without chunks) without placing the box.
                    if not boxed[a]:
                        _place_box(rot, trans, I[piece_joint + a], R, M, I, a, box_c, box_r)
                        boxed[a] = True
                    if spread[a] < 0.0:
                        spread[a] = _growth(R, I, centre + a, I[piece_joint + a], lo, hi, F[radius + a], np.int64(0))
                    live[k] = False
                    c = I[ch_start + b]
                    while c < I[ch_end + b]:          # `_uncleared`'s traversal, every test grown
                        if _sphere_point(world, a, R, ch_c + c, F[radius + a] + F[ch_rad + c] + F[margin + k] + grow[a]) or \
                                boxes_apart(box_c, box_r, obb_h, a, ch_bc, ch_br, ch_h, c, F[margin + k] + spread[a],
                                            scratch):
                            c = I[ch_skip + c]
                        elif I[ch_skip + c] == c + 1:
                            live[k] = True
                            break
                        else:
                            c += 1
            else:
                if grow[b] < 0.0:
                    _place(rot, trans, I[piece_joint + b], R, centre + b, world, b)
                    grow[b] = _growth(R, I, centre + b, I[piece_joint + b], lo, hi, 0.0, np.int64(0))
                live[k] = not _sphere_point(world, a, world, b, F[radius + a] + F[radius + b] + F[margin + k] + grow[a]
                                            + grow[b])
                if live[k] and deep:
                    for g in (a, b):
                        if not boxed[g]:
                            _place_box(rot, trans, I[piece_joint + g], R, M, I, g, box_c, box_r)
                            boxed[g] = True
                        if spread[g] < 0.0:
                            spread[g] = _growth(R, I, centre + g, I[piece_joint + g], lo, hi, F[radius + g], np.int64(0))
                    live[k] = not boxes_apart(box_c, box_r, obb_h, a, box_c, box_r, obb_h, b,
                                              F[margin + k] + spread[a] + spread[b], scratch)
            if live[k] and deep:
                reach[k] = _pair_reach(F, R, I, a, b, I[pair_obstacle + k], lo, hi, spread)
            any_live = any_live or live[k]
        keep[blk] = any_live             # a block without a live pair adds nothing
    return keep, live, reach


@helper
def _cell_decision(q: Any, F: Any, I: Any, k: Any, decided: Any) -> int:
    """The decision (`pair_cells`: UNKNOWN, CERTIFIED, UNCERTIFIED) of pair k's cell holding
    configuration q; UNCERTIFIED off the table's range or for a NaN (tested, as every pair without
    cells). `pair_cells.CellTable.cell`, operation for operation."""
    row = I[CELL] + COLUMNS * k
    lows = I[CELL_LO] + 2 * k
    flat = 0
    for m in range(I[row]):
        x = (q[I[row + 1 + m]] - F[lows + m]) * INV_CELL
        if not x >= 0.0:
            return UNCERTIFIED
        n = int(x)
        count = I[row + 3 + m]
        if n >= count:
            return UNCERTIFIED
        flat = flat * count + n
    return int(decided[I[row + 5] + flat])


@helper
def _place(rot: Any, trans: Any, j: Any, local: Any, p: Any, world: Any, g: Any) -> None:
    """world[g] = joint j's frame applied to point local[p]."""
    for r in range(3):
        world[g, r] = trans[j, r] + rot[j, r, 0] * local[p, 0] + rot[j, r, 1] * local[p, 1] + rot[j, r, 2] * local[p, 2]


@helper
def _sphere_box(world: Any, a: int, reach: float, corners: Any, lo: Any, hi: Any) -> bool:
    """Whether sphere centre a is farther than `reach` from the box of corners[lo] and corners[hi]
    (an inf reach is never cleared)."""
    d2 = 0.0
    for r in range(3):
        c = world[a, r]
        e = corners[lo, r] - c
        e = max(e, c - corners[hi, r])
        if e > 0.0:
            d2 += e * e
    return d2 > reach * reach


@helper
def _sphere_point(world: Any, a: int, points: Any, c: int, reach: float) -> bool:
    """Whether point world[a] is farther than `reach` from point points[c]."""
    d2 = 0.0
    for r in range(3):
        e = world[a, r] - points[c, r]
        d2 += e * e
    return d2 > reach * reach


@helper
def _place_box(rot: Any, trans: Any, j: Any, R: Any, M: Any, I: Any, g: Any, box_c: Any, box_r: Any) -> None:
    """Piece g's oriented box (`prefilter_layout` OBB_C, OBB_R) in joint j's frame."""
    lc, lr = I[OBB_C] + g, I[OBB_R] + g
    for r in range(3):
        box_c[g, r] = trans[j, r] + rot[j, r, 0] * R[lc, 0] + rot[j, r, 1] * R[lc, 1] + rot[j, r, 2] * R[lc, 2]
        for c in range(3):
            box_r[g, r, c] = rot[j, r, 0] * M[lr, 0, c] + rot[j, r, 1] * M[lr, 1, c] + rot[j, r, 2] * M[lr, 2, c]
