"""Bounded work: a cell asking for more than the limits (spots, objects, orientations, mesh
triangles), a spot whose IK table alone would exceed the budget, or a robot with absurd joint
limits is refused at load with the limit named (exit 2, no traceback); below the budget, a
seam's spots are solved in batches with the same candidates as in one table."""

from __future__ import annotations

import dataclasses
import re
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, app
from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.io import cell as cell_io
from robomax_py.io import cell_limits
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.io.cell_file_values import CELL_LIMITS
from robomax_py.io.yaml_files import count_items
from robomax_py.plan import candidates
from robomax_py.plan.candidates import check_ik_work, seam_candidates
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
SmallCell = Callable[..., Path]
runner = CliRunner()


def _edit(path: Path, change: Callable[[dict[str, Any]], None]) -> Path:
    data = yaml.safe_load(path.read_text())
    change(data)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _spot(k: int) -> dict[str, Any]:
    return {"name": f"x{k}", "xyz": [1.5, -0.2 + 1e-4 * k, 1.0], "normal": [0, 0, 1], "direction": [1, 0, 0]}


def _refused(cell: Path, limit: str) -> str:
    """`robomax check` refuses the cell in one line naming the limit; the message."""
    result = runner.invoke(app, ["check", str(cell)])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    assert "Traceback" not in result.output and result.exception is None or isinstance(result.exception, SystemExit)
    assert f"({limit})" in result.output, result.output
    return result.output


def test_a_10000_spot_seam_is_refused_before_the_robot_is_even_looked_up(tmp_path: Path,
                                                                         write_small_cell: SmallCell) -> None:
    def many(data: dict[str, Any]) -> None:
        data["seams"][0]["spots"] += [_spot(k) for k in range(10_000)]
        data["robot"]["model"] = "no_such_robot"    # the count is checked first: this is never read

    cell = _edit(write_small_cell(tmp_path), many)
    out = _refused(cell, "spots")
    assert "10,002 spots" in out and f"{CELL_LIMITS.spots:,}" in out


def test_the_spots_are_counted_from_the_parser_s_events_before_the_document_is_built(
        tmp_path: Path, write_small_cell: SmallCell, monkeypatch: pytest.MonkeyPatch) -> None:
    """Building the document (and, without libyaml, composing it in Python, 25 times slower than
    libyaml's events) is not spent on a cell of too many spots: it is refused from the events."""
    if count_items("a: 1", ()) is None:
        pytest.skip("PyYAML without libyaml: the spots are counted after reading")
    cell = _edit(write_small_cell(tmp_path), lambda d: d["seams"][0]["spots"].extend(_spot(k) for k in range(2_000)))

    def not_read(*_: object, **__: object) -> None:
        raise AssertionError("the document was composed")

    monkeypatch.setattr(cell_io, "read_yaml_mapping", not_read)
    with pytest.raises(CellFileError, match=r"2,002 spots, more than the 2,000 a cell may have \(spots\)"):
        load_cell(cell)


def test_count_items_counts_the_lists_at_their_key_paths_only() -> None:
    targets = (("seams", "*", "spots"), ("objects",))
    text = ("seams: [{spots: [{a: 1}, {b: 2}]}, {name: x, spots: &s [1, 2, 3]}, {spots: *s}]\n"
            "objects:\n- {name: a}\n- *s\nother: {objects: [1, 2], seams: [{spots: [1]}]}\n"
            "? [complex, key]\n: {spots: [1]}\n")
    # `spots: *s` (a list reached through an alias) is left to the count after reading; an alias
    # as an item of a list is one item; lists under other keys are not counted.
    assert count_items(text, targets) in ({targets[0]: 5, targets[1]: 2}, None)
    assert count_items("seams: [", targets) is None


def test_too_many_objects_are_refused(tmp_path: Path, write_small_cell: SmallCell) -> None:
    def crowd(data: dict[str, Any]) -> None:
        data["objects"] += [{"name": f"b{k}", "box": [0.1, 0.1, 0.1], "pose": {"xyz": [20, k, 0]}}
                            for k in range(CELL_LIMITS.objects)]

    out = _refused(_edit(write_small_cell(tmp_path), crowd), "objects")
    assert f"{CELL_LIMITS.objects:,}" in out


