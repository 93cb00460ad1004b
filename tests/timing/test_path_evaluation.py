"""Paths evaluated many times give the values of their first evaluation, and a blend's cut found
with fewer bisection steps is the cut of the full bisection, bit for bit."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.timing import GeometricPath
from robomax_py.timing.blend import _cut_at_distance
from robomax_py.timing.paths import polyline_path

N = 6


def _full_bisection_cut(path: GeometricPath, point: np.ndarray, radius: float, *, from_end: bool) -> float:
    """The cut as `_cut_at_distance` found it with all of its 60 bisection steps."""
    half = 0.5 * path.length
    s = path.grid(radius / 16.0)
    s = s[s >= half][::-1] if from_end else s[s <= half]
    dist = np.linalg.norm(path(s) - point, axis=1)
    beyond = np.nonzero(dist >= radius)[0]
    if len(beyond) == 0:
        return half
    k = int(beyond[0])
    lo, hi = float(s[k - 1]), float(s[k])
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if np.linalg.norm(GeometricPath(path.breaks, path.control_points)(mid) - point) < radius:
            lo = mid
        else:
            hi = mid
    return hi


def _curved(rng: np.random.Generator, pieces: int, scale: float) -> GeometricPath:
    """A path of quadratic Bézier pieces through random points (joint-space, rad)."""
    line = polyline_path(rng.normal(size=(pieces + 1, N)) * scale)
    bulge = rng.normal(size=(pieces, N)) * 0.3 * scale
    c = line.control_points
    return GeometricPath(line.breaks, np.stack([c[:, 0], 0.5 * (c[:, 0] + c[:, 1]) + bulge, c[:, 1]], axis=1))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 4), scale=st.sampled_from([1e-3, 0.1, 1.0, 10.0]),
       fraction=st.sampled_from([1e-4, 0.01, 0.2, 1.0]), curved=st.booleans(), from_end=st.booleans())
def test_blend_cut_equals_the_full_bisection(seed: int, pieces: int, scale: float, fraction: float, curved: bool,
                                             from_end: bool) -> None:
    rng = np.random.default_rng(seed)
    path = _curved(rng, pieces, scale) if curved else polyline_path(rng.normal(size=(pieces + 1, N)) * scale)
    point = path.end if from_end else path.start
    radius = fraction * path.length
    assert _cut_at_distance(path, point, radius, from_end=from_end) == \
        _full_bisection_cut(path, point, radius, from_end=from_end)


def test_a_path_evaluated_again_gives_its_first_values_bit_for_bit() -> None:
    rng = np.random.default_rng(7)
    path = _curved(rng, 3, 1.0)
    s = np.linspace(0.0, path.length, 57)
    first = [path(s, order) for order in (0, 1, 2)]
    path(0.3 * path.length)                          # evaluated in between, at a scalar
    again = [path(s, order) for order in (0, 1, 2)]
    fresh = GeometricPath(path.breaks, path.control_points)
    for a, b, c, order in zip(first, again, (fresh(s, o) for o in (0, 1, 2)), (0, 1, 2)):
        assert np.array_equal(a, b) and np.array_equal(a, c), order
