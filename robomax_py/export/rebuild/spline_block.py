"""A spline block rebuilt (KRL `SPLINE ... ENDSPLINE`, SRCL `SPLINE ... END SPLINE`): its segments
collected until the block ends, then the path the controller interpolates through them followed and
timed (`timing.curve_move`).

What is assumed of the controller. KSS 8.x passes exactly through every SPL and SLIN point of a
spline block, keeps an SLIN segment straight, and joins the segments with continuous tangent
(KUKA System Software 8.x, Operating and Programming Instructions for System Integrators,
"Spline motion type": SPLINE block, SPL, SLIN). KUKA does not publish its interpolating curve
between the points; verify takes it to be the one `timing.space_bezier` lays through them
(quintic segments, Catmull-Rom tangents, straight first and last segments) and bounds what that
assumption can cost: the planner writes the points so densely (chords within `SPLINE_TOL_M` of
sagitta on the planned Bézier path) that any interpolating curve with continuous tangent stays
within about that sagitta of this one. The TCP moves at each segment's `$VEL.CP` (m/s) at most,
the joints within their velocity and acceleration limits, time-optimally from rest to rest (the
block ends without `C_SPL`: an exact stop).

Supported form: SLIN, then SPL points, then SLIN (what the planner writes); another form is
reported, not simulated.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.export.rebuild.result import CONFIG_TOL_RAD, Problem, Span
from robomax_py.program import LinMove, from_frame, lin_pose
from robomax_py.robot import fk_tcp
from robomax_py.robot.ik import same_config
from robomax_py.robot.solve import config_texts_near
from robomax_py.timing import LinMoveError, TimingError
from robomax_py.timing.curve_move import spline_motion
from robomax_py.timing.space_bezier import space_path

# The builder (`builder._Builder`) is passed in as `Any`: it imports this module, and imports point
# one way.


@dataclass(frozen=True, slots=True, eq=False)
class SplinePoint:
    """One segment of a block as read: its end pose (URDF root frame), TCP speed (m/s), tool,
    statement, program line and kind (retract / detour / approach, for the speed check)."""

    T: FloatArray
    speed: float
    tool: FloatArray
    ins: LinMove
    line: int | None
    kind: str


def in_block(ins: Any) -> bool:
    return isinstance(ins, LinMove) and bool(ins.spline)


def add_point(b: Any, ins: LinMove, following: Any, index: int) -> bool:
    """Collect one segment; at the block's last, build and time the block. False when the program
    cannot be rebuilt further (reported)."""
    if not b.block and b.pending:
        b.problems.append(Problem(b.t, "flyby", "a move flies by into a spline block: the robot is not at rest",
                                  b.line))
        if not b.flush():
            return False
    kind = b._kind(ins, following)
    b.after_action = False
    checked = b._check_speeds(ins, kind)
    assert isinstance(checked, LinMove)
    resolved = b._frames_of(checked)
    if resolved is None:
        return False
    tool, base = resolved
    T = from_frame(b.robot.controller.T_root_base, base @ lin_pose(checked))
    b.block.append(SplinePoint(T, checked.speed_mm_s / 1000.0, tool, checked, b.line, kind))
    if in_block(following):
        return True
    points, b.block = b.block, []
    return _build(b, points)


def _build(b: Any, points: list[SplinePoint]) -> bool:
    shape = [p.ins.spline for p in points]
    line = points[-1].line
    if len(points) < 3 or shape[0] != "slin" or shape[-1] != "slin" or any(s != "spl" for s in shape[1:-1]):
        b.problems.append(Problem(b.t, "unsupported", "a spline block of another form than SLIN, SPL ..., SLIN is "
                                                      "not simulated", line))
        return False
    robot = b._chain_robot([p.tool for p in points], [p.line for p in points])
    start = fk_tcp(robot, b.q)
    names = [(points[0].kind, points[0].ins.comment or "spline"), ("move", points[1].ins.comment or "spline"),
             (points[-1].kind, points[-1].ins.comment or "spline")]
    try:
        curve = space_path(np.concatenate([start[None], np.array([p.T for p in points])]), straight_ends=True)
        cp, segments = spline_motion(robot, curve, b.q, np.array([p.speed for p in points]), robot.limits, names,
                                     accel=min(p.ins.accel for p in points))
    except LinMoveError as exc:
        b.problems.append(Problem(b.t, "lin", f"the spline block cannot be followed: {exc}", line))
        return False
    except TimingError as exc:
        b.problems.append(Problem(b.t, "timing", f"the spline block cannot be timed: {exc}", line))
        return False
    t_end = b.t
    for seg, at in zip(segments, (points[0].line, points[1].line, line), strict=True):
        b.spans.append(Span(t_end, t_end + seg.duration, at))
        t_end += seg.duration
    path = cp.path
    q_points = np.asarray(path(np.clip(curve.key_s[1:], 0.0, path.length)), dtype=float)
    for p, q in zip(points, q_points, strict=True):
        actual = b.config_text(q)
        b.last_config = actual
        nearby = config_texts_near(b.robot, q, b.brand, CONFIG_TOL_RAD, b.controller)
        if p.ins.config and not any(same_config(p.ins.config, text) for text in nearby):
            b.problems.append(Problem(t_end, "config", f"the spline passes {actual}, the program says {p.ins.config}",
                                      p.line))
    b.segments.extend(segments)
    b.t = t_end
    b.q = np.asarray(segments[-1].q[-1], dtype=float)
    return True
