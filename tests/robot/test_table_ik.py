"""The associative-memory IK (robot.ik.table) on the planar storage arm (robot.planar): the grid is
the paper's formula, the table keeps exactly the free rows, lookups are the nearest stored point,
routes over the k-NN graph only use free edges, Jacobian interpolation stays on the line and
arrives only in its own branch, and the container's exact collision test agrees with sampling."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.robot.ik.pose_table import ROTATION_WEIGHT_M
from robomax_py.robot.ik.table import (
    JointGrid,
    build_table,
    follow_edge,
    jacobian_interpolation,
    route,
)
from robomax_py.robot.planar import FOOT_M, Container, PlanarArm

HALF_PI = np.pi / 2
# Jacobian interpolation in steps of 5 mm keeps the tip within 0.5 mm of the straight line (the
# first-order step's error grows with the step squared over the arm's ~1 m radius of curvature).
STEP_M, LINE_TOL_M = 0.005, 0.0005


@pytest.fixture(scope="module")
def tables() -> dict[str, object]:
    box = Container.storage()
    grid = JointGrid.stepped((-HALF_PI,) * 3, (HALF_PI,) * 3, 18)
    empty, loaded = PlanarArm(), PlanarArm(held=0.25)
    return {
        "box": box, "grid": grid, "arm": empty, "loaded_arm": loaded,
        "empty": build_table(grid, empty.tip, lambda q: box.free(empty, q)),
        "loaded": build_table(grid, loaded.tip, lambda q: box.free(loaded, q)),
    }


def test_grid_follows_the_formula() -> None:
    g = JointGrid.stepped((-HALF_PI,) * 3, (HALF_PI,) * 3, 9)
    np.testing.assert_allclose(g.values(0), -HALF_PI + np.arange(9) * np.pi / 8, atol=0)
    assert g.size == 729
    rows = g.rows(0, g.size)
    assert len(np.unique(rows, axis=0)) == 729
    with pytest.raises(ValueError):
        JointGrid.stepped((0.0,), (1.0,), 1)


def test_the_table_keeps_exactly_the_free_rows(tables: dict[str, object]) -> None:
    grid, arm, box, empty = tables["grid"], tables["arm"], tables["box"], tables["empty"]
    rows = grid.rows(0, grid.size)                                     # type: ignore[union-attr]
    free = box.free(arm, rows)                                         # type: ignore[union-attr]
    assert len(empty) == int(free.sum()) and empty.grid_size == grid.size  # type: ignore[union-attr,arg-type]
    np.testing.assert_array_equal(empty.q, rows[free])                 # type: ignore[union-attr]
    np.testing.assert_allclose(empty.x, arm.tip(rows[free]), atol=0)   # type: ignore[union-attr]


def test_holding_a_part_only_removes_rows(tables: dict[str, object]) -> None:
    empty, loaded = tables["empty"], tables["loaded"]
    assert 0 < len(loaded) < len(empty)                                 # type: ignore[arg-type]
    stored = {tuple(q) for q in empty.q}                               # type: ignore[union-attr]
    assert all(tuple(q) in stored for q in loaded.q)                   # type: ignore[union-attr]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-1.2, 1.2), st.floats(-0.2, 2.2)), min_size=1, max_size=20))
def test_lookup_is_the_nearest_stored_point(targets: list[tuple[float, float]]) -> None:
    arm, box = PlanarArm(), Container.storage()
    table = build_table(JointGrid.stepped((-HALF_PI,) * 3, (HALF_PI,) * 3, 9), arm.tip, lambda q: box.free(arm, q))
    t = np.array(targets)
    q, err = table.lookup(t)
    brute = np.linalg.norm(table.x[None, :, :] - t[:, None, :], axis=2)
    np.testing.assert_allclose(err, brute.min(axis=1), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(arm.tip(q) - t, axis=1), err, atol=1e-12)
    # One target per call (the compiled scan) finds the same distance.
    for target, e in zip(t, err):
        q1, e1 = table.nearest(target)
        assert abs(e1 - e) <= 1e-12 and abs(float(np.linalg.norm(arm.tip(q1[None])[0] - target)) - e) <= 1e-12


def test_a_route_uses_only_free_edges(tables: dict[str, object]) -> None:
    arm, box, table = tables["arm"], tables["box"], tables["empty"]

    def edge_free(a: np.ndarray, b: np.ndarray) -> bool:
        steps = np.linspace(0.0, 1.0, 41)[:, None]
        return bool(box.free(arm, a + steps * (b - a)).all())        # type: ignore[union-attr]

    start = int(np.argmin(np.linalg.norm(table.x - [-0.8, 0.85], axis=1)))   # type: ignore[union-attr]
    goal = int(np.argmin(np.linalg.norm(table.x - [0.8, 1.5], axis=1)))      # type: ignore[union-attr]
    found = route(table, start, goal, 6, edge_free)                    # type: ignore[arg-type]
    assert found.found and found.nodes[0] == start and found.nodes[-1] == goal
    for u, v in zip(found.nodes[:-1], found.nodes[1:]):
        assert edge_free(table.q[u], table.q[v])                       # type: ignore[union-attr]
    with pytest.raises(ValueError):
        route(table, start, goal, 2, edge_free)                        # type: ignore[arg-type]


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1.2, 1.2), min_size=3, max_size=3))
def test_jacobian_matches_finite_differences(q: list[float]) -> None:
    arm = PlanarArm()
    qa = np.array(q)
    h = 1e-6
    numeric = np.stack([(arm.tip(qa + h * e) - arm.tip(qa - h * e))[0] / (2 * h) for e in np.eye(3)], axis=1)
    np.testing.assert_allclose(arm.jacobian(qa), numeric, atol=1e-6)


def test_jacobian_interpolation_stays_on_the_line() -> None:
    arm = PlanarArm()
    q0 = np.array([0.3, 0.6, 0.5])
    p0 = arm.tip(q0)[0]
    p1 = p0 + np.array([0.25, 0.3])
    rows, worst = jacobian_interpolation(q0, p1, arm.tip, arm.jacobian, STEP_M)
    assert worst <= LINE_TOL_M
    assert np.linalg.norm(arm.tip(rows[-1:])[0] - p1) <= LINE_TOL_M
    assert len(rows) == int(np.ceil(np.linalg.norm(p1 - p0) / STEP_M)) + 1


def test_a_grid_wholly_in_collision_is_refused() -> None:
    arm = PlanarArm()
    grid = JointGrid.stepped((-HALF_PI,) * 3, (HALF_PI,) * 3, 3)
    with pytest.raises(ValueError, match="every one of the grid's 27 rows is in collision"):
        build_table(grid, arm.tip, lambda q: np.zeros(len(q), dtype=bool))


def _sampled_hits(arm: PlanarArm, box: Container, q: np.ndarray, radius: float) -> np.ndarray:
    """Collisions found by points at most 1 mm apart along each segment (an independent test)."""
    segs = arm.segments(q)
    t = np.linspace(0.0, 1.0, 1001)
    pts = segs[:, :, :1] + t[None, None, :, None] * (segs[:, :, 1:] - segs[:, :, :1])
    along = t[None, None, :] * np.linalg.norm(segs[:, :, 1] - segs[:, :, 0], axis=2)[:, :, None]
    tested = np.ones(pts.shape[:3], dtype=bool)
    tested[:, 0] = along[:, 0] >= FOOT_M                 # the first link's foot stands on the floor
    hit = np.zeros(len(q), dtype=bool)
    for x0, y0, x1, y1 in box.rects:
        dx = np.maximum(np.maximum(x0 - pts[..., 0], pts[..., 0] - x1), 0.0)
        dy = np.maximum(np.maximum(y0 - pts[..., 1], pts[..., 1] - y1), 0.0)
        hit |= ((dx * dx + dy * dy <= radius * radius) & tested).any(axis=(1, 2))
    return hit


@pytest.mark.parametrize("held", [0.0, 0.25])
def test_the_containers_exact_test_agrees_with_dense_sampling(held: float) -> None:
    """A sample within the radius is a collision for the exact test; a collision of the exact test
    has a sample within the radius and half the spacing (0.5 mm: the 1 m link at 1,001 points)."""
    arm, box = PlanarArm(held=held), Container.storage()
    q = np.random.default_rng(7).uniform(-HALF_PI, HALF_PI, size=(400, 3))
    exact = ~box.free(arm, q)
    assert exact.any() and not exact.all()
    assert not (_sampled_hits(arm, box, q, arm.radius) & ~exact).any()
    assert not (exact & ~_sampled_hits(arm, box, q, arm.radius + 0.0005 + 1e-9)).any()


def _other_elbow(arm: PlanarArm, q: np.ndarray) -> np.ndarray:
    """The configuration with the same tip pose and the elbow (joint 2) mirrored."""
    L1, L2, L3 = arm.links
    heading = float(q.sum())
    wrist = arm.tip(q[None])[0] - L3 * np.array([-np.sin(heading), np.cos(heading)])
    h_w = np.arctan2(-wrist[0], wrist[1])                 # the wrist point's heading from the vertical
    beta = np.arctan2(L2 * np.sin(q[1]), L1 + L2 * np.cos(q[1]))
    q1, q2 = h_w + beta, -q[1]
    return np.array([q1, q2, heading - q1 - q2])


def test_an_edge_arrives_only_in_its_own_branch() -> None:
    """Following the tip's pose (a non-redundant point) the interpolation reaches a neighbouring
    configuration exactly, off the straight line in the pose space by the sagitta of the heading's
    arc (its weighted cosine and sine move on a circle) and 0.1 mm; the same pose with the elbow
    mirrored is not arrived at."""
    arm = PlanarArm()
    q_a = np.array([0.3, 0.6, 0.5])
    near = follow_edge(q_a, q_a + 0.05, arm.pose, arm.pose_jacobian, STEP_M, 0.02)
    sagitta = ROTATION_WEIGHT_M * (1 - np.cos(3 * 0.05 / 2))          # the heading turns by 0.15 rad
    assert near.arrived and np.array_equal(near.rows[-1], q_a + 0.05) and near.off_line <= sagitta + 1e-4
    mirrored = _other_elbow(arm, q_a + 0.05)
    np.testing.assert_allclose(arm.pose(mirrored[None]), arm.pose((q_a + 0.05)[None]), atol=1e-12)
    assert not follow_edge(q_a, mirrored, arm.pose, arm.pose_jacobian, STEP_M, 0.02).arrived