def test_a_seam_grid_of_too_many_orientations_is_refused(tmp_path: Path, write_small_cell: SmallCell) -> None:
    def fine(data: dict[str, Any]) -> None:
        seam = data["seams"][0]
        seam["grid"] = 11
        seam["tolerance"]["gamma"] = [-30, 30]

    out = _refused(_edit(write_small_cell(tmp_path), fine), "orientations")
    assert "1,331 grid orientations" in out


def test_a_mesh_of_too_many_triangles_is_refused(tmp_path: Path, write_small_cell: SmallCell,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    cell = write_small_cell(tmp_path)
    # The shipped panel is a binary STL: its header says how many triangles it has.
    stl = tmp_path / "parts" / "cabin_panel.stl"
    n = int.from_bytes(stl.read_bytes()[80:84], "little")
    monkeypatch.setattr(cell_limits, "CELL_LIMITS", dataclasses.replace(CELL_LIMITS, mesh_triangles=n - 1))
    with pytest.raises(CellFileError, match=re.escape(f"has {n:,} triangles, more than the {n - 1:,}")):
        load_cell(cell)
    monkeypatch.setattr(cell_limits, "CELL_LIMITS", dataclasses.replace(CELL_LIMITS, cell_triangles=n - 1))
    with pytest.raises(CellFileError, match=r"\(cell_triangles\)"):
        load_cell(cell)


def test_an_obj_of_too_many_faces_is_refused_before_it_is_read(tmp_path: Path, write_small_cell: SmallCell,
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """Reading a mesh of millions of triangles takes seconds: what the file states is judged first."""
    def boxes(data: dict[str, Any]) -> None:
        data["objects"].append({"name": "grid", "mesh": "grid.obj", "pose": {"xyz": [20, 0, 0]}})

    cell = _edit(write_small_cell(tmp_path), boxes)
    # Above every other mesh of the cell and its tool, so that this one is the first refused.
    panel = int.from_bytes((tmp_path / "parts" / "cabin_panel.stl").read_bytes()[80:84], "little")
    limit = max(panel, 10_000)
    (tmp_path / "grid.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n" + "f 1 2 3\nf 2 4 3\n" * (limit // 2 + 1))
    monkeypatch.setattr(cell_limits, "CELL_LIMITS", dataclasses.replace(CELL_LIMITS, mesh_triangles=limit))
    read = cell_limits.load_mesh

    def only_others(mesh: Path) -> Any:
        assert mesh.name != "grid.obj", "the refused mesh was read"
        return read(mesh)

    monkeypatch.setattr(cell_limits, "load_mesh", only_others)
    with pytest.raises(CellFileError, match=rf"grid.obj has {2 * (limit // 2 + 1):,} triangles or more, more than "
                                            rf"the {limit:,} a mesh may have \(mesh_triangles\)"):
        load_cell(cell)


def test_the_cell_s_meshes_are_totalled_by_what_they_state_before_any_is_read(
        tmp_path: Path, write_small_cell: SmallCell, monkeypatch: pytest.MonkeyPatch) -> None:
    def twice_more(data: dict[str, Any]) -> None:
        data["objects"] += [{"name": f"copy{k}", "mesh": "parts/cabin_panel.stl", "pose": {"xyz": [20, k, 0]}}
                            for k in range(2)]

    cell = _edit(write_small_cell(tmp_path), twice_more)
    n = int.from_bytes((tmp_path / "parts" / "cabin_panel.stl").read_bytes()[80:84], "little")
    monkeypatch.setattr(cell_limits, "CELL_LIMITS", dataclasses.replace(CELL_LIMITS, cell_triangles=2 * n))

    def not_read(mesh: Path) -> Any:
        raise AssertionError(f"{mesh} was read")

    monkeypatch.setattr(cell_limits, "load_mesh", not_read)
    with pytest.raises(CellFileError, match=rf"objects\[\d+\]\.mesh: the cell's meshes up to this one have {3 * n:,} "
                                            rf"triangles, more than the {2 * n:,} a cell may have \(cell_triangles\)"):
        load_cell(cell)


def test_a_urdf_velocity_of_1e300_is_refused_at_load(tmp_path: Path, write_small_cell: SmallCell) -> None:
    robot_dir = tmp_path / "robots" / "kr125"
    shutil.copytree(REPO / "robomax_py" / "robots" / "kr125", robot_dir)
    urdf = next(robot_dir.glob("*.urdf"))
    text = urdf.read_text()
    first = re.search(r'velocity="[^"]*"', text)
    assert first is not None
    urdf.write_text(text[:first.start()] + 'velocity="1e-300"' + text[first.end():])
    cell = _edit(write_small_cell(tmp_path), lambda d: d["robot"].update(model="robots/kr125/robot.yaml"))
    # Refused when the robot's files are read (`io.robot.check_urdf`), before any model is built.
    with pytest.raises(RobotModelError, match=r"limit velocity 1e-300 rad/s is outside \[0.001, 100\]"):
        load_cell(cell)
    result = runner.invoke(app, ["plan", str(cell), "-o", str(tmp_path / "out")])
    assert result.exit_code == EXIT_BAD_INPUT and "limit velocity 1e-300" in result.output, result.output
    assert not (tmp_path / "out").exists()


def test_robot_yaml_limits_of_1e300_are_refused(tmp_path: Path, write_small_cell: SmallCell) -> None:
    robot_dir = tmp_path / "robots" / "kr125"
    shutil.copytree(REPO / "robomax_py" / "robots" / "kr125", robot_dir)
    _edit(robot_dir / "robot.yaml", lambda d: d.setdefault("limits", {}).update(acceleration=[1e-300] * 6))
    cell = _edit(write_small_cell(tmp_path), lambda d: d["robot"].update(model="robots/kr125/robot.yaml"))
    with pytest.raises(RobotModelError, match=r"limits.acceleration.*\[1e-3, 1e9\]"):
        load_cell(cell)


def test_a_spot_whose_ik_table_alone_exceeds_the_budget_is_refused_before_planning(
        tmp_path: Path, write_small_cell: SmallCell, monkeypatch: pytest.MonkeyPatch) -> None:
    spec = load_cell(write_small_cell(tmp_path))
    robot = load_cell_robot(spec)
    check_ik_work(spec, robot)
    monkeypatch.setattr(candidates, "IK_TABLE_BUDGET_BYTES", 1000)
    with pytest.raises(CellFileError, match=r"one spot's IK table would take .* GiB \(9 orientations x 4 approach "
                                            r"samples x 216 IK columns of kr125\)"):
        check_ik_work(spec, robot)


def test_a_seam_solved_in_batches_has_the_candidates_of_one_table(
        tmp_path: Path, write_small_cell: SmallCell, monkeypatch: pytest.MonkeyPatch) -> None:
    spec = load_cell(write_small_cell(tmp_path, extra_spots=[_spot(k) for k in range(3)]))
    robot = load_cell_robot(spec)
    world = CollisionWorld(robot, build_scene(spec, robot), spec.process.clearance)
    whole, _ = seam_candidates(spec, robot, world, 0)
    one_spot = candidates.spot_table_bytes(robot, 9, candidates.approach_samples(spec), spec, "flange")
    monkeypatch.setattr(candidates, "IK_TABLE_BUDGET_BYTES", one_spot)     # a batch of one spot each
    batched, _ = seam_candidates(spec, robot, world, 0)
    assert len(whole) == len(batched) == 5
    for a, b in zip(whole, batched):
        assert a.name == b.name and a.rejected == b.rejected
        np.testing.assert_array_equal(a.column, b.column)
        np.testing.assert_array_equal(a.app_path, b.app_path)
