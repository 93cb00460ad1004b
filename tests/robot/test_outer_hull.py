"""robomax_py.robot.geometry.outer_hull: a link hull of many vertices replaced by an outer polytope
of fewer, which contains the hull and reaches at most LINK_HULL_EXCESS_M beyond it.

Both properties are checked by other means than the function's own: containment by the output's
face planes (scipy's hull of the output) against every input point; the excess by each output
vertex's distance to the input's hull as coal's GJK measures it (a point against the convex
polytope), not by the surface distance (trimesh's closest points) the function uses."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from robomax_py.robot.geometry import (
    LINK_HULL_EXCESS_M,
    LINK_HULL_MAX_VERTICES,
    hull_shape,
    hull_vertices,
    outer_hull,
)

# Round-off allowed on containment and on the excess bound, m (GJK's tolerance is 1e-6).
ROUND_OFF_M = 2e-6


def _distance_to_hull(points: np.ndarray, p: np.ndarray) -> float:
    """Distance from p to the convex hull of `points`, by coal's GJK (a sphere of 1 nm at p)."""
    import coal

    result = coal.DistanceResult()
    coal.distance(hull_shape(points), coal.Transform3s(), coal.Sphere(1e-9), coal.Transform3s(np.eye(3), p),
                  coal.DistanceRequest(), result)
    return max(0.0, float(result.min_distance) + 1e-9)


def _check(points: np.ndarray, excess: float = LINK_HULL_EXCESS_M) -> np.ndarray:
    original = hull_vertices(points)
    outer = outer_hull(points, excess)
    planes = ConvexHull(outer).equations
    assert np.max(original @ planes[:, :3].T + planes[:, 3]) <= ROUND_OFF_M       # contains the hull
    assert max(_distance_to_hull(original, v) for v in outer) <= excess + ROUND_OFF_M
    return outer


def _tessellated_casting(sections: int) -> np.ndarray:
    """A link-like solid as CAD tessellates it: a 0.4 m cylinder with a boss, `sections` facets."""
    body = trimesh.creation.cylinder(radius=0.08, height=0.4, sections=sections)
    boss = trimesh.creation.cylinder(radius=0.05, height=0.1, sections=sections).apply_translation([0.1, 0, 0.15])
    return np.vstack([body.vertices, boss.vertices])


def test_a_finely_tessellated_casting_gets_fewer_vertices_within_the_excess() -> None:
    points = _tessellated_casting(400)
    assert len(hull_vertices(points)) > LINK_HULL_MAX_VERTICES
    outer = _check(points)
    assert len(outer) < len(hull_vertices(points)) / 3


def test_a_hull_of_few_vertices_is_kept_as_it_is() -> None:
    points = _tessellated_casting(32)
    assert len(hull_vertices(points)) <= LINK_HULL_MAX_VERTICES
    np.testing.assert_array_equal(outer_hull(points), hull_vertices(points))


def test_a_flat_mesh_is_kept_as_it_is() -> None:
    disc = trimesh.creation.annulus(0.05, 0.2, 1e-9, sections=400).vertices
    disc[:, 2] = 0.0
    np.testing.assert_array_equal(outer_hull(disc), hull_vertices(disc))


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), axes=st.tuples(*[st.floats(0.02, 0.3)] * 3),
       excess=st.sampled_from([0.0005, 0.001, 0.003]))
def test_random_clouds_are_contained_and_within_the_excess(seed: int, axes: tuple[float, float, float],
                                                          excess: float) -> None:
    """Points on and in an ellipsoid (a smooth hull of hundreds of vertices, the hard case)."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(1500, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    points = d * np.asarray(axes) * rng.uniform(0.9, 1.0, size=(len(d), 1))
    if len(hull_vertices(points)) <= LINK_HULL_MAX_VERTICES:
        return
    _check(points, excess)


@pytest.mark.parametrize("excess", [0.001])
def test_coal_sees_the_outer_polytope_touch_whatever_touches_the_hull(excess: float) -> None:
    """A box moved towards the casting until coal reports contact with the hull: coal reports the
    outer polytope in contact there too, and already within `excess` before it."""
    import coal

    points = _tessellated_casting(400)
    inner, outer = hull_shape(hull_vertices(points)), hull_shape(outer_hull(points, excess))
    box = coal.Box(0.05, 0.05, 0.05)
    request = coal.CollisionRequest()
    request.enable_contact = True
    for direction in np.eye(3).tolist() + [[1, 1, 0], [0.3, -1, 0.5]]:
        u = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
        for r in np.linspace(0.3, 0.0, 301):
            at = coal.Transform3s(np.eye(3), u * r)
            if coal.collide(inner, coal.Transform3s(), box, at, request, coal.CollisionResult()):
                assert coal.collide(outer, coal.Transform3s(), box, at, request, coal.CollisionResult())
                break
            near = coal.DistanceResult()
            coal.distance(outer, coal.Transform3s(), box, at, coal.DistanceRequest(), near)
            far = coal.DistanceResult()
            coal.distance(inner, coal.Transform3s(), box, at, coal.DistanceRequest(), far)
            assert far.min_distance - excess - 1e-6 <= near.min_distance <= far.min_distance + 1e-9
