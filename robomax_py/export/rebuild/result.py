"""What a rebuild gives: the motion, its spots, the program's problems and the program line each
stretch of time comes from; and the tolerances its checks allow."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal

from robomax_py.timing import Trajectory
from robomax_py.tolerances import DEFAULT as TOL

# Frame definitions must match the cell's tool and base within the program's decimals.
FRAME_TOL_MM = TOL.frame_tol_mm
FRAME_TOL_DEG = TOL.frame_tol_deg
# A target's configuration data may name either side of a boundary the joint is this close to.
CONFIG_TOL_RAD = math.radians(TOL.config_tol_deg)
# A line's TCP speed may exceed the cell's line speed by this much (FANUC TP states whole mm/sec).
TCP_SPEED_TOL_MM_S = 0.5
# A weld time is the cell's within half the last decimal programs state it with (3 decimals, s).
WELD_TIME_TOL_S = 0.5e-3 + 1e-9


@dataclass(frozen=True, slots=True)
class Problem:
    t: float | None
    kind: str
    detail: str
    line: int | None = None          # the program line of the statement, where known


@dataclass(frozen=True, slots=True)
class Span:
    """The time a statement's motion takes in the rebuilt trajectory (s, from program start)."""

    t_start: float
    t_end: float
    line: int | None


@dataclass(frozen=True, slots=True)
class SignalEvent:
    """A signal the program sets (`kind` "set", to `value`) or waits for (`kind` "wait") between
    robots of a station, at time `t` of its own motion (s, the robot at rest): the cell's signal
    name (an input or output number read through `robot.controller`)."""

    t: float
    kind: Literal["set", "wait"]
    signal: str
    value: bool = True
    line: int | None = None


@dataclass(slots=True)
class Rebuilt:
    """The motion of a program: a trajectory (None when it could not be built to the end), the
    spots it welds (as the trajectory file's `spots` entries) and what was wrong on the way."""

    trajectory: Trajectory | None
    spots: list[dict[str, Any]] = field(default_factory=list)
    problems: list[Problem] = field(default_factory=list)
    spans: list[Span] = field(default_factory=list)
    # Waits for and settings of signals between robots, in program order (station replay).
    events: list[SignalEvent] = field(default_factory=list)
    # rad per axis: the finest step the program's joint values can state (`Parsed.joint_step`).
    joint_step: tuple[float, ...] = ()

    def line_at(self, t: float | None) -> int | None:
        """The program line whose statement commands the motion at time t (s)."""
        if t is None:
            return None
        for span in self.spans:
            if span.t_start - 1e-9 <= t <= span.t_end + 1e-9:
                return span.line
        return None
