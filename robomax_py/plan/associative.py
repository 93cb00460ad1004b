"""Carried moves planned as Diane and Anikina plan them (`planner.transfers: associative`): an
associative memory of the carried configurations, a route over its k-nearest-neighbour graph by
Dijkstra, and Jacobian interpolation along the route (their formulas (9)-(15)).

For one carried move, from the grip's approach configuration to the release's:

1. The memory (`robot.ik.table`): the joint grid of formula (11), q_i(j) = q_start + j (q_end -
   q_start) / (J_i - 1), at STEP_RAD over the box the move's two configurations span, widened by
   MARGIN_STEPS steps on each side and clipped to the joint limits; forward kinematics fills the
   rows Q -> X, and the rows in collision with the part in the gripper are dropped (formula (2)).
   The paper's planar arm has three joints over [-90, 90] deg; a six-axis arm's whole grid at its
   step would be 10^8 rows, so the table covers the region of the move.
2. The points X are TCP poses (`pose_features`: position, and the rotation's columns weighted by
   0.3 m): for a planar arm the tip's (x, y) nearly fixes the configuration, for a six-axis arm
   only the pose does.
3. The graph (formula (13)): every stored point joined to its k = NEIGHBOURS nearest. The move's
   two configurations join the graph as nodes of their own, where the paper replaces each end by
   its nearest stored point (formula (8)): a program must grip and release at the exact poses.
4. Dijkstra (formula (14)) over lengths in the point space, edges checked lazily: an edge is used
   when the Jacobian interpolation (15) from its first configuration towards its second's point
   arrives at that configuration (within ARRIVAL_TOL_RAD, so not in another IK branch), within
   the joint limits, every step collision-free with the part held.
5. The motion: the route's nodes written as PTP waypoints (and the interpolated rows every
   WAYPOINT_SPACING of the point's path, by default none; an edge whose straight joint move leaves
   free space keeps all its rows), flown by as every detour is, then timed and checked like every
   other move (`time_junction`, the planner's final check, `verify`). The paper's controller runs
   (15) itself in position mode; a robot program states targets, and the controller interpolates
   between them.

Each carried move's two ends are chosen before sequencing (`pin_transfer_ends`): grip and release
candidates in one IK branch, the nearest pair in joint space, since the Jacobian interpolation
follows poses continuously and cannot change branch on the way. docs/associative.md has the
measurements.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from scipy.spatial import cKDTree

from robomax_py._typing import FloatArray
from robomax_py.plan.candidates import SpotCandidates
from robomax_py.plan.loads import Loads
from robomax_py.plan.results import Transition
from robomax_py.plan.sequence import HOME, Tour
from robomax_py.program import as_written_joints
from robomax_py.robot import RobotModel
from robomax_py.robot.ik._chain import (
    Chain,
    chain_to_frame,
    frame_pose,
    frame_pose_and_jacobian,
)
from robomax_py.robot.ik.pose_table import ROTATION_WEIGHT_M, grid_of, pose_features
from robomax_py.robot.ik.table import (
    EdgeFollow,
    JointGrid,
    TableIk,
    TableRoute,
    follow_edge,
    route,
)
from robomax_py.spec import CellSpec
from robomax_py.world.collision import CollisionWorld

# The grid step of every joint: the paper's coarser table ("20 deg": J = 9 over its 180 deg).
STEP_RAD = math.radians(20.0)
# The box of the grid reaches this many steps beyond the move's two configurations on each side.
MARGIN_STEPS = 1
# k of the k-NN graph; the paper asks k >= 3 and chooses it by trial. A six-axis grid row has 12
# neighbours one step along one joint: with k = 12 a route turns one joint at a time and
# cells/pick_place.yaml's transfers took 47 % longer than with 48; beyond 48 they shorten little
# while the graph's edges grow (bench_transfers.py --sweep, docs/associative.md).
NEIGHBOURS = 48
# A grid larger than this is not built (about 0.6 s of collision checks per 100,000 rows, KR 16).
MAX_ROWS = 400_000
# Steps of formula (15) along an edge, point units (m).
INTERPOLATION_STEP = 0.01
# An edge's interpolation must end this close (rad, every joint) to the far node's configuration.
ARRIVAL_TOL_RAD = 0.02
# Waypoints written along the route at most this far apart in the point space (m); inf: the nodes
# alone. The rows every 0.1 m as well lengthened cells/pick_place.yaml's cycle (every via point is
# flown by under the part's limits) and its planning (bench_transfers.py, docs/associative.md).
WAYPOINT_SPACING = math.inf
# Blocked edges after which a move's route search gives up.
MAX_BLOCKED = 400

TransferStatus = Literal["routed", "no_route", "grid_too_large"]


@dataclass(frozen=True, slots=True)
class AssociativeSettings:
    """The method's parameters (radians, point units of m)."""

    step: float = STEP_RAD
    margin_steps: int = MARGIN_STEPS
    k: int = NEIGHBOURS
    max_rows: int = MAX_ROWS
    interpolation_step: float = INTERPOLATION_STEP
    waypoint_spacing: float = WAYPOINT_SPACING


