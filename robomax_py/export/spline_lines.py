"""A spline block as short straight lines flown by, for the dialects without spline motion (RAPID
`MoveL ... zN`, FANUC `L ... CNTn`, URScript `movel(..., r=)`, INFORM, AS).

Each segment of the block becomes a LIN to its point at the segment's speed. The spline points
are sampled from the planned Bézier path with at most `plan.spline_junction.SPLINE_TOL_M` of
sagitta, so the lines between them keep within that of the path; each point but the last is flown
by at a fraction of the shorter chord meeting there (`plan.spline_junction.line_flybys`, which the
planner times them with too: the blends of neighbouring points never overlap, and a blend cuts the
corner by less than the chords' sagitta; a smaller fraction where the straight retract and
approach meet the curve, so the TCP stays on the electrode axis). The last segment (the
approach into the spot) stops. The controller then runs a path within about twice that sagitta of
the plan's and, its blends being sharper turns than the spline's, somewhat slower: `publish`
checks both against `tolerances.spline_lines_mm` and `spline_lines_time`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.export.dialect import PlannedProgram
from robomax_py.plan.spline_junction import line_flybys
from robomax_py.program import Comment, Instruction, LinMove
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.timing.chain import tcp_flyby_radius


def has_splines(planned: PlannedProgram) -> bool:
    return any(isinstance(i, LinMove) and i.spline for i in planned.program.instructions)


def as_lines(planned: PlannedProgram, robot: RobotModel) -> PlannedProgram:
    """The program with every spline block written as lines flown by (joint values unchanged:
    one line per segment). A block is a run of spline segments with only comments between them."""
    out: list[Instruction] = list(planned.program.instructions)
    block: list[int] = []
    for k, ins in enumerate(out):
        if isinstance(ins, LinMove) and ins.spline:
            block.append(k)
        elif not isinstance(ins, Comment) and block:
            _convert(out, block, planned.joints, robot)
            block = []
    if block:
        _convert(out, block, planned.joints, robot)
    return dataclasses.replace(planned, program=dataclasses.replace(planned.program, instructions=tuple(out)))


def _convert(out: list[Instruction], block: list[int], joints: tuple[FloatArray, ...], robot: RobotModel) -> None:
    """The block's segments as lines; each fly-by (`plan.spline_junction.line_flybys`) stated as
    the joint-space radius (deg) its TCP distance makes on that line (`timing.chain.tcp_flyby_radius`),
    which every dialect states in its own terms (KRL C_DIS, RAPID zones, URScript r: back to the
    distance; FANUC CNT)."""
    # The chords from the planned joints (robot base frame): the points' own frame may be a user frame.
    pts = np.array([robot_tcp_mm(robot, joints[k]) for k in block])
    flybys = line_flybys(pts, robot_tcp_mm(robot, joints[block[0] - 1]))
    for j, k in enumerate(block):
        m = out[k]
        assert isinstance(m, LinMove)
        q_prev = joints[block[j - 1]] if j > 0 else joints[k - 1]
        radius = tcp_flyby_radius(robot, q_prev, joints[k], float(flybys[j]) / 1000.0) if flybys[j] > 0 else 0.0
        out[k] = dataclasses.replace(m, spline="", flyby=math.degrees(radius))


def robot_tcp_mm(robot: RobotModel, q: FloatArray) -> FloatArray:
    """The TCP position (mm) at q in the robot base frame (URDF root)."""
    return np.asarray(fk_tcp(robot, q)[:3, 3] * 1000.0, dtype=float)
