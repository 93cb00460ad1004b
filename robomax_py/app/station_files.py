"""A planned station -> its files: per robot `<station>_<robot>.<ext>` programs in the requested
dialects with the interlocks stated (each proven as a lone program is, the waits for other robots
taking no time there) and `<station>_<robot>.json` (its own motion, with its waits on the shared
clock), and `<station>.station.json`: robots, assignment, interlocks, makespan, lower bound."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Sequence
from typing import Any

from robomax_py.export.dialect import NumberedSignal, PlannedProgram, setup_signals
from robomax_py.plan import PlanResult
from robomax_py.program import Comment, Instruction, PtpMove, SetSignal, Spot, WaitFor
from robomax_py.spec_station import StationRobot
from robomax_py.station.interlocks import StationInterlock, allocate, with_interlock_io
from robomax_py.station.pipeline import StationPlan
from robomax_py.station.zones import ZoneBox

STATION_FORMAT = "robomax.station/1"
# An own-clock time of the plan and the same time read back from a spot's leave time agree this well.
SAME_TIME_S = 1e-6


def station_signals(index: int, robot: StationRobot) -> tuple[NumberedSignal, ...]:
    """The input and output numbers the station file gives robot `index` (robots[index]): its
    controller's signals, and both ends of the ranges it lends to interlocks (the planner may
    allocate any number of them)."""
    prefix = f"robots[{index}].controller"
    io = f"{prefix}.interlock_io"
    ends = (NumberedSignal(f"{io}.inputs", "input", robot.interlock_inputs.first),
            NumberedSignal(f"{io}.inputs", "input", robot.interlock_inputs.last),
            NumberedSignal(f"{io}.outputs", "output", robot.interlock_outputs.first),
            NumberedSignal(f"{io}.outputs", "output", robot.interlock_outputs.last))
    return (*setup_signals(robot.cell.controller, prefix), *ends)


def interlock_edit(robot: str, result: PlanResult, interlocks: Sequence[StationInterlock]
                   ) -> Callable[[PlannedProgram], PlannedProgram]:
    """The change to a robot's program that states its interlocks: its outputs switched off after
    the first move home, each SetSignal after the weld where it has left its zone (or at the end),
    each WaitFor after the weld (or the first move home) before the zone it waits for; a signal set
    at a point comes before a wait there, so two robots never wait on each other at one point."""
    traj = result.trajectory
    assert traj is not None
    t0 = float(traj.t[0])
    leave = [s.t_leave - t0 for s in result.spots]

    def point(at: float) -> int:
        """-1: home at the start; k: after spot k's weld; len(spots): the end."""
        if at <= SAME_TIME_S:
            return -1
        k = next((k for k, t in enumerate(leave) if abs(t - at) <= SAME_TIME_S), None)
        return len(leave) if k is None else k

    at_point: dict[int, list[Instruction]] = {}
    mine = [x for x in interlocks if robot in (x.leader, x.waiter)]
    for x in mine:
        if x.leader == robot:
            at_point.setdefault(point(x.signal_at), []).extend(
                [Comment(f"{x.zone} left: {x.waiter} may enter"), SetSignal(x.signal, x.output, True)])
    for x in mine:
        if x.waiter == robot:
            at_point.setdefault(point(x.wait_at), []).extend(
                [Comment(f"wait until {x.leader} has left {x.zone}"), WaitFor(x.signal, x.input)])
    resets: list[Instruction] = [SetSignal(x.signal, x.output, False) for x in mine if x.leader == robot]

    def edit(planned: PlannedProgram) -> PlannedProgram:
        out: list[Instruction] = []
        joints = []
        spot = -1
        first_move = True
        for ins, q in zip(planned.program.instructions, planned.joints, strict=True):
            out.append(ins)
            joints.append(q)
            added: list[Instruction] = []
            if isinstance(ins, PtpMove) and first_move:
                first_move = False
                added = [*([Comment("interlock outputs off at the start of the cycle")] if resets else []), *resets,
                         *at_point.get(-1, [])]
            elif isinstance(ins, Spot):
                spot += 1
                added = at_point.get(spot, [])
            out.extend(added)
            joints.extend(q for _ in added)
        end = at_point.get(len(leave), [])
        out.extend(end)
        joints.extend(planned.joints[-1] for _ in end)
        program = dataclasses.replace(planned.program, instructions=tuple(out))
        return dataclasses.replace(planned, program=program, joints=tuple(joints))

    return edit


