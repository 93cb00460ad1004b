"""Moves past dynamic obstacles that know their windows: wait nearer the goal, or go round.

Today's way (`waiting`) plans the cell as if its dynamic obstacles were absent and holds the robot
at rest before a move that would meet one, until its window ends. Here a blocked junction is
searched again in time (`timed_search`, the time-windowed A* of Kholopov et al.) over the cell's
roadmap, the junction's own planned path and a direct move: each node and edge is blocked in the
windows of the dynamic obstacles its configuration or straight move touches (checked once per
obstacle, since an obstacle does not move while it is there), the goal for as long as the approach,
the action and the retract stay there. The route found may wait at a node near the door, so the
robot is in front of it when it opens, or go round.

The route is then timed for real: exact stops at its waits, each wait the shortest at rest that
keeps the rest of the junction clear (`waiting.wait_at_rest`, so `WAIT FOR <door>_open` holds as
planned), every piece checked against the dynamic obstacles at its times. The caller keeps it only
when it finishes before waiting at rest would; otherwise, or when anything fails, today's way stays.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import RobomaxError
from robomax_py.plan.junction import (
    DETOUR_RADII_DEG,
    JUNCTION_RADII_DEG,
    Extension,
    WeldEnd,
    time_junction_at,
)
from robomax_py.plan.results import Stage
from robomax_py.plan.roadmap import Roadmap
from robomax_py.plan.shortcut import greedy_shortcut
from robomax_py.plan.tcp_route import TcpSpace, follow, tcp_route
from robomax_py.plan.timed_search import (
    NoRoute,
    TimedGraph,
    TimedRoute,
    Windows,
    merge_windows,
    timed_astar,
)
from robomax_py.plan.waiting import (
    WaitingError,
    ceil_ms,
    first_dynamic_hit,
    wait_at_rest,
)
from robomax_py.program import as_written_joints
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.spec import CellSpec
from robomax_py.timing import Segment, dwell, ptp_time_estimate
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene


class DynamicConflicts:
    """Which dynamic obstacles a configuration or a straight joint move touches (any time), and the
    windows in which that matters. One collision world of them all, robot-against-obstacle pairs
    only; a moving object is there as its spans (`world.moving`), each with its own window, so a
    node or an edge is blocked only while the moving object is where it touches it."""

    def __init__(self, cell: CellSpec, robot: RobotModel) -> None:
        scene = build_scene(replace(cell, objects=()), robot)
        self.windows = tuple(d.present if d.present is not None else ((0.0, math.inf),) for d in scene.dynamic)
        self._all = CollisionWorld(robot, scene, cell.process.clearance).restricted(obstacles=True, self_pairs=False)
        # Answers by the moves' exact bytes: the searches of every junction of a cell ask about the
        # same roadmap edges and nodes again.
        self._known: dict[bytes, frozenset[int]] = {}

    def point(self, q: FloatArray) -> frozenset[int]:
        q = np.asarray(q, dtype=float)
        key = q.tobytes()
        if key not in self._known:
            # Most configurations touch none, and then one check answers.
            self._known[key] = frozenset() if self._all.is_free(q) else self._all.obstacles_touched(q[None])
        return self._known[key]

    def segment(self, qa: FloatArray, qb: FloatArray) -> frozenset[int]:
        qa, qb = np.asarray(qa, dtype=float), np.asarray(qb, dtype=float)
        key = qa.tobytes() + qb.tobytes()
        if key not in self._known:
            self._known[key] = frozenset() if self._all.check_segment(qa, qb).free else \
                self._all.obstacles_touched(self._all.segment_states(qa, qb))
        return self._known[key]

    def windows_of(self, objects: frozenset[int]) -> Windows:
        return merge_windows([w for i in sorted(objects) for w in self.windows[i]])


# Searches again from later when a route waits where the retract ends (see `staged_junction`).
MAX_HELD_SEARCHES = 2
# (junction, corner) radii tried for a staged junction's pieces, deg: the largest first, then stops.
STAGED_RADII_DEG = ((JUNCTION_RADII_DEG[0], DETOUR_RADII_DEG[0]), (JUNCTION_RADII_DEG[0], DETOUR_RADII_DEG[-1]),
                    (JUNCTION_RADII_DEG[-1], 0.0), (0.0, 0.0))


@dataclass(frozen=True, slots=True, eq=False)
class StagedJunction:
    """A junction timed with stops where the robot waits, ready to replace the one waiting at rest."""

    segments: list[Segment]          # retract ... approach with the waits (not the action after it)
    waypoints: FloatArray            # (m, n): where the retract ends, ..., the approach point
    stages: tuple[Stage, ...]
    junction_radius: float           # rad, as `Junction`
    corner_radius: float
    extension: Extension
    pre_wait: float = 0.0            # s at rest at q_rest before the segments (a moving object passing)


@dataclass(frozen=True, slots=True)
class JunctionContext:
    """What a junction's time-aware search needs besides the junction itself."""

    robot: RobotModel
    world: CollisionWorld            # the static obstacles (the plan's world)
    dynamic_world: CollisionWorld    # the dynamic obstacles alone, at their times
    conflicts: DynamicConflicts
    roadmap: Roadmap | None
    windows: dict[str, tuple[tuple[float, float], ...]]
    doors: frozenset[str]
    tcp_speed: float
    speed: float
    jerk_limited: bool
    max_wait: float
    tcp: TcpSpace | None = None      # the TCP's free voxels: a route through them is one more way
    moving: frozenset[str] = frozenset()   # moving objects: `windows` holds their spans' windows
    # The classical A* of the paper (a baseline): the same graph, heuristic and timing, every node
    # and edge free at all times; the route is timed as if nothing moved (the caller checks it).
    ignore_time: bool = False


