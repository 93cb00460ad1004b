"""`robomax replan` end to end on the shipped tending cell, continuing its program (the shipped
program, tests/golden/shipped/tending.srcl, read back from its statements) late in the third
cycle, so that little is left to plan."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_INFEASIBLE, EXIT_OK, app
from robomax_py.export import krl
from robomax_py.io.cell import load_cell

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "cells" / "tending.yaml"
PROGRAM = REPO / "tests" / "golden" / "shipped" / "tending.srcl"
# The continuation starts at the stop configuration as the program states joints: 1e-4 deg.
START_TOL_DEG = 1e-4
# Times in the trajectory file: 1 microsecond.
TIME_TOL_S = 1e-6
T_AT = 36.0               # the robot waits at rest in front of CNC 1 for the third load
runner = CliRunner()


@pytest.fixture
def program(tmp_path: Path) -> Path:
    copy = tmp_path / "tending.srcl"
    shutil.copyfile(PROGRAM, copy)
    return copy


def _door_windows(name: str) -> tuple[tuple[float, float], ...]:
    door = next(d for d in load_cell(CELL).dynamic if d.name == name)
    assert door.present is not None
    return door.present


@pytest.mark.slow
def test_a_door_opening_late_is_waited_for_and_the_continuation_verifies(tmp_path: Path, program: Path) -> None:
    out = tmp_path / "out"
    late = 3.0
    result = runner.invoke(app, ["replan", str(CELL), str(program), "--at", str(T_AT), "--event",
                                 f"late:cnc1=+{late}", "-o", str(out), "--format", "srcl,krl", "--json"])
    assert result.exit_code == EXIT_OK, result.output
    report = json.loads(result.stdout)
    assert report["ok"] and report["verify"]["clean"], report
    name = report["name"]
    assert name == "tending_from_36"
    assert {Path(p).name for p in report["written"]} >= {f"{name}.json", f"{name}.srcl", f"{krl.program_name(name)}.src"}
    # The door closed at T now opens `late` s later, in the program's clock.
    w0, w1 = next(w for w in _door_windows("cnc1_door") if w[0] <= T_AT <= w[1])
    opens = w1 + late
    trajectory = json.loads((out / f"{name}.json").read_text())
    t_stop = report["stop"]["t"]
    np.testing.assert_allclose(np.degrees(trajectory["q"][0]), report["stop"]["q_deg"], atol=START_TOL_DEG)
    load = next(s for s in trajectory["spots"] if s["name"] == "c3_cnc1_load")
    assert t_stop + load["t_arrive"] >= opens - TIME_TOL_S      # it waited for the door
    assert report["left"][0] == "tending/c3_cnc1_load"
    assert "start at the stop configuration" in (out / f"{name}.srcl").read_text()
    assert report["new_finish"] == pytest.approx(t_stop + trajectory["cycle_time"], abs=1e-3)
    assert report["new_finish"] > report["old_finish"]
    # The cell it runs in, written beside it: cnc1's door windows as they now are (no longer its
    # schedule's period), in the program's clock; its programs verify against it.
    cell_file = out / f"{name}.cell.yaml"
    assert report["verify"]["cell"] == str(cell_file)
    machine = next(m for m in yaml.safe_load(cell_file.read_text())["tending"]["machines"] if m["name"] == "cnc1")
    assert "schedule" not in machine and [w0, opens] in machine["windows"]
    verified = runner.invoke(app, ["verify", str(cell_file), str(out / f"{krl.program_name(name)}.src")])
    assert verified.exit_code == EXIT_OK, verified.output


def test_an_object_on_a_station_left_is_infeasible_named_and_nothing_written(tmp_path: Path, program: Path) -> None:
    out = tmp_path / "out"
    station = load_cell(CELL).seams[0].spots[-1]          # c3_outfeed_place, still to do at T
    xyz = ",".join(f"{v:g}" for v in station.xyz)
    result = runner.invoke(app, ["replan", str(CELL), str(program), "--at", str(T_AT), "--event",
                                 f"appear:crate box=0.2,0.2,0.2 xyz={xyz}", "-o", str(out)])
    assert result.exit_code == EXIT_INFEASIBLE, result.output
    text = " ".join(result.output.split())
    assert "infeasible" in text and station.name in text and "nothing was written" in text
    assert not out.exists()


@pytest.mark.parametrize(("args", "said"), [
    (["--event", "late:cnc9=+4"], "unknown dynamic object or machine 'cnc9'"),
    (["--event", "late:cnc1=nan"], "plain decimal"),
    (["--event", "window:cnc1_door=1e400-2"], "outside"),
    (["--event", "appear:box box=1,1 xyz=0,0,0"], "3 comma-separated"),
    (["--event", "late:cnc1=+4", "--at", "100"], "not inside the program"),
])
def test_bad_input_exits_2_names_the_problem_and_writes_nothing(tmp_path: Path, program: Path, args: list[str],
                                                                said: str) -> None:
    out = tmp_path / "out"
    at = [] if "--at" in args else ["--at", str(T_AT)]
    result = runner.invoke(app, ["replan", str(CELL), str(program), *at, *args, "-o", str(out)])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    text = " ".join(result.output.split())
    assert said in text and "Traceback" not in text
    assert ("--at 100" if "--at" in args else "--event:") in text        # the option named
    assert not out.exists()


def test_a_station_file_is_refused_by_name_and_nothing_written(tmp_path: Path, program: Path) -> None:
    """A station's robots wait on each other's signals: replan says so instead of reading the
    station as a one-robot cell (which named its `robot` and `tool` keys missing)."""
    out = tmp_path / "out"
    station = REPO / "cells" / "stations" / "side_frame.yaml"
    result = runner.invoke(app, ["replan", str(station), str(program), "--at", str(T_AT), "--event", "remove:x",
                                 "-o", str(out)])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    text = " ".join(result.output.split())
    assert "side_frame.yaml" in text and "robots" in text and "a station file" in text and "Traceback" not in text
    assert "required key is missing" not in text
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.parametrize(("name", "at"), [("frame", 5), ("ur10_tray", 8)])
def test_a_robot_stopped_where_no_roadmap_node_is_seen_continues(tmp_path: Path, name: str, at: int) -> None:
    """Stopped there, neither the straight move nor the roadmap reaches the first approach point
    of the rest from the stop (both continuations were refused): cells/frame.yaml at 5 s rests on
    its move from l1 towards the pillar and joins the tour's own first move where it sees it;
    cells/ur10_tray.yaml at 8 s sees none of it and the random trees find the way. Each program
    verifies clean against the cell it runs in."""
    cell, program, out = REPO / "cells" / f"{name}.yaml", tmp_path / f"{name}.srcl", tmp_path / "out"
    shutil.copyfile(REPO / "tests" / "golden" / "shipped" / f"{name}.srcl", program)
    result = runner.invoke(app, ["replan", str(cell), str(program), "--at", str(at), "--event",
                                 "appear:post box=0.1,0.1,0.3 xyz=5,5,0.15", "-o", str(out), "--json"])
    assert result.exit_code == EXIT_OK, result.output
    report = json.loads(result.stdout)
    assert report["status"] == "planned" and report["verify"]["clean"], report
    assert (out / f"{name}_from_{at}.cell.yaml").exists()


@pytest.mark.slow
def test_a_trajectory_file_is_replanned_through_the_api(tmp_path: Path, program: Path) -> None:
    """The continuation's own trajectory file (.json) is a program `replan_program` reads: replanned
    again, with no event, where the robot is moving; the second continuation is written and verified
    against its cell, and starts where the first one stops."""
    from robomax_py.app.api import (
        LoadedCell,
        replan_program,
        verify_program,
        write_programs,
    )
    from robomax_py.io.cell import load_cell_robot

    spec = load_cell(CELL)
    cell = LoadedCell(spec, load_cell_robot(spec))
    first = replan_program(cell, program, T_AT, ["late:cnc1=+3"])
    assert first.status == "planned" and first.cell is not None and first.result is not None
    first_cell = LoadedCell(first.cell, cell.robot)
    written = write_programs(first_cell, first.result, tmp_path / "first")
    assert verify_program(first_cell, written.trajectory).clean
    # 0.3 s before the first station left: the robot is moving into CNC 1 there.
    at = first.result.spots[0].t_arrive - 0.3
    trajectory = json.loads(written.trajectory.read_text())
    moving = np.max(np.abs(np.diff(np.interp(at + np.array([0.0, 0.01]), trajectory["t"],
                                             np.array(trajectory["q"])[:, 0]))))
    second = replan_program(first_cell, written.trajectory, float(at), [])
    assert second.status == "planned" and second.cell is not None and second.result is not None, second.message
    assert moving > 0
    assert second.stop.how in ("slowed", "program stop", "action")
    second_cell = LoadedCell(second.cell, cell.robot)
    again = write_programs(second_cell, second.result, tmp_path / "second")
    assert verify_program(second_cell, again.trajectory).clean
    q0 = np.array(json.loads(again.trajectory.read_text())["q"][0])
    np.testing.assert_allclose(np.degrees(q0), np.degrees(second.stop.q), atol=START_TOL_DEG)
