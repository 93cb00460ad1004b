"""Station files (docs/stations.md): read into a StationSpec, each robot a cell; bad input refused
with one message naming the file and the station's key."""

from __future__ import annotations

import copy
import re
from pathlib import Path
from typing import Any

import pytest
import yaml

from robomax_py.errors import CellFileError
from robomax_py.io.station import is_station_file, load_station
from robomax_py.spec_station import robot_view

STATION = Path(__file__).parents[1] / "data" / "station" / "two_robots.yaml"


def _data() -> dict[str, Any]:
    data = yaml.safe_load(STATION.read_text())
    for obj in data["objects"]:
        if "mesh" in obj:
            obj["mesh"] = str((STATION.parent / obj["mesh"]).resolve())
    return data


def _write(tmp_path: Path, data: dict[str, Any]) -> Path:
    path = tmp_path / "station.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_reads_robots_and_allowed_spots() -> None:
    station = load_station(STATION)
    assert station.robot_names == ("r1", "r2")
    assert is_station_file(STATION)
    r1, r2 = station.robots
    assert r1.cell.name == "two_robots_r1" and r2.cell.name == "two_robots_r2"
    assert r2.cell.T_world_base[0, 3] == pytest.approx(3.4)
    assert r1.interlock_outputs.numbers() == range(101, 109)
    allowed = {s.key: s.robots for s in station.spots}
    assert allowed[("front_rail", "f1")] == ("r1",)            # the seam's list
    assert allowed[("right_rail", "r4")] == ("r2",)            # a spot's list narrows it
    assert allowed[("left_rail", "l1")] == ("r1", "r2")        # no list: any robot
    view = robot_view(station, "r2", station.allowed("r2"))
    assert [(seam.name, [s.name for s in seam.spots]) for seam in view.seams] == \
        [("left_rail", ["l1", "l4"]), ("right_rail", ["r1", "r4"])]


def test_single_robot_cell_is_not_a_station() -> None:
    assert not is_station_file(Path(__file__).parents[2] / "cells" / "frame.yaml")


def _robot_key(data: dict[str, Any], i: int, key: str, value: Any) -> dict[str, Any]:
    data["robots"][i][key] = value
    return data


HOSTILE = [
    ("unknown robot in a seam", lambda d: d["seams"][1].update(robots=["r9"]) or d, "seams[1].robots", "unknown robot 'r9'"),
    ("spot widens its seam", lambda d: d["seams"][0]["spots"][0].update(robots=["r2"]) or d,
     "seams[0].spots[0].robots", "narrows"),
    ("duplicate robot name", lambda d: _robot_key(d, 1, "name", "r1"), "robots[1].name", "duplicate robot name"),
    ("robot and robots", lambda d: d.update(robot={"model": "kr125", "home": [0] * 6}) or d, "robot", "robots"),
    ("bad robot name", lambda d: _robot_key(d, 0, "name", "1st robot"), "robots[0].name", ""),
    ("unknown model", lambda d: _robot_key(d, 1, "model", "kr999"), "robots[1].model", "unknown robot"),
    ("home outside limits", lambda d: _robot_key(d, 1, "home", [0, -90, 90, 0, 500, 0]), "robots[1].home[4]", "limits"),
    ("interlock range too small",
     lambda d: d["robots"][0]["controller"].update(interlock_io={"inputs": [5, 5], "outputs": [1, 0]}) or d,
     "robots[0].controller.interlock_io", ""),
    ("interlock range missing", lambda d: d["robots"][1]["controller"].pop("interlock_io") and d,
     "robots[1].controller.interlock_io", "required"),
    ("brand differs", lambda d: d["robots"][0]["controller"].update(brand="abb") or d, "robots[0].controller.brand",
     "kuka"),
    ("unknown controller key", lambda d: d["robots"][0]["controller"].update(colour=3) or d,
     "robots[0].controller.colour", ""),
    ("bad spot", lambda d: d["seams"][2]["spots"][1].update(normal=[0, 0, 0]) or d, "seams[2].spots[1].normal", ""),
]


