"""`robomax verify` of what `robomax plan STATION` writes (the crossing station of tests/data: one
robot leads through the shared zone, the other waits for its signal): every dialect set replayed clean, with
the makespan and the idle shares the plan's `<station>.station.json` states, found independently
by the replay; the same programs without r1's wait make the arms touch."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, EXIT_VIOLATIONS, app

REPO = Path(__file__).resolve().parents[2]
CROSSING = REPO / "tests" / "data" / "station" / "crossing.yaml"
# The plan rounds its station file to 1e-6 s; the replay rebuilds from the programs' written values.
PLAN_TOL_S = 2e-3
runner = CliRunner()


@pytest.fixture(scope="module")
def planned(crossing_station_plan: dict[str, str]) -> dict[str, str]:
    return crossing_station_plan


def _folder(tmp_path: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    return tmp_path


@pytest.mark.slow
def test_the_planned_station_replays_as_planned(tmp_path: Path, planned: dict[str, str]) -> None:
    folder = _folder(tmp_path, planned)
    result = runner.invoke(app, ["verify", str(CROSSING), str(folder), "--json"])
    assert result.exit_code == EXIT_OK, result.output
    data = json.loads(result.output)
    station = json.loads(planned["crossing.station.json"])
    assert len(data["sets"]) == 2                      # KRL (native) and SRCL
    for replay in data["sets"]:
        assert replay["clean"] and not replay["collisions"]
        assert abs(replay["makespan"] - station["makespan"]) <= PLAN_TOL_S
        for ours, theirs in zip(replay["robots"], station["robots"], strict=True):
            assert ours["name"] == theirs["name"]
            assert abs(ours["idle_share"] - theirs["idle_share"]) <= PLAN_TOL_S


@pytest.mark.slow
def test_without_the_wait_the_arms_touch(tmp_path: Path, planned: dict[str, str]) -> None:
    srcl = {k: v for k, v in planned.items() if k.endswith((".srcl", ".station.json"))}
    waiter = json.loads(srcl["crossing.station.json"])["interlocks"][0]["waiter"]   # the robot the plan makes wait
    program = f"crossing_{waiter}.srcl"
    waits = [line for line in srcl[program].splitlines() if line.strip().startswith("WAIT FOR")]
    assert waits, f"the plan makes {waiter} wait"
    srcl[program] = "\n".join(line for line in srcl[program].splitlines() if line not in waits) + "\n"
    result = runner.invoke(app, ["verify", str(CROSSING), str(_folder(tmp_path, srcl))])
    assert result.exit_code == EXIT_VIOLATIONS, result.output
    assert "r1 and r2 touch" in result.output
