"""robomax_py.plan.cspace_detour: detours through the local A1-A3 map, and `planner.detours`.

What must hold: a detour it offers starts at qa, ends at qb and every segment is free by the swept
check (checked here again, independently); it finds detours round the reference cell's objects for
blocked straight moves; the cell key takes roadmap / cspace / both and refuses anything else.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions
from robomax_py.plan.cspace_detour import grid_detour
from robomax_py.plan.results import resolved_options
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"


@pytest.fixture(scope="module")
def reference():  # type: ignore[no-untyped-def]
    assert REFERENCE_CELL.is_file(), "the reference cell (tests/data/reference) is shipped with the repository"
    cell = load_cell(REFERENCE_CELL)
    robot = load_cell_robot(cell)
    return cell, robot, CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)


def test_detours_are_free_and_join_their_ends(reference, rng: np.random.Generator) -> None:  # type: ignore[no-untyped-def]
    _, robot, world = reference
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    home = np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])
    found = tried = 0
    while tried < 12:
        qa, qb = home + rng.uniform(-0.8, 0.8, size=(2, robot.dof))
        qa, qb = np.clip(qa, lo, hi), np.clip(qb, lo, hi)
        if not (world.is_free(qa) and world.is_free(qb)) or world.segment_free(qa, qb):
            continue                                   # a blocked move between two free ends
        tried += 1
        det, checks = grid_detour(world, robot.limits, qa, qb)
        assert checks > 0
        if det is None:
            continue
        found += 1
        np.testing.assert_array_equal(det.waypoints[0], qa)
        np.testing.assert_array_equal(det.waypoints[-1], qb)
        assert all(world.segment_free(a, b) for a, b in zip(det.waypoints[:-1], det.waypoints[1:]))
        assert np.isfinite(det.time_estimate) and det.checks == checks
    assert found >= 3


def test_the_cell_key_chooses_the_back_end(tmp_path: Path) -> None:
    data = yaml.safe_load(REFERENCE_CELL.read_text())
    (tmp_path / "parts").symlink_to(REFERENCE_CELL.parent / "parts")
    for value in ("roadmap", "cspace", "both"):
        data.setdefault("planner", {})["detours"] = value
        path = tmp_path / f"cell_{value}.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False))
        cell = load_cell(path)
        assert cell.planner.detours == value
        assert resolved_options(cell, PlanOptions()).detours == value
        assert resolved_options(cell, PlanOptions(detours="roadmap")).detours == "roadmap"
    data["planner"]["detours"] = "astar"
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(CellFileError, match="planner.detours"):
        load_cell(path)
