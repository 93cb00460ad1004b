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
exact verdict, only reached with fewer tests. A pair of two neighbouring robot pieces is also
cleared where the cell of its joints holding the configuration was certified free (`pair_cells`).
Spheres enclose each piece's support points (hull vertices, box corners), so they enclose the piece;
obstacle AABBs are taken over the same points in the base frame.

The chain is modelled as Pinocchio models it (each joint's placement in its parent, then the joint's
own motion); revolute and prismatic joints about any axis with one coordinate are supported. A model
with another joint kind (a continuous joint's cos/sin pair, a mimic joint) gets no filter, and its
world keeps coal's broad phase for every query.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.world.bounds import support_points, triangles
from robomax_py.world.cell_cache import decisions_key, shared_decisions
from robomax_py.world.pair_cells import PairCells, pair_cells
from robomax_py.world.prefilter_kernels import _near, _placements, _uncleared
from robomax_py.world.prefilter_layout import (
    B_MARGIN,
    MARGIN,
    N_FLOAT_TABLES,
    N_HEADER,
    N_INT_TABLES,
)
from robomax_py.world.prefilter_tree import TREE_MIN_BLOCKS, block_walk

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
    vectors: FloatArray          # (n, 3) view of floats: the tables of 3-vectors
    matrices: FloatArray         # (n, 3, 3) view of floats: the tables of 3x3 matrices
    ints: IntArray               # every integer table and the offsets of both, packed
    every_block: BoolArray       # (blocks,) all True: `uncleared` without `blocks`
    cells: PairCells             # the neighbouring pieces' cells and which are certified free (`pair_cells`)

    @staticmethod
    def of(model: pin.Model, gm: pin.GeometryModel, obstacle: list[bool], pair_a: IntArray, pair_b: IntArray,
           pair_margin: FloatArray, tree_min_blocks: int = TREE_MIN_BLOCKS) -> Prefilter | None:
        """The filter of a world's geometry, or None when the chain has a joint it does not model.
        tree_min_blocks: a joint group with this many obstacle blocks walks them by a box tree
        (`prefilter_tree`); the answers are the same either way."""
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
            if is_obs[b]:
                key = (0, ga, int(b))
            else:
                # (An obstacle's joint, the universe, has a group only when some robot piece is
                # fixed there too: not on an arm whose root link carries no geometry.)
                gb = group_of[int(piece_joint[b])]
                key = (1, min(ga, gb), max(ga, gb))
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
        counts = np.array([piece.chunk_count if piece is not None else 0 for piece in bounds_of], dtype=np.int64)
        skips = [piece.skip if piece is not None else [] for piece in bounds_of]
        ch_end = np.cumsum(counts).astype(np.int64)
        ch_start = ch_end - counts
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

        walk = block_walk(block_kind, block_a, block_b, block_margin, box_lo, box_hi, tree_min_blocks)
        cells, cell_ints, cell_lows = pair_cells(parent, kind, qi, model.lowerPositionLimit, model.upperPositionLimit,
                                                 piece_joint, pa, pb, is_obs)
        # The decisions other worlds of this arm and tool made, in this process or an earlier run.
        cells_key = decisions_key(model, gm, pa, pb, np.asarray(pair_margin, dtype=float), cells.tables)
        cells = replace(cells, decided=shared_decisions(cells_key, len(cells.decided)))

        # The walk's boxes and margins ride in the pieces' and blocks' tables, its ints in one table:
        # each table more is a slice more for numba to compile in every kernel.
        floats, vectors, matrices, ints = _pack(
            [axis, rot, trans, centre, radius, np.concatenate([box_lo, walk.lo]), np.concatenate([box_hi, walk.hi]),
             margin, g_centre, g_radius, np.concatenate([block_margin, walk.margin]),
             obb_centre, obb_axes, obb_half, ch_centre, ch_radius, ch_box_c, ch_box_r, ch_half, cell_lows.ravel()],
            [parent, kind, qi, piece_joint, robot_side, other, is_obs[other].astype(np.int64), group_joint,
             block_kind, block_a, block_b, block_end, block_pairs, ch_start, ch_end, ch_skip,
             np.stack([walk.block, walk.group, walk.skip], axis=1).ravel(), cell_ints.ravel()],
            int(counts.sum()), len(walk.block),
        )
        return Prefilter(floats=floats, vectors=vectors, matrices=matrices, ints=ints,
                         every_block=np.ones(len(keys), dtype=bool), cells=cells)

    def uncleared(self, qs: FloatArray, active: BoolArray, blocks: BoolArray | None = None,
                  rows: IntArray | None = None) -> tuple[IntArray, IntArray]:
        """For each configuration of qs (k, n), the active pairs it does not clear.

        blocks: which blocks to test (`near`: the others are cleared at every configuration of qs, and
        skipped: the same answer with fewer tests); None: every block.
        rows: per configuration, the row of `active` (r, p) and `blocks` (r, b) it takes (each row
        the `near` of a part of qs); None: `active` (p,) and `blocks` (b,) for all.
        Returns (offsets (k + 1,), pairs): configuration i's pairs are pairs[offsets[i]:offsets[i + 1]],
        in pair order.
        """
        offsets, pairs, _ = self.left_for_coal(qs, active, blocks, rows)
        return offsets, pairs

    def left_for_coal(self, qs: FloatArray, active: BoolArray, blocks: BoolArray | None = None,
                      rows: IntArray | None = None) -> tuple[IntArray, IntArray, BoolArray]:
        """`uncleared`, and for each configuration whether one of its pairs lies in a cell not decided
        yet (`pair_cells`: the caller decides it before coal's test, `CollisionWorldCore._exact`)."""
        if rows is None:
            rows = np.zeros(len(qs), dtype=np.int64)
            active = active[None]
            blocks = (self.every_block if blocks is None else blocks)[None]
        elif blocks is None:
            blocks = np.broadcast_to(self.every_block, (len(active), len(self.every_block)))
        # The offsets come from the kernel: numpy's concatenate and cumsum of per-configuration counts
        # cost about two configurations' tests on every call.
        offsets, pairs, undecided = _uncleared(_read_only(qs), self.floats, self.vectors, self.matrices, self.ints,
                                               np.ascontiguousarray(active), np.ascontiguousarray(blocks),
                                               np.ascontiguousarray(rows, dtype=np.int64), self.cells.decided)
        return offsets, pairs, undecided

    def with_margin(self, distance: float) -> Prefilter:
        """This filter with `distance` (m) as every pair's margin (SLACK_M added, as to every margin):
        a pair its `uncleared` leaves out at a configuration is there provably farther apart than
        `distance`, so a search for the least distance need not compute it. Every block's and every
        node's margin (the largest of the pairs' under it) is `distance` too. distance >= 0: the
        bounds say nothing of how deep two pieces that overlap are."""
        if not distance >= 0.0:
            raise ValueError(f"a screen's distance must be >= 0 m, got {distance}")
        ints = self.ints
        n_pairs, n_blocks, n_nodes = int(ints[2]), int(ints[4]), int(ints[6])
        pairs_at, blocks_at = int(ints[MARGIN]), int(ints[B_MARGIN])
        floats = self.floats.copy()        # only the scalar tables are read from it; the views stay
        floats[pairs_at:pairs_at + n_pairs] = distance + SLACK_M
        floats[blocks_at:blocks_at + n_blocks + n_nodes] = distance + SLACK_M
        # A cell certified free for the pairs' own margins says nothing of this distance.
        return replace(self, floats=floats, cells=self.cells.undecided())

    def near(self, qs: FloatArray, active: BoolArray) -> tuple[BoolArray, BoolArray]:
        """(blocks (b,) bool, pairs (p,) bool): the blocks, and the pairs of `active`, that a
        configuration in the joint-space box spanned by qs (k, n) may not clear; the others are
        cleared at every configuration of the box, so `uncleared(q, pairs, blocks)` of any q in it
        gives what `uncleared(q, active)` gives (`prefilter_kernels._near`)."""
        blocks, pairs, _ = _near(_read_only(qs), self.floats, self.vectors, self.matrices, self.ints, active, False)
        return blocks, pairs

    def near_reach(self, qs: FloatArray, active: BoolArray) -> tuple[BoolArray, BoolArray, FloatArray]:
        """`near(qs, active)` with the finer tests (chunks, oriented boxes) at the box's centre too,
        grown by the box's motion: fewer pairs, each left out provably free at every configuration of
        the box, though `uncleared` of one might have left it to coal (so the same verdicts, perhaps
        from fewer exact tests). Also, for each pair left, how much its distance can shrink between
        the centre of qs's box ((min + max) / 2 per joint) and any configuration of the box (m; inf
        for the others): a pair farther apart at the centre than its margin plus its reach is farther
        apart than its margin at every configuration of the box."""
        blocks, pairs, reach = _near(_read_only(qs), self.floats, self.vectors, self.matrices, self.ints, active, True)
        return blocks, pairs, reach

    def joint_placements(self, q: FloatArray) -> tuple[FloatArray, FloatArray]:
        """(J, 3, 3) rotations and (J, 3) translations of every joint frame at q (as Pinocchio's oMi)."""
        q = np.ascontiguousarray(q, dtype=np.float64)
        return _placements(q, self.floats, self.vectors, self.matrices, self.ints)  # type: ignore[no-any-return]


def _read_only(qs: FloatArray) -> FloatArray:
    """qs as a contiguous float64 read-only view: numba compiles one specialisation per array type,
    and a writable and a read-only batch are two (each about half a kernel's compile time on a
    first plan)."""
    batch = np.ascontiguousarray(qs, dtype=np.float64).view()
    batch.flags.writeable = False
    return batch


@dataclass(frozen=True, slots=True, eq=False)
class _PieceBounds:
    """One piece's enclosing volumes at its placement in its joint (or the base) frame."""

    geometry: Any                # held, so that no other piece takes its id while the entry lives
    placed: FloatArray           # its support points
    sphere: tuple[FloatArray, float]
    box: tuple[FloatArray, FloatArray, FloatArray]
    # An obstacle's chunk tree (`_mesh_chunks`), by its nodes' volumes: the nodes' point sets are
    # not kept (a 790,000-triangle part's were 71 MB a placement, and this table outlives worlds).
    chunk_count: int
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
    # Each sphere is centred on its points' box: the box is computed once for both.
    box = _enclosing_box(placed)
    boxes = [_enclosing_box(c) for c in nodes]
    entry = _PieceBounds(geom, placed, _enclosing_sphere(placed, box), box, len(nodes), skip,
                         [_enclosing_sphere(c, b) for c, b in zip(nodes, boxes)], boxes)
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


def _enclosing_sphere(points: FloatArray,
                      box: tuple[FloatArray, FloatArray, FloatArray] | None = None) -> tuple[FloatArray, float]:
    """A sphere containing every point: centred on the middle of the points' principal box
    (`box`, their `_enclosing_box` where the caller has it already), its radius measured to every
    point and padded against rounding (within a few per cent of the smallest sphere on the shipped
    pieces, at a tenth of the time of an exact solver)."""
    c, _, _ = _enclosing_box(points) if box is None else box
    r = float(np.linalg.norm(points - c, axis=1).max())
    return c, r * (1 + 1e-9) + 1e-9


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


def _pack(floats: list[FloatArray], ints: list[IntArray], n_chunks: int,
          n_nodes: int) -> tuple[FloatArray, FloatArray, FloatArray, IntArray]:
    """Every table in one float and one int buffer, so a call unboxes a few arrays, not forty.

    The float buffer holds the scalar tables, then the tables of 3-vectors, then those of 3x3
    matrices; the kernels take it whole and as (n, 3) and (n, 3, 3) views of its two later parts,
    and read a table's row at the table's start plus the row in one of them. Each table reshaped in
    the kernels instead (`F[a:b].reshape((G, 3))`) cost numba about 0.05 s of compile apiece, 14 of
    them about 0.75 s of a first plan; each a slice, about a third of the kernels' compile.

    ints starts with the header, then the start of each float table, then of each int table
    (`prefilter_layout`).
    Returns (floats, vectors, matrices, ints).
    """
    parent, piece_joint, pair_a, group_joint, block_kind = ints[0], ints[3], ints[4], ints[7], ints[8]
    header = [len(parent), len(piece_joint), len(pair_a), len(group_joint), len(block_kind), n_chunks, n_nodes]
    tables = [np.ascontiguousarray(a, dtype=float) for a in floats]
    parts: list[list[FloatArray]] = [[], [], []]      # scalars, 3-vectors, 3x3 matrices
    f_starts = []
    for a in tables:
        part = parts[a.ndim - 1]
        f_starts.append(sum(len(b) for b in part))
        part.append(a)
    assert (len(header), len(floats), len(ints)) == (N_HEADER, N_FLOAT_TABLES, N_INT_TABLES), "see prefilter_layout"
    n_head = len(header) + len(floats) + len(ints)
    i_starts = n_head + np.cumsum([0] + [a.size for a in ints])[:-1]
    flat_f = np.concatenate([a.ravel() for part in parts for a in part])
    n1, n3 = sum(len(a) for a in parts[0]), sum(len(a) for a in parts[1])
    vectors = flat_f[n1:n1 + 3 * n3].reshape(-1, 3)
    matrices = flat_f[n1 + 3 * n3:].reshape(-1, 3, 3)
    flat_i = np.concatenate([np.array(header + f_starts + list(i_starts), dtype=np.int64)]
                            + [np.ascontiguousarray(a, dtype=np.int64).ravel() for a in ints])
    return flat_f, vectors, matrices, flat_i


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


