"""A station -> one plan per robot, coordinated on a shared clock for the makespan (no file I/O).

Stages: what each robot can weld (`reach`), a min-max assignment of spots to robots (`assign`), each
robot's spots planned by the single-robot planner (`plan.plan_cell` on the robot's cell narrowed
to its spots, with the candidates `reach` found), robot-robot collisions on the shared clock found
(`bodies`) and ordered by interlocks (`coordinate`); where the robot that ends last waits, another spot
order (`reorder`) kept when the makespan shortens; where the waits cost more than a different
assignment, the assignment searched again with the waits as costs, and the nearest-robot assignment,
each kept when the makespan shortens (the orders then searched again where its robots wait); and
where the station then ends at one robot's own cycle with no wait, spots moved from that robot to
others (`unload`), kept when the coordinated makespan shortens.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan import PlanOptions, PlanResult, plan_cell
from robomax_py.plan.pipeline import home_collision
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.spec_station import SpotKey, StationSpec, robot_view
from robomax_py.station.assign import Assignment, assign, nearest, side_prior
from robomax_py.station.bodies import (
    RobotBody,
    body_poses,
    clash_map,
    robot_body,
    sample_steps,
)
from robomax_py.station.bound import (
    LowerBound,
    SpotWork,
    half_line_time,
    lower_bound,
    spot_work,
)
from robomax_py.station.coordinate import Coordination, PairMap, Timeline, coordinate
from robomax_py.station.homes import homes_touching
from robomax_py.station.reach import RobotReach, cost_matrix, robot_reach, tour_legs
from robomax_py.station.reorder import (
    OrderChange,
    OrderSearch,
    improve_orders,
    most_gain,
    ordered_view,
)
from robomax_py.station.reorder import candidates as order_candidates
from robomax_py.station.unload import bottleneck, cycle_scales, tour_estimator, unloads
from robomax_py.station.zones import ZoneBox, meeting_box
from robomax_py.timing.trajectory import evaluate
from robomax_py.world.scene import build_scene

log = logging.getLogger(__name__)

Method = Literal["full", "minmax", "nearest"]
# Own-clock step of the coordination diagrams, s; the margin kept between robots grows with the
# distance a piece moves in half a step (`bodies.sample_step`), so a finer step waits less.
DIAGRAM_DT_S = 0.04
# Rounds of re-assignment with the waits as costs (method "full").
REASSIGN_ROUNDS = 2
# The min-max assignment's prior against robots crossing into each other's side: a spot costs a
# robot this many seconds per metre its base is farther from the spot than the nearest base of a
# robot that reaches it. Joint-space tour estimates alone cannot tell a robot's own side from its
# neighbour's (the legs between spots cost alike on both), and a tie broken the wrong way makes
# the two robots' whole tours cross (a generated 4-robot station did: every move of one in the
# other's way).
SIDE_PRIOR_S_PER_M = 0.5


@dataclass(frozen=True, slots=True)
class StationOptions:
    """method: "full" (min-max assignment, zone orders by look-ahead, another spot order where the
    robot that ends last waits, then re-assignment where waits cost more), "minmax" (min-max
    assignment, zone orders by look-ahead, neither of those), "nearest" (each spot to the nearest
    robot that reaches it, first come first served)."""

    method: Method = "full"
    dt: float = DIAGRAM_DT_S
    plan: PlanOptions = PlanOptions()


@dataclass(frozen=True, slots=True, eq=False)
class RobotPlan:
    """One robot's plan: its cell narrowed to its spots, and the single-robot plan of it (None when
    the robot welds nothing and stays home)."""

    robot: str
    cell: CellSpec
    model: RobotModel
    result: PlanResult | None

    @property
    def own_cycle(self) -> float:
        traj = None if self.result is None else self.result.trajectory
        return 0.0 if traj is None else traj.duration


@dataclass(frozen=True, slots=True, eq=False)
class StationPlan:
    station: str
    status: Literal["planned", "infeasible"]
    message: str
    robots: tuple[RobotPlan, ...]
    assignment: Assignment
    bound: LowerBound
    coordination: Coordination | None
    seconds: Mapping[str, float]
    margin: float = 0.0          # m kept between robots on the diagrams, at most (where both move fastest)
    rounds: int = 0              # re-assignments tried
    orders_tried: int = 0        # spot orders planned instead of waiting (`reorder`) and spot moves' trials (`unload`)
    orders_skipped: int = 0      # spot orders not planned: they could not gain enough (`reorder.most_gain`)
    order_changes: tuple[OrderChange, ...] = ()    # those kept, in order
    zones: tuple[ZoneBox | None, ...] = ()         # where each interlock's robots would meet (`zones`), in order

    @property
    def makespan(self) -> float:
        return np.inf if self.coordination is None else self.coordination.schedule.makespan


@dataclass(frozen=True, slots=True)
class _Made:
    """What one `plan_station` has made so far: each robot's plans by the spots they weld (planning
    is deterministic, so a robot given spots it was planned for before keeps that plan, in any
    re-assignment round), and the sampled motions (piece poses, half steps) and pair diagrams by the
    robot plans they are of (the diagram of two unchanged plans is the one already made)."""

    plans: dict[tuple[str, frozenset[SpotKey]], RobotPlan] = field(default_factory=dict)
    motion: dict[RobotPlan, tuple[FloatArray, FloatArray]] = field(default_factory=dict)
    pairs: dict[tuple[RobotPlan, RobotPlan], PairMap] = field(default_factory=dict)


# Spots named with their robots' reasons when no robot can weld them; the rest only counted.
NOBODY_LISTED = 10


def _nobody_message(nobody: Sequence[SpotKey], reaches: Sequence[RobotReach]) -> str:
    """The spots no robot can weld, each with every allowed robot's reason, as the single-robot
    planner states them (one spot a line)."""
    lines = [f"{len(nobody)} spot(s) no robot allowed to weld them can reach collision-free:"]
    for seam, name in nobody[:NOBODY_LISTED]:
        reasons = "; ".join(f"{r.robot}: {r.why.get((seam, name), 'no candidate')}" for r in reaches
                            if (seam, name) in r.unreachable)
        lines.append(f"  {seam}/{name}: {reasons}")
    if len(nobody) > NOBODY_LISTED:
        lines.append(f"  and {len(nobody) - NOBODY_LISTED} more")
    return "\n".join(lines)


def plan_station(station: StationSpec, models: Mapping[str, RobotModel],
                 options: StationOptions = StationOptions()) -> StationPlan:
    """Plan every robot of a station; `models[name]` is each robot's model with its tool mounted."""
    clock: dict[str, float] = {}
    t0 = time.process_time()
    reaches = [robot_reach(station, r.name, models[r.name]) for r in station.robots]
    clock["reach"] = time.process_time() - t0
    keys = [s.key for s in station.spots]
    groups = _ordered_groups(station)
    t0 = time.process_time()
    works = {r.name: spot_work(reach, half_line_time(r.cell, options.plan))
             for r, reach in zip(station.robots, reaches, strict=True)}
    bound = lower_bound(list(works.values()), keys, groups)
    clock["bound"] = time.process_time() - t0
    nobody = [k for k in keys if not any(k in r.index() for r in reaches)]
    if nobody:
        return StationPlan(station.name, "infeasible", _nobody_message(nobody, reaches), (), Assignment({}, {}), bound,
                           None, clock)
    t0 = time.process_time()
    scenes = {r.name: build_scene(r.cell, models[r.name]) for r in station.robots}
    blocked = next(((r.name, text) for r in station.robots if (text := home_collision(r.cell, models[r.name]))), None)
    if blocked is not None:
        clock["homes"] = time.process_time() - t0
        return StationPlan(station.name, "infeasible", f"{blocked[0]}: {blocked[1]}", (), Assignment({}, {}), bound,
                           None, clock)
    touching = homes_touching(station, models, scenes)
    clock["homes"] = time.process_time() - t0
    if touching is not None:
        return StationPlan(station.name, "infeasible", touching.message(), (), Assignment({}, {}), bound, None, clock)
    t0 = time.process_time()
    prior = side_prior(station, reaches, SIDE_PRIOR_S_PER_M)
    chosen = nearest(station, reaches, keys, groups) if options.method == "nearest" \
        else assign(reaches, keys, groups, prior)
    clock["assignment"] = time.process_time() - t0
    bodies = {r.name: robot_body(r.name, models[r.name], scenes[r.name]) for r in station.robots}
    made = _Made()
    by_robot = {r.robot: r for r in reaches}
    best = _realise(station, models, bodies, by_robot, chosen, options, clock, bound, made)
    if best.status != "planned":
        return best
    if options.method != "full":
        return dataclasses.replace(best, zones=_zones(best, bodies, made, station.clearance, options.dt))
    # Another spot order instead of waiting, where the robot that ends last waits; before the
    # re-assignment, whose new tours are each robot's own best again (on a generated station of four
    # KR 125-class arms the other way round ended 15 % later: 18.10 s against 15.79 s).
    ordered = [g for g in groups if len(g) > 1]
    robot_plans: dict[tuple[str, tuple[SpotKey, ...]], RobotPlan | None] = {}
    costs: dict[str, FloatArray] = {}

    def search_orders(start: StationPlan) -> OrderSearch[StationPlan]:
        return improve_orders(
            start, lambda p: p.makespan, _orders, lambda p: _order_candidates(p, ordered),
            lambda p, change: _with_orders(station, models, bodies, by_robot, p, (change,), options, clock, bound,
                                           made, robot_plans),
            lambda p, change: _most_gain(p, change, works), lambda p, change: _tour_growth(p, change, by_robot, costs))

    search = search_orders(best)
    best = search.best
    penalty: dict[tuple[str, SpotKey], float] = dict(prior)
    rounds = 0
    assignments = {_frozen(chosen)}
    for _ in range(REASSIGN_ROUNDS):
        assert best.coordination is not None
        if not best.coordination.interlocks or best.coordination.schedule.makespan <= 0:
            break
        _add_wait_costs(penalty, best)
        t0 = time.process_time()
        again = assign(reaches, keys, groups, penalty)
        clock["assignment"] += time.process_time() - t0
        if dict(again.spots) == dict(best.assignment.spots):
            break
        rounds += 1
        seen = _frozen(again)
        if seen in assignments:      # planned before and not kept: the same plans again
            continue
        assignments.add(seen)
        # The makespan is at least every robot's own cycle: a trial is given up as soon as one of its
        # robots, kept or planned again (longest estimate first), is no shorter than the best makespan.
        trial = _realise(station, models, bodies, by_robot, again, options, clock, bound, made,
                         beat=best.makespan - 1e-6)
        if trial.status == "planned" and trial.makespan < best.makespan - 1e-6:
            best = trial
    # The estimates above know nothing of the other robots, and the waits charged to the waiter's
    # spots cannot tell which robot crossed into the other's side. Where the best plan still has
    # interlocks, the nearest-robot assignment (each robot on its own side) is planned too and kept
    # when its coordinated makespan is shorter: on a hat section welded from both sides by two arms
    # set off along it, the min-max estimate gave each the far end of the other's flange (17.80 s,
    # 4 interlocks), each flange to its own robot ends at 11.31 s with none. It is not planned where
    # a robot's own cycle is predicted no shorter than the best makespan, as `unload` predicts one
    # (the shipped example's: 37.76 s against 38.48 s then, so planned, and not kept).
    assert best.coordination is not None
    if best.coordination.interlocks and best.coordination.schedule.makespan > 0:
        t0 = time.process_time()
        near = nearest(station, reaches, keys, groups)
        longest = _predicted_longest(best, near, tour_estimator(by_robot, prior, costs))
        clock["assignment"] += time.process_time() - t0
        log.debug("nearest-robot assignment: longest own cycle predicted %.3f s (best makespan %.3f s)", longest,
                  best.makespan)
        if _frozen(near) not in assignments and longest < best.makespan - 1e-6:
            assignments.add(_frozen(near))
            rounds += 1
            trial = _realise(station, models, bodies, by_robot, near, options, clock, bound, made,
                             beat=best.makespan - 1e-6)
            if trial.status == "planned" and trial.makespan < best.makespan - 1e-6:
                best = trial
    # A re-assignment that won plans each robot in its own best order again: the changes kept before
    # are not in its programs. Where its robots still wait, their orders are searched again.
    kept = search.kept if best is search.best else ()
    tried, skipped = search.tried, search.skipped
    assert best.coordination is not None
    if best is not search.best and best.coordination.interlocks:
        again_search = search_orders(best)
        best, kept = again_search.best, again_search.kept
        tried, skipped = tried + again_search.tried, skipped + again_search.skipped
    # Where the station now ends at one robot's own cycle with no wait, the waits charge nothing: spots
    # moved away from that robot instead, each trial judged with its interlocks.
    fixed = frozenset(k for g in ordered for k in g)
    best, moved, unloaded = _unload(station, models, bodies, by_robot, best, options, clock, bound, made, robot_plans,
                                    prior, fixed, costs)
    return dataclasses.replace(best, seconds=clock, rounds=rounds, orders_tried=tried + unloaded,
                               orders_skipped=skipped, order_changes=(*kept, *moved),
                               zones=_zones(best, bodies, made, station.clearance, options.dt))