@pytest.mark.parametrize(("what", "edit", "key", "words"), HOSTILE, ids=[h[0] for h in HOSTILE])
def test_bad_station_names_file_and_key(tmp_path: Path, what: str, edit: Any, key: str, words: str) -> None:
    path = _write(tmp_path, edit(copy.deepcopy(_data())))
    with pytest.raises(CellFileError) as err:
        load_station(path)
    assert err.value.file == str(path)
    assert (err.value.key or "").startswith(key), str(err.value)
    assert words in str(err.value)


def test_interlock_range_clashing_with_an_input(tmp_path: Path) -> None:
    data = _data()
    data["objects"][1]["signal"] = "clamp_front"
    data["robots"][0]["controller"]["inputs"] = {"clamp_front": 103}
    with pytest.raises(CellFileError, match="clamp_front") as err:
        load_station(_write(tmp_path, data))
    assert err.value.key == "robots[0].controller.interlock_io.inputs"


def test_check_command_summarises_a_station_and_refuses_a_bad_one(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from robomax_py.app.cli import app

    runner = CliRunner()
    done = runner.invoke(app, ["check", str(STATION)])
    assert done.exit_code == 0, done.output
    said = " ".join(done.output.split())          # rich wraps at the terminal's width, the paths are long
    assert "2 robots" in said and "valid station" in said
    data = _data()
    data["robots"][1]["name"] = "r1"
    bad = _write(tmp_path, data)
    done = runner.invoke(app, ["check", str(bad)])
    assert done.exit_code == 2
    assert "robots[1].name" in " ".join(done.output.split()) and "Traceback" not in done.output
    done = runner.invoke(app, ["plan", str(bad), "-o", str(tmp_path / "out")])
    assert done.exit_code == 2 and not (tmp_path / "out").exists()


def test_shipped_station_is_valid() -> None:
    from typer.testing import CliRunner

    from robomax_py.app.cli import app

    shipped = Path(__file__).parents[2] / "cells" / "stations" / "side_frame.yaml"
    done = CliRunner().invoke(app, ["check", str(shipped)])
    assert done.exit_code == 0, done.output
    assert "4 robots, 120 spots" in done.output


def test_spots_from_a_spot_list_alone(tmp_path: Path) -> None:
    """A station handed over as CAD data has a spot list and no `seams:`: every robot may weld every
    spot of the list, and the spots are those the seams above give."""
    data = _data()
    seams = data.pop("seams")
    rows = ["id,x,y,z,nx,ny,nz,group"]
    for seam in seams[1:]:
        for s in seam["spots"]:
            rows.append(",".join([s["name"], *map(str, s["xyz"]), *map(str, s["normal"]), seam["name"]]))
    (tmp_path / "spots.csv").write_text("\n".join(rows) + "\n")
    data["spot_lists"] = [{"file": "spots.csv", "part": "frame", "units": "m", "grid": 3,
                           "tolerance": {"alpha": 10, "beta": 10, "gamma": [-180, 180]}}]
    station = load_station(_write(tmp_path, data))
    assert {s.key: s.robots for s in station.spots} == {
        ("left_rail", "l1"): ("r1", "r2"), ("left_rail", "l4"): ("r1", "r2"),
        ("right_rail", "r1"): ("r1", "r2"), ("right_rail", "r4"): ("r1", "r2")}
    from_list = {(seam.name, s.name): s.xyz for seam in station.robots[1].cell.seams for s in seam.spots}
    given = {(seam["name"], s["name"]): s["xyz"] for seam in seams[1:] for s in seam["spots"]}
    assert from_list.keys() == given.keys()
    for key, xyz in given.items():
        assert from_list[key] == pytest.approx(xyz, abs=1e-12)


def test_robots_touching_at_home_are_named_by_check_and_refused_by_plan(tmp_path: Path) -> None:
    """Both arms turned to face each other at home (A1 = 0) touch across the table: no program can
    start. `check` warns naming both robots, the pieces and the keys; `plan` exits 3 before planning
    anything, with the same words, and writes nothing."""
    from typer.testing import CliRunner

    from robomax_py.app.cli import app

    data = _data()
    for robot in data["robots"]:
        robot["home"] = [0, -90, 90, 0, 0, 0]
    said, refused = _checked_and_refused(tmp_path, data)
    assert re.search(r"r1 and r2 touch where they stand at home \(r1's \S+ within 5 mm of r2's \S+\)", said), said
    assert "robots[0].home, robots[1].home" in said and "`plan` refuses this station" in said
    assert "r1 and r2 touch where they stand at home" in refused
    # The shipped layout (A1 = 60 deg) stands apart: no warning.
    done = CliRunner().invoke(app, ["check", str(STATION)])
    assert "touch where they stand" not in done.output


def _checked_and_refused(tmp_path: Path, data: dict[str, Any]) -> tuple[str, str]:
    """What `check` of the station `data` says (exit 0) and what `plan` says refusing it (exit 3,
    nothing written), each with its lines joined."""
    from typer.testing import CliRunner

    from robomax_py.app.cli import app

    path = _write(tmp_path, data)
    runner = CliRunner()
    checked = runner.invoke(app, ["check", str(path)])
    assert checked.exit_code == 0, checked.output
    out = tmp_path / "out"
    planned = runner.invoke(app, ["plan", str(path), "-o", str(out)])
    assert planned.exit_code == 3 and not out.exists(), planned.output
    return " ".join(checked.output.split()), " ".join(planned.output.split())


def test_a_robot_that_cannot_stand_at_home_is_named_by_check_and_refused_by_plan(tmp_path: Path) -> None:
    """A post where r2's gun stands at home: no program of r2 can start. `check` warns naming the
    robot and the pieces; `plan` exits 3 with the same words before any robot is planned, and
    writes nothing."""
    import numpy as np

    from robomax_py.io.cell import load_cell_robot
    from robomax_py.robot import fk_tcp

    r2 = load_station(STATION).robots[1].cell
    at = (np.asarray(r2.T_world_base) @ fk_tcp(load_cell_robot(r2), np.asarray(r2.home)))[:3, 3]
    data = _data()
    data["objects"].append({"name": "post", "box": [0.1, 0.1, 0.1], "pose": {"xyz": [float(c) for c in at]}})
    said, refused = _checked_and_refused(tmp_path, data)
    assert re.search(r"r2: home is in collision: \S+ vs post; `plan` refuses this station", said), said
    assert "r1: home" not in said
    assert re.search(r"r2: home is in collision: \S+ vs post", refused), refused


def test_a_spot_list_may_name_the_robots_that_weld_its_spots(tmp_path: Path) -> None:
    """A CAD export per robot: `spot_lists[i].robots` allows only those robots the list's spots (a
    station key: taken out before each robot's cell is read); a list without it allows every robot.
    An unknown robot is named with the list's key."""
    data = _data()
    seams = data.pop("seams")
    lists = []
    for k, seam in enumerate(seams[1:]):
        rows = ["id,x,y,z,nx,ny,nz,group"]
        rows += [",".join([s["name"], *map(str, s["xyz"]), *map(str, s["normal"]), seam["name"]]) for s in seam["spots"]]
        (tmp_path / f"spots{k}.csv").write_text("\n".join(rows) + "\n")
        lists.append({"file": f"spots{k}.csv", "part": "frame", "units": "m", "grid": 3,
                      "tolerance": {"alpha": 10, "beta": 10, "gamma": [-180, 180]}})
    lists[1]["robots"] = ["r2"]
    data["spot_lists"] = lists
    station = load_station(_write(tmp_path, data))
    assert {s.key: s.robots for s in station.spots} == {
        ("left_rail", "l1"): ("r1", "r2"), ("left_rail", "l4"): ("r1", "r2"),
        ("right_rail", "r1"): ("r2",), ("right_rail", "r4"): ("r2",)}
    view = robot_view(station, "r1", station.allowed("r1"))
    assert [seam.name for seam in view.seams] == ["left_rail"]
    lists[1]["robots"] = ["r3"]
    with pytest.raises(CellFileError, match="unknown robot 'r3'") as err:
        load_station(_write(tmp_path, data))
    assert err.value.key == "spot_lists[1].robots"
