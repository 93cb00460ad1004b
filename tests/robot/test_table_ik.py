"""The associative-memory IK (robot.ik.table) on the planar storage arm (robot.planar): the grid is
the paper's formula, the table keeps exactly the free rows, lookups are the nearest stored point,
routes over the k-NN graph only use free edges, and Jacobian interpolation stays on the line."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.robot.ik.table import (
    JointGrid,
    build_table,
    jacobian_interpolation,
    route,
)
from robomax_py.robot.planar import Container, PlanarArm

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
