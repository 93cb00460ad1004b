"""Errors cross process boundaries whole: a process pool (batch, the family bench) or a Ray worker
pickles the exception a cell's run raised, and the parent must get the same error back, not a
TypeError from its constructor."""

from __future__ import annotations

import pickle

import pytest

from robomax_py.errors import (
    CellFileError,
    ControllerSetupError,
    ExportError,
    OutputError,
    ProgramError,
    RobotModelError,
)
from robomax_py.plan.waiting import Trapped
from robomax_py.robot.ik.fit import FitError
from robomax_py.timing._common import LinMoveError, TimingError

ERRORS = [
    CellFileError("cells/a.yaml", "robot.home", "expected six joint values"),
    RobotModelError(None, None, "no such robot"),
    ProgramError("p.src", "line 3, column 1", "unknown statement"),
    OutputError("ex/frame.yaml", None, "exists with other content; use --force to replace it"),
    ControllerSetupError("robot.controller.tool.number", "must be 1..16"),
    ExportError("no dialect"),
    FitError("axes 2 and 3 must be parallel"),
    TimingError("cannot be timed"),
    LinMoveError("unreachable", 4, 0.5, "the line leaves the workspace"),
    Trapped("trapped by door", "door", 3.5, True),
]


@pytest.mark.parametrize("error", ERRORS, ids=[type(e).__name__ for e in ERRORS])
def test_an_error_survives_pickling(error: Exception) -> None:
    back = pickle.loads(pickle.dumps(error))
    assert type(back) is type(error) and str(back) == str(error)
    assert {k: v for k, v in vars(back).items()} == {k: v for k, v in vars(error).items()}
