"""How far the pieces of a revolute chain move over a box of configurations (the pre-filter's
`_near`): a point's, a whole piece's, and how much a pair's distance can shrink."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robomax_py.jit import helper
from robomax_py.world.prefilter_layout import (
    CENTRE,
    JQ,
    JTRANS,
    PARENT,
    PIECE_JOINT,
    RADIUS,
)


@helper
def _pair_reach(F: Any, R: Any, I: Any, a: int, b: int, obstacle: bool, lo: Any, hi: Any, spread: Any) -> float:
    """How much the distance between robot piece a and piece b can shrink from the centre of the box
    [lo, hi] (`_near`), m: a's spread against an obstacle; between two robot pieces one of whose
    joints is the other's ancestor, the spread of the farther piece by the joints between them only
    (the nearer one's frame carries both), else both spreads. F, R, I: the packed tables
    (`prefilter_layout`); spread: cached per piece (< 0: not yet)."""
    centre, radius, piece_joint, parent = I[CENTRE], I[RADIUS], I[PIECE_JOINT], I[PARENT]
    if obstacle:
        if spread[a] < 0.0:
            spread[a] = _growth(R, I, centre + a, I[piece_joint + a], lo, hi, F[radius + a], np.int64(0))
        return float(spread[a])
    for near, far in ((a, b), (b, a)):
        k = I[piece_joint + far]
        while k != I[piece_joint + near] and k > 0:
            k = I[parent + k]
        if k == I[piece_joint + near]:
            return _growth(R, I, centre + far, I[piece_joint + far], lo, hi, F[radius + far], I[piece_joint + near])
    for g in (a, b):
        if spread[g] < 0.0:
            spread[g] = _growth(R, I, centre + g, I[piece_joint + g], lo, hi, F[radius + g], np.int64(0))
    return float(spread[a] + spread[b])


@helper
def _growth(R: Any, I: Any, p: Any, j: Any, lo: Any, hi: Any, reach: float, stop: Any) -> float:
    """How far point R[p] of joint j's link, or any point within `reach` of it, can move from where
    it is at the centre of the box [lo, hi] of a revolute chain's configurations (`_near`), m;
    grown by a micrometre so that the round-off of the two tests it separates cannot tell them apart.
    stop: an ancestor joint of j (0: the base); the motion in its frame (by the joints after it only).
    Every caller passes every argument, `p`, `j` and `stop` as int64 (not a literal 0): numba compiles
    one specialisation per set of omitted arguments and per literal."""
    parent, jtrans, jq = I[PARENT], I[JTRANS], I[JQ]
    # x * x, not x ** 2: the same number (numba's power by 2 is 1.0 * (x * x)) without compiling numba's power
    arm = math.sqrt(R[p, 0] * R[p, 0] + R[p, 1] * R[p, 1] + R[p, 2] * R[p, 2]) + reach
    moved = 0.0
    k = j
    while k != stop and k > 0:
        moved += (hi[I[jq + k]] - lo[I[jq + k]]) / 2.0 * arm
        t = jtrans + k
        arm += math.sqrt(R[t, 0] * R[t, 0] + R[t, 1] * R[t, 1] + R[t, 2] * R[t, 2])
        k = I[parent + k]
    return moved * (1.0 + 1e-9) + 1e-6