class _StageFailed(RobomaxError):
    pass


def staged_junction(ctx: JunctionContext, index: int, t_block: float, q_rest: FloatArray, waypoints: FloatArray,
                    kind: str, label: str, before: WeldEnd | None, after: WeldEnd | None, baseline: Sequence[Segment],
                    action_s: float, q_action: FloatArray | None, depth: int = 0) -> StagedJunction | NoRoute:
    """Junction `index` searched and timed with its dynamic obstacles' windows, starting at rest at
    q_rest at t_block; `baseline` is its timing without them (for the retract and approach times).
    q_action: the configuration of the action after it (None: the way home). The junction found may
    start after a wait at rest (`pre_wait`)."""
    retract_s = sum(s.duration for s in baseline if s.kind == "retract")
    approach_s = sum(s.duration for s in baseline if s.kind == "approach")
    # The goal is held for the approach, the action and the retract after it.
    tail_s = 2.0 * approach_s + action_s if q_action is not None else 0.0
    chains = [waypoints[1:-1]]
    if ctx.tcp is not None:
        p = fk_tcp(ctx.robot, waypoints[[0, -1]])[:, :3, 3]
        route = tcp_route(ctx.tcp, p[0], p[1], t_block + retract_s, ctx.max_wait)
        if not isinstance(route, NoRoute):
            followed = follow(ctx.robot, ctx.world, route, waypoints[0], waypoints[-1])
            if followed is not None:
                # Its points are close together (the arm follows the TCP's line); the search times
                # each edge from rest to rest, so only the corners it needs are kept: the last
                # point before a dynamic object, where it may wait, survives.
                chains.append(_compress(ctx, followed)[1:-1])
    graph, points = _graph(ctx, waypoints, q_action, tail_s, chains)
    start, goal = len(points) - 2, len(points) - 1
    found = timed_astar(graph, start, goal, t_block + retract_s, ctx.max_wait)
    if isinstance(found, NoRoute):
        return found
    held = found.steps[0].depart - found.steps[0].arrive
    if held > 1e-6:
        # It waits where the retract ends: the same wait at rest before the retract (the caller
        # checks the robot is not hit there), then the junction searched again from then. For a
        # door this is waiting at rest; a moving object may clear the way long before its last
        # window ends, which is when waiting at rest for it ends.
        if depth >= MAX_HELD_SEARCHES or not ctx.moving:
            return NoRoute("no_gain", "the route waits where the retract ends: no better than waiting at rest", 0)
        pre = ceil_ms(held)
        later = staged_junction(ctx, index, t_block + pre, q_rest, waypoints, kind, label, before, after, baseline,
                                action_s, q_action, depth + 1)
        return replace(later, pre_wait=pre + later.pre_wait) if isinstance(later, StagedJunction) else later
    try:
        return _timed(ctx, index, t_block, q_rest, found, points, kind, label, before, after, action_s, q_action)
    except RobomaxError as exc:             # a piece that cannot be timed (TimingError) or checked
        return NoRoute("timing", str(exc), found.expansions)


