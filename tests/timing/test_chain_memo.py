"""A chain given again (the same joint values, poses and radii, in new arrays) is built and timed
once; one that differs in a bit is built and timed afresh; one timed under other names takes the
timing and the new names."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.timing import chain as chain_module
from robomax_py.timing.chain import LinStep, PtpStep, Step, chain_path, time_chain

REPO = Path(__file__).resolve().parents[2]
Q0_DEG = [10.0, -80.0, 100.0, 5.0, 30.0, 10.0]
Q1_DEG = [25.0, -70.0, 90.0, 15.0, 40.0, 0.0]
Q2_DEG = [40.0, -75.0, 95.0, 0.0, 35.0, -10.0]
FLYBY_RAD = 0.05
LIFT_M = 0.05                   # the LIN move's rise along the base z axis
TCP_SPEED_M_S = 0.5


@pytest.fixture(scope="module")
def kr125() -> RobotModel:
    return load_cell_robot(load_cell(REPO / "cells" / "cabin_flange.yaml"))


def _steps(robot: RobotModel, kind: str = "move", label: str = "a") -> tuple[np.ndarray, list[Step]]:
    """q_start and a chain: a LIN rise flying by into two PTP moves, every array new."""
    q0 = np.deg2rad(Q0_DEG)
    T1 = fk_tcp(robot, q0).copy()
    T1[2, 3] += LIFT_M
    return q0, [LinStep(T1, TCP_SPEED_M_S, flyby=FLYBY_RAD, kind="retract", label=label),
                PtpStep(np.deg2rad(Q1_DEG), flyby=FLYBY_RAD, kind=kind, label=label),
                PtpStep(np.deg2rad(Q2_DEG), kind=kind, label=label)]


@pytest.fixture()
def counted(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    """Calls of the chain's build and timing behind the memo; the memo emptied first."""
    monkeypatch.setattr(chain_module, "_PATHS", type(chain_module._PATHS)())
    monkeypatch.setattr(chain_module, "_TIMED", type(chain_module._TIMED)())
    calls = {"built": 0, "timed": 0}
    build, timing = chain_module._build_chain_path, chain_module._time_chain

    def built(*args: Any) -> Any:
        calls["built"] += 1
        return build(*args)

    def timed(*args: Any) -> Any:
        calls["timed"] += 1
        return timing(*args)

    monkeypatch.setattr(chain_module, "_build_chain_path", built)
    monkeypatch.setattr(chain_module, "_time_chain", timed)
    return calls


def test_a_chain_given_again_is_built_and_timed_once(kr125: RobotModel, counted: dict[str, int]) -> None:
    q0, steps = _steps(kr125)
    first = chain_path(kr125, q0, steps)
    segments = time_chain(first, steps, kr125.limits)
    q0_again, steps_again = _steps(kr125)
    again = chain_path(kr125, q0_again, steps_again)
    assert again is first
    assert all(a is b for a, b in zip(time_chain(again, steps_again, kr125.limits), segments, strict=True))
    assert counted == {"built": 1, "timed": 1}


def test_a_chain_differing_in_one_bit_is_built_and_timed_afresh(kr125: RobotModel, counted: dict[str, int]) -> None:
    q0, steps = _steps(kr125)
    first = chain_path(kr125, q0, steps)
    time_chain(first, steps, kr125.limits)
    q0, nudged = _steps(kr125)
    target = np.array(nudged[2].q)
    target[0] = np.nextafter(target[0], np.inf)
    nudged[2] = PtpStep(target, kind="move", label="a")
    other = chain_path(kr125, q0, nudged)
    time_chain(other, nudged, kr125.limits)
    assert other is not first and np.array_equal(other.targets[-1], target)
    time_chain(first, steps, kr125.limits, speed=0.5)          # another speed: timed afresh too
    assert counted == {"built": 2, "timed": 3}


def test_a_chain_timed_under_other_names_takes_the_timing_and_the_names(kr125: RobotModel,
                                                                        counted: dict[str, int]) -> None:
    q0, steps = _steps(kr125, kind="detour", label="home -> s1")
    path = chain_path(kr125, q0, steps)
    time_chain(path, steps, kr125.limits)
    _, renamed = _steps(kr125, kind="move", label="statement 3")
    got = time_chain(path, renamed, kr125.limits)
    fresh = chain_module._time_chain(path, renamed, kr125.limits, 1.0, True, chain_module.DEFAULT_DT_S)
    assert counted["timed"] == 2              # the first timing and the fresh one above
    assert [(s.kind, s.label) for s in got] == [("retract", "statement 3"), ("move", "statement 3"),
                                                ("move", "statement 3")]
    for a, b in zip(got, fresh, strict=True):
        assert all(np.array_equal(getattr(a, f), getattr(b, f)) for f in ("t", "q", "qd", "qdd"))


def test_another_robot_s_chain_empties_the_memo(kr125: RobotModel, counted: dict[str, int]) -> None:
    """A robot model holds its meshes: the memo keeps one robot's chains at a time, so a process
    planning cell after cell does not keep every robot it loaded."""
    q0, steps = _steps(kr125)
    time_chain(chain_path(kr125, q0, steps), steps, kr125.limits)
    other = load_cell_robot(load_cell(REPO / "cells" / "cabin_flange.yaml"))     # the same arm, loaded again
    time_chain(chain_path(other, q0, steps), steps, other.limits)
    assert all(entry[0] is other for entry in chain_module._PATHS.values())
    assert len(chain_module._PATHS) == 1 and len(chain_module._TIMED) == 1
    assert counted == {"built": 2, "timed": 2}
