"""The lower bound every station plan's makespan is measured against.

It bounds the makespan of any plan of the station in which each spot is welded once, by a robot
allowed to weld it, at one of that robot's candidate weld configurations (the single-robot
planner's orientation grid x IK branches, collision-free: every plan robomax makes welds there),
each robot starting and ending at rest at home and resting at each spot while it welds, its joints
within their velocity and acceleration limits and its TCP within the line speed on the near half of
each approach and retract line; waits and robot-robot collisions ignored.

Per robot, the legs of its tour run between rests (home, each spot). A leg from rest at a to rest
at b takes at least the slowest joint's time-optimal rest-to-rest trapezoid between their weld
configurations, and at least the near halves of a's retract and b's approach lines at the line
speed plus the slowest joint at its velocity limit between their approach points (as the single
robot's bound, `app.bench.lower_bound`, counts a fixed tour). Over the candidates of both spots the
least of that is the leg's bound. Each spot of a tour has one leg in and one leg out, so a tour
takes at least the sum over its spots of the weld and half of the cheapest leg in and out (to any
spot the robot could weld or home), plus half of the cheapest leg out of and into home. Which robot
welds which spot is then chosen for the least longest tour by a mixed-integer program (HiGHS through
`scipy.optimize.milp`, whose proven dual bound is taken, so a search cut short still bounds).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan import PlanOptions, resolved_options
from robomax_py.program import written_tcp_speed
from robomax_py.spec import CellSpec
from robomax_py.spec_station import SpotKey
from robomax_py.station.bound_kernels import least_leg
from robomax_py.station.reach import RobotReach

# A limit may be exceeded by the planner's own check's slack (plan.pipeline PLAN_VELOCITY_RTOL ~1e-5);
# the bound takes velocities and accelerations this much higher so that it stays a bound.
BOUND_VELOCITY_SLACK = 1e-3
# The partition's value is taken this much lower for the solver's feasibility tolerance (~1e-7 s).
PARTITION_RTOL = 1e-6
# Branch-and-bound nodes of the partition search: the proven bound at that point is kept (the
# search is deterministic, a node limit keeps it so where a time limit would not).
PARTITION_NODES = 500


@dataclass(frozen=True, slots=True)
class LowerBound:
    """The bound of this module, three ways (each a bound; `value` the largest), s:

    single : the spot whose cheapest round trip home -> spot -> home, its weld included, is longest.
    shared : every spot's least work (weld and half the cheapest legs in and out) and the home
        legs of the robots that weld, shared evenly by them (however many they are).
    partition : the same work assigned to the robots that may weld it, for the least longest tour
        (no robot's tour shorter than any one of its round trips)."""

    single: float
    shared: float
    partition: float = 0.0

    @property
    def value(self) -> float:
        return max(self.single, self.shared, self.partition)


@dataclass(frozen=True, slots=True, eq=False)
class SpotWork:
    """What one robot's tour costs at least, per spot it can weld (in `RobotReach.keys` order).

    work : (m,) s, the weld and half of the cheapest leg in plus half of the cheapest leg out.
    trip : (m,) s, the cheapest round trip home -> spot -> home with the weld.
    home : s, half of the cheapest leg out of home and half of the cheapest leg back.
    """

    robot: str
    keys: tuple[SpotKey, ...]
    work: FloatArray
    trip: FloatArray
    home: float

    def tour_bound(self, spots: Sequence[SpotKey]) -> float:
        """A lower bound on this robot's own cycle welding `spots` (0 for none), s."""
        if not spots:
            return 0.0
        index = {k: i for i, k in enumerate(self.keys)}
        rows = [index[k] for k in spots]
        return max(float(self.work[rows].sum()) + self.home, float(self.trip[rows].max()))


def half_line_time(cell: CellSpec, options: PlanOptions) -> float:
    """Half an approach line at the line speed the robot of `cell` is planned with (s): the planned
    or the written speed, the higher."""
    resolved = resolved_options(cell, options)
    planned = float(resolved.tcp_speed) * float(resolved.speed)
    speed = max(planned, written_tcp_speed(planned))
    return 0.5 * cell.process.approach / speed if speed > 0 else 0.0


def spot_work(reach: RobotReach, half_line_s: float) -> SpotWork:
    """`SpotWork` of one robot; `half_line_s` the time of half an approach line at the line speed."""
    v = reach.velocity * (1 + BOUND_VELOCITY_SLACK)
    a = reach.acceleration * (1 + BOUND_VELOCITY_SLACK)
    m = len(reach.keys)
    home = reach.home[None, :]
    out_home = np.array([_leg(home, home, reach.weld_q[i], reach.app_q[i], v, a, 0.0, half_line_s)
                         for i in range(m)])
    nearest = out_home.copy()
    # Spots are compared nearest box first; a spot whose candidate box is already farther than the
    # best leg found is passed over, with every spot after it (the box gap bounds every leg).
    boxes = _box_trapezoid(reach.lo[:, None, :], reach.hi[:, None, :], reach.lo[None, :, :], reach.hi[None, :, :], v, a)
    np.fill_diagonal(boxes, np.inf)
    for i in range(m):
        for j in np.argsort(boxes[i], kind="stable"):
            if boxes[i, j] >= nearest[i]:
                break
            nearest[i] = least_leg(reach.weld_q[i], reach.app_q[i], reach.weld_q[j], reach.app_q[j], v, a,
                                   2 * half_line_s, float(nearest[i]))
    trip = 2 * out_home + reach.dwell           # the legs are symmetric: out and back cost alike
    work = reach.dwell + nearest                # half in + half out, both at least `nearest`
    return SpotWork(reach.robot, reach.keys, work, trip, float(out_home.min(initial=0.0)))


def lower_bound(works: Sequence[SpotWork], spots: Sequence[SpotKey],
                groups: Sequence[Sequence[SpotKey]] = ()) -> LowerBound:
    """The bound of `LowerBound` over `spots`; `groups` the spots that go to one robot together (an
    ordered seam's) wherever some robot can weld all of one."""
    index = [{k: i for i, k in enumerate(w.keys)} for w in works]
    single = 0.0
    total = 0.0
    for key in spots:
        able = [(w, ix[key]) for w, ix in zip(works, index, strict=True) if key in ix]
        if not able:
            continue
        single = max(single, min(float(w.trip[i]) for w, i in able))
        total += min(float(w.work[i]) for w, i in able)
    # The robots that weld anything (k of them, unknown) share the work and each pays its home
    # legs: the longest tour is at least the least, over k, of the work and the k cheapest home
    # legs over k.
    homes = np.cumsum(sorted(w.home for w in works if len(w.keys)))
    shared = min(((total + float(h)) / (k + 1) for k, h in enumerate(homes)), default=0.0) if total > 0 else 0.0
    return LowerBound(single, shared, _partition(works, index, spots, groups))


def _partition(works: Sequence[SpotWork], index: Sequence[Mapping[SpotKey, int]], spots: Sequence[SpotKey],
               groups: Sequence[Sequence[SpotKey]]) -> float:
    """The least longest tour over assignments of `spots` (x[r, i] = 1: robot r welds spot i; y[r]:
    robot r welds any), each robot's tour its spots' work plus its home legs, and at least each of
    its round trips: the proven dual bound of the mixed-integer program (0 when it finds none)."""
    from scipy.optimize import Bounds, LinearConstraint, milp
    from scipy.sparse import coo_matrix

    whole = {k: tuple(g) for g in groups for k in g
             if any(all(x in ix for x in g) for ix in index)}
    pairs = [(r, key) for key in spots for r, ix in enumerate(index)
             if key in ix and all(x in ix for x in whole.get(key, (key,)))]
    if not pairs:
        return 0.0
    n_r = len(works)
    col = {p: c for c, p in enumerate(pairs)}
    y0, t_col = len(pairs), len(pairs) + n_r
    n = t_col + 1
    rows: list[int] = []
    cols: list[int] = []
    vals: list[float] = []
    lo: list[float] = []
    hi: list[float] = []

    def row(entries: Sequence[tuple[int, float]], low: float, high: float) -> None:
        r = len(lo)
        for c, v in entries:
            rows.append(r)
            cols.append(c)
            vals.append(v)
        lo.append(low)
        hi.append(high)

    for key in dict.fromkeys(spots):                      # each spot welded by one robot
        able = [(col[(r, key)], 1.0) for r in range(n_r) if (r, key) in col]
        if able:
            row(able, 1.0, 1.0)
    for r, w in enumerate(works):                         # each tour at most T
        mine = [(col[(r, k)], float(w.work[index[r][k]])) for k in dict.fromkeys(spots) if (r, k) in col]
        row([*mine, (y0 + r, w.home), (t_col, -1.0)], -np.inf, 0.0)
    for (r, key), j in col.items():
        row([(j, 1.0), (y0 + r, -1.0)], -np.inf, 0.0)   # a spot welded: the robot leaves home
        row([(j, float(works[r].trip[index[r][key]])), (t_col, -1.0)], -np.inf, 0.0)
    for key, g in whole.items():                          # an ordered seam to one robot
        if key != g[0]:
            for r in range(n_r):
                if (r, key) in col:
                    row([(col[(r, key)], 1.0), (col[(r, g[0])], -1.0)], 0.0, 0.0)
    matrix = coo_matrix((vals, (rows, cols)), shape=(len(lo), n)).tocsr()
    objective = np.zeros(n)
    objective[t_col] = 1.0
    integrality = np.ones(n)
    integrality[t_col] = 0
    upper = np.ones(n)
    upper[t_col] = np.inf
    res = milp(objective, constraints=LinearConstraint(matrix, lo, hi), integrality=integrality, bounds=Bounds(np.zeros(n), upper),
               options={"node_limit": PARTITION_NODES, "presolve": True})
    bound = getattr(res, "mip_dual_bound", None)
    if bound is None or not np.isfinite(bound):
        return 0.0
    return max(0.0, float(bound) * (1 - PARTITION_RTOL))


def _trapezoid(d: FloatArray, v: FloatArray, a: FloatArray) -> FloatArray:
    """(..., n) joint distances -> (...) the slowest joint's least rest-to-rest time, s."""
    t = np.where(d > v * v / a, d / v + v / a, 2.0 * np.sqrt(d / a))
    out: FloatArray = t.max(axis=-1)
    return out


def _box_trapezoid(lo_a: FloatArray, hi_a: FloatArray, lo_b: FloatArray, hi_b: FloatArray, v: FloatArray,
                   a: FloatArray) -> FloatArray:
    """A lower bound on every rest-to-rest leg between two boxes of configurations, s."""
    gap = np.maximum(0.0, np.maximum(lo_a - hi_b, lo_b - hi_a))
    return _trapezoid(gap, v, a)


def _leg(spot_a: FloatArray, app_a: FloatArray, spot_b: FloatArray, app_b: FloatArray, v: FloatArray,
         a: FloatArray, line_a: float, line_b: float) -> float:
    """The least leg from rest at any row of `spot_a` to rest at any row of `spot_b` (each row's
    approach point the same row of `app_*`), s: the larger of the rest-to-rest trapezoid and the
    lines' near halves (`line_*` s; 0 at home) plus the move between the approach points."""
    return float(least_leg(np.ascontiguousarray(spot_a, dtype=float), np.ascontiguousarray(app_a, dtype=float),
                           np.ascontiguousarray(spot_b, dtype=float), np.ascontiguousarray(app_b, dtype=float),
                           v, a, line_a + line_b, np.inf))
