"""`robomax verify STATION ...` end to end on a station file: the programs named one per robot (any
dialect each, the KRL one on the interlock I/O numbers `<station>.station.json` gives) or found in
the output folder; exit 0 clean, 1 for a deadlock or a contact (named), 2 for bad input; the Gantt
chart of the replay with `--chart`."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import pytest
from station_case import program, station_cells, station_file, write
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_OK, EXIT_VIOLATIONS, app
from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.spec import ControllerInput, ControllerOutput

runner = CliRunner()
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
IO = {"r1": ({"r2_z1_clear": 1}, {"r1_z1_clear": 3}), "r2": ({"r1_z1_clear": 2}, {"r2_z1_clear": 4})}


@pytest.fixture(scope="module")
def station(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("duo")
    return station_file(folder, station_cells(folder))


def _write(folder: Path, station: Path, plans: dict[str, Any]) -> list[Path]:
    """`duo_<robot>.<ext>` per robot (waits, sets, dialect) and `duo.station.json` with the interlock I/O."""
    spec = load_station(station)
    paths = []
    for name, (waits, sets, dialect) in plans.items():
        cell = spec.robot(name).cell
        inputs, outputs = IO[name]
        controller = dataclasses.replace(cell.controller, inputs=tuple(ControllerInput(s, n) for s, n in inputs.items()),
                                         outputs=tuple(ControllerOutput(s, n) for s, n in outputs.items()))
        cell = dataclasses.replace(cell, controller=controller)
        robot = load_cell_robot(cell)
        spot = "a1" if name == "r1" else "b1"
        paths.append(write(folder, cell, robot, program(cell, robot, f"duo_{name}", waits, sets, spot), dialect))
    # As robomax plan STATION writes it: each interlock the leader's output and the waiter's input.
    (folder / "duo.station.json").write_text(json.dumps({"interlocks": [
        {"signal": "r1_z1_clear", "leader": "r1", "waiter": "r2", "leader_output": 3, "waiter_input": 2},
        {"signal": "r2_z1_clear", "leader": "r2", "waiter": "r1", "leader_output": 4, "waiter_input": 1}]}))
    return paths


def test_interlocked_programs_in_two_dialects_are_clean(tmp_path: Path, station: Path) -> None:
    paths = _write(tmp_path, station, {"r1": ((), ("r1_z1_clear",), "srcl"), "r2": (("r1_z1_clear",), (), "krl")})
    result = runner.invoke(app, ["verify", str(station), *map(str, paths), "--chart"])
    assert result.exit_code == EXIT_OK, result.output
    assert "clean" in result.output and "r2: ends" in result.output
    assert (tmp_path / "duo.gantt.png").read_bytes().startswith(PNG_MAGIC)
    data = json.loads(runner.invoke(app, ["verify", str(station), *map(str, paths), "--json"]).output)
    (only,) = data["sets"]
    r2 = only["robots"][1]
    assert r2["timeline"][0]["signal"] == "r1_z1_clear" and r2["timeline"][0]["of"] == "r1"
    r1, span = only["robots"][0], only["makespan"]
    assert abs(r1["idle_share"] - (span - r1["end"]) / span) <= 1e-4        # done while r2 works
    wait = r2["timeline"][0]
    assert abs(r2["idle_share"] - (wait["t_end"] - wait["t"]) / span) <= 1e-4


def test_a_deadlock_in_the_folder_exits_one_naming_robots_and_signals(tmp_path: Path, station: Path) -> None:
    _write(tmp_path, station, {"r1": (("r2_z1_clear",), ("r1_z1_clear",), "srcl"),
                               "r2": (("r1_z1_clear",), ("r2_z1_clear",), "srcl")})
    result = runner.invoke(app, ["verify", str(station), str(tmp_path)])
    assert result.exit_code == EXIT_VIOLATIONS, result.output
    assert "deadlock" in result.output
    assert "r1 waits for r2_z1_clear" in result.output and "r2 waits for r1_z1_clear" in result.output


def test_without_interlocks_the_contact_is_reported(tmp_path: Path, station: Path) -> None:
    _write(tmp_path, station, {"r1": ((), (), "srcl"), "r2": ((), (), "srcl")})
    result = runner.invoke(app, ["verify", str(station), str(tmp_path)])
    assert result.exit_code == EXIT_VIOLATIONS, result.output
    assert "collision" in result.output and "r1 and r2 touch" in result.output


@pytest.mark.parametrize("case", ["stranger", "one_missing", "empty_folder", "no_such_folder", "trajectories"])
def test_bad_input_exits_two(tmp_path: Path, station: Path, case: str) -> None:
    paths = _write(tmp_path, station, {"r1": ((), (), "srcl"), "r2": ((), (), "srcl")})
    if case == "stranger":
        stranger = tmp_path / "other_r9.srcl"
        stranger.write_text(paths[0].read_text())
        args = [str(paths[0]), str(stranger)]
    elif case == "one_missing":
        args = [str(paths[0])]
    elif case == "trajectories":
        # The robots' trajectory files, as a single cell's verify takes one.
        args = [str(tmp_path / f"duo_{r}.json") for r in ("r1", "r2")]
        for a in args:
            Path(a).write_text("{}")
    elif case == "empty_folder":
        (tmp_path / "empty").mkdir()
        args = [str(tmp_path / "empty")]
    else:
        args = [str(tmp_path / "never_written")]
    result = runner.invoke(app, ["verify", str(station), *args])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    assert "Traceback" not in result.output
    if case == "no_such_folder":
        assert "no such file or folder" in result.output
    if case == "trajectories":
        assert "duo_r1.json: a trajectory file: station duo is replayed from its robots' programs" in result.output


def test_station_preview_needs_its_folder(tmp_path: Path, station: Path) -> None:
    result = runner.invoke(app, ["preview", str(station)])
    assert result.exit_code == EXIT_BAD_INPUT and "output folder" in result.output


@pytest.mark.slow
def test_station_preview_page(tmp_path: Path, station: Path) -> None:
    """One page: both robots on the replay's clock (a meshcat server runs while it is made)."""
    _write(tmp_path, station, {"r1": ((), ("r1_z1_clear",), "srcl"), "r2": (("r1_z1_clear",), (), "srcl")})
    page = tmp_path / "duo.html"
    result = runner.invoke(app, ["preview", str(station), str(tmp_path), "--html", str(page), "--json"])
    assert result.exit_code == EXIT_OK, result.output
    data = json.loads(result.output)
    replay = json.loads(runner.invoke(app, ["verify", str(station), str(tmp_path), "--json"]).output)["sets"][0]
    assert data["robots"] == ["r1", "r2"] and abs(data["duration"] - replay["makespan"]) <= 1e-4
    assert "<html" in page.read_text(encoding="utf-8").lower()


