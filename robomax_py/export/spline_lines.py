"""A spline block as short straight lines flown by, for the dialects without spline motion (RAPID
`MoveL ... zN`, FANUC `L ... CNTn`, URScript `movel(..., r=)`, INFORM, AS).

Each segment of the block becomes a LIN to its point at the segment's speed. The spline points
are sampled from the planned Bézier path with at most `plan.spline_junction.SPLINE_TOL_M` of
sagitta, so the lines between them keep within that of the path; each interior point is flown by
at `FLYBY_FRACTION` of the shorter chord meeting there (the blends of neighbouring points never
overlap, and a blend cuts the corner by less than the chords' sagitta), except where the straight
retract and approach meet the curve: there the fly-by is `END_FLYBY_FRACTION` of it, so the TCP
leaves and reaches the electrode axis all but on it. The last segment (the approach into the
spot) stops. The controller then runs a path within about twice that sagitta of the plan's and,
its blends being sharper turns than the spline's, somewhat slower: `publish` checks both against
`tolerances.spline_lines_mm` and `spline_lines_time`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.export.dialect import PlannedProgram
from robomax_py.program import Comment, Instruction, LinMove
from robomax_py.robot import RobotModel
from robomax_py.timing.chain import tcp_flyby_radius

# Fly-by at an interior spline point, as a fraction of the shorter chord meeting there (< 0.5).
FLYBY_FRACTION = 0.4
# ... and where the straight retract or approach meets the curve.
END_FLYBY_FRACTION = 0.1


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
    """The block's segments as lines; each fly-by stated as the joint-space radius (deg) its TCP
    distance makes on that line (`timing.chain.tcp_flyby_radius`), which every dialect states in
    its own terms (KRL C_DIS, RAPID zones, URScript r: back to the distance; FANUC CNT)."""
    moves = [out[k] for k in block]
    assert all(isinstance(m, LinMove) for m in moves)
    pts = np.array([m.position_mm for m in moves if isinstance(m, LinMove)], dtype=float)
    chords = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    for j, k in enumerate(block):
        m = out[k]
        assert isinstance(m, LinMove)
        flyby = 0.0
        if 0 < j + 1 < len(block):
            # The chord into point j + 1 from point j and out of it: point j's neighbours in the block.
            before = chords[j - 1] if j > 0 else None
            after = chords[j]
            shorter = float(after if before is None else min(before, after))
            ends = j == 0 or j == len(block) - 2
            flyby = (END_FLYBY_FRACTION if ends else FLYBY_FRACTION) * shorter
        q_prev = joints[block[j - 1]] if j > 0 else joints[k - 1]
        radius = tcp_flyby_radius(robot, q_prev, joints[k], flyby / 1000.0) if flyby > 0 else 0.0
        out[k] = dataclasses.replace(m, spline="", flyby=math.degrees(radius))
