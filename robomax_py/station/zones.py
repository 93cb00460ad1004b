"""Where an interlock's two robots would meet: the box, in the station's world, around the places
their pieces come within the margin of each other while both are in the two program segments the
interlock orders. It is what the preview draws as the interlock's zone.

From the pair's coordination diagram: the cells of the two segments' time spans (each robot's own
clock) where the two would collide, and at each such cell the pieces of one whose boxes (each
piece's own box carried by its pose, the axis-aligned box around that, grown by half the cell's
margin) overlap a piece's box of the other; the zone is the box around those overlaps. The boxes
hold their pieces, so the place two pieces touch lies in their overlap: the zone holds every
contact the interlock prevents.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.station.bodies import RobotBody


@dataclass(frozen=True, slots=True)
class ZoneBox:
    """An axis-aligned box in the world, m."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]


def _piece_boxes(body: RobotBody, poses: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(k, p, 3) world box centres and half extents of every piece at each of k samples."""
    R, t = poses[..., :3, :3], poses[..., :3, 3]
    centre = np.einsum("kpij,pj->kpi", R, body.centre) + t
    half = np.einsum("kpij,pj->kpi", np.abs(R), body.half)
    return centre, half


def meeting_box(a: RobotBody, poses_a: FloatArray, rows: slice, b: RobotBody, poses_b: FloatArray, cols: slice,
                clash: BoolArray, margin: float, slack_a: FloatArray, slack_b: FloatArray) -> ZoneBox | None:
    """The box around where a (samples `rows` of `poses_a`) and b (samples `cols`) meet in the
    cells `clash[rows, cols]` marks, each cell's pieces grown by half its margin (`margin +
    slack_a[i] + slack_b[j]`, m, as the diagram has it); None
    when no marked cell has two overlapping piece boxes (the diagram's cells come from the exact
    pieces, whose boxes then overlap: None only for an empty span)."""
    cells = np.argwhere(clash[rows, cols])
    if len(cells) == 0:
        return None
    ca, ha = _piece_boxes(a, poses_a[rows])
    cb, hb = _piece_boxes(b, poses_b[cols])
    lo_all = np.full(3, np.inf)
    hi_all = np.full(3, -np.inf)
    for i, j in cells:
        grow = (margin + slack_a[rows.start + i] + slack_b[cols.start + j]) / 2.0
        lo_a, hi_a = ca[i] - ha[i] - grow, ca[i] + ha[i] + grow          # (pa, 3)
        lo_b, hi_b = cb[j] - hb[j] - grow, cb[j] + hb[j] + grow          # (pb, 3)
        lo = np.maximum(lo_a[:, None], lo_b[None, :])                       # (pa, pb, 3)
        hi = np.minimum(hi_a[:, None], hi_b[None, :])
        meet = np.all(lo <= hi, axis=2)
        if meet.any():
            lo_all = np.minimum(lo_all, lo[meet].min(axis=0))
            hi_all = np.maximum(hi_all, hi[meet].max(axis=0))
    if not np.all(np.isfinite(lo_all)):
        return None
    return ZoneBox((float(lo_all[0]), float(lo_all[1]), float(lo_all[2])),
                   (float(hi_all[0]), float(hi_all[1]), float(hi_all[2])))
