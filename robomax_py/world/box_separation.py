"""Whether two oriented boxes are apart: the separating-axis test the pre-filter's kernels
(`world.prefilter_kernels`) and the robot-pair clash descent (`station.clash_kernels`) share,
compiled with numba."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robomax_py.jit import helper, kernel


@helper
def boxes_apart(ca: Any, ra: Any, ha: Any, a: int, cb: Any, rb: Any, hb: Any, b: int, gap: float, scratch: Any) -> bool:
    """Whether oriented box a (centre ca[a], axes the columns of ra[a], half extents ha[a]) and box b
    are more than `gap` apart along one of the 15 separating axes (`separated`). False proves nothing.
    scratch: (7, 3) float the tests work in (allocated by the caller: this runs in inner loops)."""
    ea, eb = ha[a], hb[b]
    if not (math.isfinite(ea[0]) and math.isfinite(eb[0])):    # math's, not numpy's ufunc: cheaper to compile
        return False
    R = scratch[0:3]
    t = scratch[3]
    for i in range(3):
        t[i] = 0.0
        for k in range(3):
            t[i] += ra[a, k, i] * (cb[b, k] - ca[a, k])
        for j in range(3):
            v = 0.0
            for k in range(3):
                v += ra[a, k, i] * rb[b, k, j]
            R[i, j] = v
    return _separated(R, t, ea, eb, gap, scratch[4:7])


@kernel
def separated(R: Any, t: Any, ea: Any, eb: Any, gap: float) -> bool:
    """Whether two oriented boxes are more than `gap` apart along one of the 15 separating axes
    (Gottschalk et al., SIGGRAPH 1996; Ericson, Real-Time Collision Detection 4.4.1; a cross-product
    axis's gap scaled by its length). R (3, 3): box b's axes in box a's frame; t (3,): b's centre
    less a's in a's frame; ea, eb (3,): half extents, m. False proves nothing."""
    return _separated(R, t, ea, eb, gap, np.empty((3, 3)))


@helper
def _separated(R: Any, t: Any, ea: Any, eb: Any, gap: float, AbsR: Any) -> bool:
    """`separated`, working in AbsR (3, 3)."""
    for i in range(3):
        for j in range(3):
            AbsR[i, j] = abs(R[i, j]) + 1e-9    # near-parallel edges: no false separation
    for i in range(3):
        if abs(t[i]) > ea[i] + eb[0] * AbsR[i, 0] + eb[1] * AbsR[i, 1] + eb[2] * AbsR[i, 2] + gap:
            return True
    for j in range(3):
        if abs(t[0] * R[0, j] + t[1] * R[1, j] + t[2] * R[2, j]) > \
                ea[0] * AbsR[0, j] + ea[1] * AbsR[1, j] + ea[2] * AbsR[2, j] + eb[j] + gap:
            return True
    for i in range(3):
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            length = math.sqrt(max(0.0, 1.0 - R[i, j] * R[i, j]))
            if length < 1e-6:
                continue
            ra = ea[i1] * AbsR[i2, j] + ea[i2] * AbsR[i1, j]
            rb = eb[j1] * AbsR[i, j2] + eb[j2] * AbsR[i, j1]
            if abs(t[i2] * R[i1, j] - t[i1] * R[i2, j]) > ra + rb + gap * length:
                return True
    return False