def station_block(plan: StationPlan, robot: str) -> dict[str, Any]:
    """What a robot's trajectory file adds for the station: the shared clock's start of its motion
    and its waits on that clock (own time of the wait point, seconds waited)."""
    assert plan.coordination is not None
    schedule = plan.coordination.schedule
    return {"name": plan.station, "robot": robot, "start": 0.0,
            "waits": [{"at": round(at, 6), "seconds": round(w, 6)} for at, w in schedule.waits[robot]],
            "end": round(schedule.ends[robot], 6), "makespan": round(schedule.makespan, 6)}


def with_station_block(text: str, block: dict[str, Any]) -> str:
    """The trajectory file's text with its `station` key, after `cycle_time`."""
    return text.replace('\n  "t": [', f'\n  "station": {json.dumps(block)},\n  "t": [', 1)


def station_summary(plan: StationPlan, interlocks: Sequence[StationInterlock]) -> str:
    """`<station>.station.json`."""
    assert plan.coordination is not None
    schedule = plan.coordination.schedule
    makespan = schedule.makespan
    robots = []
    for p in plan.robots:
        end = schedule.ends[p.robot]
        robots.append({
            "name": p.robot, "model": p.cell.robot.name, "brand": p.cell.robot.controller.brand,
            "spots": [f"{s.seam}/{s.name}" for s in (p.result.spots if p.result else ())],
            "own_cycle": round(p.own_cycle, 6), "waits": round(schedule.waited(p.robot), 6), "end": round(end, 6),
            "idle_share": round((makespan - p.own_cycle) / makespan, 6) if makespan > 0 else 0.0})
    bound = plan.bound.value
    data = {
        "format": STATION_FORMAT, "station": plan.station, "makespan": round(makespan, 6),
        "lower_bound": {"value": round(bound, 6), "single_spot_round_trip": round(plan.bound.single, 6),
                        "shared_work": round(plan.bound.shared, 6),
                        "partition": round(plan.bound.partition, 6),
                        "gap": round((makespan - bound) / makespan, 6) if makespan > 0 else 0.0},
        "robots": robots,
        "interlocks": [{"zone": x.zone, "leader": x.leader, "waiter": x.waiter, "signal": x.signal,
                        "leader_output": x.output, "waiter_input": x.input, "signal_at": round(x.signal_at, 6),
                        "wait_at": round(x.wait_at, 6), "leader_span": [round(v, 6) for v in x.leader_span],
                        "waiter_span": [round(v, 6) for v in x.waiter_span],
                        **({} if box is None else {"region": {"min": [round(v, 6) for v in box.lo],
                                                              "max": [round(v, 6) for v in box.hi]}})}
                       for x, box in zip(interlocks, _regions(plan, len(interlocks)), strict=True)],
        "robot_margin_m": round(plan.margin, 6), "reassignments": plan.rounds,
        "orders_tried": plan.orders_tried, "orders_skipped": plan.orders_skipped,
        "order_changes": [{"robot": c.robot, "spots": [f"{seam}/{name}" for seam, name in c.order], "why": c.why}
                          for c in plan.order_changes],
    }
    return json.dumps(data, indent=2) + "\n"


def _regions(plan: StationPlan, count: int) -> tuple[ZoneBox | None, ...]:
    """Each interlock's meeting box, in the interlocks' order (none where the plan has not got them)."""
    return plan.zones if len(plan.zones) == count else (None,) * count


__all__ = ["allocate", "interlock_edit", "station_block", "station_summary", "with_interlock_io",
           "with_station_block"]