def _graph(ctx: JunctionContext, waypoints: FloatArray, q_action: FloatArray | None,
           tail_s: float, chains: list[FloatArray]) -> tuple[TimedGraph, FloatArray]:
    """Roadmap nodes, then the inner points of each chain (joint paths from start to goal whose
    straight moves are known to be statically free: the junction's own, the TCP route's), then
    start and goal."""
    roadmap = ctx.roadmap
    nodes = roadmap.nodes if roadmap is not None else np.zeros((0, waypoints.shape[1]))
    n_road = len(nodes)
    points = np.vstack([nodes, *chains, waypoints[:1], waypoints[-1:]])
    start, goal = len(points) - 2, len(points) - 1
    limits = ctx.robot.limits
    links: dict[int, set[int]] = {u: set() for u in (start, goal)}
    known_free: set[tuple[int, int]] = set()
    at = n_road
    for inner in chains:
        chain = [start, *range(at, at + len(inner)), goal]
        at += len(inner)
        for a, b in itertools.pairwise(chain):
            links.setdefault(a, set()).add(b)
            links.setdefault(b, set()).add(a)
            known_free.add((min(a, b), max(a, b)))
    links[start].add(goal)
    links[goal].add(start)
    ends: dict[int, list[int]] = {}
    if roadmap is not None:
        for end in (start, goal):
            for v in roadmap.nearest(points[end]):
                links[end].add(v)
                ends.setdefault(v, []).append(end)
    static: dict[tuple[int, int], bool] = {}
    dynamic: dict[tuple[int, int], frozenset[int]] = {}
    node_objs: dict[int, frozenset[int]] = {}

    def duration(u: int, v: int) -> float:
        return float(ptp_time_estimate(points[u], points[v], limits, ctx.speed))

    def neighbours(u: int) -> list[tuple[int, float]]:
        out = [(v, w / ctx.speed) for v, w in roadmap.neighbours(u)] if roadmap is not None and u < n_road else []
        return out + [(v, duration(u, v)) for v in sorted(links.get(u, ())) + ends.get(u, [])]

    def edge_windows(u: int, v: int) -> Windows | None:
        if ctx.ignore_time:
            return edge_static(u, v)
        return edge_timed(u, v)

    def edge_static(u: int, v: int) -> Windows | None:
        key = (min(u, v), max(u, v))
        if key not in static:
            if key in known_free:
                static[key] = True
            elif roadmap is not None and max(u, v) < n_road:
                static[key] = roadmap.edge_free(u, v)
            else:
                static[key] = ctx.world.check_segment(points[u], points[v]).free
        return () if static[key] else None

    def edge_timed(u: int, v: int) -> Windows | None:
        if edge_static(u, v) is None:
            return None
        key = (min(u, v), max(u, v))
        if key not in dynamic:
            dynamic[key] = ctx.conflicts.segment(points[u], points[v])
        return ctx.conflicts.windows_of(dynamic[key])

    def node_windows(u: int) -> Windows:
        if ctx.ignore_time:
            return ()
        if u == goal and q_action is not None:
            objs = ctx.conflicts.segment(points[goal], q_action)
            # Arriving at t holds the goal until t + tail: blocked from a window's start - tail.
            return merge_windows([(max(0.0, a - tail_s), b) for a, b in ctx.conflicts.windows_of(objs)])
        if u not in node_objs:
            node_objs[u] = ctx.conflicts.point(points[u])
        return ctx.conflicts.windows_of(node_objs[u])

    def heuristic(u: int) -> float:
        return float(ptp_time_estimate(points[u], points[goal], limits, ctx.speed, straight=False))

    return TimedGraph(neighbours, node_windows, edge_windows, heuristic), points


def _timed(ctx: JunctionContext, index: int, t_block: float, q_rest: FloatArray, route: TimedRoute, points: FloatArray,
           kind: str, label: str, before: WeldEnd | None, after: WeldEnd | None, action_s: float,
           q_action: FloatArray | None) -> StagedJunction:
    """The route timed piece by piece, split where it waits; each wait the shortest at rest."""
    nodes = [s.node for s in route.steps]
    cuts = [i for i, s in enumerate(route.steps) if 0 < i < len(nodes) - 1 and s.depart - s.arrive > 1e-6]
    bounds = [0, *cuts, len(nodes) - 1]
    # Rounded as the program states them, so the written program is exactly the motion timed.
    pieces = [as_written_joints(_shortcut(ctx, points[nodes[a:b + 1]]), ctx.robot.prismatic) for a, b in itertools.pairwise(bounds)]
    # One corner and one junction radius for every piece (the program states one per transition),
    # the largest that times and stays free in every piece; the pieces stop where they wait.
    for rj_deg, rd_deg in STAGED_RADII_DEG:
        timed = _pieces(ctx, index, t_block, q_rest, pieces, kind, label, before, after, action_s, q_action,
                        math.radians(rj_deg), math.radians(rd_deg))
        if timed is not None:
            break
    if timed is None:
        raise _StageFailed("the pieces cannot be timed")
    segments, stages, t, extension = timed
    waypoints = [pieces[0][0], *(q for piece in pieces for q in piece[1:])]
    if q_action is not None and not ctx.ignore_time:
        # The retract after the action leaves along the approach line: nothing may close on it then.
        t_out = t + action_s
        retract_s = sum(s.duration for s in segments if s.kind == "approach")
        objs = ctx.conflicts.segment(np.asarray(waypoints[-1]), np.asarray(q_action))
        if any(w0 <= t_out + retract_s and w1 >= t_out for w0, w1 in ctx.conflicts.windows_of(objs)):
            raise _StageFailed("a dynamic obstacle would close on the retract after the action")
    return StagedJunction(segments, np.array(waypoints), tuple(stages), math.radians(rj_deg),
                          math.radians(rd_deg), extension)


