"""The cell a continuation runs in, written by `robomax replan` beside its programs: the shipped
cabin_flange program (tests/golden/shipped/cabin_flange.srcl, read back from its statements)
continued at 6 s after a post appeared, in a copy of the cell in another folder; its programs
verify clean against the written cell with `robomax verify`, from the stop, welding only what was
left; and the cell keys that make it (`robot.start`, `continuation`) refuse bad values."""

from __future__ import annotations

import json
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_OK, EXIT_VIOLATIONS, app
from robomax_py.export import krl
from robomax_py.io.cell import load_cell

REPO = Path(__file__).resolve().parents[2]
PROGRAM = REPO / "tests" / "golden" / "shipped" / "cabin_flange.srcl"
EVENT = "appear:post box=0.1,0.1,0.4 xyz=1.0,0.9,1.0"
NAME = "cabin_flange_from_6"
# The KRL program's files are named as its DEF, a KRL name short enough for `<name>_frames`.
KRL_SRC = f"{krl.program_name(NAME)}.src"
# The start is written as the programs write joints (1e-4 deg), read back as the stop configuration.
START_TOL_DEG = 1e-4
runner = CliRunner()


@dataclass(frozen=True)
class Continued:
    cell: Path               # the original cell (a copy, with its parts)
    out: Path                # the continuation's folder
    report: dict[str, Any]   # replan --json

    @property
    def cell_file(self) -> Path:
        return self.out / f"{NAME}.cell.yaml"


@pytest.fixture(scope="module")
def continued(tmp_path_factory: pytest.TempPathFactory) -> Continued:
    folder = tmp_path_factory.mktemp("continued")
    shutil.copyfile(REPO / "cells" / "cabin_flange.yaml", folder / "cabin_flange.yaml")
    shutil.copytree(REPO / "cells" / "parts", folder / "parts")
    shutil.copyfile(PROGRAM, folder / "cabin_flange.srcl")
    out = folder / "out"
    result = runner.invoke(app, ["replan", str(folder / "cabin_flange.yaml"), str(folder / "cabin_flange.srcl"),
                                 "--at", "6", "--event", EVENT, "-o", str(out), "--format", "krl", "--json"])
    assert result.exit_code == EXIT_OK, result.output
    return Continued(folder / "cabin_flange.yaml", out, json.loads(result.stdout))


def _verify(cell: Path, program: Path) -> tuple[int, str]:
    result = runner.invoke(app, ["verify", str(cell), str(program)])
    return result.exit_code, " ".join(result.output.split())


@pytest.mark.slow
def test_the_continuation_cell_is_written_in_the_set_and_holds_the_stop(continued: Continued) -> None:
    report = continued.report
    assert report["verify"]["clean"] and report["verify"]["cell"] == str(continued.cell_file)
    assert str(continued.cell_file) in report["written"]
    manifest = json.loads((continued.out / f"{NAME}.manifest.json").read_text())
    assert continued.cell_file.name in {f["name"] for f in manifest["files"]}
    data = yaml.safe_load(continued.cell_file.read_text())
    assert data["continuation"]["done"] == report["done"]
    assert data["continuation"]["at"] == pytest.approx(report["stop"]["t"], abs=1e-4)
    np.testing.assert_allclose(data["robot"]["start"], report["stop"]["q_deg"], atol=START_TOL_DEG)
    assert any(o["name"] == "post" for o in data["objects"])
    # Loaded, it is the cell the continuation was planned in: what is left, from the stop.
    cell = load_cell(continued.cell_file)
    assert [f"{s.name}/{p.name}" for s in cell.seams for p in s.spots] == report["left"]
    assert cell.start is not None


@pytest.mark.slow
@pytest.mark.parametrize("program", [KRL_SRC, f"{NAME}.json"])
def test_its_programs_verify_clean_against_it(continued: Continued, program: str) -> None:
    code, text = _verify(continued.cell_file, continued.out / program)
    assert code == EXIT_OK, text
    assert "note" not in text                  # the set's own cell: no other version of it


@pytest.mark.slow
def test_a_spot_left_that_the_program_does_not_weld_is_a_violation(continued: Continued) -> None:
    data = yaml.safe_load(continued.cell_file.read_text())
    undone = data["continuation"]["done"].pop()              # done before the stop: not in the program
    edited = continued.out / "edited.yaml"                   # beside it: its relative paths resolve alike
    edited.write_text(yaml.safe_dump(data, sort_keys=False))
    code, text = _verify(edited, continued.out / f"{NAME}.json")
    assert code == EXIT_VIOLATIONS
    assert f"{undone} is never welded" in text


