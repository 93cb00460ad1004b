"""Probable mistakes in valid cell files become notices (file, key, message), never silence; bad
files list every independent error; misspelt robot and tool names get a suggestion."""

from __future__ import annotations

import json
import shutil
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml
from typer.testing import CliRunner

import robomax_py as rm
from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_INFEASIBLE, EXIT_OK, app
from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell
from robomax_py.io.yaml_files import MAX_LISTED_PROBLEMS
from robomax_py.spec import Notice

CELLS = Path(__file__).resolve().parents[2] / "cells"
runner = CliRunner()

# Nothing in a shipped cell may be flagged (they keep 5-10 mm of clearance).
SHIPPED = sorted(p.stem for p in CELLS.glob("*.yaml"))


def _copy(tmp_path: Path, edit: Callable[[dict[str, Any]], None], cell: str = "cabin_flange") -> Path:
    """A copy of a shipped cell (and its parts) in tmp_path, edited."""
    shutil.copytree(CELLS / "parts", tmp_path / "parts", dirs_exist_ok=True)
    data = yaml.safe_load((CELLS / f"{cell}.yaml").read_text())
    edit(data)
    path = tmp_path / f"{cell}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _notices(path: Path) -> list[Notice]:
    return list(load_cell(path).notices)


def _keys(path: Path) -> list[str]:
    return [n.key for n in _notices(path)]


def _only(path: Path, key: str) -> Notice:
    found = [n for n in _notices(path) if n.key == key]
    assert len(found) == 1, _notices(path)
    assert found[0].file == str(path)
    return found[0]


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_cells_raise_no_false_alarms(name: str) -> None:
    assert _keys(CELLS / f"{name}.yaml") == []


def test_a_cell_in_millimetres_is_named(tmp_path: Path) -> None:
    def to_mm(d: dict[str, Any]) -> None:
        for obj in d["objects"]:
            obj.setdefault("pose", {}).setdefault("xyz", [0, 0, 0])
            obj["pose"]["xyz"] = [v * 1000 for v in obj["pose"]["xyz"]]
            if "box" in obj:
                obj["box"] = [v * 1000 for v in obj["box"]]
        for spot in d["seams"][0]["spots"]:
            spot["xyz"] = [v * 1000 for v in spot["xyz"]]

    path = _copy(tmp_path, to_mm)
    position = _only(path, "objects[0].pose.xyz")
    assert "1850 m from the cell's origin" in position.message and "millimetres" in position.message
    assert "also 22 more positions beyond 50 m" in position.message     # 10 objects and 12 spots
    size = _only(path, "objects[0].box")
    assert "table: it measures 1800 m across, larger than any workshop (100 m)" in size.message
    assert "also 10 more objects over 100 m" in size.message
    assert [n.key for n in _notices(path)] == ["objects[0].pose.xyz", "objects[0].box"]


def test_a_700_m_table_is_named(tmp_path: Path) -> None:
    path = _copy(tmp_path, lambda d: d["objects"][0].update(box=[0.7, 700, 0.7]))
    assert "it measures 700 m across, larger than any workshop" in _only(path, "objects[0].box").message


def test_an_approach_in_millimetres_is_named(tmp_path: Path) -> None:
    path = _copy(tmp_path, lambda d: d["process"].update(approach=30))
    assert "30 m is longer than any approach" in _only(path, "process.approach").message


def test_zero_clearance_to_a_workpiece_is_named_and_a_margin_silences_it(tmp_path: Path) -> None:
    zero = _copy(tmp_path / "zero", lambda d: d["process"].update(clearance=0))
    assert "may pass the workpiece" in _only(zero, "process.clearance").message
    path = _copy(tmp_path / "margin", lambda d: d["process"].update(clearance=0.005))
    assert _keys(path) == []


def test_a_spot_inside_the_table_is_named(tmp_path: Path) -> None:
    path = _copy(tmp_path, lambda d: d["seams"][0]["spots"][3].update(xyz=[1.85, 0.3, 0.5]))
    notice = _only(path, "seams[0].spots[3].xyz")
    assert notice.message.startswith("s4 lies 200 mm inside table (objects[0])")


def test_a_spot_off_every_workpiece_is_named(tmp_path: Path) -> None:
    path = _copy(tmp_path, lambda d: d["seams"][0]["spots"][0].update(xyz=[1.28, -0.7, 0.88]))
    notice = _only(path, "seams[0].spots[0].xyz")
    assert notice.message.startswith("s1 lies 49 mm from the surface of every workpiece (nearest: cabin_panel")


