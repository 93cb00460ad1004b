"""The station preview (`app.preview_station`): both robots drawn and animated on the replay's one
clock (r2 stands still at home while it waits for r1's signal, then moves), the interlock zone of
`<station>.station.json` drawn as a box of its extents, and a zone that is not one refused."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import meshcat
import numpy as np
import pytest
from station_case import members, station_cells

from robomax_py.app.preview_station import ShownRobot, populate_station, read_zones
from robomax_py.errors import ProgramError
from robomax_py.verify_station import verify_station

FPS = 5
POSE_TOL_M = 1e-9


class Recorder:
    """A meshcat window that keeps the lowered commands instead of sending them to a server."""

    def __init__(self) -> None:
        self.commands: list[dict[str, Any]] = []

    def send(self, command: Any) -> None:
        self.commands.append(command.lower())


def _track(commands: list[dict[str, Any]], path: str) -> dict[float, list[float]]:
    (anim,) = [c for c in commands if c["type"] == "set_animation"]
    (clip,) = [a["clip"] for a in anim["animations"] if a["path"] == path]
    (track,) = [t for t in clip["tracks"] if t["name"] == ".position"]
    return {round(float(k["time"]) / FPS, 6): list(k["value"]) for k in track["keys"]}


def test_both_robots_move_on_the_replay_clock(tmp_path: Path) -> None:
    cells = station_cells(tmp_path)
    plans = {"r1": ((), ("r1_z1_clear",), "srcl"), "r2": (("r1_z1_clear",), (), "srcl")}
    group = members(tmp_path, cells, plans)
    report = verify_station(group)
    shown = [ShownRobot(m.name, m.cell, m.robot, r.motion) for m, r in zip(group, report.members) if r.motion]
    zones = read_zones(_station_json(tmp_path, {"min": [1.5, -0.6, 0.8], "max": [2.7, 0.8, 1.9]}))
    rec = Recorder()
    content = populate_station(meshcat.Visualizer(window=rec), shown, zones, fps=FPS)
    assert content.robots == ("robomax/robots/r1", "robomax/robots/r2")
    assert content.frames == int(np.ceil(report.makespan * FPS)) + 1
    (box,) = [c for c in rec.commands if c["type"] == "set_object" and c["path"].startswith("/meshcat/robomax/zones/")]
    assert box["object"]["geometries"][0]["width"] == pytest.approx(1.2)
    wrist = next(c["path"] for c in rec.commands if c["type"] == "set_object" and "/robots/r2/robot/links/" in c["path"]
                 and "link_6" in c["path"])
    r2 = _track(rec.commands, wrist)
    wait = report.members[1].timeline[0]
    still = [p for t, p in r2.items() if t <= wait.t_end]
    assert len(still) > 1 and np.ptp(np.asarray(still), axis=0).max() <= POSE_TOL_M     # waits at home
    moving = [p for t, p in r2.items() if t > wait.t_end]
    assert np.ptp(np.asarray(moving), axis=0).max() > 0.1                               # then welds


def _station_json(folder: Path, zone: Any) -> Path:
    path = folder / "duo.station.json"
    path.write_text(json.dumps({"robots": [], "interlocks": [{"signal": "r1_z1_clear", "zone": zone}]}))
    return path


@pytest.mark.parametrize("zone", [{"box": [1.0, -1.0, 1.0], "pose": {"xyz": [0, 0, 0]}}, {"box": [1.0, 1.0]},
                                  {"min": [0, 0, 0], "max": [1, 1]}])
def test_a_zone_that_is_not_one_is_refused(tmp_path: Path, zone: Any) -> None:
    with pytest.raises(ProgramError, match=r"interlocks\[0\]\.zone"):
        read_zones(_station_json(tmp_path, zone))
