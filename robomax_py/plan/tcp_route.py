"""The TCP's way through the cell's free voxels, then followed by the arm (Kholopov et al.'s graph).

The work space's free leaves (`world.voxels`, the static objects inflated by the tool tips' reach
round the TCP and the clearance) are the nodes of a graph: each joined to its nearest leaves where
the straight line between their centres stays in free leaves. A leaf near a dynamic object is
blocked in that object's windows, and the time-windowed A* (`timed_search`) finds the TCP's
earliest route from where a junction starts to where it ends, waiting where that pays.

The route is then followed by the arm: the TCP poses along it (positions of the route, orientation
turned evenly from the start's to the goal's) solved by IK in the start's configuration branch,
each solution the nearest to the one before, the last the junction's own goal. The joint path is
kept only where every straight joint move of it is free of the static objects for the whole arm
and no joint jumps; it is then one more way the junction's joint-space search may take (and that
search weighs the dynamic objects for the whole arm). Where the arm cannot follow, the junction
keeps the configuration roadmap alone.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation, Slerp

from robomax_py._typing import FloatArray
from robomax_py.plan.shortcut import greedy_shortcut
from robomax_py.plan.timed_search import (
    NoRoute,
    TimedGraph,
    Windows,
    merge_windows,
    timed_astar,
)
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.robot.solve import solve_all
from robomax_py.world.bounds import support_points
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import Scene
from robomax_py.world.voxels import VoxelMap, build_voxels

# Precision limit of the TCP's voxel map, m: the leaves near objects are this small.
PRECISION_M = 0.04
# Each leaf is joined to this many nearest leaves (where the line between them is free).
NEIGHBOURS = 10
# The TCP is taken to move at this speed between leaves for the search's times, m/s.
TCP_SPEED_M_S = 1.0
# A joint may change by at most this much between two route points (rad): more is a branch flip.
MAX_JOINT_STEP_RAD = 0.6
# The search keeps to the leaves within this of the box spanned by a route's ends (m).
REGION_MARGIN_M = 0.6
# Route points are this far apart at most when the arm follows them (m).
FOLLOW_STEP_M = 0.1
# The work space searched: the robot's reach round its base, m.
HALF_WIDTH_M = 2.0


@dataclass(frozen=True, slots=True, eq=False)
class TcpSpace:
    """The free leaves of the cell's work space (base frame), each with its dynamic objects' windows."""

    voxels: VoxelMap
    centres: FloatArray              # (N, 3) m, the free leaves' centres
    door_windows: tuple[Windows, ...]  # per free leaf: windows in which a dynamic object is near it
    # Whether the straight line between two points is free, by their bytes: the routes of a cell's
    # junctions ask about the same lines between leaves again (a third of the lines, on the tending cell).
    lines: dict[bytes, bool] = field(default_factory=dict, repr=False, compare=False)


def tcp_space(scene: Scene, robot: RobotModel, clearance: float,
              dynamic: tuple[tuple[FloatArray, FloatArray, Windows], ...]) -> TcpSpace:
    """The free space for the TCP; dynamic: (AABB lo, hi in the base frame, windows) per dynamic object."""
    tips = np.vstack([support_points(g) for g in scene.tool.tips]) if scene.tool.tips else np.zeros((1, 3))
    # Tips in the TCP frame: the farthest of them from the TCP is the ball the TCP's point stands for.
    T_tcp_flange = np.linalg.inv(np.asarray(robot.T_flange_tcp))
    reach = float(np.max(np.linalg.norm(tips @ T_tcp_flange[:3, :3].T + T_tcp_flange[:3, 3], axis=1)))
    inflation = reach + clearance
    lo = np.array([-HALF_WIDTH_M, -HALF_WIDTH_M, -0.5])
    hi = np.array([HALF_WIDTH_M, HALF_WIDTH_M, HALF_WIDTH_M + 0.5])
    voxels = build_voxels(scene, lo, hi, PRECISION_M, inflation)
    free = np.flatnonzero(voxels.free)
    centres = voxels.corner[free] + voxels.edge[free, None] / 2
    half = voxels.edge[free, None] / 2
    near = [np.all((centres + half >= dlo - inflation) & (centres - half <= dhi + inflation), axis=1)
            for dlo, dhi, _ in dynamic]
    door_windows = [merge_windows([w for m, (_, _, ws) in zip(near, dynamic) if m[i] for w in ws])
                    if any(m[i] for m in near) else () for i in range(len(free))]
    return TcpSpace(voxels, centres, tuple(door_windows))


def dynamic_boxes(scene: Scene) -> tuple[tuple[FloatArray, FloatArray, Windows], ...]:
    """Each dynamic object's AABB (base frame) and windows, for `tcp_space`."""
    out = []
    for obj in scene.dynamic:
        pts = np.vstack([support_points(g, np.asarray(obj.T_base_object)) for g in obj.pieces])
        grow = obj.margin                  # a moving object's span counts larger (`world.moving`)
        out.append((pts.min(axis=0) - grow, pts.max(axis=0) + grow, tuple(obj.present or ((0.0, math.inf),))))
    return tuple(out)


