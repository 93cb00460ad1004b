"""A station of arms this project does not ship: a KUKA KR 120 R2500 pro and an ABB IRB 2400 imported
from their ROS-Industrial support packages (tests/data/rosi, `robomax import-urdf`) beside a shipped
KR 125-class arm and a UR10, on a generated side-frame rim (tests/bench/station_cells.py). Each robot
gets its controller's own program (KRL, URScript, RAPID), and `robomax verify` replays the four
together clean. And a FANUC M-710iC/50 off the origin, yawed and on a riser, that is home long before
a KR 125-class arm passes through its home posture (tests/data/station/parked_home.yaml)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, app
from tests.bench.station_cells import station, write

runner = CliRunner()
DATA = Path(__file__).parent.parent / "data"


@pytest.mark.slow
def test_imported_arms_of_three_brands_plan_and_verify_together(tmp_path: Path) -> None:
    path = write(tmp_path, station(4, 16, 0, ["kr125", "kr120", "ur10", "irb2400"], name="imported_mix"))
    out = tmp_path / "out"
    planned = runner.invoke(app, ["plan", str(path), "-o", str(out), "--format", "native"])
    assert planned.exit_code == EXIT_OK, planned.output
    written = {p.name for p in out.iterdir()}
    assert {"imported_mix_r1.src", "imported_mix_r2.src", "imported_mix_r3.script", "imported_mix_r4.mod"} <= written
    plan = json.loads((out / "imported_mix.station.json").read_text())
    welded = [s for r in plan["robots"] for s in r["spots"]]
    assert sorted(welded) == sorted({*welded}) and len(welded) == 16          # every spot once
    checked = runner.invoke(app, ["verify", str(path), str(out)])
    assert checked.exit_code == EXIT_OK, checked.output
    assert "clean: no robot touches another" in checked.output


def test_a_robot_home_early_is_kept_out_of_the_others_way_home(tmp_path: Path) -> None:
    """Plan and station verify agree where one robot has ended: its home posture is checked against
    the other's motion to the station's end, so the plan orders r2's way home before r1's, and the
    programs replay clean together (they touched at 4.7 s when r1 was taken as gone once home)."""
    robots = tmp_path / "robots"
    source = DATA / "rosi" / "fanuc_m710ic_support" / "urdf" / "m710ic50.xacro"
    imported = runner.invoke(app, ["import-urdf", str(source), "-o", str(robots / "m710ic50"),
                                   "--packages", str(DATA / "rosi"), "--brand", "fanuc"])
    assert imported.exit_code == EXIT_OK, imported.output
    station, out = DATA / "station" / "parked_home.yaml", tmp_path / "out"
    planned = runner.invoke(app, ["--robots", str(robots), "plan", str(station), "-o", str(out), "--format", "native"])
    assert planned.exit_code == EXIT_OK, planned.output
    assert {"PARKED_HOME_R1.ls", "parked_home_r2.src"} <= {p.name for p in out.iterdir()}
    checked = runner.invoke(app, ["--robots", str(robots), "verify", str(station), str(out)])
    assert checked.exit_code == EXIT_OK, checked.output
    assert "clean: no robot touches another" in checked.output
