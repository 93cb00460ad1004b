"""A planar serial arm in a 2-D storage container with shelves: the test case of Diane and Anikina's
associative-memory IK (a 3-link arm, links 1, 0.65 and 0.41 m, fixed at the centre of the floor of
a 2 x 2 m container, every joint in [-90, 90] deg), for `robot.ik.table`.

Joint 1 turns from the vertical (0: the first link points straight up), each further joint from
the link before; angles in rad, lengths in m, the container's floor on y = 0 from x = -1 to 1.
The arm's links (and a held part, a bar carried along the last link beyond its tip) are line
segments of a stated radius; they collide with a rectangle (a shelf, or the container's walls,
floor and ceiling) when they come within the radius of it (an exact segment-rectangle distance).
The shelves are laid out after the paper's figure (its exact dimensions are not given).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.robot.ik.pose_table import ROTATION_WEIGHT_M

# The first link's first FOOT_M (m) stand on the floor and are not tested: its radius, and 5 mm.
FOOT_M = 0.025


@dataclass(frozen=True, slots=True)
class PlanarArm:
    links: tuple[float, ...] = (1.0, 0.65, 0.41)
    radius: float = 0.02              # m, half the links' width
    held: float = 0.0                 # m, length of a part carried beyond the tip along the last link

    def joints(self, q: FloatArray) -> FloatArray:
        """(m, n + 1, 2) the base, every joint and the tip, for rows q (m, n)."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        heading = np.cumsum(q, axis=1)                            # from the vertical
        steps = np.stack([-np.sin(heading), np.cos(heading)], axis=2) * np.asarray(self.links)[None, :, None]
        return np.concatenate([np.zeros((len(q), 1, 2)), np.cumsum(steps, axis=1)], axis=1)

    def tip(self, q: FloatArray) -> FloatArray:
        """(m, 2) the tip (the point the table stores) of rows q (m, n)."""
        return self.joints(q)[:, -1, :]

    def jacobian(self, q: FloatArray) -> FloatArray:
        """(2, n) d tip / d q at one configuration."""
        q = np.asarray(q, dtype=float)
        heading = np.cumsum(q)
        out = np.zeros((2, len(q)))
        for i in range(len(q)):
            # Joint i moves every link from i on: the derivative of sum_k L_k (-sin h_k, cos h_k).
            out[0, i] = -np.sum(np.asarray(self.links[i:]) * np.cos(heading[i:]))
            out[1, i] = -np.sum(np.asarray(self.links[i:]) * np.sin(heading[i:]))
        return out

    def pose(self, q: FloatArray) -> FloatArray:
        """(m, 4) the tip's pose as a point, for rows q (m, n): its position and the last link's
        direction (cos, sin of its heading) times ROTATION_WEIGHT_M, as `pose_table.pose_features`
        weighs a six-axis arm's rotation. The tip's (x, y) alone leaves a 3-link arm one degree of
        freedom; its pose does not."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        heading = q.sum(axis=1)
        return np.column_stack([self.tip(q), ROTATION_WEIGHT_M * np.cos(heading), ROTATION_WEIGHT_M * np.sin(heading)])

    def pose_jacobian(self, q: FloatArray) -> FloatArray:
        """(4, n) d pose / d q at one configuration."""
        q = np.asarray(q, dtype=float)
        heading = float(q.sum())
        turn = np.array([-np.sin(heading), np.cos(heading)])[:, None] * ROTATION_WEIGHT_M * np.ones((1, len(q)))
        return np.vstack([self.jacobian(q), turn])

    def segments(self, q: FloatArray) -> FloatArray:
        """(m, s, 2, 2) the segments that can collide: every link, and the held part if any."""
        pts = self.joints(q)
        segs = np.stack([pts[:, :-1], pts[:, 1:]], axis=2)
        if self.held > 0:
            d = pts[:, -1] - pts[:, -2]
            d = d / np.linalg.norm(d, axis=1, keepdims=True)
            part = np.stack([pts[:, -1], pts[:, -1] + self.held * d], axis=1)
            segs = np.concatenate([segs, part[:, None]], axis=1)
        return segs


@dataclass(frozen=True, slots=True)
class Container:
    """Axis-aligned rectangles (x0, y0, x1, y1), m: the walls, floor and ceiling as thick slabs
    outside the 2 x 2 m inside, and the shelves."""

    rects: tuple[tuple[float, float, float, float], ...]

    @staticmethod
    def storage() -> Container:
        walls = ((-1.5, -0.5, -1.0, 2.5), (1.0, -0.5, 1.5, 2.5), (-1.5, -0.5, 1.5, 0.0), (-1.5, 2.0, 1.5, 2.5))
        # Two shelves a side, 0.4 m deep, 30 mm boards, at 0.7 and 1.35 m; a post on the floor at
        # each side holds the lower ones.
        shelves = ((-1.0, 0.67, -0.6, 0.70), (0.6, 0.67, 1.0, 0.70), (-1.0, 1.32, -0.6, 1.35), (0.6, 1.32, 1.0, 1.35),
                   (-0.64, 0.0, -0.6, 0.67), (0.6, 0.0, 0.64, 0.67))
        return Container(walls + shelves)

    def free(self, arm: PlanarArm, q: FloatArray) -> BoolArray:
        """(m,) whether rows q keep the arm (and its held part) clear of every rectangle: no segment
        within the arm's radius of one (exactly: the segment crosses it, or an end of one is that
        close to the other). The first link's foot stands on the floor: its first FOOT_M along it
        are not tested."""
        segs = arm.segments(q)                                       # (m, s, 2, 2)
        a, b = segs[:, :, 0].copy(), segs[:, :, 1]
        first = b[:, 0] - a[:, 0]
        a[:, 0] += first * (FOOT_M / np.linalg.norm(first, axis=1, keepdims=True))
        hit = np.zeros(segs.shape[:2], dtype=bool)
        for rect in self.rects:
            hit |= _near(a, b, rect, arm.radius)
        return np.asarray(~hit.any(axis=1))


def _near(a: FloatArray, b: FloatArray, rect: tuple[float, float, float, float], r: float) -> BoolArray:
    """(...,) whether segments a -> b (..., 2) come within r of the rectangle (x0, y0, x1, y1)."""
    lo, hi = np.array(rect[:2]), np.array(rect[2:])
    d = b - a
    # Crossing: the segment's parameter interval inside both slabs (Liang-Barsky) is not empty.
    t0 = np.zeros(a.shape[:-1])
    t1 = np.ones(a.shape[:-1])
    inside = np.ones(a.shape[:-1], dtype=bool)
    for k in range(2):
        moving = d[..., k] != 0
        with np.errstate(divide="ignore", invalid="ignore"):
            ta = (lo[k] - a[..., k]) / d[..., k]
            tb = (hi[k] - a[..., k]) / d[..., k]
        t0 = np.where(moving, np.maximum(t0, np.minimum(ta, tb)), t0)
        t1 = np.where(moving, np.minimum(t1, np.maximum(ta, tb)), t1)
        inside &= moving | ((a[..., k] >= lo[k]) & (a[..., k] <= hi[k]))
    crossing = inside & (t0 <= t1)
    # Apart, the nearest points are an end of the segment or a corner of the rectangle.
    def to_rect(p: FloatArray) -> FloatArray:
        g = np.maximum(np.maximum(lo - p, p - hi), 0.0)
        return np.asarray(np.hypot(g[..., 0], g[..., 1]))

    near = np.minimum(to_rect(a), to_rect(b))
    length2 = np.maximum((d * d).sum(axis=-1), np.finfo(float).tiny)
    for corner in ((lo[0], lo[1]), (hi[0], lo[1]), (lo[0], hi[1]), (hi[0], hi[1])):
        c = np.array(corner)
        t = np.clip(((c - a) * d).sum(axis=-1) / length2, 0.0, 1.0)
        near = np.minimum(near, np.linalg.norm(a + t[..., None] * d - c, axis=-1))
    return np.asarray(crossing | (near <= r))
