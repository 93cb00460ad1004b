"""The step of the candidate-choice DP (`sequence.best_choice`) in one compiled pass: for every
candidate j of the next spot, the least of value[i] + matrix[i, j] over the candidates i of the last
spot (and which i), plus j's own cost. And the (min, +) matrix product that prices the known detours
between two spots' candidates (`graph_knowledge`), each sum one IEEE addition as numpy's.

numpy spends the step in two passes: the (N_prev, N_next) sums are written out, then reduced down
their columns, and `argmin` down a column is a strided walk. One pass row by row reads the matrix
once, in memory order: on 600 x 600 candidates about 2.5 times faster for the least, 6 times with
the argmin. The sums are numpy's (one IEEE addition each, no reordering) and the least is exact, so
the values are numpy's bit for bit; the argmin is the first index of the least, as `np.argmin`'s.
Costs are never NaN: the sequencer's are move-time estimates, finite or inf, and `sequence._Costs`
refuses NaN; numpy's reduction would carry a NaN where this comparison skips it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robomax_py.jit import kernel


@kernel
def min_plus(value: Any, matrix: Any, node: Any) -> Any:
    """out[j] = min_i (value[i] + matrix[i, j]) + node[j]; value (n,), matrix (n, m), node (m,), n >= 1."""
    n, m = matrix.shape
    out = np.empty(m)
    for j in range(m):
        out[j] = value[0] + matrix[0, j]
    for i in range(1, n):
        v = value[i]
        for j in range(m):
            t = v + matrix[i, j]
            out[j] = min(out[j], t)
    for j in range(m):
        out[j] += node[j]
    return out


@kernel
def min_plus_arg(value: Any, matrix: Any, node: Any) -> Any:
    """`min_plus` and, per j, the first i at which the least is reached."""
    n, m = matrix.shape
    out = np.empty(m)
    arg = np.zeros(m, dtype=np.int64)
    for j in range(m):
        out[j] = value[0] + matrix[0, j]
    for i in range(1, n):
        v = value[i]
        for j in range(m):
            t = v + matrix[i, j]
            if t < out[j]:
                out[j] = t
                arg[j] = i
    for j in range(m):
        out[j] += node[j]
    return out, arg


@kernel
def min_plus_product(a: Any, b: Any) -> Any:
    """out[r, c] = min_k (a[r, k] + b[k, c]); a (n, p), b (p, m), p >= 1: the (min, +) matrix
    product, row by row in memory order (numpy's broadcast writes out the (n, p, m) sums first)."""
    n, p = a.shape
    m = b.shape[1]
    out = np.empty((n, m))
    for r in range(n):
        v = a[r, 0]
        for c in range(m):
            out[r, c] = v + b[0, c]
        for k in range(1, p):
            v = a[r, k]
            for c in range(m):
                out[r, c] = min(out[r, c], v + b[k, c])
    return out