@dataclass(frozen=True, slots=True, eq=False)
class TransferTable:
    """The memory of one move: the stored rows with the two ends appended (rows `start`, `goal`)."""

    table: TableIk
    grid: JointGrid
    start: int
    goal: int


@dataclass(frozen=True, slots=True, eq=False)
class AssociativeTransfer:
    """One carried move planned by the method.

    status : "routed" (waypoints from the start's configuration to the goal's), "no_route" (the
        graph joins them by no usable edges) or "grid_too_large"; `detail` says more.
    waypoints : (m, n) rad, the PTP targets, both ends included.
    grid_rows, stored : rows of the grid, and those free with the part held (the table's K*).
    route : the route's nodes and what its search spent.
    line_error : the largest distance (point units) of the interpolated point from the straight
        line of its edge, over the route's edges.
    """

    status: TransferStatus
    waypoints: FloatArray
    grid_rows: int
    stored: int
    route: TableRoute
    line_error: float = 0.0
    detail: str = ""


class TcpPoints:
    """The TCP pose as the table's point (`pose_features`, 12 numbers) and its Jacobian (12, n)."""

    def __init__(self, robot: RobotModel) -> None:
        self._chain: Chain = chain_to_frame(robot.model, robot.flange_frame_id)
        self._T = np.asarray(robot.T_flange_tcp, dtype=float)

    def points(self, q: FloatArray) -> FloatArray:
        """(m, 12) points of configurations (m, n)."""
        return pose_features(frame_pose(self._chain, np.atleast_2d(q)) @ self._T)

    def jacobian(self, q: FloatArray) -> FloatArray:
        """(12, n) d point / d q at one configuration (n,)."""
        R3, _, J6 = frame_pose_and_jacobian(self._chain, np.asarray(q, dtype=float)[None, :])
        R = R3[:, :, 0]
        r = R @ self._T[:3, 3]                      # flange origin -> TCP, world axes
        Jv, Jw = J6[0, :3], J6[0, 3:]
        # v_tcp = v_flange + w x r; a rotation column c moves as w x c.
        rows = [Jv - _skew(r) @ Jw]
        R_tcp = R @ self._T[:3, :3]
        rows.extend(-ROTATION_WEIGHT_M * _skew(R_tcp[:, c]) @ Jw for c in range(3))
        return np.vstack(rows)


def _skew(v: FloatArray) -> FloatArray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


@dataclass(frozen=True, slots=True)
class GridTooLarge:
    """A move's grid of more rows than `AssociativeSettings.max_rows`: not built."""

    rows: int


def transfer_table(robot: RobotModel, world: CollisionWorld, points: TcpPoints, q_start: FloatArray,
                   q_goal: FloatArray, settings: AssociativeSettings) -> TransferTable | GridTooLarge:
    """The memory of the move from q_start to q_goal (module docstring, 1-3)."""
    lo_lim, hi_lim = np.asarray(robot.limits.lower, dtype=float), np.asarray(robot.limits.upper, dtype=float)
    margin = settings.margin_steps * settings.step
    lo = np.maximum(np.minimum(q_start, q_goal) - margin, lo_lim)
    hi = np.minimum(np.maximum(q_start, q_goal) + margin, hi_lim)
    grid = grid_of(lo, hi, (settings.step,) * robot.dof)
    if grid.size > settings.max_rows:
        return GridTooLarge(grid.size)
    rows = grid.rows(0, grid.size)
    stored = rows[world.are_free(rows)]
    q = np.vstack([stored, np.asarray(q_start, dtype=float)[None], np.asarray(q_goal, dtype=float)[None]])
    x = points.points(q)
    return TransferTable(TableIk(q, x, grid.size, cKDTree(x)), grid, len(stored), len(stored) + 1)


def plan_transfer(robot: RobotModel, world: CollisionWorld, q_start: FloatArray, q_goal: FloatArray,
                  settings: AssociativeSettings = AssociativeSettings(),
                  points: TcpPoints | None = None) -> AssociativeTransfer:
    """The carried move from q_start to q_goal by the method (module docstring), in `world` (the
    cell with the part in the gripper)."""
    points = points if points is not None else TcpPoints(robot)
    q_start, q_goal = np.asarray(q_start, dtype=float), np.asarray(q_goal, dtype=float)
    memory = transfer_table(robot, world, points, q_start, q_goal, settings)
    if isinstance(memory, GridTooLarge):
        return AssociativeTransfer("grid_too_large", q_start[None], memory.rows, 0, TableRoute("no_route"),
                                   detail=f"the grid has {memory.rows:,} rows, more than {settings.max_rows:,}")
    followed: dict[tuple[bytes, bytes], EdgeFollow] = {}      # the usable edges checked, by their ends

    def edge_free(qa: FloatArray, qb: FloatArray) -> bool:
        edge = follow_edge(qa, qb, points.points, points.jacobian, settings.interpolation_step, ARRIVAL_TOL_RAD)
        # Not arrived: the interpolation lands in another branch, short of the far node, or jumps.
        if not edge.arrived or not bool(robot.limits.contains(edge.rows).all()) or \
                not world.check_path(edge.rows).free:
            return False
        followed[(qa.tobytes(), qb.tobytes())] = edge
        return True

    table = memory.table
    found = route(table, memory.start, memory.goal, settings.k, edge_free, max_blocked=MAX_BLOCKED)
    stored = memory.goal - 1
    if not found.found:
        why = "no route joins the two ends" if found.status == "no_route" else f"{len(found.blocked)} edges blocked"
        return AssociativeTransfer("no_route", q_start[None], memory.grid.size, stored, found,
                                   detail=f"{why} on the k-NN graph of {stored:,} stored rows")
    legs: list[FloatArray] = []
    line_error = 0.0
    for u, v in itertools.pairwise(found.nodes):
        qa, qb = table.q[u], table.q[v]
        edge = followed.get((qa.tobytes(), qb.tobytes()))
        # An edge checked in the other direction is followed back along the same rows.
        back = edge is None
        edge = edge if edge is not None else followed[(qb.tobytes(), qa.tobytes())]
        legs.append(edge.rows[::-1] if back else edge.rows)
        line_error = max(line_error, edge.off_line)
    waypoints = _waypoints(world, points, legs, settings.waypoint_spacing)
    return AssociativeTransfer("routed", waypoints, memory.grid.size, stored, found, line_error)


