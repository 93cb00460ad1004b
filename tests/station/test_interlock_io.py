"""Interlock signals and I/O numbers: allocated in order from each controller's interlock_io range,
`<leader>_<zone>_clear`; a range too small for the plan's interlocks is bad input naming its key."""

from __future__ import annotations

import copy
import re
from pathlib import Path

import pytest
import yaml

from robomax_py.errors import CellFileError
from robomax_py.io.station import load_station
from robomax_py.station.coordinate import Interlock
from robomax_py.station.interlocks import allocate, with_interlock_io

STATION = Path(__file__).parents[1] / "data" / "station" / "two_robots.yaml"


def _lock(leader: str, waiter: str, k: int) -> Interlock:
    return Interlock(("r1", "r2"), (k, k), leader, waiter, float(k + 1), float(k), (k, k + 1.0), (k, k + 1.0))


def test_signals_numbered_from_each_range() -> None:
    station = load_station(STATION)
    locks = allocate(station, [_lock("r1", "r2", 0), _lock("r2", "r1", 1), _lock("r1", "r2", 2)])
    assert [x.signal for x in locks] == ["r1_z1_clear", "r2_z2_clear", "r1_z3_clear"]
    assert [(x.output, x.input) for x in locks] == [(101, 201), (201, 101), (102, 202)]
    setup = with_interlock_io(station.robot("r1").cell.controller, "r1", locks)
    assert {o.signal: o.number for o in setup.outputs} == {"r1_z1_clear": 101, "r1_z3_clear": 102}
    assert {i.signal: i.number for i in setup.inputs} == {"r2_z2_clear": 101}


def test_range_too_small_names_its_key(tmp_path: Path) -> None:
    data = yaml.safe_load(STATION.read_text())
    for obj in data["objects"]:
        if "mesh" in obj:
            obj["mesh"] = str((STATION.parent / obj["mesh"]).resolve())
    data = copy.deepcopy(data)
    data["robots"][0]["controller"]["interlock_io"]["outputs"] = [101, 101]
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data))
    station = load_station(path)
    with pytest.raises(CellFileError) as err:
        allocate(station, [_lock("r1", "r2", 0), _lock("r1", "r2", 1)])
    assert err.value.key == "robots[0].controller.interlock_io.outputs"
    assert "needs 2" in str(err.value)


@pytest.mark.parametrize(("edit", "key", "signal"), [
    (lambda d: d["objects"][1].update(signal="r1-z2-clear"), "objects[1].signal", "r1-z2-clear"),
    (lambda d: d.setdefault("dynamic", []).append({"name": "R2_z1", "box": [0.1, 0.1, 0.1], "present": [[0, 1]],
                                                   "pose": {"xyz": [3, 3, 3]}}), "dynamic[0].name", "R2_z1_clear"),
], ids=["clamp", "dynamic object"])
def test_a_cell_signal_written_as_an_interlock_s_is_refused(tmp_path: Path, edit, key: str, signal: str) -> None:  # type: ignore[no-untyped-def]
    # The robot waiting for the interlock would wait on the cell signal's input, or on both.
    data = yaml.safe_load(STATION.read_text())
    for obj in data["objects"]:
        if "mesh" in obj:
            obj["mesh"] = str((STATION.parent / obj["mesh"]).resolve())
    edit(data)
    path = tmp_path / "station.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(CellFileError, match=re.escape(f"{key}: the signal '{signal}' is written as a station interlock's")):
        load_station(path)
