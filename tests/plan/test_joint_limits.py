"""The controller's software limits (`robot.joint_limits`, narrower than the URDF's: a dress pack
that allows the wrist less than its gear does) hold for the plan, for verify and for a station's
robot; a robot placed off the origin, turned and raised."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, app
from robomax_py.export.trajectory_json import render
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.plan import plan_cell
from robomax_py.publish import publish
from robomax_py.verify import verify_program
from tests.conftest import place_cell

A6 = 5
LIMIT_DEG = 90.0
STATION = Path(__file__).resolve().parents[1] / "data" / "station" / "two_robots.yaml"


@pytest.fixture(scope="module")
def cells(tmp_path_factory: pytest.TempPathFactory, write_small_cell: Any) -> dict[str, Any]:
    folder = tmp_path_factory.mktemp("joint_limits")
    data = yaml.safe_load(write_small_cell(folder).read_text())
    place_cell(data, (3.0, -2.0, 0.4), 120.0)
    free, kept = folder / "free.yaml", folder / "kept.yaml"
    free.write_text(yaml.safe_dump({**data, "name": "free"}))
    data["robot"]["joint_limits"] = [None] * A6 + [[-LIMIT_DEG, LIMIT_DEG]]
    kept.write_text(yaml.safe_dump({**data, "name": "kept"}))
    out: dict[str, Any] = {"folder": folder}
    for name, path in (("free", free), ("kept", kept)):
        cell = load_cell(path)
        robot = load_cell_robot(cell)
        out[name] = (cell, robot, plan_cell(cell, robot))
    return out


def test_the_plan_keeps_within_the_software_limits(cells: dict[str, Any]) -> None:
    (_, free_robot, free), (_, robot, kept) = cells["free"], cells["kept"]
    assert free.status == kept.status == "planned"
    # Without the limits the plan turns A6 beyond them: the limits chose another way.
    assert np.abs(np.degrees(free.trajectory.q[:, A6])).max() > LIMIT_DEG + 10
    assert np.abs(np.degrees(kept.trajectory.q[:, A6])).max() <= LIMIT_DEG + 1e-7
    assert robot.limits.upper[A6] == pytest.approx(np.radians(LIMIT_DEG), abs=1e-12)
    np.testing.assert_array_equal(robot.limits.upper[:A6], free_robot.limits.upper[:A6])   # the URDF's: not given
    np.testing.assert_array_equal(robot.limits.velocity, free_robot.limits.velocity)


def test_verify_holds_a_program_to_the_software_limits(cells: dict[str, Any]) -> None:
    (_, _, free), (cell, robot, kept) = cells["free"], cells["kept"]
    folder: Path = cells["folder"]
    path = folder / "free.json"
    path.write_text(render(free))
    report = verify_program(cell, robot, path)
    limits = [v for v in report.violations if v.kind == "joint_limit"]
    assert limits and "joint_a6" in limits[0].detail and f"{LIMIT_DEG:.3f}" in limits[0].detail, report.violations
    files, _ = publish(kept, cell, robot, ["srcl", "krl"])
    for name, text in files.items():
        (folder / name).write_text(text)
    for main in ("kept.srcl", "kept.src"):
        assert verify_program(cell, robot, folder / main).clean


def test_a_station_robot_keeps_its_own_software_limits(tmp_path: Path) -> None:
    data = yaml.safe_load(STATION.read_text())
    for obj in data["objects"]:
        if "mesh" in obj:
            obj["mesh"] = str((STATION.parent / obj["mesh"]).resolve())
    data["robots"][1]["joint_limits"] = [None, [-120, -30], None, None, None, None]
    path = tmp_path / "station.yaml"
    path.write_text(yaml.safe_dump(data))
    station = load_station(path)
    first, second = (load_cell_robot(r.cell) for r in station.robots)
    assert first.limits.lower[1] < np.radians(-120.0) and first.limits.upper[1] > np.radians(-30.0)  # the URDF's
    assert (second.limits.lower[1], second.limits.upper[1]) == pytest.approx(np.radians([-120.0, -30.0]), abs=1e-12)


def test_check_states_the_software_limits(cells: dict[str, Any]) -> None:
    result = CliRunner().invoke(app, ["check", str(cells["folder"] / "kept.yaml")])
    assert result.exit_code == EXIT_OK, result.output
    assert "software limits joint_a6 [-90.0, 90.0] deg" in " ".join(result.stdout.split())