def _waypoints(world: CollisionWorld, points: TcpPoints, legs: Sequence[FloatArray], spacing: float) -> FloatArray:
    """Every node and, on each leg, the rows at most `spacing` apart along the point's path; a leg
    whose thinned polyline is not free keeps every row (the checked polyline itself)."""
    out = [legs[0][:1]]
    for rows in legs:
        x = points.points(rows)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))])
        n = max(1, math.ceil(float(s[-1]) / spacing))
        keep = np.unique(np.searchsorted(s, s[-1] * np.arange(1, n + 1) / n))
        keep = np.minimum(keep, len(rows) - 1)
        keep[-1] = len(rows) - 1
        thin = np.vstack([rows[:1], rows[keep]])
        out.append(thin[1:] if world.check_path(thin).free else rows[1:])
    return np.vstack(out)


def pin_transfer_ends(cell: CellSpec, spots: list[SpotCandidates]) -> list[SpotCandidates]:
    """Per transfer, the grip's and the release's candidates cut to one pair: in one IK branch
    (the same configuration status), the nearest in joint space at their approach points (the
    interpolation follows poses continuously: of two turns of a wrist joint that give the same
    pose, it reaches the nearer); where the two share no branch, the nearest pair (the route then
    finds no edge into it)."""
    specs = [s for seam in cell.seams for s in seam.spots]
    out = list(spots)
    for i in range(len(specs) - 1):
        if specs[i].action != "grip" or specs[i + 1].action != "release":
            continue
        g, r = spots[i], spots[i + 1]
        if not len(g) or not len(r):
            continue
        cost = np.linalg.norm(g.q_app[:, None, :] - r.q_app[None, :, :], axis=2)
        same = g.status[:, None] == r.status[None, :]
        a, b = np.unravel_index(int(np.argmin(np.where(same, cost, np.inf) if same.any() else cost)), cost.shape)
        out[i], out[i + 1] = _only(g, int(a)), _only(r, int(b))
    return out


def _only(c: SpotCandidates, a: int) -> SpotCandidates:
    sel = np.array([a])
    return replace(c, orient=c.orient[sel], angles=c.angles[sel], column=c.column[sel], q_spot=c.q_spot[sel],
                   q_app=c.q_app[sel], app_path=c.app_path[sel], status=c.status[sel], turn=c.turn[sel])


@dataclass(frozen=True, slots=True, eq=False)
class AssociativeMoves:
    """A tour's transitions with every carried move planned by the method; `failure` names the
    first move it could not plan (then `transitions` is empty)."""

    transitions: tuple[Transition, ...]
    planned: tuple[AssociativeTransfer, ...] = ()
    failure: str | None = None


def associative_moves(robot: RobotModel, loads: Loads, tour: Tour, transitions: Sequence[Transition],
                      settings: AssociativeSettings = AssociativeSettings()) -> AssociativeMoves:
    """The tour's carried moves replaced by the method's (detours through the route's waypoints)."""
    points = TcpPoints(robot)
    out: list[Transition] = []
    planned: list[AssociativeTransfer] = []
    for k, trans in enumerate(transitions):
        part = loads.part_after(tour.order[k - 1] if k > 0 else HOME)
        if part is None:
            out.append(trans)
            continue
        # From the two ends as the program states them, so that the route is the one the written
        # ends give (the table's grid is laid out from them).
        wp = as_written_joints(np.asarray(trans.waypoints, dtype=float), robot.prismatic)
        found = plan_transfer(robot, loads.worlds[part], wp[0], wp[-1], settings, points)
        if found.status != "routed":
            return AssociativeMoves((), tuple(planned), f"{trans.label} carrying {part}: {found.detail}")
        planned.append(found)
        out.append(replace(trans, kind="detour", waypoints=found.waypoints, checks=found.route.edge_checks))
    return AssociativeMoves(tuple(out), tuple(planned))
