"""`robomax verify` of what `robomax plan STATION` writes (the crossing station of tests/data: r2
leads through the shared zone, r1 waits for r2_z1_clear): every dialect set replayed clean, with
the makespan and the idle shares the plan's `<station>.station.json` states, found independently
by the replay; the same programs without r1's wait make the arms touch."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, EXIT_VIOLATIONS, app

REPO = Path(__file__).resolve().parents[2]
CROSSING = REPO / "tests" / "data" / "station" / "crossing.yaml"
# The plan rounds its station file to 1e-6 s; the replay rebuilds from the programs' written values.
PLAN_TOL_S = 2e-3
runner = CliRunner()


@pytest.fixture(scope="module")
def planned(shared_once: Callable[[str, Callable[[], Any]], Any], tmp_path_factory: pytest.TempPathFactory
            ) -> dict[str, str]:
    """The plan tests/station/test_station_plan.py makes (shared: planned once per session)."""
    def run() -> dict[str, str]:
        out = tmp_path_factory.mktemp("station")
        done = CliRunner().invoke(app, ["plan", str(CROSSING), "-o", str(out), "--format", "native,srcl"])
        assert done.exit_code == 0, done.output
        return {p.name: p.read_text() for p in out.iterdir() if p.is_file()}

    files: dict[str, str] = shared_once("station-crossing-cli:" + CROSSING.read_text(), run)
    return files


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
    waits = [line for line in srcl["crossing_r1.srcl"].splitlines() if line.strip().startswith("WAIT FOR")]
    assert waits, "the plan makes r1 wait"
    srcl["crossing_r1.srcl"] = "\n".join(line for line in srcl["crossing_r1.srcl"].splitlines()
                                         if line not in waits) + "\n"
    result = runner.invoke(app, ["verify", str(CROSSING), str(_folder(tmp_path, srcl))])
    assert result.exit_code == EXIT_VIOLATIONS, result.output
    assert "r1 and r2 touch" in result.output