def test_a_part_not_marked_workpiece_is_named(tmp_path: Path) -> None:
    path = _copy(tmp_path, lambda d: d["objects"][2].pop("workpiece"))
    notice = _only(path, "objects[2]")
    assert "cabin_panel is not marked `workpiece: true`" in notice.message
    assert "s1 (seams[0].spots[0])" in notice.message and "add `workpiece: true`" in notice.message
    assert "process.clearance" not in _keys(path)       # no workpiece, no clearance to it


def test_a_part_above_its_support_is_named(tmp_path: Path) -> None:
    """low_2 raised 50 mm: the housing there lies 50 mm above the low board (a box on a box, so the
    gap is exact); 1 mm (CAD round-off) is not named."""
    def raise_by(dz: float) -> Callable[[dict[str, Any]], None]:
        def edit(data: dict[str, Any]) -> None:
            data["pick_place"]["locations"][1]["pose"]["xyz"][2] += dz
        return edit

    notice = _only(_copy(tmp_path, raise_by(0.05), "pick_place"), "pick_place.locations[1].pose")
    assert "housing at low_2 lies 50 mm from its nearest support (rack_low)" in notice.message
    assert _keys(_copy(tmp_path, raise_by(0.001), "pick_place")) == []


def test_parts_carried_by_an_arm_without_loaded_limits_are_named(tmp_path: Path) -> None:
    """The shipped UR10 states its payload but no loaded limits: a part in its gripper is carried at
    the unloaded limits, which the cell is told (the KR 16 states both: nothing, as above)."""
    def on_the_ur10(data: dict[str, Any]) -> None:
        data["robot"]["model"] = "ur10"
        data["pick_place"]["parts"][0]["mass"] = 2.0

    notice = _only(_copy(tmp_path, on_the_ur10, "pick_place"), "pick_place.parts")
    assert notice.message.startswith("ur10 states no limits.loaded (")
    assert "carried at the unloaded joint limits, whatever their mass (the heaviest, housing, 2 kg)" in notice.message


def test_a_home_in_radians_is_named_and_whole_degrees_are_not(tmp_path: Path) -> None:
    path = _copy(tmp_path, lambda d: d["robot"].update(home=[0, -1.5708, 1.5708, 0, 0, 0]))
    notice = _only(path, "robot.home")
    assert "looks like radians (in degrees: [0, -90, 90, 0, 0, 0])" in notice.message
    for home in ([0, 0, 0, 0, 0, 0], [0, -2, 3, 0, 1, 0], [0, -90, 90, 0, 1.5, 0]):
        path = _copy(tmp_path, lambda d, home=home: d["robot"].update(home=home))
        assert "robot.home" not in _keys(path)


def test_misspelt_robot_and_tool_get_a_suggestion_both_in_one_error(tmp_path: Path) -> None:
    def misspell(d: dict[str, Any]) -> None:
        d["robot"]["model"] = "kr_125"
        d["tool"] = "spot_gun_cc"

    path = _copy(tmp_path, misspell)
    with pytest.raises(CellFileError) as caught:
        load_cell(path)
    text = str(caught.value)
    assert text.startswith(f"{path}: 2 problems:")
    assert f"{path}: robot.model: unknown robot 'kr_125' (did you mean 'kr125'" in text
    assert f"{path}: tool: unknown tool 'spot_gun_cc' (did you mean 'spot_gun_c'" in text


def test_a_lone_error_keeps_its_key(tmp_path: Path) -> None:
    path = _copy(tmp_path, lambda d: d.update(tool="spot_gun_cc"))
    with pytest.raises(CellFileError) as caught:
        load_cell(path)
    assert caught.value.key == "tool"


def test_independent_errors_are_listed_together(tmp_path: Path) -> None:
    def break_it(d: dict[str, Any]) -> None:
        d["robot"]["model"] = "kr_125"
        d["seams"][0]["spots"][1]["normal"] = [0, 0, 0]
        d["seams"][0]["spots"][4]["direction"] = d["seams"][0]["spots"][4]["normal"]

    path = _copy(tmp_path, break_it)
    with pytest.raises(CellFileError) as caught:
        load_cell(path)
    lines = str(caught.value).splitlines()
    assert lines[0] == f"{path}: 3 problems:"
    assert [line.split(": ")[1] for line in lines[1:]] == [
        "seams[0].spots[1].normal", "seams[0].spots[4].direction", "robot.model"]


