"""How far the pieces of a revolute chain move over a box of configurations (the pre-filter's
`_near`): a point's, a whole piece's, and how much a pair's distance can shrink."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robomax_py.jit import helper


@helper
def _pair_reach(centre: Any, radius: Any, piece_joint: Any, a: int, b: int, obstacle: bool, lo: Any, hi: Any,
                parent: Any, jtrans: Any, jq: Any, spread: Any) -> float:
    """How much the distance between robot piece a and piece b can shrink from the centre of the box
    [lo, hi] (`_near`), m: a's spread against an obstacle; between two robot pieces one of whose
    joints is the other's ancestor, the spread of the farther piece by the joints between them only
    (the nearer one's frame carries both), else both spreads. spread: cached per piece (< 0: not yet)."""
    if obstacle:
        if spread[a] < 0.0:
            spread[a] = _growth(centre, a, piece_joint[a], lo, hi, parent, jtrans, jq, radius[a], np.int64(0))
        return float(spread[a])
    for near, far in ((a, b), (b, a)):
        k = piece_joint[far]
        while k != piece_joint[near] and k > 0:
            k = parent[k]
        if k == piece_joint[near]:
            return _growth(centre, far, piece_joint[far], lo, hi, parent, jtrans, jq, radius[far], piece_joint[near])
    for g in (a, b):
        if spread[g] < 0.0:
            spread[g] = _growth(centre, g, piece_joint[g], lo, hi, parent, jtrans, jq, radius[g], np.int64(0))
    return float(spread[a] + spread[b])


@helper
def _growth(local: Any, g: int, j: int, lo: Any, hi: Any, parent: Any, jtrans: Any, jq: Any,
            reach: float, stop: Any) -> float:
    """How far point local[g] of joint j's link, or any point within `reach` of it, can move from
    where it is at the centre of the box [lo, hi] of a revolute chain's configurations (`_near`), m;
    grown by a micrometre so that the round-off of the two tests it separates cannot tell them apart.
    stop: an ancestor joint of j (0: the base); the motion in its frame (by the joints after it only).
    Every caller passes every argument, `stop` as an int64 (not a literal 0): numba compiles one
    specialisation per set of omitted arguments and per literal."""
    # x * x, not x ** 2: the same number (numba's power by 2 is 1.0 * (x * x)) without compiling numba's power
    arm = math.sqrt(local[g, 0] * local[g, 0] + local[g, 1] * local[g, 1] + local[g, 2] * local[g, 2]) + reach
    moved = 0.0
    k = j
    while k != stop and k > 0:
        moved += (hi[jq[k]] - lo[jq[k]]) / 2.0 * arm
        arm += math.sqrt(jtrans[k, 0] * jtrans[k, 0] + jtrans[k, 1] * jtrans[k, 1] + jtrans[k, 2] * jtrans[k, 2])
        k = parent[k]
    return moved * (1.0 + 1e-9) + 1e-6
