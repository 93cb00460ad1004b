"""robomax_py.world.pair_cells: the cells of the joints between two neighbouring pieces of the arm,
certified free once and then cleared by the pre-filter without coal's test.

What must hold: the pairs given cells are exactly the pairs of two robot pieces with one or two
revolute joints between them (by Pinocchio's own list of the joints that support each joint); a
certified cell is free throughout by coal's own distance, whatever the other joints are; every
verdict of a world is coal's (a world without the pre-filter); a filter made for another margin
starts with no cell decided.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.robot import RobotModel
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.collision_core import CERTIFY_SLACK_M
from robomax_py.world.pair_cells import (
    CELL_PAD_RAD,
    CELL_RAD,
    CERTIFIED,
    UNCERTIFIED,
    CellTable,
)
from tests.world.cell_checks import either_side, free_throughout, undecided_world

REFERENCE_CELL = Path(__file__).resolve().parents[2] / "tests" / "data" / "reference" / "cabin_flange.yaml"


@pytest.fixture()
def reference() -> tuple[RobotModel, CollisionWorld]:
    """A world of its own (its cells' decisions start empty), the KR 16-class arm of the reference
    cell with its gun (three pairs get cells: the forearm against the flange and two gun pieces)."""
    return undecided_world(REFERENCE_CELL)


def _tables(world: CollisionWorld) -> tuple[CellTable | None, ...]:
    assert world._s.prefilter is not None
    return world._s.prefilter.cells.tables


def test_the_pairs_given_cells(reference: tuple[RobotModel, CollisionWorld]) -> None:
    _, world = reference
    s = world._s
    model, gm = s.model, s.geom_model
    expected = {}
    for k, (a, b) in enumerate(zip(s.pair_a, s.pair_b)):
        if s.pair_obstacle[k] >= 0:
            continue
        ja, jb = (int(gm.geometryObjects[int(g)].parentJoint) for g in (a, b))
        for near, far in ((ja, jb), (jb, ja)):
            between = [int(j) for j in model.supports[far] if j not in set(model.supports[near])]
            if near in model.supports[far] and 1 <= len(between) <= 2:
                expected[k] = tuple(int(model.idx_qs[j]) for j in between)
    given_cells = {k: t.q_index for k, t in enumerate(_tables(world)) if t is not None}
    assert given_cells == expected
    assert len(given_cells) == 3                  # the forearm and the flange, the forearm and two gun pieces
    for t in given_cells:
        table = _tables(world)[t]
        assert table is not None
        for i, count in zip(table.q_index, table.count):
            span = s.model.upperPositionLimit[i] - s.model.lowerPositionLimit[i]
            assert (count - 1) * CELL_RAD <= span < count * CELL_RAD


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-8.0, 8.0) | st.just(float("nan")), min_size=6, max_size=6))
def test_a_configuration_is_in_the_box_of_its_cell(q: list[float]) -> None:
    table = CellTable(q_index=(4, 5), low=(-2.0943951, -6.10865238), count=(84, 245), start=17)
    cell = table.cell(np.array(q))
    inside = all(low <= q[i] < low + count * CELL_RAD for i, low, count in zip(table.q_index, table.low, table.count))
    if not inside:
        assert cell == -1
        return
    assert 17 <= cell < 17 + 84 * 245
    lo, hi = table.box(np.array(q), cell)
    joints = list(table.q_index)
    assert (lo[joints] <= np.array(q)[joints]).all() and (np.array(q)[joints] <= hi[joints]).all()
    np.testing.assert_allclose(hi[joints] - lo[joints], CELL_RAD + 2 * CELL_PAD_RAD, atol=1e-12)
    others = [i for i in range(6) if i not in joints]     # the other joints stay at q's values
    np.testing.assert_array_equal(lo[others], np.array(q)[others])


def _near_the_gun(robot: RobotModel, world: CollisionWorld, rng: np.random.Generator, n: int) -> np.ndarray:
    """Configurations on both sides of a contact between the forearm and the gun or flange (pairs
    with cells), a few microradians of A5 and A6 apart, and others around them in the same cells."""
    exact = world.copy(prefilter=False)
    tables = _tables(world)
    lo, hi = robot.limits.lower, robot.limits.upper
    out: list[np.ndarray] = []
    while len(out) < n:
        q = rng.uniform(lo, hi)
        contact = exact.check(q).contact
        if contact is None or not ({contact.body_a, contact.body_b} & {"link_6", "tool_body"}):
            continue
        free = q.copy()
        free[4:] = rng.uniform(lo[4:], hi[4:])
        if not exact.is_free(free):
            continue
        a, b = either_side(exact, q, free)  # only A5 and A6 differ: the self pairs' joints
        out.extend([a, b])
        # Others in the same cells (A5 and A6 within a cell's width), the arm elsewhere.
        for _ in range(4):
            other = b.copy()
            other[:4] = rng.uniform(lo[:4], hi[:4])
            other[4:] += rng.uniform(-CELL_RAD, CELL_RAD, size=2)
            out.append(np.clip(other, lo, hi))
    assert any(t is not None for t in tables)
    return np.asarray(out)


def test_the_same_verdicts_as_coal_alone(reference: tuple[RobotModel, CollisionWorld]) -> None:
    robot, world = reference
    rng = np.random.default_rng(11)
    qs = np.concatenate([_near_the_gun(robot, world, rng, 60), rng.uniform(robot.limits.lower, robot.limits.upper,
                                                                          size=(300, robot.dof))])
    exact = world.copy(prefilter=False)
    expected = np.array([exact.is_free(q) for q in qs])
    assert 0 < expected.sum() < len(qs)
    first = world.are_free(qs)               # decides the cells the configurations reach
    decided = world._s.prefilter.cells.decided  # type: ignore[union-attr]
    assert (decided == CERTIFIED).any() and (decided == UNCERTIFIED).any()
    second = world.are_free(qs)              # the filter clears the certified cells' pairs
    np.testing.assert_array_equal(first, expected)
    np.testing.assert_array_equal(second, expected)
    for q, free in zip(qs[:40], expected[:40]):
        assert world.check(q).free == free
        assert world.segment_free(q, q) == free


def test_a_certified_cell_is_free_throughout(reference: tuple[RobotModel, CollisionWorld]) -> None:
    """coal's distance at configurations spread over each certified cell (the other joints anywhere)
    exceeds the pair's margin: the definition the certificate stands for."""
    robot, world = reference
    rng = np.random.default_rng(5)
    qs = np.concatenate([_near_the_gun(robot, world, rng, 30),
                         rng.uniform(robot.limits.lower, robot.limits.upper, size=(100, robot.dof))])
    pairs = [k for k, t in enumerate(_tables(world)) if t is not None]
    for q in qs:                            # each pair's cell at each configuration decided
        world._uncertified(q, pairs)
    s = world._s
    scratch = (s.model.createData(), s.geom_model.createData())
    decided = s.prefilter.cells.decided  # type: ignore[union-attr]
    checked = 0
    for k, table in enumerate(_tables(world)):
        if table is None:
            continue
        for q in qs:
            cell = table.cell(q)
            if cell >= 0 and decided[cell] == CERTIFIED:
                checked += free_throughout(world, robot, k, table, *table.box(q, cell), rng, scratch)
    assert checked >= 100


def test_a_screen_for_another_distance_decides_nothing(reference: tuple[RobotModel, CollisionWorld]) -> None:
    """A cell certified for a pair's own margin says nothing of a larger distance: the screen made for
    one (`distance_screen`) starts with none decided, and still names the pair."""
    robot, world = reference
    rng = np.random.default_rng(3)
    qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(50, robot.dof))
    pairs = [k for k, t in enumerate(_tables(world)) if t is not None]
    for q in qs:
        world._uncertified(q, pairs)
    cells = world._s.prefilter.cells  # type: ignore[union-attr]
    k, table = next((k, t) for k, t in enumerate(cells.tables) if t is not None
                    and any(t.cell(q) >= 0 and cells.decided[t.cell(q)] == CERTIFIED for q in qs))
    q = next(q for q in qs if table.cell(q) >= 0 and cells.decided[table.cell(q)] == CERTIFIED)
    distance = world.pair_distances(q, np.array([k]))[0]
    screen = world.distance_screen(distance + 0.01)
    assert screen is not None and not screen.cells.decided.any()
    only = np.zeros(world.n_pairs, dtype=bool)
    only[k] = True
    assert distance > world._s.pair_margin[k] + CERTIFY_SLACK_M       # certified: farther than its margin
    assert k in world.pairs_within(q, only, screen).tolist()