def _predicted_longest(plan: StationPlan, other: Assignment,
                       tour_time: Callable[[str, tuple[SpotKey, ...]], float]) -> float:
    """The longest own cycle predicted for another assignment: each robot's planned own cycle scaled
    by its estimated tour there over its estimated tour now (a robot idle now: its estimate)."""
    now = _orders(plan)
    scale = cycle_scales(now, {p.robot: p.own_cycle for p in plan.robots}, tour_time)
    return max((scale.get(robot, 1.0) * tour_time(robot, tuple(spots)) for robot, spots in other.spots.items()),
               default=0.0)


def _zones(plan: StationPlan, bodies: Mapping[str, RobotBody], made: _Made, clearance: float,
           dt: float) -> tuple[ZoneBox | None, ...]:
    """Where each interlock's two robots would meet (`zones.meeting_box`), from their diagram (made
    at `clearance`, m, every dt of each robot's own clock)."""
    if plan.coordination is None:
        return ()
    by_name = {p.robot: p for p in plan.robots}
    out: list[ZoneBox | None] = []
    for lock in plan.coordination.interlocks:
        pa, pb = by_name[lock.pair[0]], by_name[lock.pair[1]]
        pair = made.pairs.get((pa, pb))
        if pair is None:
            out.append(None)
            continue
        (poses_a, half_a), (poses_b, half_b) = made.motion[pa], made.motion[pb]
        span_a, span_b = (lock.leader_span, lock.waiter_span) if lock.leader == pa.robot else \
            (lock.waiter_span, lock.leader_span)
        rows = _span_samples(span_a, dt, len(poses_a))
        cols = _span_samples(span_b, dt, len(poses_b))
        out.append(meeting_box(bodies[pa.robot], poses_a, rows, bodies[pb.robot], poses_b, cols, pair.clash,
                               clearance, half_a, half_b))
    return tuple(out)


