"""A planar serial arm in a 2-D storage container with shelves: the test case of Diane and Anikina's
associative-memory IK (a 3-link arm, links 1, 0.65 and 0.41 m, fixed at the centre of the floor of
a 2 x 2 m container, every joint in [-90, 90] deg), for `robot.ik.table`.

Joint 1 turns from the vertical (0: the first link points straight up), each further joint from
the link before; angles in rad, lengths in m, the container's floor on y = 0 from x = -1 to 1.
The arm's links (and a held part, a bar carried along the last link beyond its tip) are line
segments of a stated radius; they collide with a rectangle (a shelf, or the container's walls,
floor and ceiling) when a point sampled along them at `SAMPLE_M` lies within the radius of it.
The shelves are laid out after the paper's figure (its exact dimensions are not given).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import BoolArray, FloatArray

# Points along each segment tested against the rectangles are this far apart at most (m).
SAMPLE_M = 0.005


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
        """(m,) whether rows q keep the arm (and its held part) clear of every rectangle."""
        segs = arm.segments(q)                                       # (m, s, 2, 2)
        length = float(max(max(arm.links), arm.held))
        t = np.linspace(0.0, 1.0, int(np.ceil(length / SAMPLE_M)) + 1)
        pts = segs[:, :, :1] + t[None, None, :, None] * (segs[:, :, 1:] - segs[:, :, :1])   # (m, s, k, 2)
        # The first link's foot stands on the floor: its first points are not tested against it.
        hit = np.zeros(len(segs), dtype=bool)
        r = arm.radius
        for x0, y0, x1, y1 in self.rects:
            dx = np.maximum(np.maximum(x0 - pts[..., 0], pts[..., 0] - x1), 0.0)
            dy = np.maximum(np.maximum(y0 - pts[..., 1], pts[..., 1] - y1), 0.0)
            near = dx * dx + dy * dy <= r * r
            near[:, 0, : int(np.ceil(r / (arm.links[0] / (len(t) - 1)))) + 1] = False
            hit |= near.any(axis=(1, 2))
        return ~hit
