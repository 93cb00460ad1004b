"""robomax_py.plan.learned_detour: planning in the learned C-space map (`planner.detours: learned`).

What must hold: a cell whose clamp stands between its spots plans with every detour taken from the
learned map (the detours' inner waypoints are map cells, at the map's wrist), its program verifies,
and every step of the timed motion passes the exact swept check of a collision world built here (an
independent check: the learned map has no say in it); a map that is wrong on purpose (no obstacle
at all) has its path through the clamp refused by the exact check, counted and repaired, and what
it offers, if anything, is free; the cell keys take `learned` and its settings and refuse bad ones;
a robot the method cannot map is one message naming the cell and the key.
The model is trained on the coarse grid into a folder of the test's own (seconds).
"""

from __future__ import annotations

import itertools
import json
import re
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.cspace import CSpaceError, exact_map
from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import learned_detour, plan_cell
from robomax_py.plan.candidates import seam_candidates
from robomax_py.plan.learned_detour import LearnedDetours
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
FLANGE_CELL = REPO / "tests" / "data" / "flange_cell" / "cabin_flange.yaml"
WRIST_TOL_RAD = 1e-12
WALL_PAIRS = 6             # searches across walls of the exact map in a map without obstacles
# s5 and s6 of the frozen reference cell with clamp 1 on the flange between them, the panel on its
# table: the straight moves home -> s5 -> s6 -> home are blocked, so the plan needs detours.
KEEP_OBJECTS = ("table", "fixture_plate", "cabin_panel", "clamp1_jaw", "clamp1_arm", "clamp1_post")
LEARNED = {"detours": "learned", "learned": {"training": "coarse", "resolution": 30}}


def write_clamp_cell(folder: Path, planner: dict[str, Any]) -> Path:
    data = yaml.safe_load(FLANGE_CELL.read_text())
    if not (folder / "parts").exists():
        shutil.copytree(FLANGE_CELL.parent / "parts", folder / "parts")
    data["name"] = "clamp_learned"
    data["objects"] = [o for o in data["objects"] if o["name"] in KEEP_OBJECTS]
    seam = data["seams"][0]
    seam.update(ordered=True, grid=3)
    seam["tolerance"]["gamma"] = [0, 0]
    seam["spots"] = [s for s in seam["spots"] if s["name"] in ("s5", "s6")]
    data["planner"] = {"seed": 0, **planner}
    path = folder / "clamp_learned.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def clamp_cell(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, Any, Any]]:
    """The cell, loaded, with the model cache in a folder of this module's own."""
    folder = tmp_path_factory.mktemp("learned_plan")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ROBOMAX_CACHE", str(folder / "cache"))
        path = write_clamp_cell(folder, LEARNED)
        cell = load_cell(path)
        yield path, cell, load_cell_robot(cell)


@pytest.fixture(scope="module")
def learned_plan(clamp_cell):  # type: ignore[no-untyped-def]
    _, cell, robot = clamp_cell
    return plan_cell(cell, robot)


def test_a_clamped_cell_plans_in_the_learned_map_and_every_motion_is_free(  # type: ignore[no-untyped-def]
        clamp_cell, learned_plan, tmp_path: Path) -> None:
    path, cell, robot = clamp_cell
    result = learned_plan
    assert result.status == "planned", result.message
    assert result.stats is not None and result.stats.learned is not None
    m = result.stats.learned
    detours = [t for t in result.transitions if t.kind == "detour"]
    assert detours and m.found >= len({t.label for t in detours})
    # Every detour is the map's: it passes map cells, which hold the map's wrist (a lift or a
    # roadmap path would not; a detour found for other candidates of the two spots also passes
    # those candidates' configurations, joined to it by checked legs).
    for t in detours:
        at_wrist = np.all(np.abs(t.waypoints[1:-1, 3:] - np.asarray(m.wrist)) <= WRIST_TOL_RAD, axis=1)
        assert at_wrist.any(), t.label
    # Needed: the straight move between the planned configurations at s5 and s6 is blocked.
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    s5, s6 = result.spots
    assert not world.segment_free(s5.q_app, s6.q_app)
    # Every step of the timed motion, swept exactly (2 mm), in a world built here.
    q = result.trajectory.q
    blocked = [k for k in range(len(q) - 1) if not world.segment_free(q[k], q[k + 1])]
    assert blocked == []

    # The program, written and proved as `robomax plan` does, verifies as `robomax verify` reads it.
    from robomax_py.app.api import LoadedCell, write_programs
    from robomax_py.app.cli import app
    from robomax_py.app.report import plan_report

    written = write_programs(LoadedCell(cell, robot), result, tmp_path / "programs")
    verified = CliRunner().invoke(app, ["verify", str(path), str(written.by_dialect["srcl"][0])], env={"COLUMNS": "400"})
    assert verified.exit_code == 0, verified.output
    assert "clean" in verified.output
    report = json.loads(json.dumps(plan_report(result, 0.0, list(written))))
    assert report["learned_map"]["found"] == m.found and report["learned_map"]["neurons"] == m.neurons