def _span_samples(span: tuple[float, float], dt: float, count: int) -> slice:
    """The diagram's samples (every dt of the robot's own clock) within a time span, ends included."""
    first = max(0, min(count - 1, int(np.floor(span[0] / dt + 1e-9))))
    return slice(first, max(first + 1, min(count, int(np.ceil(span[1] / dt - 1e-9)) + 1)))


def _orders(plan: StationPlan) -> dict[str, tuple[SpotKey, ...]]:
    """Each robot's spots in its planned order."""
    return {p.robot: tuple((s.seam, s.name) for s in (p.result.spots if p.result else ())) for p in plan.robots}


def _order_candidates(plan: StationPlan, ordered: Sequence[Sequence[SpotKey]]) -> list[OrderChange]:
    assert plan.coordination is not None
    schedule = plan.coordination.schedule
    return order_candidates(_orders(plan), schedule.ends, schedule.waits, plan.coordination.interlocks, ordered)


def _most_gain(plan: StationPlan, change: OrderChange, works: Mapping[str, SpotWork]) -> float:
    """The most `change` can shorten the plan's makespan (`reorder.most_gain`), the re-planned robot's
    own cycle taken at least its tour's lower bound (`bound.SpotWork.tour_bound`)."""
    own = {p.robot: p.own_cycle for p in plan.robots}
    return most_gain(plan.makespan, own, change.robot, works[change.robot].tour_bound(change.order))


