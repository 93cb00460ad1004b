"""A finer certificate for a cell of two neighbouring pieces (`pair_cells`): how much their distance
can shrink over the cell, bounded slab by slab of the moving piece.

The cells' first test (`Prefilter.near_reach`) bounds the shrink by the farther piece's enclosing
sphere: its radius plus its distance from each joint's origin, times the joint's half-width. On a
UR10 the base and the upper arm are about 19 mm apart at nearly every state (the shoulder's end of
the upper arm turns about its own axis above the base), but the upper arm is 0.6 m long, so that
bound is about 40 mm for a 0.05 rad cell: none of the 4,485 cells a box cell's plan reached was
certified, and coal tested the pair at 815,000 of the plan's 1.5 million exact tests.

Here the moving piece is cut into slabs across its longest principal axis. A slab's points move by
at most their distance from each joint's axis (the joint's speed of the slab's sphere, from the
world Jacobian at the cell's centre) times the joint's half-width, plus what the joints after it
moved them by, summed from the moving piece's joint towards the other piece. The slab near the other
piece sits close to the joints' axes; the slabs far along the arm move more, but are farther away:
each slab's distance at the centre is at least coal's distance of the two pieces, and at least its
sphere's distance from the other piece's enclosing box. The pair is free over the cell when every
slab's lower distance less its shrink exceeds the pair's margin.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray, IntArray
from robomax_py.world.bounds import joint_path, support_points
from robomax_py.world.prefilter import _enclosing_box, _enclosing_sphere

# Slabs the moving piece is cut into. On the UR10 box cell's uncertified base/upper-arm cells,
# 8 slabs certified 61 % of a sample, 24 slabs 65 %: the slab nearest the base, not their number,
# sets the bound.
SLABS = 16

# Per geometry model and pair: the worlds of one process share their geometry model, and a plan
# decides thousands of cells of the same few pairs (`prefilter._BOUNDS` keeps pieces' volumes so).
_PAIRS: OrderedDict[tuple[int, int, int], tuple[Any, PairChunks | None]] = OrderedDict()
_PAIRS_SIZE = 1024


@dataclass(frozen=True, slots=True)
class Slabs:
    """Spheres covering a piece, in its joint's frame: centres (k, 3) and radii (k,), m."""

    centres: FloatArray
    radii: FloatArray


@dataclass(frozen=True, slots=True)
class PairChunks:
    """What the finer certificate needs of one pair: the moving piece's slabs and joint, the other
    piece's enclosing box in its joint's frame (centre, axes as columns, half extents) and joint, and
    the joints between them, from the moving piece's towards the other's (their v and q indices)."""

    slabs: Slabs
    moving_joint: int
    box: tuple[FloatArray, FloatArray, FloatArray]
    fixed_joint: int
    v_index: IntArray
    q_index: IntArray


def chunks_of_pair(model: pin.Model, gm: pin.GeometryModel, first: int, second: int) -> PairChunks | None:
    """`pair_chunks`, kept per geometry model and pair (a plan asks for the same pairs thousands of
    times; the slabs take a convex hull)."""
    key = (id(gm), first, second)
    hit = _PAIRS.get(key)
    if hit is not None and hit[0] is gm:
        _PAIRS.move_to_end(key)
        return hit[1]
    chunks = pair_chunks(model, gm, first, second)
    _PAIRS[key] = (gm, chunks)
    while len(_PAIRS) > _PAIRS_SIZE:
        _PAIRS.popitem(last=False)
    return chunks


def pair_chunks(model: pin.Model, gm: pin.GeometryModel, first: int, second: int) -> PairChunks | None:
    """The certificate's data for the pieces `first` and `second` (geometry indices), or None when
    it does not apply: neither joint is the other's ancestor, or a joint between them is not a plain
    revolute joint with its own value (a `<mimic>` joint, a continuous joint stored as cos and sin,
    a prismatic joint)."""
    ja, jb = int(gm.geometryObjects[first].parentJoint), int(gm.geometryObjects[second].parentJoint)
    path = joint_path(model, ja, jb)
    if not path:
        return None
    for k in path:
        joint = model.joints[k]
        name = joint.shortname()
        if joint.nq != 1 or joint.nv != 1 or not name.startswith("JointModelR") or name.startswith("JointModelRUB"):
            return None
    moving, fixed = (gm.geometryObjects[second], gm.geometryObjects[first]) if jb > ja else \
        (gm.geometryObjects[first], gm.geometryObjects[second])
    return PairChunks(slabs=slabs_of(moving.geometry, moving.placement.homogeneous), moving_joint=max(ja, jb),
                      box=_enclosing_box(support_points(fixed.geometry, fixed.placement.homogeneous)),
                      fixed_joint=min(ja, jb),
                      v_index=np.array([model.joints[k].idx_v for k in reversed(path)], dtype=np.int64),
                      q_index=np.array([model.joints[k].idx_q for k in reversed(path)], dtype=np.int64))


