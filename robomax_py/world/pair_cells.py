"""Cells of the joint values between two neighbouring pieces of the arm, certified free once.

Two robot or tool pieces, one riding on a joint after the other's with at most two revolute joints
between them (the forearm and the flange, the wrist and the gun), have the same relative pose for
the same values of those joints, whatever the others are: their distance is a function of one or
two joint values. Such pairs are often never far apart (a generated M-20iA tube cell: the forearm
and the flange, the wrist and the gun, a few millimetres apart), so no bounding volume clears them,
and coal tested them at nearly every state of every swept move: 2.5 of the 3.1 million exact tests of
that cell's plan.

The range of those joints is cut into cells `CELL_RAD` wide (a square of two, a segment of one). A
cell is decided the first time a configuration in it reaches coal with the pair
(`world.collision_core`): it is *certified* when coal's distance at the cell's centre, less how much
the distance can shrink within the cell (`Prefilter.near_reach`, by the joints between the two
pieces only), exceeds the pair's margin by `CERTIFY_SLACK_M`: the test of the swept checks' near
runs. The pre-filter then clears the pair at every configuration in a certified cell without a test
(`prefilter_kernels._cell_decision`); a cell that cannot be certified is tested as before. A
certified pair is free at every configuration of its cell, so every verdict is coal's as before,
reached with fewer tests.

The decisions are kept with the world's geometry (`Prefilter.cells`), shared by its copies; a
filter made for another margin (`Prefilter.with_margin`) starts with none decided.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray, IntArray

# The cells' width, rad. A cell's distance can shrink by about its half-diagonal times the lever of
# the farther piece (0.035 rad x 0.2 m, 7 mm on an M-20iA wrist), so the cells certify pairs a few
# millimetres apart; on that tube cell 0.05 rad certified 10,065 of the 13,750 cells its plan
# reached, which then cleared 2.76 of the 3.9 million tests the pairs with cells came to.
CELL_RAD = 0.05
INV_CELL = 1.0 / CELL_RAD
# The box a cell certifies is widened by this much on every side (rad), so that a configuration the
# compiled filter and Python place in a cell by rounding is inside its box.
CELL_PAD_RAD = 1e-9
# A pair whose cells would number more than this gets none (a joint with a very wide range).
MAX_CELLS = 1 << 20
UNKNOWN, CERTIFIED, UNCERTIFIED = 0, 1, 2
COLUMNS = 6          # per pair: joints (0: no cells), their q indices (2), cells along each (2), first cell


@dataclass(frozen=True, slots=True)
class CellTable:
    """One pair's cells: the q index, lowest value (rad) and cell count of each of its joints, and
    where its cells start in the shared decisions."""

    q_index: tuple[int, ...]
    low: tuple[float, ...]
    count: tuple[int, ...]
    start: int

    def cell(self, q: FloatArray) -> int:
        """The index (into the decisions) of the cell holding configuration q, -1 outside the table
        (a value off the joint's range or NaN). The compiled filter's arithmetic, operation for
        operation (`prefilter_kernels._cell_decision`)."""
        flat = 0
        for i, low, count in zip(self.q_index, self.low, self.count):
            x = (float(q[i]) - low) * INV_CELL
            if not x >= 0.0:
                return -1
            k = int(x)
            if k >= count:
                return -1
            flat = flat * count + k
        return self.start + flat

    def box(self, q: FloatArray, cell: int) -> tuple[FloatArray, FloatArray]:
        """The corners of cell `cell` (padded by CELL_PAD_RAD), the other joints at q's values."""
        lo, hi = np.array(q, dtype=float), np.array(q, dtype=float)
        rest = cell - self.start
        for i, low, count in reversed(list(zip(self.q_index, self.low, self.count))):
            rest, k = divmod(rest, count)
            lo[i] = low + k * CELL_RAD - CELL_PAD_RAD
            hi[i] = low + (k + 1) * CELL_RAD + CELL_PAD_RAD
        return lo, hi


@dataclass(frozen=True, slots=True, eq=False)
class PairCells:
    """Every pair's cells (None: the pair has none) and the decisions of all of them (int8:
    UNKNOWN, CERTIFIED or UNCERTIFIED), which the compiled filter reads and the world writes."""

    tables: tuple[CellTable | None, ...]
    decided: np.ndarray

    def undecided(self) -> PairCells:
        """The same cells, none decided (for a filter made for another margin)."""
        return PairCells(self.tables, np.zeros_like(self.decided))


def pair_cells(parent: IntArray, kind: IntArray, q_index: IntArray, lower: FloatArray, upper: FloatArray,
               piece_joint: IntArray, pair_a: IntArray, pair_b: IntArray,
               obstacle: np.ndarray) -> tuple[PairCells, IntArray, FloatArray]:
    """The cells of every pair (robot pieces a, b by their geometry index; obstacle: per piece) of a
    chain (per joint its parent, kind (0 revolute) and q index; per q its limits), and the tables the
    compiled filter reads: (P, COLUMNS) ints and (P, 2) lowest values (`prefilter_layout` CELL,
    CELL_LO)."""
    n_pairs = len(pair_a)
    ints = np.zeros((n_pairs, COLUMNS), dtype=np.int64)
    lows = np.zeros((n_pairs, 2))
    tables: list[CellTable | None] = []
    start = 0
    for k in range(n_pairs):
        a, b = int(pair_a[k]), int(pair_b[k])
        joints = None if obstacle[a] or obstacle[b] else _between(parent, int(piece_joint[a]), int(piece_joint[b]))
        table = None
        if joints and len(joints) <= 2 and all(kind[j] == 0 for j in joints):
            qs = tuple(int(q_index[j]) for j in joints)
            low = tuple(float(lower[i]) for i in qs)
            span = [float(upper[i]) - float(lower[i]) for i in qs]
            if all(math.isfinite(s) and s >= 0.0 for s in span):
                count = tuple(int(s * INV_CELL) + 1 for s in span)
                if math.prod(count) <= MAX_CELLS:
                    table = CellTable(qs, low, count, start)
                    start += math.prod(count)
        tables.append(table)
        if table is not None:
            m = len(table.q_index)
            ints[k, 0] = m
            ints[k, 1:1 + m] = table.q_index
            ints[k, 3:3 + m] = table.count
            ints[k, 5] = table.start
            lows[k, :m] = table.low
    return PairCells(tuple(tables), np.zeros(start, dtype=np.int8)), ints, lows


def _between(parent: IntArray, ja: int, jb: int) -> list[int] | None:
    """The joints from the nearer of joints ja, jb (exclusive) out to the farther (inclusive), when
    one is an ancestor of the other (or they are one joint: none between); None otherwise."""
    for near, far in ((ja, jb), (jb, ja)):
        path: list[int] = []
        k = far
        while k != near and k > 0:
            path.append(k)
            k = int(parent[k])
        if k == near:
            return path[::-1]
    return None
