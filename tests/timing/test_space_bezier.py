"""The spline path in space (`timing.space_bezier`) and the per-stretch speed bound of
`timing.curve_move`: measured from the curve's own points, not from its construction."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from robomax_py.timing.curve_move import stretch_speeds
from robomax_py.timing.space_bezier import deviation, sample_lines, space_path

# Key points are placed to 1e-12 m by the Bernstein form; arclength tables are trapezoid sums.
POINT_TOL_M = 1e-9
# A tangent's direction is compared by finite differences this far (m) either side of a join.
FD_STEP_M = 1e-6
ANGLE_TOL_RAD = 1e-3


def _poses(points: np.ndarray, rng: np.random.Generator | None = None) -> np.ndarray:
    T = np.repeat(np.eye(4)[None], len(points), axis=0)
    T[:, :3, 3] = points
    if rng is not None:
        T[:, :3, :3] = Rotation.random(len(points), random_state=int(rng.integers(1 << 30))).as_matrix()
    return T


def _key_points(draw: st.DrawFn) -> np.ndarray:
    n = draw(st.integers(4, 7))
    steps = draw(st.lists(st.tuples(*[st.floats(-0.3, 0.3)] * 3), min_size=n - 1, max_size=n - 1))
    pts = np.cumsum(np.vstack([np.zeros(3), np.array(steps)]), axis=0)
    return pts


@st.composite
def key_points(draw: st.DrawFn) -> np.ndarray:
    pts = _key_points(draw)
    chords = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if np.any(chords < 0.01):
        pts = pts + np.arange(len(pts))[:, None] * np.array([0.02, 0.0, 0.0])
    return pts


@settings(max_examples=40, deadline=None)
@given(key_points())
def test_the_path_passes_through_every_key_point_and_its_ends_are_straight(pts: np.ndarray) -> None:
    path = space_path(_poses(pts), straight_ends=True)
    np.testing.assert_allclose(path.points(path.key_s), pts, atol=POINT_TOL_M)
    for a, b, P, Q in ((0.0, path.key_s[1], pts[0], pts[1]), (path.key_s[-2], path.length, pts[-2], pts[-1])):
        inner = path.points(np.linspace(a, b, 50))
        axis = (Q - P) / np.linalg.norm(Q - P)
        rel = inner - P
        off = np.linalg.norm(rel - np.outer(rel @ axis, axis), axis=1)
        assert float(off.max()) < POINT_TOL_M, "a straight end leaves its line"


@settings(max_examples=40, deadline=None)
@given(key_points())
def test_the_joins_are_tangent_continuous_with_zero_curvature(pts: np.ndarray) -> None:
    path = space_path(_poses(pts))
    for s in path.key_s[1:-1]:
        before = path.points(np.array([s - 2 * FD_STEP_M, s - FD_STEP_M]))
        after = path.points(np.array([s + FD_STEP_M, s + 2 * FD_STEP_M]))
        t0 = np.diff(before, axis=0)[0]
        t1 = np.diff(after, axis=0)[0]
        cos = float(t0 @ t1 / np.linalg.norm(t0) / np.linalg.norm(t1))
        assert np.arccos(min(1.0, cos)) < ANGLE_TOL_RAD
        assert float(path.curvature(np.array([s]))[0]) < 1e-6


def test_orientation_turns_with_the_arclength_between_key_poses(rng: np.random.Generator) -> None:
    pts = np.array([[0, 0, 0], [0.1, 0, 0], [0.2, 0.1, 0], [0.3, 0.1, 0.05]], dtype=float)
    T = _poses(pts, rng)
    path = space_path(T)
    np.testing.assert_allclose(path.poses(path.key_s)[:, :3, :3], T[:, :3, :3], atol=1e-9)
    keys = path.key_s
    mid = path.poses(np.array([0.5 * (keys[1] + keys[2])]))[0, :3, :3]
    half = Rotation.from_matrix(T[1, :3, :3].T @ mid).magnitude()
    whole = Rotation.from_matrix(T[1, :3, :3].T @ T[2, :3, :3]).magnitude()
    np.testing.assert_allclose(half, 0.5 * whole, rtol=1e-6)


def test_the_sampled_chords_keep_their_sagitta() -> None:
    """Quarter turns of 0.1 m radius: chords sampled for a 1 mm sagitta stay within it."""
    pts = np.array([[0, 0, 0], [0, 0, 0.1], [0.1, 0, 0.2], [0.2, 0, 0.1], [0.2, 0, 0]], dtype=float)
    path = space_path(_poses(pts), straight_ends=True)
    tol = 0.001
    samples = sample_lines(path, tol, 0.12, 0.005)
    np.testing.assert_allclose(samples.poses[[0, -1], :3, 3], pts[[0, -1]], atol=POINT_TOL_M)
    dense = path.points(np.linspace(0.0, path.length, 4000))
    worst = 0.0
    for a, b in zip(samples.poses[:-1, :3, 3], samples.poses[1:, :3, 3], strict=True):
        u = np.linspace(0.0, 1.0, 50)[:, None]
        chord = a + u * (b - a)
        worst = max(worst, float(np.min(np.linalg.norm(chord[:, None] - dense[None], axis=2), axis=1).max()))
    assert worst <= tol * 1.05, f"chord {worst * 1000:.3f} mm off the path"
    assert deviation(path, path.points(samples.s)) < 1e-7


def test_a_stretch_has_its_own_speed_and_a_key_point_the_lower() -> None:
    at = stretch_speeds(np.array([0.0, 0.03, 0.2, 0.23]), np.array([0.5, 1.0, 0.5]))
    got = at(np.array([0.0, 0.01, 0.03, 0.1, 0.2, 0.21, 0.23]))
    np.testing.assert_allclose(got, [0.5, 0.5, 0.5, 1.0, 0.5, 0.5, 0.5])

