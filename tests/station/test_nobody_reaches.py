"""A station with spots no robot can weld says, for each, every allowed robot's reason, as the
single-robot planner states it: a spot above both arms is out of reach by so much for each, a spot
inside a block is a collision for the robot that gets there."""

from __future__ import annotations

from pathlib import Path

import yaml

from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.station.pipeline import plan_station

REPO = Path(__file__).resolve().parents[2]
STATION = REPO / "tests" / "data" / "station" / "two_robots.yaml"


def test_each_robot_s_reason_is_named(tmp_path: Path) -> None:
    data = yaml.safe_load(STATION.read_text())
    for obj in data["objects"]:
        if "mesh" in obj:
            obj["mesh"] = str((STATION.parent / obj["mesh"]).resolve())
    data["objects"].append({"name": "block", "box": [0.2, 0.2, 0.2], "pose": {"xyz": [1.3, 0.0, 0.86]}})
    data["seams"].append({"name": "odd", "tolerance": {"alpha": 10, "beta": 10, "gamma": [-180, 180]}, "spots": [
        {"name": "high", "xyz": [1.7, 0.0, 3.6], "normal": [-1, 0, 0], "direction": [0, 1, 0]},
        {"name": "boxed", "xyz": [1.3, 0.0, 0.86], "normal": [-1, 0, 0], "direction": [0, 1, 0], "robots": ["r1"]}]})
    path = tmp_path / "station.yaml"
    path.write_text(yaml.safe_dump(data))
    station = load_station(path)
    plan = plan_station(station, {r.name: load_cell_robot(r.cell) for r in station.robots})
    assert plan.status == "infeasible"
    lines = plan.message.splitlines()
    assert lines[0] == "2 spot(s) no robot allowed to weld them can reach collision-free:"
    high = next(line for line in lines if line.startswith("  odd/high: "))
    for robot in ("r1", "r2"):
        assert f"{robot}: " in high and high.count("m out of reach at the best orientation") == 2, high
    boxed = next(line for line in lines if line.startswith("  odd/boxed: "))
    assert boxed.startswith("  odd/boxed: r1: collision (") and "r2" not in boxed, boxed    # r2 may not weld it
    assert "block" in boxed, boxed
