"""Where each table of the pre-filter sits in its packed buffers (`prefilter._pack`), as the compiled
loops (`prefilter_kernels`, `prefilter_reach`) read them.

ints starts with the header: J (joints), G (pieces), P (pairs), NG (groups), NB (blocks), C (obstacle
chunks), N (nodes of the block walk, `prefilter_tree`); then the start of each float table (an index
into the scalars, the 3-vectors or the 3x3 matrices, by its shape), then the start of each int table
(an index into ints). The kernels index the buffers at a table's start plus the row
(`R[CENTRE start + g, r]`), not slices of them: numba typed and lowered a slice per table, and the
tuple of them, in every kernel (about a third of a first plan's compile).
"""

from __future__ import annotations

N_HEADER, N_FLOAT_TABLES, N_INT_TABLES = 7, 20, 18
_F = N_HEADER                          # where the float tables' starts are in ints
_I = N_HEADER + N_FLOAT_TABLES         # where the int tables' starts are in ints

# Float tables, in `Prefilter.of`'s order. The chain: per joint its axis (R), rotation (M) and
# translation (R) in its parent.
AXIS, JROT, JTRANS = _F + 0, _F + 1, _F + 2
# The sphere tests: per piece its centre (R) and radius (F), per obstacle piece (then per node of the
# block walk) its box corners (R), per pair its margin (F), per group its centre (R) and radius (F),
# per block (then per node) its margin (F).
CENTRE, RADIUS, BOX_LO, BOX_HI, MARGIN = _F + 3, _F + 4, _F + 5, _F + 6, _F + 7
G_CENTRE, G_RADIUS, B_MARGIN = _F + 8, _F + 9, _F + 10
# The box and chunk tests: per piece its oriented box (centre R, rotation M, half extents R); per
# chunk of an obstacle's mesh its sphere (centre R, radius F) and box (centre R, rotation M, half R).
OBB_C, OBB_R, OBB_H = _F + 11, _F + 12, _F + 13
CH_C, CH_RAD, CH_BC, CH_BR, CH_H = _F + 14, _F + 15, _F + 16, _F + 17, _F + 18
# Per pair the lowest value of each of its cells' joints (F, two per pair: `pair_cells`).
CELL_LO = _F + 19

# Int tables: the chain's parent, kind and q index per joint; per piece its joint; per pair its
# pieces and whether b is an obstacle; per group its joint; per block its kind, groups and end; the
# pairs in block order; per piece its first and end chunk; per chunk the chunk after its subtree;
# the block walk (per node its block, group and the node after its subtree, interleaved).
PARENT, KIND, JQ, PIECE_JOINT = _I + 0, _I + 1, _I + 2, _I + 3
PAIR_A, PAIR_B, PAIR_OBSTACLE, GROUP_JOINT = _I + 4, _I + 5, _I + 6, _I + 7
B_KIND, B_A, B_B, B_END, B_PAIRS = _I + 8, _I + 9, _I + 10, _I + 11, _I + 12
CH_START, CH_END, CH_SKIP, WALK = _I + 13, _I + 14, _I + 15, _I + 16
# Per pair its cells (`pair_cells.COLUMNS` ints: joints, their q indices, cells along each, first cell).
CELL = _I + 17