def test_the_robots_own_dialects_are_a_program_set(tmp_path: Path) -> None:
    """`plan STATION --format native` on a KUKA and a UR robot writes a KRL and a URScript program:
    the folder holds no one dialect's set, and the robots' own programs are the set verified."""
    from robomax_py.app.station_verify import station_programs

    source = Path(__file__).resolve().parents[1] / "data" / "station" / "two_robots.yaml"
    # Its meshes are named relative to its own folder: made absolute for the copy.
    text = source.read_text().replace("mesh: ../../../", f"mesh: {source.parents[3].as_posix()}/")
    first, rest = text.split("  - name: r2", 1)
    rest = rest.replace("model: kr125", "model: ur10", 1).replace("tool: spot_gun_c", "tool: spot_gun_light", 1)
    rest = rest.replace("home: [60, -90, 90, 0, 0, 0]", "home: [0, -90, 90, -90, -90, 0]", 1)
    rest = rest.replace("controller: {interlock_io: {inputs: [201, 208], outputs: [201, 208]}}",
                        "controller: {brand: ur, interlock_io: {inputs: [0, 3], outputs: [0, 3]}}", 1)
    path = tmp_path / "two_robots.yaml"
    path.write_text(first + "  - name: r2" + rest)
    spec = load_station(path)
    out = tmp_path / "out"
    out.mkdir()
    (out / "two_robots_r1.src").write_text("")
    (out / "two_robots_r2.script").write_text("")
    (out / "two_robots_r1.json").write_text("{}")
    sets = station_programs(spec, [out])
    assert [{r: p.name for r, p in s.items()} for s in sets] == [{"r1": "two_robots_r1.src", "r2": "two_robots_r2.script"}]
    (out / "two_robots_r2.script").unlink()
    with pytest.raises(Exception, match="no program set"):
        station_programs(spec, [out])
