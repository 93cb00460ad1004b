"""`robomax verify` on SRCL programs: the motion rebuilt from the statements alone.

The rebuilt motion of a program `plan` wrote is the planned trajectory itself (same chains, same
rounded values): equal sample for sample. Each injected fault is caught and named.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_OK, EXIT_VIOLATIONS, app
from robomax_py.export.plan_program import program_from_plan
from robomax_py.export.rebuild import rebuild
from robomax_py.export.srcl import parse_program, write_program
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.verify import verify_srcl_file

SmallCell = Callable[..., Path]
runner = CliRunner()


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell) -> dict[str, Any]:
    tmp = tmp_path_factory.mktemp("verify_srcl")
    cell_path = write_small_cell(tmp)
    cell = load_cell(cell_path)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot, PlanOptions())
    assert result.status == "planned", result.message
    text = write_program(program_from_plan(result))
    (tmp / "small_cell.srcl").write_text(text)
    return {"tmp": tmp, "cell_path": cell_path, "cell": cell, "robot": robot, "result": result, "text": text}


def violations(planned: dict[str, Any], text: str) -> set[str]:
    path = planned["tmp"] / "edited.srcl"
    path.write_text(text)
    report = verify_srcl_file(planned["cell"], planned["robot"], path)
    return {v.kind for v in report.violations}


def test_rebuilt_motion_is_the_planned_trajectory(planned: dict[str, Any]) -> None:
    rebuilt = rebuild(parse_program(planned["text"]), planned["cell"], planned["robot"], "small_cell.srcl")
    assert rebuilt.problems == []
    want = planned["result"].trajectory
    got = rebuilt.trajectory
    assert got is not None
    np.testing.assert_array_equal(got.t, want.t)
    np.testing.assert_array_equal(got.q, want.q)
    assert [(s["name"], s["t_arrive"]) for s in rebuilt.spots] == \
        [(s.name, s.t_arrive) for s in planned["result"].spots]


def test_cli_verifies_the_written_program_clean(planned: dict[str, Any]) -> None:
    result = runner.invoke(app, ["verify", str(planned["cell_path"]), str(planned["tmp"] / "small_cell.srcl")])
    assert result.exit_code == EXIT_OK, result.output
    assert "clean" in result.output


def test_removed_detour_collides(planned: dict[str, Any]) -> None:
    lines = planned["text"].splitlines(keepends=True)
    assert any("detour point" in line for line in lines)       # the premise: the plan has detours
    edited = "".join(line for line in lines if "detour point" not in line)
    assert "collision" in violations(planned, edited)


def test_skipped_spot(planned: dict[str, Any]) -> None:
    edited = re.sub(r"^\s*SPOT s8 .*\n", "", planned["text"], count=1, flags=re.MULTILINE)
    assert "spot" in violations(planned, edited)


def test_short_dwell(planned: dict[str, Any]) -> None:
    edited = planned["text"].replace("TIME 0.500 SEC", "TIME 0.300 SEC", 1)
    assert "dwell" in violations(planned, edited)


def test_wrong_configuration_indicator(planned: dict[str, Any]) -> None:
    config = re.search(r"CONFIG '(S\d{3}) (T\d+)'", planned["text"])
    assert config is not None
    status = config.group(1)
    flipped = "S" + ("1" if status[1] == "0" else "0") + status[2:]
    edited = planned["text"].replace(config.group(0), f"CONFIG '{flipped} {config.group(2)}'", 1)
    assert "config" in violations(planned, edited)


def test_lin_target_off_the_seam(planned: dict[str, Any]) -> None:
    # Move the first approach target (the spot) by 1 mm along x.
    match = re.search(r"MOVE LIN POS\(([-\d.]+), ([-\d.]+), ([-\d.]+)\)(.*\{ approach \})", planned["text"])
    assert match is not None
    x = float(match.group(1)) + 1.0
    edited = planned["text"].replace(match.group(0), f"MOVE LIN POS({x:.3f}, {match.group(2)}, {match.group(3)}){match.group(4)}", 1)
    assert "spot" in violations(planned, edited)


def test_spot_while_flying_by(planned: dict[str, Any]) -> None:
    edited = planned["text"].replace("MM/S { approach };", "MM/S FLYBY 1.0000 { approach };", 1)
    assert "flyby" in violations(planned, edited)


def test_program_for_another_robot_is_bad_input(planned: dict[str, Any]) -> None:
    path = planned["tmp"] / "other.srcl"
    path.write_text(planned["text"].replace("ROBOT kr125 ", "ROBOT kr16 ", 1))
    result = runner.invoke(app, ["verify", str(planned["cell_path"]), str(path)])
    assert result.exit_code == EXIT_BAD_INPUT
    assert "kr16" in result.output and "Traceback" not in result.output


def test_broken_program_names_line_and_column(planned: dict[str, Any]) -> None:
    path = planned["tmp"] / "broken.srcl"
    path.write_text(planned["text"].replace("SPOT s7 SEAM", "SPOT s7 SEEM", 1))
    result = runner.invoke(app, ["verify", str(planned["cell_path"]), str(path)])
    assert result.exit_code == EXIT_BAD_INPUT
    assert re.search(r"line \d+, column \d+", result.output), result.output


def test_violations_exit_one(planned: dict[str, Any]) -> None:
    path = planned["tmp"] / "short.srcl"
    path.write_text(planned["text"].replace("TIME 0.500 SEC", "TIME 0.300 SEC", 1))
    result = runner.invoke(app, ["verify", str(planned["cell_path"]), str(path)])
    assert result.exit_code == EXIT_VIOLATIONS
    assert "dwell" in result.output