@pytest.mark.slow
def test_against_the_original_cell_it_fails_and_names_the_cell_it_runs_in(continued: Continued) -> None:
    code, text = _verify(continued.cell, continued.out / KRL_SRC)
    assert code == EXIT_VIOLATIONS
    assert "does not start at robot.home" in text
    assert f"{NAME}.cell.yaml" in text and "verify it against that file" in text


def _edited_small_cell(folder: Path, write_small_cell: Any, edit: Any) -> Path:
    path = write_small_cell(folder)
    data = yaml.safe_load(path.read_text())
    edit(data)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.mark.parametrize(("edit", "key", "said"), [
    (lambda d: d["robot"].update(start=[0, -90, 90, 0, 0]), "robot.start", "expected 6 joint values"),
    (lambda d: d["robot"].update(start=[0, -90, 90, 0, 0, 400]), "robot.start[5]", "outside its limits"),
    (lambda d: d["robot"].update(start=[0, -90, "a", 0, 0, 0]), "robot.start[2]", ""),
    (lambda d: d.update(continuation={"at": 1.0, "done": ["flange/s99"]}), "continuation.done[0]",
     "not an action of the cell"),
    (lambda d: d.update(continuation={"at": 1.0, "done": ["flange/s7", "flange/s8"]}), "continuation.done",
     "nothing is left"),
    (lambda d: d.update(continuation={"at": -1.0}), "continuation.at", ""),
])
def test_bad_start_and_continuation_keys_exit_2_naming_file_and_key(tmp_path: Path, write_small_cell: Any, edit: Any,
                                                                    key: str, said: str) -> None:
    path = _edited_small_cell(tmp_path, write_small_cell, edit)
    result = runner.invoke(app, ["check", str(path)])
    text = " ".join(result.output.split())
    assert result.exit_code == EXIT_BAD_INPUT, text
    assert path.name in text and key in text and said in text and "Traceback" not in text


def test_a_start_within_limits_is_where_programs_start(tmp_path: Path, write_small_cell: Any) -> None:
    path = _edited_small_cell(tmp_path, write_small_cell, lambda d: d["robot"].update(start=[10, -80, 95, 0, 20, 0]))
    cell = load_cell(path)
    assert cell.start is not None
    np.testing.assert_allclose(np.degrees(cell.q_start), [10, -80, 95, 0, 20, 0], atol=1e-9)


def _tending_with(tmp_path: Path, edit: Any) -> Path:
    data = yaml.safe_load((REPO / "cells" / "tending.yaml").read_text())
    edit(data)
    path = tmp_path / "tending.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_a_continuation_loads_as_the_work_left_in_its_own_clock(tmp_path: Path) -> None:
    whole = load_cell(REPO / "cells" / "tending.yaml")
    visits = [s.name for s in whole.seams[0].spots]
    path = _tending_with(tmp_path, lambda d: d.update(continuation={"at": 20.0, "done": [f"tending/{v}" for v in
                                                                                          visits[:2]]}))
    cell = load_cell(path)
    assert [s.name for s in cell.seams[0].spots] == visits[2:]
    door = next(d for d in cell.dynamic if d.name == "cnc1_door")
    assert door.present == ((0.0, 5.0), (12.0, 21.0))        # [16, 25], [32, 41] of the program's clock, from 20 s


def test_a_machine_door_takes_its_windows_as_they_are_or_a_schedule_not_both(tmp_path: Path) -> None:
    windows = [[0.0, 9.0], [16.0, 25.0], [32.0, 44.0]]
    path = _tending_with(tmp_path, lambda d: d["tending"]["machines"][0].update(schedule=None, windows=windows)
                         or d["tending"]["machines"][0].pop("schedule"))
    door = next(d for d in load_cell(path).dynamic if d.name == "cnc1_door")
    assert door.present == tuple(tuple(w) for w in windows)
    both = _tending_with(tmp_path, lambda d: d["tending"]["machines"][0].update(windows=windows))
    result = runner.invoke(app, ["check", str(both)])
    text = " ".join(result.output.split())
    assert result.exit_code == EXIT_BAD_INPUT and "tending.machines[0]" in text and "exactly one of schedule" in text
