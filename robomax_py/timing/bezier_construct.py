"""The quintic Bézier curve built in seven steps from its end poses, end curvatures and the first
tangent lengths, after Benko Loknar, Klančar and Blažič, "Generiranje časovno minimalnih
trajektorij v avtomatiziranem skladišču z omejitvami hitrosti, pospeška in trzaja" (section 3.1,
eqs. 8-11, figure 1), and chains of such curves joined as the paper joins them.

The seven steps (P0..P5 the control points, t1 the unit vector at heading phi_1 and n1 its left
normal; t5, n5 the same at the end heading phi_5):

1. P1 = P0 + d1 t1.
2. From P1, d2_par = d1 / 2 along t1 (eq. 8),
3. then d2_perp = 5/4 d1^2 kappa_0 along n1 (eq. 9): P2.
4. The line parallel to P0P1 at d3_perp = 5/12 d1^2 kappa'_0 beyond P2 along n1 (eq. 10).
5. P4 = P5 - d5 t5.
6. The line parallel to P4P5 at d4_perp = 5/4 d5^2 kappa_5 from it along n5 (eq. 11).
7. P3 is where the two lines meet.

Here kappa' is the derivative of the curvature in the curve's own parameter lambda (d kappa /
d lambda): eq. 10 is dimensionally right only so, and it is what the geometry gives (the
derivation is in docs/bezier-paper.md). Eq. 11 prints kappa'_5; the offset of P3 from the line
P4P5 sets the end curvature kappa_5 (the mirror of eq. 9), which is what step 6 needs, so kappa_5
is used. The paper sets kappa'_0 = 0 at the start of every curve ("a sensible additional jerk
constraint at the joins"); `construct` takes it as an argument with that default.

A straight piece (kappa = 0 throughout) is the quintic with evenly spaced collinear control points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.timing._common import TimingError

# Two construction lines closer to parallel than this (|sin| of the angle between them) do not meet.
PARALLEL_SIN = 1e-9


@dataclass(frozen=True, slots=True)
class EndPose:
    """A curve's end: point (m), heading (rad), curvature (1/m)."""

    x: float
    y: float
    heading: float
    curvature: float = 0.0

    @property
    def point(self) -> FloatArray:
        return np.array([self.x, self.y])

    @property
    def tangent(self) -> FloatArray:
        return np.array([math.cos(self.heading), math.sin(self.heading)])

    @property
    def normal(self) -> FloatArray:
        """The left normal of the heading."""
        return np.array([-math.sin(self.heading), math.cos(self.heading)])


def construct(start: EndPose, end: EndPose, d1: float, d5: float, dkappa0: float = 0.0) -> FloatArray:
    """The six control points (6, 2) of the quintic of the paper's seven steps.

    start, end : the curve's end poses; their curvatures are kappa_0 and kappa_5.
    d1, d5 : |P0P1| and |P4P5|, m (> 0).
    dkappa0 : d kappa / d lambda at the start, 1/m (the paper: 0).
    """
    if not (d1 > 0.0 and d5 > 0.0):
        raise TimingError(f"tangent lengths must be > 0, got d1 = {d1}, d5 = {d5}")
    t1, n1, t5, n5 = start.tangent, start.normal, end.tangent, end.normal
    p0, p5 = start.point, end.point
    p1 = p0 + d1 * t1
    d2_perp = 1.25 * d1**2 * start.curvature
    p2 = p1 + 0.5 * d1 * t1 + d2_perp * n1
    # Line 0 through q0 along t1; line 5 through q5 along t5 (steps 4 and 6).
    q0 = p2 + (5.0 / 12.0) * d1**2 * dkappa0 * n1
    p4 = p5 - d5 * t5
    q5 = p4 + 1.25 * d5**2 * end.curvature * n5
    cross = t1[0] * t5[1] - t1[1] * t5[0]
    if abs(cross) < PARALLEL_SIN:
        raise TimingError("the construction lines of P3 are parallel (start and end headings equal or opposite)")
    diff = q5 - q0
    along = (diff[0] * t5[1] - diff[1] * t5[0]) / cross
    p3 = q0 + along * t1
    return np.stack([p0, p1, p2, p3, p4, p5])


def straight(p0: FloatArray, p5: FloatArray) -> FloatArray:
    """The straight quintic (6, 2) from p0 to p5, control points evenly spaced (unit speed in lambda
    times the length, so its arclength is linear in lambda)."""
    w = np.linspace(0.0, 1.0, 6)[:, None]
    return np.asarray((1.0 - w) * np.asarray(p0, dtype=float) + w * np.asarray(p5, dtype=float), dtype=float)


def hodographs(control: FloatArray, lam: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Position and the first three derivatives in lambda of a quintic (6, 2) at lam (k,): each (k, 2)."""
    b = np.asarray(control, dtype=float)
    u = np.asarray(lam, dtype=float)[:, None]
    w = 1.0 - u
    pos = (w**5 * b[0] + 5 * u * w**4 * b[1] + 10 * u**2 * w**3 * b[2] + 10 * u**3 * w**2 * b[3]
           + 5 * u**4 * w * b[4] + u**5 * b[5])
    d = 5.0 * np.diff(b, axis=0)
    d1 = w**4 * d[0] + 4 * u * w**3 * d[1] + 6 * u**2 * w**2 * d[2] + 4 * u**3 * w * d[3] + u**4 * d[4]
    dd = 4.0 * np.diff(d, axis=0)
    d2 = w**3 * dd[0] + 3 * u * w**2 * dd[1] + 3 * u**2 * w * dd[2] + u**3 * dd[3]
    ddd = 3.0 * np.diff(dd, axis=0)
    d3 = w**2 * ddd[0] + 2 * u * w * ddd[1] + u**2 * ddd[2]
    return pos, d1, d2, d3


def curvature(control: FloatArray, lam: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Signed curvature kappa (1/m), d kappa / d lambda (1/m) and d kappa / ds (1/m^2) at lam (k,)."""
    _, r1, r2, r3 = hodographs(control, lam)
    speed2 = np.einsum("ij,ij->i", r1, r1)
    speed = np.sqrt(speed2)
    c12 = r1[:, 0] * r2[:, 1] - r1[:, 1] * r2[:, 0]
    c13 = r1[:, 0] * r3[:, 1] - r1[:, 1] * r3[:, 0]
    dot12 = np.einsum("ij,ij->i", r1, r2)
    kappa = c12 / speed**3
    dkappa_dlam = (c13 * speed2 - 3.0 * c12 * dot12) / speed**5
    return kappa, dkappa_dlam, dkappa_dlam / speed
