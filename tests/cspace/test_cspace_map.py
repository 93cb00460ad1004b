"""robomax_py.cspace: the exact A1-A3 map of a cell with the wrist fixed, and `robomax cspace`.

What must hold: a cell is blocked in the map exactly when the cell's collision world says its
configuration is not free (objects and self contact split, never lost); the answer does not depend
on the number of processes; a restricted world checks only the pairs it keeps; bad requests are
one message and exit 2.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_OK, app
from robomax_py.cspace import CSpaceError, CSpaceGrid, build_map, check_arm, exact_map
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

SmallCell = Callable[..., Path]
runner = CliRunner()


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell):  # type: ignore[no-untyped-def]
    path = write_small_cell(tmp_path_factory.mktemp("cs"), "small")
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    return path, cell, robot, CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)


def test_the_map_is_the_worlds_verdict_cell_by_cell(small) -> None:  # type: ignore[no-untyped-def]
    _, cell, robot, world = small
    grid = CSpaceGrid.of(robot, 9, np.asarray(cell.home)[3:])
    m = exact_map(world, grid)
    qs = grid.configs(0, grid.size)
    free = world.are_free(qs).reshape(9, 9, 9)
    assert (m.blocked == ~free).all()
    assert m.obstacle.any() and m.self_contact.any() and (~m.blocked).any()   # all three kinds occur
    only_objects = world.restricted(obstacles=True, self_pairs=False).are_free(qs).reshape(9, 9, 9)
    assert (m.obstacle == ~only_objects).all()
    assert m.checks == 2 * grid.size
    # cell (i, j, k) is (q1[i], q2[j], q3[k], wrist)
    i, j, k = 3, 5, 7
    np.testing.assert_array_equal(qs[(i * 9 + j) * 9 + k], [grid.axes[0][i], grid.axes[1][j], grid.axes[2][k],
                                                          *grid.wrist])
    assert grid.cell_of(qs[(i * 9 + j) * 9 + k]) == (i, j, k)


def test_processes_do_not_change_the_map(small) -> None:  # type: ignore[no-untyped-def]
    _, cell, robot, world = small
    grid = CSpaceGrid.of(robot, 26, np.asarray(cell.home)[3:])           # 17,576 cells: two blocks
    one, two = exact_map(world, grid, 1), exact_map(world, grid, 2)
    assert (one.obstacle == two.obstacle).all() and (one.self_contact == two.self_contact).all()


def test_a_restricted_world_checks_only_what_it_keeps(small) -> None:  # type: ignore[no-untyped-def]
    _, cell, robot, world = small
    grid = CSpaceGrid.of(robot, 12, np.asarray(cell.home)[3:])
    qs = grid.configs(0, grid.size)
    objects = ~world.restricted(obstacles=True, self_pairs=False).are_free(qs)
    itself = ~world.restricted(obstacles=False, self_pairs=True).are_free(qs)
    everything = ~world.are_free(qs)
    assert (everything == (objects | itself)).all()
    q_obj = qs[np.flatnonzero(objects & ~itself)[0]]
    only_self = world.restricted(obstacles=False, self_pairs=True)
    assert only_self.is_free(q_obj) and only_self.copy().is_free(q_obj)      # a copy stays restricted
    assert only_self.first_contact(q_obj) is None
    assert not world.restricted(obstacles=True, self_pairs=False).is_free(q_obj)
    nothing = world.restricted(obstacles=False, self_pairs=False)
    assert nothing.are_free(qs).all()


def test_bad_requests_are_cspace_errors(small) -> None:  # type: ignore[no-untyped-def]
    _, cell, robot, _ = small
    for r in (3, 401):
        with pytest.raises(CSpaceError, match="resolution must be 4..400"):
            CSpaceGrid.of(robot, r, np.zeros(3))
    with pytest.raises(CSpaceError, match="needs 3 finite joint values"):
        CSpaceGrid.of(robot, 10, np.array([0.0, np.nan, 0.0]))
    with pytest.raises(CSpaceError, match="no objects"):
        build_map(replace(cell, objects=(), dynamic=()), robot, "home", 8)
    with pytest.raises(CSpaceError, match="5 axes"):
        check_arm(types.SimpleNamespace(dof=5, name="five"))  # type: ignore[arg-type]
    sample = pin.buildSampleModelManipulator()                  # six axes, A1 about x
    arm = types.SimpleNamespace(dof=6, name="sample", model=sample, flange_frame_id=sample.getFrameId("effector_body"),
                                prismatic_joints=())
    with pytest.raises(CSpaceError, match="A1 is not vertical"):
        check_arm(arm)  # type: ignore[arg-type]
    # A vertical lift under five revolute axes would pass for a vertical A1: its axis is the base's z.
    lift = types.SimpleNamespace(dof=6, name="lift", prismatic_joints=("j1",))
    with pytest.raises(CSpaceError, match="lift: j1 is prismatic; the C-space map needs six revolute axes"):
        check_arm(lift)  # type: ignore[arg-type]


def test_cli_writes_the_picture_and_refuses_bad_requests(small, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    path = small[0]
    png = tmp_path / "map.png"
    result = runner.invoke(app, ["cspace", str(path), "--resolution", "10", "--plot", str(png), "-j", "1", "--json"])
    assert result.exit_code == EXIT_OK, result.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert '"cells": 1000' in result.output and '"method": "exact"' in result.output
    result = runner.invoke(app, ["cspace", str(path), "--wrist", "s7", "--resolution", "6", "-j", "1"])
    assert result.exit_code == EXIT_OK, result.output
    planned = runner.invoke(app, ["plan", str(path), "-o", str(tmp_path / "prog")])
    assert planned.exit_code == EXIT_OK, planned.output
    with_path = tmp_path / "with_path.png"
    result = runner.invoke(app, ["cspace", str(path), "--resolution", "8", "-j", "1", "--plot", str(with_path),
                                 "--program", str(tmp_path / "prog" / "small.json")])
    assert result.exit_code == EXIT_OK, result.output
    assert with_path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for args, message in ((["--resolution", "3"], "resolution must be 4..400"),
                          (["--wrist", "nope"], "no spot named 'nope'"),
                          (["--program", str(tmp_path / "missing.json")], "program file not found")):
        bad = tmp_path / "bad.png"
        result = runner.invoke(app, ["cspace", str(path), *args, "--plot", str(bad)])
        assert result.exit_code == EXIT_BAD_INPUT, result.output
        assert message in " ".join(result.output.split())
        assert "Traceback" not in result.output
        assert not bad.exists()