def slabs_of(geom: Any, placement: FloatArray, count: int = SLABS) -> Slabs:
    """Spheres covering a piece (coal geometry at `placement` in its joint's frame): its support
    points' convex hull, which holds the piece, cut into `count` slabs of equal width across its
    longest principal axis. A slab of the hull is the convex hull of the hull's vertices in it and of
    the points where the hull's edges cross its two planes; each sphere is measured to those points.
    A flat or tiny piece whose hull cannot be built is one sphere round all its points."""
    # Imported here: the planner has scipy.spatial loaded, a command that only builds a world need not.
    from scipy.spatial import ConvexHull, QhullError

    points = support_points(geom, placement)
    try:
        hull = ConvexHull(points)
    except (QhullError, ValueError):
        return _spheres([points])
    vertices = points[hull.vertices]
    centred = vertices - vertices.mean(axis=0)
    _, axes = np.linalg.eigh(centred.T @ centred)
    along = axes[:, -1]
    edges = np.unique(np.sort(np.concatenate([hull.simplices[:, [0, 1]], hull.simplices[:, [1, 2]],
                                              hull.simplices[:, [0, 2]]]), axis=1), axis=0)
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    ta, tb = a @ along, b @ along
    t = vertices @ along
    cuts = np.linspace(t.min(), t.max(), count + 1)
    groups = []
    for i in range(count):
        lo, hi = cuts[i], cuts[i + 1]
        parts = [vertices[(t >= lo) & (t <= hi)]]
        for plane in (lo, hi):
            crossing = (np.minimum(ta, tb) < plane) & (np.maximum(ta, tb) > plane)
            s = (plane - ta[crossing]) / (tb[crossing] - ta[crossing])
            parts.append(a[crossing] + s[:, None] * (b[crossing] - a[crossing]))
        group = np.concatenate(parts)
        if len(group):
            groups.append(group)
    return _spheres(groups)


def _spheres(groups: list[FloatArray]) -> Slabs:
    """One sphere per point group, each the pre-filter's enclosing sphere of its points."""
    spheres = [_enclosing_sphere(group) for group in groups]
    return Slabs(np.array([c for c, _ in spheres], dtype=float).reshape(-1, 3),
                 np.array([r for _, r in spheres], dtype=float))


def certified(chunks: PairChunks, data: Any, distance: float, half: FloatArray, bar: float) -> bool:
    """Whether the pair is farther apart than `bar` (m) at every configuration within `half` (per q,
    rad) of the centre where `data` holds the joints' placements and the world Jacobian
    (`pinocchio.computeJointJacobians`) and where coal measured the pieces `distance` apart."""
    centres, moved = slab_motion(chunks, data, half)
    fixed = data.oMi[chunks.fixed_joint]
    box_centre, box_axes, box_half = chunks.box
    rotation = fixed.rotation
    local = (centres - (rotation @ box_centre + fixed.translation)) @ (rotation @ box_axes)
    outside = np.maximum(np.abs(local) - box_half, 0.0)
    apart = np.sqrt(np.einsum("ij,ij->i", outside, outside)) - chunks.slabs.radii
    lower = np.maximum(apart, distance) - moved
    return bool(lower.min() > bar)


def slab_motion(chunks: PairChunks, data: Any, half: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(centres (k, 3), moved (k,)): where the slabs' centres are at the centre configuration (in the
    world, as `data` holds it), and how far any point of each slab's sphere can move relative to the
    other piece within `half` (per q, rad) of it, m (grown by a micrometre against round-off)."""
    slabs = chunks.slabs
    moving = data.oMi[chunks.moving_joint]
    centres = slabs.centres @ moving.rotation.T + moving.translation
    jacobian = data.J
    moved = np.zeros(len(slabs.radii))
    for v, q in zip(chunks.v_index.tolist(), chunks.q_index.tolist()):
        x, y, z = jacobian[3:, v].tolist()
        # A point c moves at linear + turn x c per radian: its distance from the joint's axis. Grown
        # by the slab's radius, and by how far the joints after this one may have moved the slab off
        # where it is at the centre. (turn x c as c times the cross-product matrix: np.cross costs
        # ten times as much on a few rows.)
        cross = np.array([[0.0, z, -y], [-z, 0.0, x], [y, -x, 0.0]])
        velocity = centres @ cross + jacobian[:3, v]
        speed = np.sqrt(np.einsum("ij,ij->i", velocity, velocity)) + (x * x + y * y + z * z) ** 0.5 * slabs.radii
        moved += float(half[q]) * (speed + moved)
    return centres, moved * (1.0 + 1e-9) + 1e-6
