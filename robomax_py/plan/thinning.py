"""A few representatives of a spot's candidates, for searching the spot order.

A spot has hundreds of candidates (orientations x IK branches x turns), most of them a few degrees
from a neighbour. The order search only needs to know how far apart two spots are for the kinds of
configuration they allow, so it sees a spread-out subset; the exact DP over every candidate then
chooses the configurations for the order found. The subset is a farthest-point sample in the
velocity-time metric max_j |q_a,j - q_b,j| / v_j (a lower bound of the move time between two
candidates), started from the candidate with the least node cost, so every branch and turn
variant is represented before any is represented twice.
"""

from __future__ import annotations

import numpy as np

from robomax_py._typing import FloatArray, IntArray


def representatives(q: FloatArray, node: FloatArray, velocity: FloatArray, count: int) -> IntArray:
    """Indices (ascending) of at most `count` candidates spread over q (k, n); all when k <= count.

    Deterministic: ties go to the lowest index.
    """
    k = len(q)
    if k <= count:
        return np.arange(k, dtype=np.int64)
    scaled = np.asarray(q, dtype=float) / np.asarray(velocity, dtype=float)
    chosen = [int(np.argmin(node))]
    gap = np.max(np.abs(scaled - scaled[chosen[0]]), axis=1)
    for _ in range(count - 1):
        far = int(np.argmax(gap))
        if gap[far] <= 0.0:
            break                               # the rest duplicate chosen ones
        chosen.append(far)
        gap = np.minimum(gap, np.max(np.abs(scaled - scaled[far]), axis=1))
    return np.array(sorted(chosen), dtype=np.int64)
