"""Tending cells (cell-file `tending`): the job becomes one ordered seam of station visits, the doors
dynamic objects closed in the schedule's windows; every mistake is one located message, exit 2."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, app
from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell
from robomax_py.io.cell_file_jobs import TENDING_SEAM
from robomax_py.plan.poses import orientation_grid, spot_poses
from robomax_py.transforms import pose_matrix

REPO = Path(__file__).resolve().parents[2]
TENDING = REPO / "cells" / "tending.yaml"
runner = CliRunner()


@pytest.fixture(scope="module")
def tending() -> dict[str, Any]:
    data = yaml.safe_load(TENDING.read_text())
    assert isinstance(data, dict)
    return data


def _write(tmp: Path, data: dict[str, Any]) -> Path:
    path = tmp / "tending.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_the_job_is_one_ordered_seam_of_station_visits(tending: dict[str, Any]) -> None:
    cell = load_cell(TENDING)
    (seam,) = cell.seams
    job = tending["tending"]
    per_cycle = [s["name"] for s in job["stations"]]
    assert seam.name == TENDING_SEAM and seam.ordered
    assert [s.name for s in seam.spots] == [f"c{c}_{n}" for c in range(1, job["cycles"] + 1) for n in per_cycle]
    stations = {s["name"]: s for s in job["stations"]}
    grid = orientation_grid(seam)
    assert len(grid) == 1
    for spot, T in zip(seam.spots, spot_poses(seam.spots, grid)[:, 0]):
        st = stations[spot.name.split("_", 1)[1]]
        # The station's pose is the TCP pose planned: z (the way the tool arrives and leaves) as given.
        np.testing.assert_allclose(T, pose_matrix(st["xyz"], np.radians(st["rpy"])), atol=1e-12)
        assert spot.action == st["action"] and spot.machine == st.get("machine")
        assert spot.weld_time == job["gripper"][st["action"]]
    doors = {d.name: d for d in cell.dynamic}
    for m, spec in zip(job["machines"], cell.machines):
        s = m["schedule"]
        expected = tuple((s["start"] + k * s["period"], s["start"] + k * s["period"] + s["machining"])
                         for k in range(job["cycles"]))
        assert spec.windows == expected and doors[spec.door].present == expected and doors[spec.door].door


def test_a_station_repeated_in_the_sequence_gets_numbered_visits(tmp_path: Path, tending: dict[str, Any]) -> None:
    data = copy.deepcopy(tending)
    data["tending"]["cycles"] = 1
    data["tending"]["sequence"] = ["conveyor_pick", "cnc1_load", "conveyor_pick", "outfeed_place"]
    cell = load_cell(_write(tmp_path, data))
    assert [s.name for s in cell.seams[0].spots] == ["c1_conveyor_pick", "c1_cnc1_load", "c1_conveyor_pick_2",
                                                      "c1_outfeed_place"]


def _edit(data: dict[str, Any], key: str, value: Any) -> None:
    *path, last = key.split(".")
    node: Any = data
    for part in path:
        node = node[int(part)] if part.isdigit() else node[part]
    if value is _DROP:
        del node[last]
    else:
        node[int(last) if last.isdigit() else last] = value


_DROP = object()


@pytest.mark.parametrize(("key", "value", "where", "says"), [
    ("tending.machines.0.schedule.machining", 20, "tending.machines[0].schedule", "never opens"),
    ("tending.machines.0.schedule.period", -1, "tending.machines[0].schedule.period", "greater than 0"),
    ("tending.machines.0.schedule.start", 1e6, "tending.machines[0].schedule.start", "less than or equal"),
    ("tending.stations.1.machine", "cnc9", "tending.stations[1].machine", "unknown machine 'cnc9'"),
    ("tending.stations.1.name", "conveyor_pick", "tending.stations[1].name", "duplicate station name"),
    ("tending.stations.1.name", "conveyor-pick", "tending.stations[1].name",
     "'conveyor-pick' and 'conveyor_pick' (stations[0]) are both written conveyor_pick in programs"),
    ("tending.stations.0.action", "weld", "tending.stations[0].action", "'grip' or 'release'"),
    ("tending.sequence", ["conveyor_pick", "lathe"], "tending.sequence[1]", "unknown station 'lathe'"),
    ("tending.machines.1.door.name", "conveyor", "tending.machines[1].door.name", "duplicate name 'conveyor'"),
    ("tending.cycles", 0, "tending.cycles", "greater than or equal to 1"),
    ("tending.stations", [], "tending.stations", "at least 1"),
    ("seams", [{"name": "s", "spots": [{"name": "p", "xyz": [1, 0, 1], "normal": [0, 0, 1], "direction": [1, 0, 0]}]}],
     "tending", "both given"),
    ("tending", _DROP, "seams", "at least one seam"),
])
def test_bad_tending_sections_are_refused_with_the_key(tmp_path: Path, tending: dict[str, Any], key: str, value: Any,
                                                       where: str, says: str) -> None:
    data = copy.deepcopy(tending)
    _edit(data, key, value)
    path = _write(tmp_path, data)
    with pytest.raises(CellFileError) as err:
        load_cell(path)
    assert err.value.key == where, str(err.value)
    assert says in str(err.value)
    result = runner.invoke(app, ["check", str(path)])
    assert result.exit_code == EXIT_BAD_INPUT
    assert where in result.output and "Traceback" not in result.output


def test_a_station_out_of_reach_is_named_by_its_key(tmp_path: Path, tending: dict[str, Any]) -> None:
    data = copy.deepcopy(tending)
    data["tending"]["stations"][1]["xyz"] = [2.6, 0.0, 0.75]
    result = runner.invoke(app, ["check", str(_write(tmp_path, data))])
    assert result.exit_code == EXIT_BAD_INPUT
    assert "tending.stations[1]" in result.output and "out of kr16's reach" in result.output
