"""Bounding-volume pre-filter: the enabled pairs of a configuration that coal must still decide.

coal's broad phase costs ~10 us a configuration on a 40-piece cell, almost all of it in the naive
manager's 780 AABB tests, AABB updates and pair look-ups, while only ~1.7 pairs a configuration
reach the narrow phase. This filter does the broad phase for a whole batch of configurations in one
compiled loop (numba): forward kinematics of the serial chain, one enclosing sphere per moving
piece, and for every enabled pair a lower bound on its distance,

- robot/tool piece vs obstacle: distance from the sphere's centre to the obstacle's world AABB,
  minus the radius;
- robot/tool piece vs robot/tool piece: distance between the centres minus both radii.

A pair whose bound exceeds its margin (the clearance, or 0 between robot bodies) by `SLACK_M` is
*cleared*: its true distance exceeds the margin, so coal would call it free. Every other pair is
returned, and the caller gives it to coal's exact test; so the verdict of a configuration is coal's
exact verdict, only reached with fewer tests. Spheres enclose each piece's support points (hull
vertices, box corners), so they enclose the piece; obstacle AABBs are taken over the same points in
the base frame.

The chain is modelled as Pinocchio models it (each joint's placement in its parent, then the joint's
own motion); revolute and prismatic joints about any axis with one coordinate are supported. A model
with another joint kind (a continuous joint's cos/sin pair, a mimic joint) gets no filter, and its
world keeps coal's broad phase for every query.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass
from typing import Any

import coal
import numpy as np
import pinocchio as pin
from numba import njit

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.world.bounds import support_points, triangles

SLACK_M = 1e-6                 # m: a cleared pair's bound exceeds its margin by this (GJK decides to ~1e-9 m)
_REVOLUTE, _PRISMATIC = 0, 1
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


@dataclass(frozen=True, slots=True, eq=False)
class Prefilter:
    """The packed arrays the compiled filter reads (see `_pack`); built once per world by `of`.

    Pairs are tested in blocks: all pairs between the pieces of one joint and one obstacle piece, or
    between the pieces of two joints. A block whose joint's enclosing sphere clears its partner
    (the obstacle's AABB, or the other joint's sphere) clears all its pairs in one test.
    """

    floats: FloatArray           # every float table, packed (see `_pack`)
    ints: IntArray               # every integer table and the offsets of both, packed

    @staticmethod
    def of(model: pin.Model, gm: pin.GeometryModel, obstacle: list[bool], pair_a: IntArray, pair_b: IntArray,
           pair_margin: FloatArray) -> Prefilter | None:
        """The filter of a world's geometry, or None when the chain has a joint it does not model."""
        chain = _chain(model)
        if chain is None:
            return None
        parent, kind, axis, rot, trans, qi = chain
        n_geom = gm.ngeoms
        centre = np.zeros((n_geom, 3))
        radius = np.full(n_geom, np.inf)
        box_lo = np.full((n_geom, 3), -np.inf)
        box_hi = np.full((n_geom, 3), np.inf)
        piece_joint = np.zeros(n_geom, dtype=np.int64)
        obb_centre = np.zeros((n_geom, 3))
        obb_axes = np.tile(np.eye(3), (n_geom, 1, 1))
        obb_half = np.full((n_geom, 3), np.inf)
        points_of: list[FloatArray | None] = []
        bounds_of: list[_PieceBounds | None] = []
        for g, obj in enumerate(gm.geometryObjects):
            piece_joint[g] = int(obj.parentJoint)
            piece = _piece_bounds(obj.geometry, obj.placement.homogeneous, bool(obstacle[g]))
            bounds_of.append(piece)
            if piece is None:
                points_of.append(None)
                continue                                      # unbounded shape: never cleared
            points_of.append(piece.placed)
            if obstacle[g]:
                box_lo[g], box_hi[g] = piece.placed.min(axis=0), piece.placed.max(axis=0)
            centre[g], radius[g] = piece.sphere
            obb_centre[g], obb_axes[g], obb_half[g] = piece.box
        is_obs = np.asarray(obstacle, dtype=bool)
        pa, pb = np.asarray(pair_a, dtype=np.int64), np.asarray(pair_b, dtype=np.int64)
        swap = is_obs[pa]                                     # the robot piece first
        robot_side, other = np.where(swap, pb, pa), np.where(swap, pa, pb)
        margin = np.asarray(pair_margin, dtype=float) + SLACK_M

        # Groups: the robot pieces of one joint, with a sphere enclosing all their points.
        joints = sorted({int(piece_joint[g]) for g in (*robot_side, *other) if not is_obs[g]})
        group_of = {j: n for n, j in enumerate(joints)}
        g_centre = np.zeros((len(joints), 3))
        g_radius = np.full(len(joints), np.inf)
        for j in joints:
            members = [points_of[g] for g in range(n_geom) if not is_obs[g] and piece_joint[g] == j]
            present = [m for m in members if m is not None]
            if len(present) == len(members):
                g_centre[group_of[j]], g_radius[group_of[j]] = _enclosing_sphere(np.concatenate(present))
        # Blocks: (group, obstacle piece) or (group, group), each with its pairs.
        blocks: dict[tuple[int, int, int], list[int]] = {}
        for k, (a, b) in enumerate(zip(robot_side, other)):
            ga = group_of[int(piece_joint[a])]
            gb = group_of[int(piece_joint[b])]
            key = (0, ga, int(b)) if is_obs[b] else (1, min(ga, gb), max(ga, gb))
            blocks.setdefault(key, []).append(k)
        keys = list(blocks)
        block_kind = np.array([key[0] for key in keys], dtype=np.int64)
        block_a = np.array([key[1] for key in keys], dtype=np.int64)
        block_b = np.array([key[2] for key in keys], dtype=np.int64)
        block_margin = np.array([max(margin[k] for k in blocks[key]) for key in keys])
        block_end = np.cumsum([len(blocks[key]) for key in keys]).astype(np.int64)
        block_pairs = np.array([k for key in keys for k in blocks[key]], dtype=np.int64)
        group_joint = np.array(joints, dtype=np.int64)

        # Obstacle chunks: an unbounded obstacle has none, and is never cleared.
        chunks = [piece.chunks if piece is not None else [] for piece in bounds_of]
        skips = [piece.skip if piece is not None else [] for piece in bounds_of]
        flat = [c for piece in chunks for c in piece]
        ch_end = np.cumsum([len(c) for c in chunks]).astype(np.int64)
        ch_start = ch_end - np.array([len(c) for c in chunks], dtype=np.int64)
        ch_skip = np.array([int(start) + k for start, skip in zip(ch_start, skips) for k in skip], dtype=np.int64)
        for g in range(n_geom):
            if is_obs[g] and points_of[g] is None:
                ch_start[g] = ch_end[g] = -1
        spheres = [s for piece in bounds_of if piece is not None for s in piece.chunk_spheres]
        boxes = [b for piece in bounds_of if piece is not None for b in piece.chunk_boxes]
        ch_centre = np.array([c for c, _ in spheres]).reshape(-1, 3)
        ch_radius = np.array([r for _, r in spheres], dtype=float)
        ch_box_c = np.array([b[0] for b in boxes]).reshape(-1, 3)
        ch_box_r = np.array([b[1] for b in boxes]).reshape(-1, 3, 3)
        ch_half = np.array([b[2] for b in boxes]).reshape(-1, 3)

        floats, ints = _pack(
            [axis, rot, trans, centre, radius, box_lo, box_hi, margin, g_centre, g_radius, block_margin,
             obb_centre, obb_axes, obb_half, ch_centre, ch_radius, ch_box_c, ch_box_r, ch_half],
            [parent, kind, qi, piece_joint, robot_side, other, is_obs[other].astype(np.int64), group_joint,
             block_kind, block_a, block_b, block_end, block_pairs, ch_start, ch_end, ch_skip],
            len(flat),
        )
        return Prefilter(floats=floats, ints=ints)

    def uncleared(self, qs: FloatArray, active: BoolArray) -> tuple[IntArray, IntArray]:
        """For each configuration of qs (k, n), the active pairs it does not clear.

        Returns (offsets (k + 1,), pairs): configuration i's pairs are pairs[offsets[i]:offsets[i + 1]],
        in pair order.
        """
        # Always a read-only view: numba compiles one specialisation per array type, and a writable
        # and a read-only batch are two (each about half the kernel's compile time on a first plan).
        batch = np.ascontiguousarray(qs, dtype=np.float64).view()
        batch.flags.writeable = False
        counts, pairs = _uncleared(batch, self.floats, self.ints, active)
        return np.concatenate([[0], np.cumsum(counts)]).astype(np.int64), pairs

    def joint_placements(self, q: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(J, 3, 3) rotations and (J, 3) translations of every joint frame at q (as Pinocchio's oMi)."""
        return _placements(np.ascontiguousarray(q, dtype=np.float64), self.floats, self.ints)  # type: ignore[no-any-return]


@dataclass(frozen=True, slots=True, eq=False)
class _PieceBounds:
    """One piece's enclosing volumes at its placement in its joint (or the base) frame."""

    geometry: Any                # held, so that no other piece takes its id while the entry lives
    placed: FloatArray           # its support points
    sphere: tuple[FloatArray, float]
    box: tuple[FloatArray, FloatArray, FloatArray]
    chunks: list[FloatArray]     # an obstacle's chunk tree (`_mesh_chunks`); none for a robot piece
    skip: list[int]
    chunk_spheres: list[tuple[FloatArray, float]]
    chunk_boxes: list[tuple[FloatArray, FloatArray, FloatArray]]


# Worlds of one process share their pieces' coal geometry (the robot's link geometry and a cell's
# meshes are loaded once: robot.model, world.scene), and a piece's volumes depend only on its
# geometry and placement, so each is computed once: a verify or a batch builds the same world many
# times, and these volumes were the most of a world's build. Bounded; the oldest entries go first.
_BOUNDS: OrderedDict[tuple[int, bytes, bool], _PieceBounds] = OrderedDict()
_BOUNDS_SIZE = 4096


def _piece_bounds(geom: Any, placement: FloatArray, obstacle: bool) -> _PieceBounds | None:
    """The volumes of a piece `geom` at `placement`; None for an unbounded shape."""
    key = (id(geom), np.asarray(placement, dtype=float).tobytes(), obstacle)
    hit = _BOUNDS.get(key)
    if hit is not None and hit.geometry is geom:
        _BOUNDS.move_to_end(key)
        return hit
    placed = support_points(geom, placement)
    if not np.isfinite(placed).all():
        return None
    nodes, skip = _mesh_chunks(geom, placed) if obstacle else ([], [])
    entry = _PieceBounds(geom, placed, _enclosing_sphere(placed), _enclosing_box(placed), nodes, skip,
                         [_enclosing_sphere(c) for c in nodes], [_enclosing_box(c) for c in nodes])
    _BOUNDS[key] = entry
    while len(_BOUNDS) > _BOUNDS_SIZE:
        _BOUNDS.popitem(last=False)
    return entry


def _enclosing_box(points: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """An oriented box containing every point: centre, axes (columns) and half extents, padded.

    Along the points' principal axes (a tenth of the time of trimesh's minimum-volume box, and on
    the shipped arms' pieces as good a filter); the extents are measured to every point."""
    centred = points - points.mean(axis=0)
    _, axes = np.linalg.eigh(centred.T @ centred)        # columns: orthonormal principal axes
    local = points @ axes
    lo, hi = local.min(axis=0), local.max(axis=0)
    half = (hi - lo) / 2 * (1 + 1e-9) + 1e-9
    return axes @ ((lo + hi) / 2), axes, half


def _enclosing_sphere(points: FloatArray) -> tuple[FloatArray, float]:
    """A sphere containing every point: centred on the middle of the points' principal box, its
    radius measured to every point and padded against rounding (within a few per cent of the
    smallest sphere on the shipped pieces, at a tenth of the time of an exact solver)."""
    c, _, _ = _enclosing_box(points)
    r = float(np.linalg.norm(points - c, axis=1).max())
    return c, r * (1 + 1e-9) + 1e-9


_N_HEADER, _N_FLOAT_TABLES, _N_INT_TABLES = 6, 19, 16
CHUNK_SIZE_M = 0.12            # an obstacle mesh is covered by chunks about this size (each its own box)
CHUNK_MIN_TRIANGLES = 64       # meshes with fewer triangles are one chunk


def _mesh_chunks(geom: Any, placed: FloatArray) -> tuple[list[FloatArray], list[int]]:
    """A tree of point sets whose convex hulls cover an obstacle piece, in pre-order, and for each
    node the index just past its subtree (where a traversal goes when the node is cleared).

    A mesh (coal BVH: a triangle surface, which is all coal collides with) is split by triangle
    centroids at the median of the longest side, until a node is within CHUNK_SIZE_M or holds one
    triangle; a node's points are its triangles' vertices, so its hull holds all its triangles and
    a node's children together hold its triangles. Anything else (a convex piece, a box) is one
    node: its own points.
    """
    if not isinstance(geom, coal.BVHModelBase) or geom.num_tris < CHUNK_MIN_TRIANGLES:
        return [placed], [1]
    tris = triangles(geom)
    centroid = placed[tris].mean(axis=1)
    nodes: list[FloatArray] = []
    skip: list[int] = []

    def visit(idx: IntArray) -> None:
        pts = placed[np.unique(tris[idx])]
        me = len(nodes)
        nodes.append(pts)
        skip.append(-1)
        span = pts.max(axis=0) - pts.min(axis=0)
        if len(idx) > 1 and span.max() > CHUNK_SIZE_M:
            order = idx[np.argsort(centroid[idx, int(np.argmax(span))], kind="stable")]
            visit(order[: len(order) // 2])
            visit(order[len(order) // 2:])
        skip[me] = len(nodes)

    visit(np.arange(len(tris)))
    return nodes, skip


def _pack(floats: list[FloatArray], ints: list[IntArray], n_chunks: int) -> tuple[FloatArray, IntArray]:
    """Every table in one float and one int buffer, so a call unboxes four arrays, not forty.

    ints starts with J (joints), G (pieces), P (pairs), NG (groups), NB (blocks), C (obstacle
    chunks), then the start of each float table in `floats`, then the start of each int table.
    """
    parent, piece_joint, pair_a, group_joint, block_kind = ints[0], ints[3], ints[4], ints[7], ints[8]
    header = [len(parent), len(piece_joint), len(pair_a), len(group_joint), len(block_kind), n_chunks]
    f_starts = np.cumsum([0] + [a.size for a in floats])[:-1]
    n_head = len(header) + len(floats) + len(ints)
    i_starts = n_head + np.cumsum([0] + [a.size for a in ints])[:-1]
    flat_f = np.concatenate([np.ascontiguousarray(a, dtype=float).ravel() for a in floats])
    flat_i = np.concatenate([np.array(header + list(f_starts) + list(i_starts), dtype=np.int64)]
                            + [np.ascontiguousarray(a, dtype=np.int64).ravel() for a in ints])
    return flat_f, flat_i


def _chain(model: pin.Model) -> tuple[IntArray, IntArray, FloatArray, FloatArray, FloatArray, IntArray] | None:
    n = model.njoints
    parent = np.array([int(p) for p in model.parents], dtype=np.int64)
    kind = np.zeros(n, dtype=np.int64)
    axis = np.zeros((n, 3))
    rot = np.tile(np.eye(3), (n, 1, 1))
    trans = np.zeros((n, 3))
    qi = np.zeros(n, dtype=np.int64)
    for j in range(1, n):
        joint = model.joints[j]
        name = joint.shortname()
        if joint.nq != 1 or joint.nv != 1:
            return None
        if name in ("JointModelRX", "JointModelRY", "JointModelRZ"):
            kind[j], axis[j] = _REVOLUTE, _AXES[name[-1]]
        elif name in ("JointModelPX", "JointModelPY", "JointModelPZ"):
            kind[j], axis[j] = _PRISMATIC, _AXES[name[-1]]
        elif name == "JointModelRevoluteUnaligned":
            kind[j], axis[j] = _REVOLUTE, np.asarray(joint.extract().axis, dtype=float)
        elif name == "JointModelPrismaticUnaligned":
            kind[j], axis[j] = _PRISMATIC, np.asarray(joint.extract().axis, dtype=float)
        else:
            return None
        placement = model.jointPlacements[j]
        rot[j], trans[j] = np.asarray(placement.rotation), np.asarray(placement.translation)
        qi[j] = int(joint.idx_q)
    return parent, kind, axis, rot, trans, qi


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def _offsets(I: Any) -> Any:
    """Where each float and each int table starts in the packed buffers (see `_pack`)."""
    fo = I[_N_HEADER:_N_HEADER + _N_FLOAT_TABLES]
    io = I[_N_HEADER + _N_FLOAT_TABLES:_N_HEADER + _N_FLOAT_TABLES + _N_INT_TABLES]
    return fo, io


@njit(cache=True, nogil=True)
def _chain_tables(F: Any, I: Any) -> Any:
    """The chain's tables in `_forward`'s argument order: parent, kind, axis, rotation, translation, q index."""
    J = I[0]
    fo, io = _offsets(I)
    return (I[io[0]:io[0] + J], I[io[1]:io[1] + J], F[fo[0]:fo[0] + 3 * J].reshape((J, 3)),
            F[fo[1]:fo[1] + 9 * J].reshape((J, 3, 3)), F[fo[2]:fo[2] + 3 * J].reshape((J, 3)), I[io[2]:io[2] + J])


@njit(cache=True, nogil=True)
def _placements(q: Any, F: Any, I: Any) -> Any:
    J = I[0]
    parent, kind, axis, jrot, jtrans, jq = _chain_tables(F, I)
    rot = np.empty((J, 3, 3))
    trans = np.empty((J, 3))
    _forward(q, parent, kind, axis, jrot, jtrans, jq, rot, trans)
    return rot, trans


@njit(cache=True, nogil=True)
def _uncleared(qs: Any, F: Any, I: Any, active: Any) -> Any:
    J, G, P, NG, NB, C = I[0], I[1], I[2], I[3], I[4], I[5]
    fo, io = _offsets(I)
    parent, kind, axis, jrot, jtrans, jq = _chain_tables(F, I)
    centre = F[fo[3]:fo[3] + 3 * G].reshape((G, 3))
    radius = F[fo[4]:fo[4] + G]
    box_lo = F[fo[5]:fo[5] + 3 * G].reshape((G, 3))
    box_hi = F[fo[6]:fo[6] + 3 * G].reshape((G, 3))
    margin = F[fo[7]:fo[7] + P]
    g_centre = F[fo[8]:fo[8] + 3 * NG].reshape((NG, 3))
    g_radius = F[fo[9]:fo[9] + NG]
    b_margin = F[fo[10]:fo[10] + NB]
    obb_c = F[fo[11]:fo[11] + 3 * G].reshape((G, 3))
    obb_r = F[fo[12]:fo[12] + 9 * G].reshape((G, 3, 3))
    obb_h = F[fo[13]:fo[13] + 3 * G].reshape((G, 3))
    ch_c = F[fo[14]:fo[14] + 3 * C].reshape((C, 3))
    ch_rad = F[fo[15]:fo[15] + C]
    ch_bc = F[fo[16]:fo[16] + 3 * C].reshape((C, 3))
    ch_br = F[fo[17]:fo[17] + 9 * C].reshape((C, 3, 3))
    ch_h = F[fo[18]:fo[18] + 3 * C].reshape((C, 3))
    piece_joint = I[io[3]:io[3] + G]
    pair_a, pair_b, pair_obstacle = I[io[4]:io[4] + P], I[io[5]:io[5] + P], I[io[6]:io[6] + P]
    group_joint = I[io[7]:io[7] + NG]
    b_kind, b_a, b_b, b_end = I[io[8]:io[8] + NB], I[io[9]:io[9] + NB], I[io[10]:io[10] + NB], I[io[11]:io[11] + NB]
    b_pairs = I[io[12]:io[12] + P]
    ch_start, ch_end, ch_skip = I[io[13]:io[13] + G], I[io[14]:io[14] + G], I[io[15]:io[15] + C]

    n_cfg = qs.shape[0]
    rot = np.empty((J, 3, 3))
    trans = np.empty((J, 3))
    world = np.empty((G, 3))
    g_world = np.empty((NG, 3))
    box_c = np.empty((G, 3))
    box_r = np.empty((G, 3, 3))
    placed = np.zeros(G, dtype=np.bool_)     # world box of the piece computed for this configuration
    counts = np.zeros(n_cfg, dtype=np.int64)
    out = np.empty(n_cfg * P, dtype=np.int64)
    filled = 0
    for i in range(n_cfg):
        _forward(qs[i], parent, kind, axis, jrot, jtrans, jq, rot, trans)
        for g in range(G):
            _place(rot, trans, piece_joint[g], centre, g, world)
        for g in range(NG):
            _place(rot, trans, group_joint[g], g_centre, g, g_world)
        placed[:] = False
        first = filled
        begin = 0
        for blk in range(NB):
            stop = b_end[blk]
            ga, gb = b_a[blk], b_b[blk]
            if b_kind[blk] == 0:
                cleared = _sphere_box(g_world, ga, g_radius[ga] + b_margin[blk], box_lo, box_hi, gb)
            else:
                cleared = _sphere_point(g_world, ga, g_world, gb, g_radius[ga] + g_radius[gb] + b_margin[blk])
            if not cleared:
                for n in range(begin, stop):
                    k = b_pairs[n]
                    if not active[k]:
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
                                        _boxes_apart(box_c, box_r, obb_h, a, ch_bc, ch_br, ch_h, c, margin[k]):
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
                            ok = _boxes_apart(box_c, box_r, obb_h, a, box_c, box_r, obb_h, b, margin[k])
                    if not ok:
                        out[filled] = k
                        filled += 1
            begin = stop
        for n in range(first + 1, filled):      # into pair order: a few entries, insertion sort
            k = out[n]
            m = n - 1
            while m >= first and out[m] > k:
                out[m + 1] = out[m]
                m -= 1
            out[m + 1] = k
        counts[i] = filled - first
    return counts, out[:filled]


@njit(cache=True, nogil=True)
def _place(rot: Any, trans: Any, j: int, local: Any, g: int, world: Any) -> None:
    for r in range(3):
        world[g, r] = trans[j, r] + rot[j, r, 0] * local[g, 0] + rot[j, r, 1] * local[g, 1] + rot[j, r, 2] * local[g, 2]


@njit(cache=True, nogil=True)
def _sphere_box(world: Any, a: int, reach: float, lo: Any, hi: Any, b: int) -> bool:
    """Whether sphere centre a is farther than `reach` from box b (an inf reach is never cleared)."""
    d2 = 0.0
    for r in range(3):
        c = world[a, r]
        e = lo[b, r] - c
        if c - hi[b, r] > e:
            e = c - hi[b, r]
        if e > 0.0:
            d2 += e * e
    return d2 > reach * reach


@njit(cache=True, nogil=True)
def _sphere_point(world: Any, a: int, points: Any, c: int, reach: float) -> bool:
    """Whether point world[a] is farther than `reach` from point points[c]."""
    d2 = 0.0
    for r in range(3):
        e = world[a, r] - points[c, r]
        d2 += e * e
    return d2 > reach * reach


@njit(cache=True, nogil=True)
def _place_box(rot: Any, trans: Any, j: int, local_c: Any, local_r: Any, g: int, box_c: Any, box_r: Any) -> None:
    for r in range(3):
        box_c[g, r] = trans[j, r] + rot[j, r, 0] * local_c[g, 0] + rot[j, r, 1] * local_c[g, 1] \
            + rot[j, r, 2] * local_c[g, 2]
        for c in range(3):
            box_r[g, r, c] = rot[j, r, 0] * local_r[g, 0, c] + rot[j, r, 1] * local_r[g, 1, c] \
                + rot[j, r, 2] * local_r[g, 2, c]


@njit(cache=True, nogil=True)
def _boxes_apart(ca: Any, ra: Any, ha: Any, a: int, cb: Any, rb: Any, hb: Any, b: int, gap: float) -> bool:
    """Whether oriented box a (centre ca[a], axes the columns of ra[a], half extents ha[a]) and box b
    are more than `gap` apart along one of the 15 separating axes (Gottschalk's test; a cross-product
    axis's gap scaled by its length). False proves nothing."""
    ea, eb = ha[a], hb[b]
    if not (np.isfinite(ea[0]) and np.isfinite(eb[0])):
        return False
    R = np.empty((3, 3))
    AbsR = np.empty((3, 3))
    t = np.empty(3)
    for i in range(3):
        t[i] = 0.0
        for k in range(3):
            t[i] += ra[a, k, i] * (cb[b, k] - ca[a, k])
        for j in range(3):
            v = 0.0
            for k in range(3):
                v += ra[a, k, i] * rb[b, k, j]
            R[i, j] = v
            AbsR[i, j] = abs(v) + 1e-9          # near-parallel edges: no false separation
    for i in range(3):
        if abs(t[i]) > ea[i] + eb[0] * AbsR[i, 0] + eb[1] * AbsR[i, 1] + eb[2] * AbsR[i, 2] + gap:
            return True
    for j in range(3):
        if abs(t[0] * R[0, j] + t[1] * R[1, j] + t[2] * R[2, j]) > \
                ea[0] * AbsR[0, j] + ea[1] * AbsR[1, j] + ea[2] * AbsR[2, j] + eb[j] + gap:
            return True
    for i in range(3):
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            length = math.sqrt(max(0.0, 1.0 - R[i, j] * R[i, j]))
            if length < 1e-6:
                continue
            ra = ea[i1] * AbsR[i2, j] + ea[i2] * AbsR[i1, j]
            rb = eb[j1] * AbsR[i, j2] + eb[j2] * AbsR[i, j1]
            if abs(t[i2] * R[i1, j] - t[i1] * R[i2, j]) > ra + rb + gap * length:
                return True
    return False
