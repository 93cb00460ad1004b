"""The TCP's route through the tending cell's free voxels: into a machine it passes the door
opening, waits outside while the door is closed, and the arm follows it in one branch."""

from __future__ import annotations

import itertools
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan.candidates import seam_candidates
from robomax_py.plan.tcp_route import dynamic_boxes, follow, tcp_route, tcp_space
from robomax_py.plan.timed_search import NoRoute
from robomax_py.robot import fk_tcp
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
# The door of CNC 1 (cells/tending.yaml): the plane x = 1.03 m, the opening |y| < 0.45, 0.75 < z < 1.6.
DOOR_X, OPENING_Y, OPENING_Z = 1.03, 0.45, (0.75, 1.6)


@pytest.fixture(scope="module")
def cell_world() -> dict[str, object]:
    cell = load_cell(REPO / "cells" / "tending.yaml")
    robot = load_cell_robot(cell)
    static = build_scene(replace(cell, dynamic=()), robot)
    world = CollisionWorld(robot, static, cell.process.clearance)
    space = tcp_space(static, robot, cell.process.clearance, dynamic_boxes(build_scene(cell, robot)))
    found, _ = seam_candidates(cell, robot, world, 0)
    by_name = {c.name: c for c in found}
    return {"cell": cell, "robot": robot, "world": world, "space": space, "candidates": by_name}


def test_the_route_into_a_machine_passes_the_door_opening(cell_world: dict[str, object]) -> None:
    space, robot = cell_world["space"], cell_world["robot"]
    q0, q1 = _same_branch(cell_world)
    p0, p1 = fk_tcp(robot, q0)[:3, 3], fk_tcp(robot, q1)[:3, 3]  # type: ignore[arg-type]
    route = tcp_route(space, p0, p1, 0.0, max_wait=60.0)  # type: ignore[arg-type]
    assert not isinstance(route, NoRoute), route
    np.testing.assert_allclose(route[[0, -1]], [p0, p1])
    # Where the route crosses the door's plane, it is inside the opening.
    for a, b in itertools.pairwise(route):
        if (a[0] - DOOR_X) * (b[0] - DOOR_X) < 0:
            s = (DOOR_X - a[0]) / (b[0] - a[0])
            y, z = (a + s * (b - a))[1:]
            assert abs(y) < OPENING_Y and OPENING_Z[0] < z < OPENING_Z[1]
    # Every point of it lies in free voxels (the tips' reach and the clearance kept from the walls).
    dense = np.vstack([a + np.linspace(0, 1, 40)[:, None] * (b - a) for a, b in itertools.pairwise(route)])
    assert space.voxels.is_free(dense).all()          # type: ignore[union-attr]
    followed = follow(robot, cell_world["world"], route, q0, q1)  # type: ignore[arg-type]
    assert followed is not None
    np.testing.assert_array_equal(followed[[0, -1]], [q0, q1])
    assert np.max(np.abs(np.diff(followed, axis=0))) <= 1.2


def _same_branch(cell_world: dict[str, object]) -> tuple[np.ndarray, np.ndarray]:
    """Approach points of the conveyor and CNC 1 stations in one configuration branch, nearest in joints."""
    a, b = (cell_world["candidates"][n] for n in ("c1_conveyor_pick", "c1_cnc1_load"))  # type: ignore[index]
    pairs = [(float(np.max(np.abs(a.q_app[i] - b.q_app[j]))), i, j) for i in range(len(a)) for j in range(len(b))
             if a.status[i] == b.status[j]]
    _, i, j = min(pairs)
    return a.q_app[i], b.q_app[j]


def test_the_route_waits_outside_while_the_door_is_closed(cell_world: dict[str, object]) -> None:
    space, robot = cell_world["space"], cell_world["robot"]
    cands = cell_world["candidates"]
    p0 = fk_tcp(robot, cands["c1_conveyor_pick"].q_app[0])[:3, 3]  # type: ignore[arg-type,index]
    p1 = fk_tcp(robot, cands["c1_cnc1_load"].q_app[0])[:3, 3]      # type: ignore[arg-type,index]
    # The door is closed over [0, 9] s: no route may take it before then.
    short = tcp_route(space, p0, p1, 0.0, max_wait=2.0)  # type: ignore[arg-type]
    assert isinstance(short, NoRoute) and short.reason == "wait_limit"


def test_a_line_asked_again_gets_the_answer_of_the_voxels(cell_world: dict[str, object]) -> None:
    """The lines a space keeps answer as its voxels do (the first time and again), both ways on
    random lines through the cell, free and blocked, two from each start."""
    from robomax_py.plan.tcp_route import PRECISION_M, TcpSpace, _line_free

    space = cell_world["space"]
    assert isinstance(space, TcpSpace)
    rng = np.random.default_rng(5)
    answers = set()
    for _ in range(150):
        a, *ends = rng.uniform([-1.5, -1.5, 0.0], [1.5, 1.5, 2.0], size=(3, 3))     # two lines from a
        for b in ends:
            n = max(2, int(np.ceil(np.linalg.norm(b - a) / (PRECISION_M / 2))) + 1)
            want = bool(space.voxels.is_free(a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)).all())
            assert _line_free(space, a, b) == want and _line_free(space, a, b) == want
            assert _line_free(space, b, a) == bool(space.voxels.is_free(b + np.linspace(0.0, 1.0, n)[:, None] * (a - b)).all())
            answers.add(want)
    assert answers == {True, False}
