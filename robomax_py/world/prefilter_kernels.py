"""The compiled loops of the bounding-volume pre-filter (`world.prefilter`, numba): forward
kinematics of the serial chain, the pieces' spheres and boxes placed, and the pair bounds of a batch
of configurations, read from the packed float and int tables `Prefilter` holds."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robomax_py.jit import helper, kernel
from robomax_py.world.box_separation import boxes_apart
from robomax_py.world.prefilter_reach import _growth, _pair_reach

_N_HEADER, _N_FLOAT_TABLES, _N_INT_TABLES = 7, 19, 17


@helper
def _forward(q: Any, parent: Any, kind: Any, axis: Any, jrot: Any, jtrans: Any, jq: Any, rot: Any, trans: Any) -> None:
    """Joint frames in the base frame: oMi[j] = oMi[parent] * placement[j] * motion_j(q)."""
    rot[0, :, :] = 0.0
    rot[0, 0, 0] = rot[0, 1, 1] = rot[0, 2, 2] = 1.0
    trans[0, :] = 0.0
    m = np.empty((3, 3))
    for j in range(1, parent.shape[0]):
        p = parent[j]
        # placement in the base frame: R = Rp @ Rj, t = tp + Rp @ tj
        for r in range(3):
            acc = trans[p, r]
            for c in range(3):
                acc += rot[p, r, c] * jtrans[j, c]
                s = 0.0
                for k in range(3):
                    s += rot[p, r, k] * jrot[j, k, c]
                m[r, c] = s
            trans[j, r] = acc
        x = q[jq[j]]
        ax, ay, az = axis[j, 0], axis[j, 1], axis[j, 2]
        if kind[j] == 0:
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


@helper
def _tables(F: Any, R: Any, M: Any, I: Any) -> Any:
    """Every table, as slices of the packed buffers (`prefilter._pack`): F the scalars, R (n, 3) the
    3-vectors, M (n, 3, 3) the matrices, I the ints. In order: the chain's (`_forward`'s argument
    order: parent, kind, axis, rotation, translation, q index); the sphere tests' (per piece centre,
    radius and obstacle box corners, per pair margin, per group centre and radius, per block
    margin; per piece its joint, per pair its pieces and whether b is an obstacle, per group its
    joint, per block its kind, groups and end, the pairs in block order); the box and chunk tests'
    (per piece its oriented box: centre, rotation, half extents; per chunk of an obstacle's mesh its
    sphere, centre and radius, and box; per piece its first and end chunk, per chunk the chunk after
    its subtree); the block walk's (`prefilter_tree`: per node its block, group and the node after
    its subtree, interleaved; an inner node's box and largest margin follow the pieces' boxes and
    the blocks' margins: rows G + node and NB + node). One helper, not one per group of tables: each jitted function has a fixed compile
    cost (about 0.1 s of a first plan for the three it replaces)."""
    J, G, P, NG, NB, C, N = I[0], I[1], I[2], I[3], I[4], I[5], I[6]
    fo = I[_N_HEADER:_N_HEADER + _N_FLOAT_TABLES]
    io = I[_N_HEADER + _N_FLOAT_TABLES:_N_HEADER + _N_FLOAT_TABLES + _N_INT_TABLES]
    return (I[io[0]:io[0] + J], I[io[1]:io[1] + J], R[fo[0]:fo[0] + J], M[fo[1]:fo[1] + J], R[fo[2]:fo[2] + J],
            I[io[2]:io[2] + J],
            R[fo[3]:fo[3] + G], F[fo[4]:fo[4] + G], R[fo[5]:fo[5] + G + N], R[fo[6]:fo[6] + G + N], F[fo[7]:fo[7] + P],
            R[fo[8]:fo[8] + NG], F[fo[9]:fo[9] + NG], F[fo[10]:fo[10] + NB + N],
            I[io[3]:io[3] + G], I[io[4]:io[4] + P], I[io[5]:io[5] + P], I[io[6]:io[6] + P], I[io[7]:io[7] + NG],
            I[io[8]:io[8] + NB], I[io[9]:io[9] + NB], I[io[10]:io[10] + NB], I[io[11]:io[11] + NB],
            I[io[12]:io[12] + P],
            R[fo[11]:fo[11] + G], M[fo[12]:fo[12] + G], R[fo[13]:fo[13] + G], R[fo[14]:fo[14] + C],
            F[fo[15]:fo[15] + C], R[fo[16]:fo[16] + C], M[fo[17]:fo[17] + C], R[fo[18]:fo[18] + C],
            I[io[13]:io[13] + G], I[io[14]:io[14] + G], I[io[15]:io[15] + C], I[io[16]:io[16] + 3 * N])


@kernel
def _placements(q: Any, F: Any, R: Any, M: Any, I: Any) -> Any:
    J = I[0]
    parent, kind, axis, jrot, jtrans, jq = _tables(F, R, M, I)[:6]
    rot = np.empty((J, 3, 3))
    trans = np.empty((J, 3))
    _forward(q, parent, kind, axis, jrot, jtrans, jq, rot, trans)
    return rot, trans


@kernel
def _uncleared(qs: Any, F: Any, R: Any, M: Any, I: Any, active: Any, blocks: Any, rows: Any) -> Any:
    """For each configuration i of qs, the pairs active in row rows[i] of `active` (r, P) it does
    not clear, in pair order; blocks whose entry in row rows[i] of `blocks` (r, NB) is False are
    known cleared (`_near`) and skipped."""
    J, G, P, NG, NB, N = I[0], I[1], I[2], I[3], I[4], I[6]
    (parent, kind, axis, jrot, jtrans, jq, centre, radius, box_lo, box_hi, margin, g_centre, g_radius, b_margin,
     piece_joint, pair_a, pair_b, pair_obstacle, group_joint, b_kind, b_a, b_b, b_end, b_pairs, obb_c, obb_r, obb_h,
     ch_c, ch_rad, ch_bc, ch_br, ch_h, ch_start, ch_end, ch_skip, walk) = _tables(F, R, M, I)

    n_cfg = qs.shape[0]
    rot = np.empty((J, 3, 3))
    trans = np.empty((J, 3))
    world = np.empty((G, 3))
    g_world = np.empty((NG, 3))
    box_c = np.empty((G, 3))
    box_r = np.empty((G, 3, 3))
    placed = np.zeros(G, dtype=np.bool_)     # world box of the piece computed for this configuration
    scratch = np.empty((7, 3))               # `boxes_apart`'s, allocated once
    counts = np.zeros(n_cfg, dtype=np.int64)
    out = np.empty(n_cfg * P, dtype=np.int64)
    filled = 0
    # Pieces on the base (every obstacle) are where they are at any configuration: placed once.
    rot[0, :, :] = 0.0
    rot[0, 0, 0] = rot[0, 1, 1] = rot[0, 2, 2] = 1.0
    trans[0, :] = 0.0
    moving = np.empty(G, dtype=np.int64)
    n_moving = 0
    for g in range(G):
        if piece_joint[g] == 0:
            # j an int64, not a literal 0: numba would compile `_place` again for Literal[int](0)
            _place(rot, trans, np.int64(0), centre, g, world)
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
        _forward(q, parent, kind, axis, jrot, jtrans, jq, rot, trans)
        row = rows[i]
        for m in range(n_moving):
            _place(rot, trans, piece_joint[moving[m]], centre, moving[m], world)
        for g in range(NG):
            _place(rot, trans, group_joint[g], g_centre, g, g_world)
        placed[:] = False
        first = filled
        few = n_listed[row] >= 0
        end = n_listed[row] if few else N
        nd = 0
        while nd < end:                         # the row's list, or the block walk (`prefilter_tree`)
            if few:
                blk = listed[row, nd]
                nd += 1
            else:
                blk = walk[3 * nd]
                if blk < 0:                     # a box over obstacles: cleared, all their blocks are
                    ga = walk[3 * nd + 1]
                    cleared = _sphere_box(g_world, ga, g_radius[ga] + b_margin[NB + nd], box_lo, box_hi, G + nd)
                    nd = walk[3 * nd + 2] if cleared else nd + 1
                    continue
                nd += 1
                if not blocks[row, blk]:
                    continue
            begin = b_end[blk - 1] if blk > 0 else 0
            stop = b_end[blk]
            ga, gb = b_a[blk], b_b[blk]
            if b_kind[blk] == 0:
                cleared = _sphere_box(g_world, ga, g_radius[ga] + b_margin[blk], box_lo, box_hi, gb)
            else:
                cleared = _sphere_point(g_world, ga, g_world, gb, g_radius[ga] + g_radius[gb] + b_margin[blk])
            if not cleared:
                for n in range(begin, stop):
                    k = b_pairs[n]
                    if not active[row, k]:
                        continue
                    a, b = pair_a[k], pair_b[k]
                    if pair_obstacle[k]:
                        ok = _sphere_box(world, a, radius[a] + margin[k], box_lo, box_hi, b)
                        if not ok and ch_start[b] >= 0:   # near the obstacle's box: chunk by chunk
                            if not placed[a]:
                                _place_box(rot, trans, piece_joint[a], obb_c, obb_r, a, box_c, box_r)
                                placed[a] = True
                            ok = True
                            c = ch_start[b]
                            while c < ch_end[b]:          # the chunk tree, pre-order, without a stack
                                if _sphere_point(world, a, ch_c, c, radius[a] + ch_rad[c] + margin[k]) or \
                                        boxes_apart(box_c, box_r, obb_h, a, ch_bc, ch_br, ch_h, c, margin[k], scratch):
                                    c = ch_skip[c]        # cleared: past its subtree
                                elif ch_skip[c] == c + 1:
                                    ok = False            # a leaf it cannot clear
                                    break
                                else:
                                    c += 1                # into its first child
                    else:
                        ok = _sphere_point(world, a, world, b, radius[a] + radius[b] + margin[k])
                        if not ok:                # the spheres overlap: try the pieces' boxes
                            for g in (a, b):
                                if not placed[g]:
                                    _place_box(rot, trans, piece_joint[g], obb_c, obb_r, g, box_c, box_r)
                                    placed[g] = True
                            ok = boxes_apart(box_c, box_r, obb_h, a, box_c, box_r, obb_h, b, margin[k], scratch)
                    if not ok:
                        out[filled] = k
                        filled += 1
        for n in range(first + 1, filled):      # into pair order: a few entries, insertion sort
            k = out[n]
            m = n - 1
            while m >= first and out[m] > k:
                out[m + 1] = out[m]
                m -= 1
            out[m + 1] = k
        counts[i] = filled - first
    return counts, out[:filled]


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
    (parent, kind, axis, jrot, jtrans, jq, centre, radius, box_lo, box_hi, margin, g_centre, g_radius, b_margin,
     piece_joint, pair_a, pair_b, pair_obstacle, group_joint, b_kind, b_a, b_b, b_end, b_pairs, obb_c, obb_r, obb_h,
     ch_c, ch_rad, ch_bc, ch_br, ch_h, ch_start, ch_end, ch_skip, walk) = _tables(F, R, M, I)
    keep = np.ones(NB, dtype=np.bool_)
    live = active.copy()
    reach = np.full(P, np.inf)
    for j in range(1, J):
        if kind[j] != 0:
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
    _forward(mid, parent, kind, axis, jrot, jtrans, jq, rot, trans)
    g_world = np.empty((NG, 3))
    g_grow = np.empty(NG)
    for g in range(NG):
        _place(rot, trans, group_joint[g], g_centre, g, g_world)
        g_grow[g] = _growth(g_centre, g, group_joint[g], lo, hi, parent, jtrans, jq, 0.0, np.int64(0))
    world = np.empty((G, 3))
    grow = np.full(G, -1.0)                   # not yet computed
    box_c = np.empty((G, 3))
    box_r = np.empty((G, 3, 3))
    boxed = np.zeros(G, dtype=np.bool_)       # the piece's box placed at the centre
    spread = np.full(G, -1.0)                 # how far any point of the piece can move; not yet computed
    scratch = np.empty((7, 3))
    for m in range(NB):                       # a block or pair the walk leaves out is cleared
        keep[m] = False
    for m in range(P):
        live[m] = False
    nd = 0
    while nd < N:                             # `_uncleared`'s block walk, every test grown
        blk = walk[3 * nd]
        if blk < 0:
            ga = walk[3 * nd + 1]
            cleared = _sphere_box(g_world, ga, g_radius[ga] + b_margin[NB + nd] + g_grow[ga], box_lo, box_hi, G + nd)
            nd = walk[3 * nd + 2] if cleared else nd + 1
            continue
        nd += 1
        begin = b_end[blk - 1] if blk > 0 else 0
        stop = b_end[blk]
        ga, gb = b_a[blk], b_b[blk]
        if b_kind[blk] == 0:
            cleared = _sphere_box(g_world, ga, g_radius[ga] + b_margin[blk] + g_grow[ga], box_lo, box_hi, gb)
        else:
            cleared = _sphere_point(g_world, ga, g_world, gb, g_radius[ga] + g_radius[gb] + b_margin[blk]
                                    + g_grow[ga] + g_grow[gb])
        if cleared:
            continue
        any_live = False
        for m in range(begin, stop):
            k = b_pairs[m]
            if not active[k]:
                continue
            a, b = pair_a[k], pair_b[k]
            if grow[a] < 0.0:
                _place(rot, trans, piece_joint[a], centre, a, world)
                grow[a] = _growth(centre, a, piece_joint[a], lo, hi, parent, jtrans, jq, 0.0, np.int64(0))
            if pair_obstacle[k]:
                live[k] = not _sphere_box(world, a, radius[a] + margin[k] + grow[a], box_lo, box_hi, b)
                if live[k] and deep and ch_start[b] >= 0:
                    # The box and the spread are kept apart: `_pair_reach` may have computed the
                    # spread (for an obstacle without chunks) without placing the box.
                    if not boxed[a]:
                        _place_box(rot, trans, piece_joint[a], obb_c, obb_r, a, box_c, box_r)
                        boxed[a] = True
                    if spread[a] < 0.0:
                        spread[a] = _growth(centre, a, piece_joint[a], lo, hi, parent, jtrans, jq, radius[a], np.int64(0))
                    live[k] = False
                    c = ch_start[b]
                    while c < ch_end[b]:              # `_uncleared`'s traversal, every test grown
                        if _sphere_point(world, a, ch_c, c, radius[a] + ch_rad[c] + margin[k] + grow[a]) or \
                                boxes_apart(box_c, box_r, obb_h, a, ch_bc, ch_br, ch_h, c, margin[k] + spread[a],
                                             scratch):
                            c = ch_skip[c]
                        elif ch_skip[c] == c + 1:
                            live[k] = True
                            break
                        else:
                            c += 1
            else:
                if grow[b] < 0.0:
                    _place(rot, trans, piece_joint[b], centre, b, world)
                    grow[b] = _growth(centre, b, piece_joint[b], lo, hi, parent, jtrans, jq, 0.0, np.int64(0))
                live[k] = not _sphere_point(world, a, world, b, radius[a] + radius[b] + margin[k] + grow[a] + grow[b])
                if live[k] and deep:
                    for g in (a, b):
                        if not boxed[g]:
                            _place_box(rot, trans, piece_joint[g], obb_c, obb_r, g, box_c, box_r)
                            boxed[g] = True
                        if spread[g] < 0.0:
                            spread[g] = _growth(centre, g, piece_joint[g], lo, hi, parent, jtrans, jq, radius[g], np.int64(0))
                    live[k] = not boxes_apart(box_c, box_r, obb_h, a, box_c, box_r, obb_h, b,
                                               margin[k] + spread[a] + spread[b], scratch)
            if live[k] and deep:
                reach[k] = _pair_reach(centre, radius, piece_joint, a, b, pair_obstacle[k], lo, hi, parent, jtrans, jq,
                                       spread)
            any_live = any_live or live[k]
        keep[blk] = any_live             # a block without a live pair adds nothing
    return keep, live, reach


@helper
def _place(rot: Any, trans: Any, j: Any, local: Any, g: int, world: Any) -> None:
    for r in range(3):
        world[g, r] = trans[j, r] + rot[j, r, 0] * local[g, 0] + rot[j, r, 1] * local[g, 1] + rot[j, r, 2] * local[g, 2]


@helper
def _sphere_box(world: Any, a: int, reach: float, lo: Any, hi: Any, b: int) -> bool:
    """Whether sphere centre a is farther than `reach` from box b (an inf reach is never cleared)."""
    d2 = 0.0
    for r in range(3):
        c = world[a, r]
        e = lo[b, r] - c
        e = max(e, c - hi[b, r])
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
def _place_box(rot: Any, trans: Any, j: int, local_c: Any, local_r: Any, g: int, box_c: Any, box_r: Any) -> None:
    for r in range(3):
        box_c[g, r] = trans[j, r] + rot[j, r, 0] * local_c[g, 0] + rot[j, r, 1] * local_c[g, 1] \
            + rot[j, r, 2] * local_c[g, 2]
        for c in range(3):
            box_r[g, r, c] = rot[j, r, 0] * local_r[g, 0, c] + rot[j, r, 1] * local_r[g, 1, c] \
                + rot[j, r, 2] * local_r[g, 2, c]