def _tour_growth(plan: StationPlan, change: OrderChange, reaches: Mapping[str, RobotReach],
                 costs: dict[str, FloatArray]) -> float:
    """How much longer `change.robot`'s tour is estimated in `change.order` than in its planned
    order, s (the assignment's leg estimate, `reach.cost_matrix`, made once per robot in `costs`)."""
    reach = reaches[change.robot]
    if change.robot not in costs:
        costs[change.robot] = cost_matrix(reach)
    cost = costs[change.robot]
    return tour_legs(reach, cost, change.order) - tour_legs(reach, cost, _orders(plan)[change.robot])


def _with_orders(station: StationSpec, models: Mapping[str, RobotModel], bodies: Mapping[str, RobotBody],
                 reaches: Mapping[str, RobotReach], plan: StationPlan, changes: Sequence[OrderChange],
                 options: StationOptions, clock: dict[str, float], bound: LowerBound, made: _Made,
                 known: dict[tuple[str, tuple[SpotKey, ...]], RobotPlan | None], beat: float = np.inf
                 ) -> StationPlan | None:
    """The station with each change's robot planned in its order (the published method's given order;
    `known` holds the robots planned so, by order) and coordinated again; None where one of those
    robots or the station does not plan, or as soon as one of them has an own cycle no shorter than
    `beat` (the makespan is at least every robot's own cycle): the robots planned so before first, so
    that a trial sharing such a robot with one tried before costs nothing. A change may give a robot
    other spots than `plan`'s."""
    mine: dict[str, RobotPlan] = {}
    for change in sorted(changes, key=lambda c: (c.robot, c.order) not in known):
        key = (change.robot, change.order)
        if key not in known:
            t0 = time.process_time()
            model = models[change.robot]
            cell = station.robot(change.robot).cell
            # With the candidates the robot's reach found, as its own order is planned: a candidate depends
            # on its spot, seam settings, objects and home only, not on the order
            # (tests/station/test_reach_candidates.py).
            result = plan_cell(ordered_view(cell, change.order), model,
                               dataclasses.replace(options.plan, given_order=True),
                               known=reaches[change.robot].candidates) if change.order else None
            clock["robots"] = clock.get("robots", 0.0) + time.process_time() - t0
            # The program is proven against the robot's cell as its programs are read (file order).
            known[key] = RobotPlan(change.robot, robot_view(station, change.robot, change.order), model, result) \
                if result is None or result.status == "planned" else None
        got = known[key]
        if got is None or got.own_cycle >= beat:
            return None
        mine[change.robot] = got
    # The other robots keep the plans of `plan` (with any order change kept before), not only the
    # plans made for their spots.
    # An order change keeps the assignment; a change of spots is the assignment's too.
    moved = any(set(c.order) != set(plan.assignment.spots.get(c.robot, ())) for c in changes)
    chosen = Assignment({**plan.assignment.spots, **{c.robot: c.order for c in changes}},
                        plan.assignment.estimate) if moved else plan.assignment
    trial = _realise(station, models, bodies, reaches, chosen, options, clock, bound, made,
                     given={**{p.robot: p for p in plan.robots}, **mine})
    return trial if trial.status == "planned" else None