def _pieces(ctx: JunctionContext, index: int, t_block: float, q_rest: FloatArray, pieces: list[FloatArray], kind: str,
            label: str, before: WeldEnd | None, after: WeldEnd | None, action_s: float, q_action: FloatArray | None,
            rj: float, rd: float) -> tuple[list[Segment], list[Stage], float, Extension] | None:
    """The pieces timed with radii rj, rd, each wait the shortest at rest; None where one cannot be."""
    segments: list[Segment] = []
    stages: list[Stage] = []
    t = t_block
    q_now = np.asarray(q_rest, dtype=float)
    at = 0
    retract = Extension()
    for p, piece in enumerate(pieces):
        last = p == len(pieces) - 1
        junction = time_junction_at(ctx.robot, ctx.world, ctx.robot.limits, q_now, piece, kind, label,
                                    before if p == 0 else None, after if last else None, rj, rd,
                                    tcp_speed=ctx.tcp_speed, speed=ctx.speed, jerk_limited=ctx.jerk_limited)
        if junction is None:
            return None
        block = list(junction.segments)
        check = block + ([dwell(block[-1].q[-1], action_s, kind="weld", label="")] if last and q_action is not None
                         else [])
        if p > 0:
            try:
                w = wait_at_rest(ctx.dynamic_world, check, t, ctx.windows, index, ctx.doors, ctx.moving)
            except WaitingError:
                return None
            if w is not None:
                segments.append(dwell(q_now, w.seconds, kind="wait", label=f"wait for {w.obstacle}"))
                t += w.seconds
            # The pieces stop here (timed from rest to rest), waiting or not: a stage either way,
            # so the program stops here too instead of flying by.
            stages.append(Stage(at, w))
        elif not ctx.ignore_time and first_dynamic_hit(ctx.dynamic_world, check, t) is not None:
            return None                       # the first piece meets a dynamic obstacle as timed
        segments.extend(block)
        t += sum(s.duration for s in block)
        q_now = np.asarray(block[-1].q[-1], dtype=float)
        at += len(piece) - 1
        ext = junction.extension
        if p == 0:
            retract = Extension(ext.retract_T, ext.retract_q, None)
        if last:
            retract = Extension(retract.retract_T, retract.retract_q, ext.approach_q)
    return segments, stages, t, retract


def _compress(ctx: JunctionContext, path: FloatArray) -> FloatArray:
    """A dense joint path shortcut between the points where the set of dynamic objects it touches
    changes: those points (the last one clear of a door, the first one in its way) are kept."""
    touched = [ctx.conflicts.point(q) for q in path]
    keep = [0, *(i for i in range(1, len(path) - 1) if touched[i] != touched[i - 1] or touched[i] != touched[i + 1]),
            len(path) - 1]
    keep = sorted(set(keep))
    out = [path[:1]]
    for a, b in itertools.pairwise(keep):
        out.append(_shortcut(ctx, path[a:b + 1])[1:])
    return np.vstack(out)


def _shortcut(ctx: JunctionContext, piece: FloatArray) -> FloatArray:
    """Greedy: from each kept point to the farthest later one reachable by a straight move that is
    statically free and touches no dynamic obstacle the skipped edges did not touch already."""
    if len(piece) <= 2:
        return piece
    touched = [ctx.conflicts.segment(piece[i], piece[i + 1]) for i in range(len(piece) - 1)]

    def reachable(i: int, j: int) -> bool:
        return bool(ctx.world.check_segment(piece[i], piece[j]).free
                    and ctx.conflicts.segment(piece[i], piece[j]) <= frozenset().union(*touched[i:j]))

    kept = greedy_shortcut(len(piece), reachable)
    assert kept is not None                           # neighbours are not checked: always a path
    return piece[kept]