def test_schema_errors_are_listed_together(tmp_path: Path) -> None:
    def break_it(d: dict[str, Any]) -> None:
        d["process"]["wled_time"] = 1
        d["objects"][0]["box"] = [1, 2]

    path = _copy(tmp_path, break_it)
    with pytest.raises(CellFileError) as caught:
        load_cell(path)
    text = str(caught.value)
    assert f"{path}: objects[0].box: list should have at least 3 items" in text
    assert f"{path}: process.wled_time: unknown key; did you mean 'weld_time'?" in text


def test_the_list_of_errors_is_bounded(tmp_path: Path) -> None:
    def break_it(d: dict[str, Any]) -> None:
        spots = d["seams"][0]["spots"]
        d["seams"][0]["spots"] = [dict(spots[0], name=f"p{k}", normal=[0, 0, 0]) for k in range(30)]

    path = _copy(tmp_path, break_it)
    with pytest.raises(CellFileError) as caught:
        load_cell(path)
    lines = str(caught.value).splitlines()
    assert lines[0] == f"{path}: {MAX_LISTED_PROBLEMS} or more problems:"
    assert len(lines) == 1 + MAX_LISTED_PROBLEMS + 1 and "check again" in lines[-1]


def test_check_prints_warnings_and_exits_0(tmp_path: Path) -> None:
    def edit(d: dict[str, Any]) -> None:
        d["robot"].update(home=[0, -1.5708, 1.5708, 0, 0, 0])
        d["process"].update(clearance=0)

    path = _copy(tmp_path, edit)
    result = runner.invoke(app, ["check", str(path)])
    assert result.exit_code == EXIT_OK, result.output
    text = " ".join(result.stderr.split())
    assert f"warning: {path}: robot.home:" in text and "looks like radians" in text
    assert f"warning: {path}: process.clearance:" in text


def test_check_of_a_millimetre_cell_warns_before_the_reach_error(tmp_path: Path) -> None:
    path = _copy(tmp_path, lambda d: d["seams"][0]["spots"][0].update(xyz=[1330, -700, 880]))
    result = runner.invoke(app, ["check", str(path)])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    text = " ".join(result.stderr.split())
    assert text.index("millimetres") < text.index("out of kr125's reach")


def test_the_api_warns_with_cell_warnings(tmp_path: Path) -> None:
    with pytest.warns(rm.CellWarning, match="process.clearance"):
        rm.load_cell(_copy(tmp_path, lambda d: d["process"].update(clearance=0)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", rm.CellWarning)
        rm.load_cell(CELLS / "tending.yaml")                  # none to give


def test_plan_without_workpiece_hints_it_and_lists_warnings_in_json(tmp_path: Path,
                                                                     write_small_cell: Callable[..., Path]) -> None:
    """Every spot fails on the tips touching the unmarked part: the failure says to mark it; the
    JSON report carries the load's notices under `warnings` (its other keys as before)."""
    path = write_small_cell(tmp_path, "small")
    data = yaml.safe_load(path.read_text())
    for obj in data["objects"]:
        obj.pop("workpiece", None)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    result = runner.invoke(app, ["plan", str(path), "-o", str(tmp_path / "out"), "--json"])
    assert result.exit_code == EXIT_INFEASIBLE, result.output
    report = json.loads(result.stdout)
    assert report["status"] == "infeasible"
    assert "every spot fails on 'tool_tips vs cabin_panel'" in report["message"]
    assert "mark it `workpiece: true`" in report["message"]
    assert report["warnings"] == [{"file": str(path), "key": "objects[2]", "message": report["warnings"][0]["message"]}]
    assert "cabin_panel is not marked `workpiece: true`" in report["warnings"][0]["message"]
    assert "warning:" in result.stderr


def test_preview_prints_the_cell_warnings(tmp_path: Path) -> None:
    path = _copy(tmp_path, lambda d: d["process"].update(clearance=0))
    result = runner.invoke(app, ["preview", str(path), "--html", str(tmp_path / "page.html")])
    assert result.exit_code == EXIT_OK, result.output
    assert f"warning: {path}: process.clearance:" in " ".join(result.stderr.split())
