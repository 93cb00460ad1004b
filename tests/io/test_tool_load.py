"""A tool's load (tool.yaml `load`, docs/cell-files.md "The tool folder"): read as written, refused
naming the tool.yaml and the key when it does not fit, and checked against the robot's rated
payload when a cell is read (with the heaviest part a pick-and-place job carries)."""

from __future__ import annotations

import io
import math
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from rich.console import Console
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, app
from robomax_py.app.summary import cell_summary
from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.io.robot import load_tool_spec, shipped_robots_dir

runner = CliRunner()

TOOLS = shipped_robots_dir() / "tools"
REPO = Path(__file__).resolve().parents[2]
PICK_PLACE = REPO / "cells" / "pick_place.yaml"     # kr16 (rated 16 kg), parts of 4 and 1.5 kg


@pytest.fixture(scope="module")
def gun_folder(tmp_path_factory: pytest.TempPathFactory, write_tool: Any) -> Path:
    folder: Path = write_tool(tmp_path_factory.mktemp("tools") / "gun", "spot_gun_c", None).parent
    return folder


def _with_load(folder: Path, load: Any) -> Path:
    path = folder / "tool.yaml"
    data = yaml.safe_load(path.read_text())
    data["load"] = load
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


finite = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6)


@settings(max_examples=40, deadline=None)
@given(mass=st.floats(min_value=1e-6, max_value=1e6, allow_nan=False, allow_infinity=False),
       cog=st.tuples(finite, finite, finite))
def test_a_stated_load_is_read_as_written(gun_folder: Path, mass: float, cog: tuple[float, float, float]) -> None:
    tool = load_tool_spec(_with_load(gun_folder, {"mass": mass, "cog": list(cog)}))
    assert tool.load is not None
    assert tool.load.mass == mass and tool.load.cog == cog      # YAML round-trips a float exactly


@settings(max_examples=30, deadline=None)
@given(mass=st.one_of(st.floats(max_value=0.0), st.just(math.inf), st.just(-math.inf), st.just(math.nan)))
def test_a_mass_not_above_zero_or_not_finite_is_refused(gun_folder: Path, mass: float) -> None:
    path = _with_load(gun_folder, {"mass": mass, "cog": [0, 0, 0.1]})
    with pytest.raises(RobotModelError) as err:
        load_tool_spec(path)
    assert (err.value.file, err.value.key) == (str(path), "load.mass")


@pytest.mark.parametrize(("load", "key", "problem"), [
    ({"mass": 10}, "load.cog", "required key is missing"),
    ({"cog": [0, 0, 0]}, "load.mass", "required key is missing"),
    ({"mass": 10, "cog": [0, 0]}, "load.cog", "at least 3 items"),
    ({"mass": 10, "cog": [0, 0, 0, 0]}, "load.cog", "at most 3 items"),
    ({"mass": 10, "cog": [0, 0, math.inf]}, "load.cog[2]", "finite number"),
    ({"mass": 10, "cog": [0, "a", 0]}, "load.cog[1]", "valid number"),
    ({"mass": "10", "cog": [0, 0, 0]}, "load.mass", "valid number"),
    ({"mass": 10, "cog": [0, 0, 0], "inertia": [1, 1, 1]}, "load.inertia", "unknown key"),
    (12, "load", "valid dictionary"),
])
def test_a_load_that_does_not_fit_is_refused_naming_file_and_key(gun_folder: Path, load: Any, key: str,
                                                                 problem: str) -> None:
    path = _with_load(gun_folder, load)
    with pytest.raises(RobotModelError) as err:
        load_tool_spec(path)
    assert (err.value.file, err.value.key) == (str(path), key)
    assert problem in err.value.problem


def test_no_load_stated_is_none() -> None:
    assert load_tool_spec(TOOLS / "spot_gun_c" / "tool.yaml").load is None


def test_a_gun_above_the_rated_payload_is_refused_at_check(tmp_path: Path, write_tool: Any,
                                                           write_small_cell_with_tool: Any) -> None:
    """The small cell's kr125 is rated 125 kg: a 150 kg gun is refused by `check` (exit 2) naming the
    cell, the key `tool`, both figures and the robot.yaml; a 100 kg gun is a valid cell."""
    heavy = write_tool(tmp_path / "heavy", "spot_gun_c", {"mass": 150, "cog": [0.12, 0, 0.18]})
    cell = write_small_cell_with_tool(tmp_path / "c1", heavy)
    with pytest.raises(CellFileError) as err:
        load_cell(cell)
    assert (err.value.file, err.value.key) == (str(cell), "tool")
    robot_yaml = shipped_robots_dir() / "kr125" / "robot.yaml"
    for said in ("150 kg", "rated payload 125 kg", str(heavy), str(robot_yaml)):
        assert said in err.value.problem
    done = runner.invoke(app, ["check", str(cell)])
    assert done.exit_code == EXIT_BAD_INPUT
    assert "Traceback" not in done.output and f"{cell}: tool:" in " ".join(done.output.split())
    out = tmp_path / "programs"
    done = runner.invoke(app, ["plan", str(cell), "-o", str(out)])
    assert done.exit_code == EXIT_BAD_INPUT and "rated payload 125 kg" in " ".join(done.output.split())
    assert not out.exists() or not any(out.iterdir())                 # nothing written
    light = write_tool(tmp_path / "light", "spot_gun_c", {"mass": 100, "cog": [0.12, 0, 0.18]})
    light_cell = write_small_cell_with_tool(tmp_path / "c2", light)
    loaded = load_cell(light_cell)
    assert loaded.tool.load is not None and loaded.tool.load.mass == 100.0
    done = runner.invoke(app, ["check", str(light_cell)])
    assert done.exit_code == 0, done.output
    # The summary shows the load; rendered wide here, since the console `check` prints to takes its
    # width from the terminal it was made in and wraps the line in the table at 80 columns.
    wide = Console(width=200, file=io.StringIO(), highlight=False)
    wide.print(cell_summary(loaded, load_cell_robot(loaded)))
    assert "100 kg at [0.120, 0.000, 0.180] m" in wide.file.getvalue()  # type: ignore[attr-defined]
    # At the rating exactly: within it.
    at = write_tool(tmp_path / "at", "spot_gun_c", {"mass": 125, "cog": [0, 0, 0.2]})
    assert load_cell(write_small_cell_with_tool(tmp_path / "c3", at)).tool.load is not None


def _pick_place_with(tmp_path: Path, write_tool: Any, mass: float) -> Path:
    gripper = write_tool(tmp_path / "gripper", "gripper_2f", {"mass": mass, "cog": [0, 0, 0.06]})
    data = yaml.safe_load(PICK_PLACE.read_text())
    data["tool"] = str(gripper)
    shutil.copytree(PICK_PLACE.parent / "parts", tmp_path / "parts", dirs_exist_ok=True)
    path = tmp_path / "pick_place.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_the_gripper_and_its_heaviest_part_together_within_the_payload(tmp_path: Path, write_tool: Any) -> None:
    """kr16 (16 kg): a 12 kg gripper with the 4 kg housing is at the rating; 13 kg with it is 17 kg
    together, refused naming the part, though the gripper alone and each part alone are within it."""
    assert load_cell(_pick_place_with(tmp_path / "ok", write_tool, 12.0)).tool.load is not None
    path = _pick_place_with(tmp_path / "over", write_tool, 13.0)
    with pytest.raises(CellFileError) as err:
        load_cell(path)
    assert (err.value.file, err.value.key) == (str(path), "tool")
    for said in ("13 kg", "'housing' of 4 kg", "17 kg", "rated payload 16 kg"):
        assert said in err.value.problem