def _line_free(space: TcpSpace, a: FloatArray, b: FloatArray) -> bool:
    key = a.tobytes() + b.tobytes()
    known = space.lines.get(key)
    if known is None:
        n = max(2, math.ceil(float(np.linalg.norm(b - a)) / (PRECISION_M / 2)) + 1)
        known = space.lines[key] = bool(space.voxels.is_free(a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)).all())
    return known


def tcp_route(space: TcpSpace, p_start: FloatArray, p_goal: FloatArray, t0: float,
              max_wait: float) -> FloatArray | NoRoute:
    """The TCP positions (k, 3) of the earliest route from p_start to p_goal (both included)."""
    # The leaves round the two ends only: a search held up by a window otherwise visits every
    # leaf it could reach before the window ends.
    lo = np.minimum(p_start, p_goal) - REGION_MARGIN_M
    hi = np.maximum(p_start, p_goal) + REGION_MARGIN_M
    keep = np.flatnonzero(np.all((space.centres >= lo) & (space.centres <= hi), axis=1))
    if len(keep) == 0:
        return NoRoute("no_route", "no free leaf between the ends", 0)
    tree = cKDTree(space.centres[keep])
    windows = [space.door_windows[i] for i in keep]
    n = len(keep)
    points = np.vstack([space.centres[keep], p_start, p_goal])
    start, goal = n, n + 1
    k = min(NEIGHBOURS, n)
    links: dict[int, list[int]] = {}
    for end in (start, goal):
        _, idx = tree.query(points[end], k=k)
        links[end] = [int(v) for v in np.atleast_1d(idx)]
    back = {v: [e for e in (start, goal) if v in links[e]] for e in (start, goal) for v in links[e]}
    free_edge: dict[tuple[int, int], bool] = {}

    def neighbours(u: int) -> list[tuple[int, float]]:
        if u in links:
            out = [*links[u], goal if u == start else start]
        else:
            _, idx = tree.query(points[u], k=k + 1)
            out = [int(v) for v in np.atleast_1d(idx) if int(v) != u] + back.get(u, [])
        return [(v, float(np.linalg.norm(points[v] - points[u])) / TCP_SPEED_M_S) for v in out]

    def edge_windows(u: int, v: int) -> Windows | None:
        key = (min(u, v), max(u, v))
        if key not in free_edge:
            free_edge[key] = _line_free(space, points[u], points[v])
        return () if free_edge[key] else None

    def node_windows(u: int) -> Windows:
        return windows[u] if u < n else ()

    def heuristic(u: int) -> float:
        return float(np.linalg.norm(points[goal] - points[u])) / TCP_SPEED_M_S

    found = timed_astar(TimedGraph(neighbours, node_windows, edge_windows, heuristic), start, goal, t0, max_wait)
    if isinstance(found, NoRoute):
        return found
    route = points[[s.node for s in found.steps]]
    return _shortcut(space, route)


def _shortcut(space: TcpSpace, route: FloatArray) -> FloatArray:
    kept = greedy_shortcut(len(route), lambda i, j: _line_free(space, route[i], route[j]))
    assert kept is not None                           # neighbours are not checked: always a path
    return route[kept]


def _dense(route: FloatArray) -> FloatArray:
    """The route with points added so that none is farther than FOLLOW_STEP_M from the next: the
    arm's straight joint moves between them then stay near the TCP's line."""
    out = [route[0]]
    for a, b in itertools.pairwise(route):
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / FOLLOW_STEP_M))
        out.extend(a + (b - a) * (i / n) for i in range(1, n + 1))
    return np.array(out)


def follow(robot: RobotModel, world: CollisionWorld, route: FloatArray, q_start: FloatArray,
           q_goal: FloatArray) -> FloatArray | None:
    """Joint waypoints (k, n) along a TCP route, from q_start to q_goal, or None where the arm
    cannot follow it (no IK in the start's branch, a joint jump, a blocked straight joint move)."""
    T0, T1 = fk_tcp(robot, q_start), fk_tcp(robot, q_goal)
    route = _dense(route)
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(route, axis=0), axis=1))])
    if lengths[-1] <= 0:
        return None
    turn = Slerp([0.0, 1.0], Rotation.from_matrix(np.stack([T0[:3, :3], T1[:3, :3]])))(lengths / lengths[-1])
    poses = np.repeat(np.eye(4)[None], len(route), axis=0)
    poses[:, :3, :3] = turn.as_matrix()
    poses[:, :3, 3] = route
    table = solve_all(robot, poses[1:-1]) if len(route) > 2 else None
    qs = [np.asarray(q_start, dtype=float)]
    if table is not None:
        for i in range(len(route) - 2):
            cand = table.q[i][table.valid[i]]
            if not len(cand):
                return None
            best = cand[int(np.argmin(np.max(np.abs(cand - qs[-1]), axis=1)))]
            if np.max(np.abs(best - qs[-1])) > MAX_JOINT_STEP_RAD:
                return None
            qs.append(best)
    if np.max(np.abs(np.asarray(q_goal) - qs[-1])) > MAX_JOINT_STEP_RAD * 2:
        return None
    qs.append(np.asarray(q_goal, dtype=float))
    path = np.array(qs)
    for a, b in itertools.pairwise(path):
        if not world.check_segment(a, b).free:
            return None
    return path