def _unload(station: StationSpec, models: Mapping[str, RobotModel], bodies: Mapping[str, RobotBody],
            reaches: Mapping[str, RobotReach], plan: StationPlan, options: StationOptions,
            clock: dict[str, float], bound: LowerBound, made: _Made,
            known: dict[tuple[str, tuple[SpotKey, ...]], RobotPlan | None], prior: Mapping[tuple[str, SpotKey], float],
            fixed: frozenset[SpotKey], costs: dict[str, FloatArray]) -> tuple[StationPlan, tuple[OrderChange, ...], int]:
    """Where the station ends at one robot's own cycle with no wait, spots moved from that robot to
    others that reach them (`unload`), each trial judged by its coordinated makespan: the best plan,
    the order changes that make it (none when no trial is shorter), the trials planned."""
    assert plan.coordination is not None
    own = {p.robot: p.own_cycle for p in plan.robots}
    giver = bottleneck(own, plan.coordination.schedule.ends)
    if giver is None:
        return plan, (), 0

    able: dict[SpotKey, list[str]] = {}
    for reach in reaches.values():
        for k in reach.keys:
            able.setdefault(k, []).append(reach.robot)
    tried = 0
    for trial in unloads(_orders(plan), own, giver, able, tour_estimator(reaches, prior, costs), fixed):
        if trial.predicted >= plan.makespan - 1e-6:
            continue
        tried += 1
        # The takers first: a spot inserted where the estimate puts it is likelier to cost a detour the
        # prediction does not know than a spot taken out, and a trial is given up at the first robot
        # no shorter than the best makespan.
        takers_first = sorted(trial.orders.items(), key=lambda item: item[0] == giver)
        changes = tuple(OrderChange(r, o, trial.why[r]) for r, o in takers_first)
        got = _with_orders(station, models, bodies, reaches, plan, changes, options, clock, bound, made, known,
                           beat=plan.makespan - 1e-6)
        log.debug("unload %s: makespan %s (best %.3f s, predicted %.3f s), own cycles %s", trial.why[giver],
                  "not planned" if got is None else f"{got.makespan:.3f} s", plan.makespan, trial.predicted,
                  "" if got is None else ", ".join(f"{p.robot} {p.own_cycle:.3f} s" for p in got.robots))
        if got is not None and got.makespan < plan.makespan - 1e-6:
            # The first trial that shortens the makespan is kept: each costs two or three robots' plans.
            return got, changes, tried
    return plan, (), tried