def test_a_path_the_exact_check_refuses_is_repaired_and_never_offered(clamp_cell) -> None:  # type: ignore[no-untyped-def]
    _, cell, robot = clamp_cell
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots = seam_candidates(cell, robot, world, 0)[0]
    real = LearnedDetours.build(cell, robot, world, spots, cell.planner.learned)   # trained once per module
    # A map that knows of no obstacle, asked for ways between map cells on either side of a wall of
    # two cells the exact map blocks along A1: its shortest ways run into the objects.
    exact = exact_map(world, real.grid)
    nothing = np.zeros_like(real.obstacle)
    wrong = LearnedDetours(real.grid, nothing, nothing, robot.limits, real.model, real.figures)
    free = ~(exact.obstacle | exact.self_contact)
    r = real.grid.resolution
    walls = np.argwhere(free[:-3] & free[3:] & exact.obstacle[1:-2] & exact.obstacle[2:-1])
    pairs = walls[np.linspace(0, len(walls) - 1, WALL_PAIRS).astype(int)]
    for i, j, k in pairs:
        qa = real.configs[(i * r + j) * r + k]
        qb = real.configs[((i + 3) * r + j) * r + k]
        assert not world.segment_free(qa, qb)
        det, checks = wrong.query(world, qa, qb)
        assert checks > 0
        if det is not None:                                   # what is offered is free, end to end
            np.testing.assert_array_equal(det.waypoints[[0, -1]], [qa, qb])
            assert all(world.segment_free(a, b) for a, b in itertools.pairwise(det.waypoints))
    report = wrong.report()
    assert report.searches == WALL_PAIRS
    assert report.refused_segments >= 1, report               # refused by the exact check, repaired
    assert report.found >= 1, report


def test_the_cell_keys_take_learned_and_refuse_bad_settings(tmp_path: Path) -> None:
    cell = load_cell(write_clamp_cell(tmp_path, {"detours": "learned", "learned": {"neurons": 8, "spacing": 0.2}}))
    assert cell.planner.detours == "learned"
    assert (cell.planner.learned.neurons, cell.planner.learned.spacing) == (8, 0.2)
    assert cell.planner.learned.resolution == 40 and cell.planner.learned.training == "coarse"
    for bad, key in (({"resolution": 2}, "planner.learned.resolution"), ({"training": "fine"}, "planner.learned.training"),
                     ({"spacing": 0}, "planner.learned.spacing"), ({"radius": 1}, "planner.learned.radius")):
        with pytest.raises(CellFileError, match=key.replace(".", r"\.")):
            load_cell(write_clamp_cell(tmp_path, {"detours": "learned", "learned": bad}))


def test_a_robot_the_method_cannot_map_is_one_message_naming_the_key(clamp_cell, monkeypatch: pytest.MonkeyPatch) -> None:  # type: ignore[no-untyped-def]
    _, cell, robot = clamp_cell

    def refuse(_robot: object) -> None:
        raise CSpaceError("robot kr125: A1 is not vertical; the C-space map needs a vertical A1")

    monkeypatch.setattr(learned_detour, "check_arm", refuse)
    with pytest.raises(CSpaceError, match=rf"^{re.escape(str(cell.source))}: planner\.detours: learned: robot kr125: A1"):
        LearnedDetours.build(cell, robot, None, [], cell.planner.learned)  # type: ignore[arg-type]
