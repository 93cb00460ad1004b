"""The compiled loops of `estimate.ptp_time_estimate` for the sequencer's candidate matrices and
paired rows (numba): every pair's straight-line time with the estimate's own operations in its
order (`_ptp_one`'s), so the floats are the array path's to the bit. The array path makes a dozen
passes over (rows x columns) temporaries per joint; on a 240-spot cell its matrices were a quarter
of the plan's CPU. The configurations come transposed, (n, k), so that the innermost loop runs
along contiguous values of one joint, which the compiler vectorises (about twice as fast as a
loop over the joints innermost)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robomax_py.jit import helper, kernel


@helper
def _zeroed(d: float, zero_move: float) -> float:
    """A joint difference of at most `zero_move` counts as none (NaN too), as the moves do."""
    return d if d > zero_move else 0.0


@helper
def _trapezoid(r_v: float, r_a: float) -> float:
    """Rest-to-rest time over unit distance with V = 1 / r_v, A = 1 / r_a: cruise iff r_a < r_v^2."""
    return r_v + r_a / r_v if r_a < r_v * r_v else 2.0 * math.sqrt(r_a)


@kernel
def straight_times(q0t: Any, q1t: Any, v: Any, a: Any, zero_move: float, outer: bool) -> Any:
    """Rest-to-rest straight-line times (s) under velocity limits v and acceleration limits a (n,),
    for configurations given as columns of q0t (n, r) and q1t (n, c): with `outer`, from each of
    q0t's to each of q1t's, as (r, c); else from column i of q0t to column i of q1t (c = r), as (1, r)."""
    n, rows = q0t.shape
    cols = q1t.shape[1]
    r_v = np.empty(cols)                       # the ratios' running maxima along one row of the result
    r_a = np.empty(cols)
    out = np.empty((rows if outer else 1, cols))
    for i in range(rows if outer else 1):
        for j in range(cols):
            r_v[j] = 0.0                       # every ratio is >= +0.0: 0.0 starts the maxima
            r_a[j] = 0.0
        for k in range(n):
            vk, ak = v[k], a[k]
            x0 = q0t[k, i] if outer else 0.0
            for j in range(cols):
                d = _zeroed(abs(q1t[k, j] - (x0 if outer else q0t[k, j])), zero_move)
                x = d / vk
                r_v[j] = max(r_v[j], x)
                x = d / ak
                r_a[j] = max(r_a[j], x)
        for j in range(cols):
            out[i, j] = _trapezoid(r_v[j], r_a[j])
    return out
