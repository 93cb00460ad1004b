"""Detour blending is used only when the blended path checks free, and only when it is faster."""

from __future__ import annotations

import numpy as np

from robomax_py.plan import PlanOptions, _move_segment
from robomax_py.robot import JointLimits
from robomax_py.spec import frozen_array

# Distance (rad) from the polyline beyond which the strict world reports a collision.
OFF_POLYLINE_RAD = 1e-6

LIMITS = JointLimits(
    lower=frozen_array([-3.0] * 3), upper=frozen_array([3.0] * 3), velocity=frozen_array([1.0] * 3),
    acceleration=frozen_array([3.0] * 3), jerk=frozen_array([30.0] * 3),
)
WAYPOINTS = np.array([[0.0, 0.0, 0.0], [0.6, 0.0, 0.0], [0.6, 0.6, 0.0], [1.2, 0.6, 0.2]])


def _distance_to_polyline(p: np.ndarray) -> float:
    best = np.inf
    for a, b in zip(WAYPOINTS[:-1], WAYPOINTS[1:]):
        d = b - a
        s = np.clip(np.dot(p - a, d) / np.dot(d, d), 0.0, 1.0)
        best = min(best, float(np.linalg.norm(p - (a + s * d))))
    return best


class StrictWorld:
    """Free only on the waypoint polyline: any corner cut 'collides'."""

    def segment_free(self, q0: np.ndarray, q1: np.ndarray) -> bool:
        return all(_distance_to_polyline(q0 + s * (q1 - q0)) <= OFF_POLYLINE_RAD for s in np.linspace(0, 1, 5))


class OpenWorld:
    def segment_free(self, q0: np.ndarray, q1: np.ndarray) -> bool:
        return True


def test_blocked_blend_falls_back_to_stopping_on_the_polyline() -> None:
    segment, radius = _move_segment(WAYPOINTS, LIMITS, PlanOptions(), "detour", "d", StrictWorld())  # type: ignore[arg-type]
    assert radius == 0.0
    assert max(_distance_to_polyline(q) for q in segment.q) <= OFF_POLYLINE_RAD


def test_free_blend_is_used_and_faster() -> None:
    stop, _ = _move_segment(WAYPOINTS, LIMITS, PlanOptions(), "detour", "d", StrictWorld())  # type: ignore[arg-type]
    blended, radius = _move_segment(WAYPOINTS, LIMITS, PlanOptions(), "detour", "d", OpenWorld())  # type: ignore[arg-type]
    assert radius > 0.0
    assert blended.t[-1] - blended.t[0] < stop.t[-1] - stop.t[0]
    np.testing.assert_allclose(blended.q[0], WAYPOINTS[0], atol=1e-9)
    np.testing.assert_allclose(blended.q[-1], WAYPOINTS[-1], atol=1e-9)