def _frozen(chosen: Assignment) -> frozenset[tuple[str, frozenset[SpotKey]]]:
    """An assignment as which robot welds which spots (its order aside)."""
    return frozenset((r, frozenset(spots)) for r, spots in chosen.spots.items())


def _ordered_groups(station: StationSpec) -> list[tuple[SpotKey, ...]]:
    """An ordered seam's spots go to one robot together (its order is one robot's)."""
    cell = station.robots[0].cell
    return [tuple((seam.name, s.name) for s in seam.spots) for seam in cell.seams if seam.ordered]


def _realise(station: StationSpec, models: Mapping[str, RobotModel], bodies: Mapping[str, RobotBody],
             reaches: Mapping[str, RobotReach], chosen: Assignment, options: StationOptions,
             clock: dict[str, float], bound: LowerBound, made: _Made, beat: float = np.inf,
             given: Mapping[str, RobotPlan] | None = None) -> StationPlan:
    """Plan each robot's spots (`given`: robots planned already, kept as they are; a robot given spots
    it was planned for before keeps that plan; the candidates are those its reach found), then
    coordinate the robots. `beat`: given up (status "infeasible") when a robot's own cycle reaches
    it, the station's makespan then being no shorter."""
    t0 = time.process_time()
    kept: dict[str, RobotPlan] = {}
    todo = []
    for r in station.robots:
        if given and r.name in given:
            kept[r.name] = given[r.name]
            continue
        old = made.plans.get((r.name, frozenset(chosen.spots.get(r.name, ()))))
        if old is not None:
            kept[r.name] = old
        else:
            todo.append(r.name)
    planned: dict[str, RobotPlan] = {}
    longest = max(kept.values(), key=lambda p: p.own_cycle, default=None)
    if longest is not None and longest.own_cycle >= beat:
        return StationPlan(station.name, "infeasible", f"{longest.robot}'s own cycle {longest.own_cycle:.2f} s, kept, "
                           f"is no shorter than {beat:.2f} s", tuple(kept.values()), chosen, bound, None, clock)
    for name in todo if beat == np.inf else sorted(todo, key=lambda n: -chosen.estimate.get(n, 0.0)):
        spots = chosen.spots.get(name, ())
        cell = robot_view(station, name, spots)
        t1 = time.process_time()
        result = plan_cell(cell, models[name], options.plan, known=reaches[name].candidates) if spots else None
        plan = RobotPlan(name, cell, models[name], result)
        log.debug("%s: %d spots planned in %.1f s CPU, own cycle %.2f s (to beat: %.2f s)", name, len(spots),
                  time.process_time() - t1, plan.own_cycle, beat)
        message = f"{name}: {result.message}" if result is not None and result.status != "planned" else \
            f"{name}'s own cycle {plan.own_cycle:.2f} s is no shorter than {beat:.2f} s" if plan.own_cycle >= beat else ""
        if message:
            clock["robots"] = clock.get("robots", 0.0) + time.process_time() - t0
            so_far = tuple(p for r in station.robots if (p := kept.get(r.name) or planned.get(r.name)) is not None)
            return StationPlan(station.name, "infeasible", message, so_far, chosen, bound, None, clock)
        planned[name] = made.plans[(name, frozenset(spots))] = plan
    plans = [kept.get(r.name) or planned[r.name] for r in station.robots]
    clock["robots"] = clock.get("robots", 0.0) + time.process_time() - t0
    t0 = time.process_time()
    timelines = [_timeline(p) for p in plans]
    pairs, margin = _diagrams(plans, bodies, made, station.clearance, options.dt)
    clock["clash maps"] = clock.get("clash maps", 0.0) + time.process_time() - t0
    t0 = time.process_time()
    done = coordinate(timelines, pairs, fcfs=options.method == "nearest")
    clock["coordination"] = clock.get("coordination", 0.0) + time.process_time() - t0
    status: Literal["planned", "infeasible"] = "infeasible" if done.unresolved else "planned"
    return StationPlan(station.name, status, done.unresolved or "planned", tuple(plans), chosen, bound, done, clock,
                       margin=margin)


