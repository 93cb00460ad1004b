"""The chosen tour timed junction by junction (retract, move or detour, approach), dwells at the spots,
waits for dynamic obstacles; the spot plans as the program states them."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.candidates import SpotCandidates
from robomax_py.plan.junction import (
    JUNCTION_RADII_DEG,
    Junction,
    WeldEnd,
    time_junction,
)
from robomax_py.plan.loads import (
    MAX_TCP_RETIMES,
    LoadOverrides,
    Loads,
    tcp_block_peaks,
    tcp_limits_after,
)
from robomax_py.plan.poses import (
    OrientationGrid,
    approach_poses,
    orientation_grid,
    spot_poses,
)
from robomax_py.plan.program_frames import cell_program_frames
from robomax_py.plan.results import (
    Progress,
    ResolvedOptions,
    SpotPlan,
    Transition,
    _no_progress,
)
from robomax_py.plan.roadmap import Roadmap
from robomax_py.plan.sequence import HOME, Tour
from robomax_py.plan.spline_junction import SplineSettings, choose, spline_variant
from robomax_py.plan.spline_moves import CartesianChoice
from robomax_py.plan.tcp_route import TcpSpace, dynamic_boxes, tcp_space
from robomax_py.plan.timed_moves import (
    DynamicConflicts,
    JunctionContext,
    StagedJunction,
    staged_junction,
)
from robomax_py.plan.timed_search import NoRoute
from robomax_py.plan.waiting import (
    MAX_WAITS,
    TIME_STEP_S,
    Trapped,
    WaitingError,
    WaitPlan,
    ceil_ms,
    first_dynamic_hit,
    trapped,
    wait_at_rest,
)
from robomax_py.program import (
    as_written_joints,
    written_seconds,
    written_speed,
    written_tcp_speed,
)
from robomax_py.robot import RobotModel
from robomax_py.robot.solve import config_text
from robomax_py.spec import CellSpec
from robomax_py.timing import (
    Segment,
    Trajectory,
    concatenate,
    dwell,
    resample,
)
from robomax_py.transforms import invert
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene, clamps_near

# Junctions already timed for one tour, its transitions and options: junction k from a start
# configuration (its bytes), with fly-by or stopping at every corner. A junction starts at rest
# where the one before it ended, so a tour timed again with only some junctions changed (`exact`)
# times those alone: on a 240-spot cell each timing of the whole tour cost about 17 s.
JunctionMemo = dict[tuple[int, bool, bytes], tuple[list[Segment], Transition]]


def time_tour(
    cell: CellSpec, robot: RobotModel, world: CollisionWorld, spots: list[SpotCandidates], tour: Tour,
    transitions: list[Transition], options: ResolvedOptions, progress: Progress = _no_progress,
    roadmap: Roadmap | None = None, loads: Loads | None = None, exact: frozenset[int] = frozenset(),
    memo: JunctionMemo | None = None,
) -> tuple[Trajectory, list[SpotPlan], list[Transition]]:
    """Junction by junction (retract, move or detour, approach; `junction.time_junction`) and dwells.
    A junction carrying a part (`loads`) is checked with it and slowed to its limits. The junctions
    numbered in `exact` (k: the one into the tour's k-th spot) stop at every corner, without fly-by
    blends, whatever `options.blend` says. A `memo` given for the same tour, transitions and options
    (`blend` aside) keeps the junctions timed and is read before timing one again; not with dynamic
    objects, whose waits depend on the time a junction starts."""
    grids = [orientation_grid(seam) for seam in cell.seams]
    ends: list[WeldEnd] = []
    welded: list[tuple[int, int, FloatArray, FloatArray]] = []
    for i, a in zip(tour.order, tour.choice):
        end = weld_end(cell, spots[i], a, grids)
        ends.append(end)
        welded.append((i, a, end.T_spot, end.T_app))
    blocks: list[list[Segment]] = []
    timed: list[Transition] = []
    q_now = as_written_joints(cell.q_start, robot.prismatic)         # home, or where a continuation starts
    spec_of = [cell.seams[spots[i].seam_index].spots[spots[i].spot_index] for i in tour.order]
    weld_times = [written_seconds(cell.process.weld_time_of(spot)) for spot in spec_of]
    def junction_block(k: int, q_start: FloatArray) -> tuple[list[Segment], Transition]:
        """Junction k timed from q_start, and the action after it (from `memo` where it holds it)."""
        flyby = options.blend and k not in exact
        key = (k, flyby, np.asarray(q_start, dtype=float).tobytes())
        if memo is None or key not in memo:
            got = _junction_block(k, q_start, flyby)
            if memo is None:
                return got
            memo[key] = got
        block, trans = memo[key]
        return list(block), trans             # the caller's list: a memo's block is never edited

    def _junction_block(k: int, q_start: FloatArray, flyby: bool) -> tuple[list[Segment], Transition]:
        before = ends[k - 1] if k > 0 else None
        after = ends[k] if k < len(ends) else None
        waypoints = as_written_joints(transitions[k].waypoints, robot.prismatic)      # the first row: where the retract ends
        trans = replace(transitions[k], waypoints=waypoints)
        leaving = tour.order[k - 1] if k > 0 else HOME
        part = loads.part_after(leaving) if loads is not None else None
        checked = loads.world_after(leaving, world) if loads is not None else world
        speed = options.speed * (options.detour_speed if trans.kind == "detour" else 1.0)
        load = LoadOverrides.of(cell, robot, part, speed, options.tcp_speed * options.speed)
        lin_targets, lin_speed = _lines(cell, trans, after, part, options)

        choice: CartesianChoice | None = None

        def timed(load: LoadOverrides) -> Junction:
            nonlocal choice
            junction = time_junction(
                robot, checked, robot.limits, q_start, waypoints, trans.kind, trans.label, before, after,
                tcp_speed=load.tcp_speed, speed=load.speed, accel=load.accel, jerk_limited=options.jerk_limited,
                flyby=flyby, lin_targets=lin_targets, lin_speed=lin_speed,
            )
            # Splines join two spots in a static world: a junction timed around dynamic objects keeps
            # the motion its windows were searched for.
            if options.cartesian_moves != "spline" or before is None or after is None or trans.stages or cell.dynamic:
                return junction
            settings = _spline_settings(cell, part, options, load)
            variant = spline_variant(robot, checked, robot.limits, q_start, waypoints, trans.kind, trans.label,
                                     before, after, settings, lin_targets, sum(s.duration for s in junction.segments))
            # Only KUKA's controllers run a spline block (`Dialect.splines`); the others run its lines.
            junction, choice = choose(junction, variant, native=robot.controller.brand == "kuka")
            return junction

        junction = timed(load)
        tcp_limits = tcp_limits_after(cell, part)
        for _ in range(MAX_TCP_RETIMES if tcp_limits is not None else 0):
            assert tcp_limits is not None
            slower = load.slowed(tcp_block_peaks(robot, junction.segments), tcp_limits)
            if slower is None:
                break
            load = slower
            junction = timed(load)
        if part is not None or tcp_limits is not None:
            trans = replace(trans, part=part, speed=load.speed, accel=load.accel, tcp_speed=load.tcp_speed)
        block = list(junction.segments)
        if junction.spline is not None:
            moves = junction.spline
            configs = tuple(config_text(robot, q) for q in moves.q)
            trans = replace(trans, lin_targets=None, lin_configs=(), lin_speed=0.0,
                            spline=replace(moves, configs=configs))
        elif lin_targets is not None:
            # The lines as timed: the configuration each ends in, its configuration data.
            legs = [seg for seg in block if seg.kind == trans.kind]
            line_ends = np.array([seg.q[-1] for seg in legs])
            trans = replace(trans, waypoints=np.vstack([legs[0].q[0][None, :], line_ends]), lin_targets=lin_targets,
                            lin_configs=tuple(config_text(robot, q) for q in line_ends), lin_speed=lin_speed)
        ext = junction.extension
        if after is not None:
            block.append(dwell(block[-1].q[-1], weld_times[k], kind="weld", label=after.label))
        return block, replace(trans, blend_radius=junction.corner_radius, flyby_radius=junction.junction_radius,
                              retract_T=ext.retract_T, retract_q=ext.retract_q, approach_q=ext.approach_q,
                              choice=choice)

    for k in range(len(transitions)):
        progress("timing", k, len(transitions))
        block, trans = junction_block(k, q_now)
        timed.append(trans)
        blocks.append(block)
        q_now = block[-1].q[-1]
    if cell.dynamic:
        blocks, timed = _with_dynamic(cell, robot, world, roadmap, blocks, timed, ends, weld_times, options,
                                      junction_block)
    segments = [s for block in blocks for s in block]
    progress("timing", len(transitions), len(transitions))
    traj = resample(concatenate(segments))
    plans = []
    waits_for = interlocks(cell, [spots[i] for i in tour.order])
    # The retract of spot k ends where transition k + 1's fly-by continued it (or at its approach point).
    retract_q = [timed[k + 1].retract_q if k + 1 < len(timed) else None for k in range(len(welded))]
    for k, (i, a, T_spot, T_app) in enumerate(welded):
        c = spots[i]
        seam = cell.seams[c.seam_index]
        label = f"{seam.name}/{c.name}"
        phase = traj.phases_of("weld", label)[0]
        q_spot = np.asarray(traj.q[phase.i_start], dtype=float)
        # Each target states its own configuration: on ABB and FANUC arms J2 is often near 0 at
        # the spot and changes sign over the approach line.
        q_retract = retract_q[k]
        plans.append(SpotPlan(seam.name, c.name, c.angles[a], config_text(robot, c.q_spot[a]), q_spot,
                              as_written_joints(c.q_app[a], robot.prismatic), float(phase.t_start), float(phase.t_end), T_spot, T_app,
                              config_text(robot, q_retract if q_retract is not None else c.q_app[a]),
                              weld_times[k], cell.process.gun,
                              cell.process.schedule_of(spec_of[k]), waits_for[k], spec_of[k].action))
    return traj, plans, timed


def _spline_settings(cell: CellSpec, part: str | None, options: ResolvedOptions, load: LoadOverrides) -> SplineSettings:
    """A spline junction's speeds: the approach lines' as the junction's, the curve's lines at the
    detour line speed (override applied, within a carried part's limit), the cell's TCP limits."""
    limits = tcp_limits_after(cell, part)
    curve = written_tcp_speed(options.detour_tcp_speed * options.speed)
    if limits is not None and limits.v < curve:
        curve = math.floor(limits.v * 1000.0) / 1000.0
    return SplineSettings(load.tcp_speed, curve, load.accel, limits, options.jerk_limited)


def _lines(cell: CellSpec, trans: Transition, after: WeldEnd | None, part: str | None,
           options: ResolvedOptions) -> tuple[FloatArray | None, float]:
    """A detour of TCP lines: its targets as the program states them (the last the next approach
    point, `after.T_app`) and their TCP speed (m/s, as written, within a carried part's limit);
    (None, 0) for joint moves."""
    if trans.lin_targets is None:
        return None, 0.0
    targets = np.array(trans.lin_targets, dtype=float)
    if after is not None:
        targets[-1] = after.T_app
    speed = written_tcp_speed(options.detour_tcp_speed * options.speed)
    limits = tcp_limits_after(cell, part)
    if limits is not None and limits.v < speed:
        speed = math.floor(limits.v * 1000.0) / 1000.0
    return targets, speed


# A line continued for a fly-by gets this much more than the blend cuts in, and at most this (m).
EXTENSION_MARGIN = 1.25
MAX_EXTENSION_M = 0.1


def interlocks(cell: CellSpec, order: list[SpotCandidates]) -> list[tuple[str, ...]]:
    """Per spot in weld order, the clamp signals to wait for before moving to it: each clamp
    (an object with `signal`) before the first weld within `process.interlock_distance` of it."""
    out: list[tuple[str, ...]] = [() for _ in order]
    if not any(o.signal for o in cell.objects):
        return out
    waited: set[str] = set()
    for k, c in enumerate(order):
        for obj in clamps_near(cell, cell.seams[c.seam_index].spots[c.spot_index].xyz):
            if obj.name not in waited:
                waited.add(obj.name)
                out[k] = (*out[k], str(obj.signal))
    return out


def weld_end(cell: CellSpec, c: SpotCandidates, a: int, grids: list[OrientationGrid]) -> WeldEnd:
    """Candidate a of spot c as a junction end: its TCP poses at the spot and the approach point
    (robot base frame) as the program states them. Timed and checked rounded to the program's
    decimals, so the written program is exactly the motion checked (`rebuild` gives it back).
    grids: `orientation_grid` of every seam of the cell."""
    seam = cell.seams[c.seam_index]
    T_world = spot_poses((seam.spots[c.spot_index],), grids[c.seam_index])[0, c.orient[a]]
    # Rounded as the program states them: in its user frame (docs/cell-files.md, "Controller programs").
    frames = cell_program_frames(cell)
    T_spot = frames.written(invert(np.asarray(cell.T_world_base)) @ T_world)
    T_app = frames.written(approach_poses(T_spot, cell.process.approach))
    ext = approach_extension(cell.process.approach, c.q_spot[a], c.q_app[a], T_spot, T_app)
    T_ext = frames.written(approach_poses(T_spot, cell.process.approach + ext)) if ext > 0 else None
    return WeldEnd(T_spot, T_app, None, f"{seam.name}/{c.name}", T_ext)


def approach_extension(approach: float, q_spot: FloatArray, q_app: FloatArray, T_spot: FloatArray,
                       T_app: FloatArray) -> float:
    """How far (m) a line is continued beyond its approach point for the junction's fly-by: the
    TCP length the largest junction radius cuts into it (joint radius over the line's joint-to-TCP
    chord ratio), with a margin; 0 without an approach line."""
    tcp = float(np.linalg.norm(np.asarray(T_app)[:3, 3] - np.asarray(T_spot)[:3, 3]))
    joint = float(np.linalg.norm(np.asarray(q_app) - np.asarray(q_spot)))
    if approach <= 0.0 or tcp <= 0.0 or joint <= 0.0:
        return 0.0
    cut = np.deg2rad(max(JUNCTION_RADII_DEG)) * tcp / joint
    return float(min(EXTENSION_MARGIN * cut, MAX_EXTENSION_M))


def _tcp_space(cell: CellSpec, robot: RobotModel) -> TcpSpace:
    """The TCP's free voxels of the static cell, the dynamic objects' boxes marked with their windows."""
    static = build_scene(replace(cell, dynamic=()), robot)
    return tcp_space(static, robot, cell.process.clearance, dynamic_boxes(build_scene(cell, robot)))


def _with_dynamic(cell: CellSpec, robot: RobotModel, world: CollisionWorld, roadmap: Roadmap | None,
                  blocks: list[list[Segment]], timed: list[Transition], ends: list[WeldEnd], weld_times: list[float],
                  options: ResolvedOptions, retime: Callable[[int, FloatArray], tuple[list[Segment], Transition]],
                  ) -> tuple[list[list[Segment]], list[Transition]]:
    """The blocks in time order with their waits for the dynamic obstacles: at rest before a blocked
    junction (`planner.dynamic: rest`), or the time-aware junction (`timed_moves`) where it
    finishes sooner (`timed`, the default).

    A robot that would be trapped where a junction starts (a door closing on it while it waits at
    rest, in a machine it has just served) makes the junction before start later, after that
    door's window: it then enters in the next opening (`Trapped`, at most MAX_WAITS times)."""
    dynamic_scene = build_scene(replace(cell, objects=()), robot)
    dynamic_world = CollisionWorld(robot, dynamic_scene, cell.process.clearance)
    windows = {d.name: d.present if d.present is not None else ((0.0, float("inf")),) for d in cell.dynamic}
    # A moving object waits span by span (`world.moving`), not until its last window ends.
    moving = frozenset(d.name for d in cell.dynamic if d.motion is not None)
    windows |= {name: tuple(sorted(w for o in dynamic_scene.dynamic if o.name == name for w in o.present or ()))
                for name in moving}
    doors = frozenset(d.name for d in cell.dynamic if d.door)
    ctx = None if options.dynamic == "rest" else JunctionContext(
        robot, world, dynamic_world, DynamicConflicts(cell, robot), roadmap, windows, doors,
        tcp_speed=written_tcp_speed(options.tcp_speed * options.speed), speed=written_speed(options.speed),
        jerk_limited=options.jerk_limited, max_wait=cell.planner.max_wait, tcp=_tcp_space(cell, robot), moving=moving)
    out_blocks: list[list[Segment]] = []
    out_timed: list[Transition] = []
    starts: list[float] = []
    holds: dict[int, Trapped] = {}          # block -> what trapped the robot after it: start after its window
    k, t, backtracks = 0, 0.0, 0
    while k < len(blocks):
        block, trans = blocks[k], timed[k]
        if out_blocks and not np.array_equal(out_blocks[-1][-1].q[-1], block[0].q[0]):
            # A time-aware junction before ended its line at the spot a hair away (its own LIN
            # solution): this one is timed again from there, so the program states what was timed.
            block, trans = retime(k, np.asarray(out_blocks[-1][-1].q[-1]))
        hold = holds.get(k)
        pre = ceil_ms(hold.window_end - t) + TIME_STEP_S if hold is not None and hold.window_end >= t else 0.0
        # Held back here, the robot may itself be hit while it waits: then the block before starts later.
        caught = trapped(dynamic_world, np.asarray(block[0].q[0]), t, pre, windows, doors) if pre > 0 else None
        chosen = caught if caught is not None else _next_block(ctx, options, dynamic_world, windows, doors, k, t + pre,
                                                               block, trans, ends, weld_times, moving)
        if isinstance(chosen, WaitingError):
            if isinstance(chosen, Trapped) and k > 0 and backtracks < MAX_WAITS and math.isfinite(chosen.window_end):
                backtracks += 1
                k -= 1
                holds[k] = chosen
                t = starts[k]
                del out_blocks[k:], out_timed[k:], starts[k:]
                continue
            raise chosen
        new_block, new_trans = chosen
        if pre > 0:
            assert hold is not None
            waited = pre + (new_trans.wait.seconds if new_trans.wait is not None else 0.0)
            new_block = [dwell(block[0].q[0], pre, kind="wait", label=f"wait for {hold.obstacle}"), *new_block]
            new_trans = replace(new_trans, wait=WaitPlan(k, waited, hold.obstacle, False, hold.door))
        starts.append(t)
        out_blocks.append(new_block)
        out_timed.append(new_trans)
        t += sum(s.duration for s in new_block)
        k += 1
    return out_blocks, out_timed


def _next_block(ctx: JunctionContext | None, options: ResolvedOptions, dynamic_world: CollisionWorld,
                windows: dict[str, tuple[tuple[float, float], ...]], doors: frozenset[str], k: int, t: float,
                block: list[Segment], trans: Transition, ends: list[WeldEnd], weld_times: list[float],
                moving: frozenset[str] = frozenset()) -> tuple[list[Segment], Transition] | WaitingError:
    """Block k started at t: as it is, after a wait at rest, or time-aware (ctx given), whichever
    finishes first; the reason when none can."""
    try:
        rest = wait_at_rest(dynamic_world, block, t, windows, k, doors, moving)
        rest_error: WaitingError | None = None
    except WaitingError as exc:
        rest, rest_error = None, exc
    if rest is None and rest_error is None:
        return block, trans
    rest_end = math.inf if rest is None else t + rest.seconds + sum(s.duration for s in block)
    staged: StagedJunction | NoRoute | None = None
    if ctx is not None and options.dynamic == "astar" and trans.lin_targets is None:
        return _classical_block(ctx, options, dynamic_world, windows, doors, k, t, block, trans, ends, weld_times,
                                moving, rest, rest_error)
    # A detour of TCP lines keeps its lines and waits at rest: the time-aware search plans joint moves.
    if ctx is not None and trans.lin_targets is None:
        has_action = k < len(ends)
        speed = options.speed * (options.detour_speed if trans.kind == "detour" else 1.0)
        staged = staged_junction(
            replace(ctx, speed=written_speed(speed)), k, t, np.asarray(block[0].q[0]), trans.waypoints, trans.kind,
            trans.label, ends[k - 1] if k else None, ends[k] if has_action else None,
            block[:-1] if has_action else block, weld_times[k] if has_action else 0.0,
            np.asarray(block[-1].q[0]) if has_action else None)
        if isinstance(staged, StagedJunction) and staged.pre_wait > 0 and trapped(
                dynamic_world, np.asarray(block[0].q[0]), t, staged.pre_wait, windows, doors) is not None:
            staged = NoRoute("trapped", "the robot would be hit waiting at rest before it", 0)
        if isinstance(staged, StagedJunction):
            action = block[-1]
            new_block = staged.segments + ([dwell(staged.segments[-1].q[-1], action.duration, kind=action.kind,
                                                   label=action.label)] if has_action else [])
            pre = staged.pre_wait
            if t + pre + sum(s.duration for s in new_block) < rest_end - 1e-9:
                ext = staged.extension
                hit = first_dynamic_hit(dynamic_world, block, t) if pre > 0 else None
                wait = WaitPlan(k, pre, hit[0] if hit else "dynamic objects", False) if pre > 0 else trans.wait
                lead = [dwell(block[0].q[0], pre, kind="wait", label=f"wait for {wait.obstacle}")] \
                    if pre > 0 and wait is not None else []
                return ([*lead, *new_block], replace(trans, waypoints=staged.waypoints, stages=staged.stages,
                                                     blend_radius=staged.corner_radius,
                                                     flyby_radius=staged.junction_radius, retract_T=ext.retract_T,
                                                     retract_q=ext.retract_q, approach_q=ext.approach_q, wait=wait))
    if rest is not None:
        return ([dwell(block[0].q[0], rest.seconds, kind="wait", label=f"wait for {rest.obstacle}"), *block],
                replace(trans, wait=rest))
    assert rest_error is not None
    if staged is None or isinstance(rest_error, Trapped):
        return rest_error
    why = staged.detail if isinstance(staged, NoRoute) else "its way finishes no sooner"
    return WaitingError(f"{trans.label}: waiting at rest fails ({rest_error}), and so does the time-aware "
                              f"search ({why}): the schedule cannot be met")


def _classical_block(ctx: JunctionContext, options: ResolvedOptions, dynamic_world: CollisionWorld,
                     windows: dict[str, tuple[tuple[float, float], ...]], doors: frozenset[str], k: int, t: float,
                     block: list[Segment], trans: Transition, ends: list[WeldEnd], weld_times: list[float],
                     moving: frozenset[str], rest: WaitPlan | None, rest_error: WaitingError | None,
                     ) -> tuple[list[Segment], Transition] | WaitingError:
    """`planner.dynamic: astar`, the paper's classical A* as a baseline: a junction that meets a
    dynamic object takes the A* route over the same graph the time-aware search uses, time ignored;
    where that route meets a dynamic object at its time, the robot stops at rest before it until it
    is clear (`transition.wait`: each is one of the paper's dangerous situations). Without a route
    it waits at rest on its own path, as `rest` does."""
    has_action = k < len(ends)
    speed = options.speed * (options.detour_speed if trans.kind == "detour" else 1.0)
    staged = staged_junction(
        replace(ctx, speed=written_speed(speed), ignore_time=True), k, t, np.asarray(block[0].q[0]), trans.waypoints,
        trans.kind, trans.label, ends[k - 1] if k else None, ends[k] if has_action else None,
        block[:-1] if has_action else block, weld_times[k] if has_action else 0.0,
        np.asarray(block[-1].q[0]) if has_action else None)
    if isinstance(staged, StagedJunction):
        action = block[-1]
        routed = staged.segments + ([dwell(staged.segments[-1].q[-1], action.duration, kind=action.kind,
                                           label=action.label)] if has_action else [])
        ext = staged.extension
        new_trans = replace(trans, waypoints=staged.waypoints, stages=staged.stages, blend_radius=staged.corner_radius,
                            flyby_radius=staged.junction_radius, retract_T=ext.retract_T, retract_q=ext.retract_q,
                            approach_q=ext.approach_q)
        try:
            stop = wait_at_rest(dynamic_world, routed, t, windows, k, doors, moving)
        except WaitingError as exc:
            return exc
        if stop is None:
            return routed, new_trans
        return ([dwell(routed[0].q[0], stop.seconds, kind="wait", label=f"wait for {stop.obstacle}"), *routed],
                replace(new_trans, wait=stop))
    if rest is not None:
        return ([dwell(block[0].q[0], rest.seconds, kind="wait", label=f"wait for {rest.obstacle}"), *block],
                replace(trans, wait=rest))
    assert rest_error is not None
    return rest_error

