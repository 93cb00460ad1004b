"""Paths evaluated many times give the values of their first evaluation, a blend's cut found
with fewer bisection steps (and fewer calls of the path) is the cut of the full bisection, and a
path's grid and a stack's degree elevation computed at once are those computed piece by piece, and
toppra's grid refined by evaluating only the new steps is the grid of evaluating them all every
round, bit for bit."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.timing import GeometricPath, topp
from robomax_py.timing.blend import _cut_at_distance
from robomax_py.timing.paths import (
    concatenate_paths,
    elevate,
    piecewise_linspace,
    polyline_path,
    spline_path,
)

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


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 40), scale=st.sampled_from([1e-6, 1e-3, 1.0, 100.0]),
       most=st.integers(1, 30))
def test_grid_of_all_pieces_is_linspace_piece_by_piece(seed: int, pieces: int, scale: float, most: int) -> None:
    rng = np.random.default_rng(seed)
    breaks = np.concatenate([[0.0], np.cumsum(rng.uniform(1e-3, 1.0, pieces) * scale)])
    counts = rng.integers(1, most + 1, pieces)
    each = [np.linspace(a, b, k + 1)[:-1] for a, b, k in zip(breaks[:-1], breaks[1:], counts)]
    assert np.array_equal(piecewise_linspace(breaks, counts), np.concatenate([*each, breaks[-1:]]))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), samples=st.integers(3, 30), degree=st.integers(3, 7))
def test_elevating_a_stack_elevates_each_curve_as_on_its_own(seed: int, samples: int, degree: int) -> None:
    rng = np.random.default_rng(seed)
    path = spline_path(np.cumsum(rng.uniform(1e-3, 0.1, samples)), rng.normal(size=(samples, N)))
    stacked = elevate(path.control_points, degree)
    assert np.array_equal(stacked, np.stack([elevate(c, degree) for c in path.control_points]))
    line = polyline_path(np.stack([path.end, path.end + 1.0, path.end - 1.0]))
    joined = concatenate_paths([path, line])           # the line's pieces raised to the spline's degree 3
    assert np.array_equal(joined.control_points[len(path.breaks) - 1:], np.stack([elevate(c, 3) for c in
                                                                                  line.control_points]))


def _grid_evaluating_every_step(path: GeometricPath) -> np.ndarray:
    """`topp.gridpoints` with the turn of every step evaluated again in every round."""
    c = path.control_points
    polygon = float(np.sum(np.linalg.norm(np.diff(c, axis=1), axis=2)))
    s = path.grid(max(polygon * topp.GRID_STEP_FRACTION, 1e-12))
    while len(s) < topp.MIN_GRID_POINTS:
        s = np.sort(np.concatenate([s, 0.5 * (s[:-1] + s[1:])]))
    for _ in range(20):
        ds = np.diff(s)
        mid = 0.5 * (s[:-1] + s[1:])
        turn = np.linalg.norm(path(mid, 2), axis=1) * ds / np.maximum(np.linalg.norm(path(mid, 1), axis=1), 1e-12)
        split = turn > topp.GRID_TURN_PER_STEP
        if not np.any(split) or len(s) + int(np.sum(split)) > topp.MAX_GRID_POINTS:
            break
        s = np.sort(np.concatenate([s, mid[split]]))
    return s


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 6), scale=st.sampled_from([1e-3, 0.05, 1.0, 3.0]))
def test_the_refined_grid_is_the_grid_of_evaluating_every_step(seed: int, pieces: int, scale: float) -> None:
    rng = np.random.default_rng(seed)
    curved = _curved(rng, pieces, scale)
    s = np.concatenate([[0.0], np.cumsum(rng.uniform(0.05, 1.0, pieces + 2))])
    spline = spline_path(s, rng.normal(size=(pieces + 3, N)) * scale)
    for path in (curved, spline):
        expected = _grid_evaluating_every_step(GeometricPath(path.breaks, path.control_points))
        got = topp.gridpoints(GeometricPath(path.breaks, path.control_points))
        assert got.tobytes() == expected.tobytes()


def test_toppra_sees_the_path_once_per_grid_and_order(monkeypatch: pytest.MonkeyPatch) -> None:
    """toppra's velocity and acceleration constraints both ask for q'(s) at the grid points: the
    path is evaluated once for it (and once for q''), and every answer is the path's own, in an
    array the caller may write into."""

    path = polyline_path(np.array([[0.0, 0, 0, 0, 0, 0], [1, 2, 0, 0, 0, 1], [2, 1, 1, 0, 0, 0]]))
    asked: list[int] = []
    real = GeometricPath.__call__

    def counted(self: GeometricPath, s: Any, order: int = 0) -> Any:
        asked.append(order)
        return real(self, s, order)

    monkeypatch.setattr(GeometricPath, "__call__", counted)
    seen = topp._toppra_path(path)
    grid = np.linspace(0.0, path.length, 9)
    first = seen(grid, 1)
    first[:] = 0.0                                          # the caller's copy, not the kept one
    assert np.array_equal(seen(grid, 1), real(path, grid, 1))
    assert np.array_equal(seen(grid, 2), real(path, grid, 2))
    assert np.array_equal(seen(grid[:-1], 2), real(path, grid[:-1], 2))
    assert asked == [1, 2, 2]
