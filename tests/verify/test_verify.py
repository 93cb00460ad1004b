"""`robomax verify` accepts what plan writes and catches each injected fault."""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_OK, EXIT_VIOLATIONS, app
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.robot import fk_tcp
from robomax_py.verify import verify_trajectory_file

SmallCell = Callable[..., Path]   # conftest.write_small_cell
runner = CliRunner()


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell) -> tuple[Path, dict[str, Any], Path]:
    """The small test cell (conftest.write_small_cell), its plan's trajectory file, and the folder."""
    tmp = tmp_path_factory.mktemp("verify")
    cell = write_small_cell(tmp)
    result = runner.invoke(app, ["plan", str(cell), "-o", str(tmp / "out")])
    assert result.exit_code == EXIT_OK, result.output
    return cell, json.loads((tmp / "out" / "small_cell.json").read_text()), tmp


def kinds(cell: Path, program: dict[str, Any], tmp: Path) -> set[str]:
    path = tmp / "program.json"
    path.write_text(json.dumps(program))
    spec = load_cell(cell)
    report = verify_trajectory_file(spec, load_cell_robot(spec), path)
    return {v.kind for v in report.violations}


def test_plan_output_is_clean(planned: tuple[Path, dict[str, Any], Path]) -> None:
    cell, _program, tmp = planned
    result = runner.invoke(app, ["verify", str(cell), str(tmp / "out" / "small_cell.json")])
    assert result.exit_code == EXIT_OK, result.output
    assert "clean" in result.output


def test_collision_with_an_added_obstacle(planned: tuple[Path, dict[str, Any], Path]) -> None:
    cell, program, tmp = planned
    spec = load_cell(cell)
    robot = load_cell_robot(spec)
    q = np.asarray(program["q"])
    mid = q[len(q) // 5]                       # somewhere on the way from home to the first spot
    tcp = fk_tcp(robot, mid)[:3, 3]
    data = yaml.safe_load(cell.read_text())
    data["objects"].append({"name": "intruder", "sphere": {"radius": 0.05}, "pose": {"xyz": tcp.tolist()}})
    blocked = tmp / "blocked.yaml"
    blocked.write_text(yaml.safe_dump(data, sort_keys=False))
    path = tmp / "program_ok.json"
    path.write_text(json.dumps(program))
    result = runner.invoke(app, ["verify", str(blocked), str(path)])
    assert result.exit_code == EXIT_VIOLATIONS, result.output
    assert "intruder" in result.output


def test_skipped_spot(planned: tuple[Path, dict[str, Any], Path]) -> None:
    cell, program, tmp = planned
    bad = copy.deepcopy(program)
    bad["spots"] = bad["spots"][1:]
    assert "spot" in kinds(cell, bad, tmp)


def test_short_dwell(planned: tuple[Path, dict[str, Any], Path]) -> None:
    cell, program, tmp = planned
    bad = copy.deepcopy(program)
    bad["spots"][0]["t_leave"] = bad["spots"][0]["t_arrive"] + 0.3
    assert "dwell" in kinds(cell, bad, tmp)


def test_velocity_over_the_limit(planned: tuple[Path, dict[str, Any], Path]) -> None:
    cell, program, tmp = planned
    bad = copy.deepcopy(program)
    bad["t"] = [t * 0.5 for t in bad["t"]]
    bad["cycle_time"] = bad["t"][-1]
    for s in bad["spots"]:
        s["t_arrive"] *= 0.5
        s["t_leave"] *= 0.5
    found = kinds(cell, bad, tmp)
    assert "velocity" in found and "dwell" in found


def test_wrong_configuration_indicator(planned: tuple[Path, dict[str, Any], Path]) -> None:
    cell, program, tmp = planned
    bad = copy.deepcopy(program)
    bad["spots"][0]["config"] = "S111 T000000"
    assert kinds(cell, bad, tmp) == {"spot"}


def test_target_off_the_seam(planned: tuple[Path, dict[str, Any], Path]) -> None:
    cell, program, tmp = planned
    bad = copy.deepcopy(program)
    t = np.asarray(bad["t"])
    q = np.asarray(bad["q"])
    s = bad["spots"][0]
    inside = (t >= s["t_arrive"] - 1e-6) & (t <= s["t_leave"] + 1e-6)
    q[inside, 0] += 0.001                      # 1 mrad on A1: ~1.3 mm at this reach
    bad["q"] = q.tolist()
    assert "spot" in kinds(cell, bad, tmp)


def test_ordered_seam_out_of_order(planned: tuple[Path, dict[str, Any], Path]) -> None:
    cell, program, tmp = planned
    data = yaml.safe_load(cell.read_text())
    data["seams"][0]["ordered"] = True
    data["seams"][0]["spots"] = data["seams"][0]["spots"][::-1]
    ordered = tmp / "ordered.yaml"
    ordered.write_text(yaml.safe_dump(data, sort_keys=False))
    welded = [s["name"] for s in program["spots"]]
    if welded == [s["name"] for s in data["seams"][0]["spots"]]:
        pytest.skip("the plan happened to weld in the reversed order")
    assert "order" in kinds(ordered, program, tmp)


def test_bad_program_file_exits_2(planned: tuple[Path, dict[str, Any], Path]) -> None:
    cell, _, tmp = planned
    broken = tmp / "broken.json"
    broken.write_text('{"format": "robomax.trajectory/1", "joints": [')
    result = runner.invoke(app, ["verify", str(cell), str(broken)])
    assert result.exit_code == EXIT_BAD_INPUT
    assert "line 1" in result.output and "Traceback" not in result.output
