"""A robot program -> the motion it commands, built the way the planner built it (`timing.chain`).

Speeds and weld times are checked as the program states them, in SI units (each reader converts
its dialect's units): a joint move's speed or acceleration, or a line's acceleration, above 100 % of
the axes' limits (the robot's); a line faster than the cell's line speed (`planner.tcp_speed`, the
TCP speed the cell's approach and retract lines are planned with); a weld that takes another time
than the cell's spot (a time written in ms is a thousand times the cell's). The motion is rebuilt
with the speeds capped at 100 %, as the program cannot move faster than the axes can.

Semantics (docs/srcl.md, "Motion semantics"): the first PTP is the start; moves are grouped into
chains at their FLYBY radii; a chain of one PTP is a jerk-limited joint move, every other chain is
timed by toppra on its blended path with the LIN lines' TCP speeds; SPOT and WAIT hold at rest;
`WAIT FOR <object>_clear` holds until the dynamic object `<object>` is absent. Between robots of
a station (`station`: the signals the station's robots set), a wait for one of them and each
`SetSignal` are recorded as `SignalEvent`s at rest and take no time here: the station replay
(`verify_station`) holds the robot until another program has set the signal. What the program
states that cannot be executed as stated (a LIN the arm cannot follow in its configuration, a
SPOT while flying by, a LIN ending in another configuration than its CONFIG) is a problem of the
program, reported with the time it happens; what makes the program unreadable for this cell
(another robot, other joints) is bad input.
"""

from __future__ import annotations

from robomax_py.export.rebuild.builder import rebuild
from robomax_py.export.rebuild.result import Problem, Rebuilt, SignalEvent, Span

__all__ = ["Problem", "Rebuilt", "SignalEvent", "Span", "rebuild"]
