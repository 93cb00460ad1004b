"""The warehouse of Benko Loknar, Klančar and Blažič, "Generiranje časovno minimalnih trajektorij v
avtomatiziranem skladišču z omejitvami hitrosti, pospeška in trzaja" (section 3.2, figure 2,
tables 1 and 2), as far as the text gives it, and what we assume where it does not.

Given by the paper:
- three straight rows of racks; the robot goes round the middle row clockwise, from the pick-up A
  (5.5, 3.5) to a drop-off on the other side, A' (5.5, 6.5), B (2.5, 6.5) or C (8.5, 6.5) (m), and
  back; at both it stops;
- between the racks it runs on a straight track; each turn round the end of the row is two quintic
  Bézier curves whose free parameters are optimised for travel time, so a half loop is four
  segments (straight, curve, curve, straight);
- the limits (table 1): unloaded v 1.5, a_R 4, a_T 2, j_R 10, j_T 8; loaded v 1.5, a_R 1,
  a_T 0.5, j_R 2.5, j_T 2 (m/s, m/s^2, m/s^3); loaded from pick-up to drop-off, unloaded back;
- table 2's nine loop times, and that the loop times follow from half loops by symmetry (A' is
  the mirror of A) and complement (B and C are each other's mirror).

Assumed (figure 2 is not described in the text):
- the racks end at x = 2 and x = 9, the row being seven 1 m cells with the stops at the centres of
  its first, middle and last cell (x = 2.5, 5.5, 8.5), and the aisles' centre lines are y = 3.5
  and 6.5; the turn is made beyond the rack end, x <= 2 (the curves start and end there);
- the floor ends FLOOR_X m before the rack end; the robot is a point (the paper's particle);
- the free parameters of a turn: the two curves' first and last tangent lengths (d1, d5 of each)
  and the pose and curvature where they meet (8 numbers); the paper does not list its own.

The return leg X -> A is the leg A -> mirror(X) run backwards (its mirror image in x = 5.5), as
the paper reduces its loops to half loops; its time is that leg's time under the unloaded limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.spec import TcpLimits
from robomax_py.timing._common import TimingError
from robomax_py.timing.bezier_construct import EndPose, construct, hodographs, straight
from robomax_py.timing.frenet_shape import Shape
from robomax_py.timing.quintic_chain import QuinticChain

UNLOADED = TcpLimits(v=1.5, a_T=2.0, a_R=4.0, j_T=8.0, j_R=10.0)      # N_agv, table 1
LOADED = TcpLimits(v=1.5, a_T=0.5, a_R=1.0, j_T=2.0, j_R=2.5)         # F_agv, table 1
PICK_UP = (5.5, 3.5)
DROP_OFFS = {"A'": (5.5, 6.5), "B": (2.5, 6.5), "C": (8.5, 6.5)}
MIRROR = {"A'": "A'", "B": "C", "C": "B"}
LOWER_Y, UPPER_Y = 3.5, 6.5
RACK_END_X = 2.0              # assumed: the racks run from x = 2 to x = 9
RACK_LENGTH = 7.0             # assumed
FLOOR_X = 2.0                 # assumed: the floor ends this far beyond each rack end (x = 0, x = 11)
MIRROR_X = PICK_UP[0]         # A' is A's mirror image in x = 5.5, B and C each other's

# Table 2: loop times (s) by (path the loaded leg runs on, path the unloaded leg runs on), "F" the
# path optimised for the loaded robot, "N" for the unloaded one.
PAPER_TABLE2: dict[tuple[str, str], dict[str, float]] = {
    ("N", "N"): {"A'": 21.998, "B": 21.477, "C": 21.985},
    ("F", "F"): {"A'": 21.523, "B": 21.342, "C": 21.519},
    ("F", "N"): {"A'": 21.052, "B": 20.859, "C": 21.035},
}
ROWS = (("N", "N"), ("F", "F"), ("F", "N"))

# A turn's parameters: d1, d5 of the first curve, the meeting point (x, y), heading (rad) and
# curvature (1/m), d1, d5 of the second curve. The start: a round turn of radius 1.5 m.
START = np.array([0.8, 0.8, RACK_END_X - 1.5, 0.5 * (LOWER_Y + UPPER_Y), math.pi / 2, -1 / 1.5, 0.8, 0.8])
SCALES = np.full(8, 0.3)
MIN_TANGENT_M = 0.02


@dataclass(frozen=True, slots=True)
class Turn:
    """One half loop's geometry: where its turn may go."""

    drop_x: float
    floor_x: float = RACK_END_X - FLOOR_X


def leg_chain(turn: Turn, x: FloatArray) -> QuinticChain:
    """Straight from the pick-up, the two curves round the rack end, straight to the drop-off.
    Each curve is built by the paper's seven steps with kappa' = 0 where it starts."""
    d1a, d5a, xj, yj, heading, kappa, d1b, d5b = (float(v) for v in x)
    start = EndPose(RACK_END_X, LOWER_Y, math.pi, 0.0)
    meet = EndPose(xj, yj, heading, kappa)
    end = EndPose(RACK_END_X, UPPER_Y, 0.0, 0.0)
    return QuinticChain.of([straight(PICK_UP, start.point), construct(start, meet, abs(d1a), abs(d5a)),
                            construct(meet, end, abs(d1b), abs(d5b)), straight(end.point, [turn.drop_x, UPPER_Y])])


def outside(turn: Turn, chain: QuinticChain) -> float:
    """How far (m) the curves leave the turn's region x in [floor_x, RACK_END_X]."""
    lam = np.linspace(0.0, 1.0, 201)
    worst = 0.0
    for control in chain.control[1:3]:
        x = hodographs(control, lam)[0][:, 0]
        worst = max(worst, float(np.max(x - RACK_END_X)), float(np.max(turn.floor_x - x)))
    return worst


def shape(turn: Turn) -> Shape:
    """The `optimise_shape` builder of a turn's parameters."""

    def build(x: FloatArray) -> tuple[QuinticChain | None, float]:
        if min(abs(x[0]), abs(x[1]), abs(x[6]), abs(x[7])) < MIN_TANGENT_M:
            return None, 0.0
        try:
            chain = leg_chain(turn, x)
        except TimingError:
            return None, 0.0
        return chain, outside(turn, chain)

    return build


def loop_times(leg_time: dict[tuple[str, str, str], float]) -> dict[tuple[str, str], dict[str, float]]:
    """Table 2 from half-loop times leg_time[(drop-off, path, limits)] ("F"/"N" path optimised for
    the loaded/unloaded robot; limits "F" loaded, "N" unloaded): the loaded leg A -> X on its path
    plus the unloaded leg, which is A -> mirror(X) run backwards, on its path."""
    return {(p_load, p_back): {x: leg_time[(x, p_load, "F")] + leg_time[(MIRROR[x], p_back, "N")] for x in DROP_OFFS}
            for p_load, p_back in ROWS}
