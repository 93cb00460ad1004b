"""The two baselines a Bézier path's jerk-limited profile (`timing.bezier`) is compared with.

- toppra on the same path under v, a_T and a_R (no jerk limit): the path as (x, y, s), s its
  arclength, so the speed is ds/dt; v and a_R become a path speed cap (a_R = kappa (ds/dt)^2), a_T
  the acceleration limit of the s coordinate.
- ruckig per segment: each quintic from rest to rest along its arclength under v (capped by a_R and
  j_R at the segment's tightest bend), a_T and j_T: jerk-limited, but stopping at every join.
"""

from __future__ import annotations

import numpy as np

from robomax_py.robot import JointLimits
from robomax_py.spec import TcpLimits
from robomax_py.timing.bezier import BezierPath, arclength
from robomax_py.timing.paths import spline_path
from robomax_py.timing.ptp import _ruckig
from robomax_py.timing.topp import time_path

UNLIMITED = 1e6          # a coordinate toppra should not limit (x and y)


def toppra_time(path: BezierPath, limits: TcpLimits, samples: int = 600) -> float:
    s_tab, p_tab, k_tab = path.table()
    s = np.linspace(0.0, s_tab[-1], samples)
    q = np.column_stack([np.interp(s, s_tab, p_tab[:, 0]), np.interp(s, s_tab, p_tab[:, 1]), s])
    geometric = spline_path(s, q)
    lim = JointLimits(lower=np.full(3, -UNLIMITED), upper=np.full(3, UNLIMITED),
                      velocity=np.array([UNLIMITED, UNLIMITED, limits.v]),
                      acceleration=np.array([UNLIMITED, UNLIMITED, limits.a_T]), jerk=np.full(3, UNLIMITED))

    def cap(x: np.ndarray) -> np.ndarray:
        kappa = np.abs(np.interp(x, s_tab, k_tab))
        capped: np.ndarray = np.minimum(limits.v, np.sqrt(limits.a_R / np.maximum(kappa, 1e-12)))
        return capped

    return float(time_path(geometric, lim, path_speed_limit=cap).t[-1])


def ruckig_per_segment_time(path: BezierPath, limits: TcpLimits) -> float:
    total = 0.0
    for i in range(path.segments):
        p, kappa = path.segment_table(i, 800)
        s = arclength(p)
        dkappa = np.gradient(kappa, s)
        v = min(limits.v, float(np.sqrt(limits.a_R / max(np.abs(kappa).max(), 1e-12))),
                float(np.cbrt(limits.j_R / max(np.abs(dkappa).max(), 1e-12))))
        traj = _ruckig([0.0], [0.0], [float(s[-1])], [0.0], np.array([v]), np.array([limits.a_T]),
                       np.array([limits.j_T]), f"segment {i}")
        total += float(traj.duration)
    return total
