"""The order the pre-filter's kernels walk its blocks in (`world.prefilter`): per joint group, a
bounding-box tree over the obstacle pieces it has blocks with, so that a configuration far from a
cluster of obstacles clears all of their blocks with one sphere test.

The walk is a pre-order array of nodes with skip pointers (as an obstacle's chunk tree): a leaf is a
block, tested as before; an inner node holds its group, the smallest box enclosing the world boxes of
its subtree's obstacles and the largest margin of its subtree's blocks. A group sphere farther than
that margin from the node's box is farther than each block's margin from each obstacle box inside
(in floating point too: the distance to a box and the reach are computed by the same operations, each
monotone in its inputs), so skipping the subtree leaves out exactly blocks their own test clears.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray, IntArray

# A group with fewer obstacle blocks walks them in a plain loop (a tree of a few boxes skips little).
# Measured, random configurations, every block: the reference cell (9 obstacle pieces a group) 1.25
# -> 1.10 us a configuration with its tree; a 240-spot cell with a clamp every 8 spots (85) 3.2 -> 1.8.
TREE_MIN_BLOCKS = 8
TREE_LEAF_BLOCKS = 2           # a subtree of at most this many blocks is tested block by block (1 to 6: alike)


@dataclass(frozen=True, slots=True, eq=False)
class BlockWalk:
    """The nodes in walk order: per node its block (-1 for an inner node), its group, the node after
    its subtree, and (inner nodes; zeros for a leaf) its box and its largest margin."""

    block: IntArray
    group: IntArray
    skip: IntArray
    lo: FloatArray
    hi: FloatArray
    margin: FloatArray


def block_walk(kind: IntArray, group: IntArray, obstacle: IntArray, margin: FloatArray, box_lo: FloatArray,
               box_hi: FloatArray, min_blocks: int = TREE_MIN_BLOCKS) -> BlockWalk:
    """The walk over blocks (kind 0: group vs obstacle piece, 1: group vs group; `Prefilter.of`):
    first every block not in a tree, in block order, then each tree of a group with at least
    `min_blocks` obstacle blocks. box_lo/box_hi: the obstacle pieces' world boxes (infinite for an
    unbounded piece, whose nodes then never clear)."""
    block: list[int] = []
    node_group: list[int] = []
    skip: list[int] = []
    lo: list[FloatArray] = []
    hi: list[FloatArray] = []
    node_margin: list[float] = []
    zero = np.zeros(3)

    def leaf(blk: int) -> None:
        block.append(blk)
        node_group.append(int(group[blk]))
        skip.append(len(block))
        lo.append(zero)
        hi.append(zero)
        node_margin.append(0.0)

    def visit(g: int, blks: IntArray) -> None:
        if len(blks) <= TREE_LEAF_BLOCKS:
            for blk in blks:
                leaf(int(blk))
            return
        pieces = obstacle[blks]
        me = len(block)
        block.append(-1)
        node_group.append(g)
        skip.append(-1)
        lo.append(box_lo[pieces].min(axis=0))
        hi.append(box_hi[pieces].max(axis=0))
        node_margin.append(float(margin[blks].max()))
        # Median split of the boxes' centres along their widest spread (an unbounded box's centre is
        # NaN: counted as 0, the split only shapes the tree, never what it skips).
        centres = np.nan_to_num((box_lo[pieces] + box_hi[pieces]) / 2.0, nan=0.0, posinf=0.0, neginf=0.0)
        axis = int(np.argmax(centres.max(axis=0) - centres.min(axis=0)))
        order = blks[np.argsort(centres[:, axis], kind="stable")]
        visit(g, order[: len(order) // 2])
        visit(g, order[len(order) // 2:])
        skip[me] = len(block)

    in_obstacle = kind == 0
    counts = np.bincount(group[in_obstacle], minlength=int(group.max(initial=-1)) + 1)
    treed = in_obstacle & (counts[group] >= min_blocks)
    for blk in np.flatnonzero(~treed):
        leaf(int(blk))
    for g in np.flatnonzero(counts >= min_blocks):
        visit(int(g), np.flatnonzero(treed & (group == g)))
    return BlockWalk(block=np.array(block, dtype=np.int64), group=np.array(node_group, dtype=np.int64),
                     skip=np.array(skip, dtype=np.int64), lo=np.array(lo, dtype=float).reshape(-1, 3),
                     hi=np.array(hi, dtype=float).reshape(-1, 3), margin=np.array(node_margin, dtype=float))
