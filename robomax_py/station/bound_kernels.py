"""The compiled loop of the station's lower bound (`station.bound`, numba): the least leg between two
sets of candidate configurations, pairs passed over as soon as one joint alone is slower than the
best leg found (all pairs of two spots' candidates: ~40,000 per pair of spots)."""

from __future__ import annotations

import math
from typing import Any

from robomax_py.jit import kernel


@kernel
def least_leg(spot_a: Any, app_a: Any, spot_b: Any, app_b: Any, v: Any, a: Any, lines: float, best: float) -> float:
    """min(best, the least over rows p of a and q of b of max(rest-to-rest trapezoid between
    spot_a[p] and spot_b[q], lines + slowest joint at its velocity limit between app_a[p] and
    app_b[q])), s. Arrays (k, n) float rad; v, a (n,) joint limits."""
    n = v.shape[0]
    for p in range(spot_a.shape[0]):
        for q in range(spot_b.shape[0]):
            t = 0.0
            for j in range(n):
                d = abs(spot_a[p, j] - spot_b[q, j])
                if d > v[j] * v[j] / a[j]:
                    tj = d / v[j] + v[j] / a[j]
                else:
                    tj = 2.0 * math.sqrt(d / a[j])
                if tj > t:
                    t = tj
                    if t >= best:
                        break
            if t >= best:
                continue
            u = 0.0
            for j in range(n):
                uj = abs(app_a[p, j] - app_b[q, j]) / v[j]
                u = max(u, uj)
            t = max(t, u + lines)
            best = min(best, t)
    return best