def _diagrams(plans: Sequence[RobotPlan], bodies: Mapping[str, RobotBody], made: _Made, clearance: float,
              dt: float) -> tuple[list[PairMap], float]:
    """Every pair's diagram, sampled every dt of each robot's own clock (one made before for the same
    two plans is taken from `made`), and the largest margin kept between two robots, m."""
    for p in plans:
        if p not in made.motion:
            poses = body_poses(bodies[p.robot], _samples(p, dt))
            # Each sample stands for the motion half a step either side of it: the margin there grows
            # by half the farthest any point moves to its neighbours (slow near welds, fast between).
            made.motion[p] = (poses, sample_steps(bodies[p.robot], poses) / 2)
    pairs = []
    margin = 0.0
    for i, pa in enumerate(plans):
        for pb in plans[i + 1:]:
            (poses_a, half_a), (poses_b, half_b) = made.motion[pa], made.motion[pb]
            margin = max(margin, clearance + float(half_a.max(initial=0.0)) + float(half_b.max(initial=0.0)))
            if (pa, pb) not in made.pairs:
                a, b = pa.robot, pb.robot
                made.pairs[(pa, pb)] = PairMap(a, b, dt, clash_map(bodies[a], poses_a, bodies[b], poses_b, clearance,
                                                                   slack_a=half_a, slack_b=half_b))
            pairs.append(made.pairs[(pa, pb)])
    return pairs, margin


def _timeline(p: RobotPlan) -> Timeline:
    if p.result is None or p.result.trajectory is None:
        return Timeline(p.robot, 0.0, (0.0,), (0.0,))
    t0 = float(p.result.trajectory.t[0])
    leave = tuple(s.t_leave - t0 for s in p.result.spots)
    end = p.result.trajectory.duration
    return Timeline(p.robot, end, (0.0, *leave), (*leave, end),
                    ("home", *(f"{s.seam}/{s.name}" for s in p.result.spots), "home"))


def _samples(p: RobotPlan, dt: float) -> np.ndarray:
    """(k, n) joint values every dt of the robot's own clock, to its end (home alone when idle)."""
    traj = None if p.result is None else p.result.trajectory
    if traj is None:
        return np.asarray(p.cell.home, dtype=float)[None, :]
    t = float(traj.t[0]) + np.arange(0.0, traj.duration + dt, dt)
    t = np.minimum(t, float(traj.t[-1]))
    return np.asarray(evaluate(traj, t).q)


def _add_wait_costs(penalty: dict[tuple[str, SpotKey], float], plan: StationPlan) -> None:
    """Each wait charged to the waiter's spots inside the zone it waited for (the spot after the
    wait point when none is inside), so that the next assignment weighs them with the wait."""
    assert plan.coordination is not None
    waits = {r: dict(w) for r, w in plan.coordination.schedule.waits.items()}
    for lock in plan.coordination.interlocks:
        w = waits.get(lock.waiter, {}).get(lock.wait_at, 0.0)
        if w <= 0:
            continue
        rp = next(p for p in plan.robots if p.robot == lock.waiter)
        if rp.result is None or rp.result.trajectory is None:
            continue
        t0 = float(rp.result.trajectory.t[0])
        inside = [s for s in rp.result.spots if lock.waiter_span[0] <= s.t_arrive - t0 <= lock.waiter_span[1]]
        after = [s for s in rp.result.spots if s.t_arrive - t0 >= lock.wait_at][:1]
        for s in inside or after:
            key = (lock.waiter, (s.seam, s.name))
            penalty[key] = penalty.get(key, 0.0) + w / max(len(inside or after), 1)
