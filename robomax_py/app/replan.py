"""`robomax replan`: a running program's continuation after the cell changed (a door late, an
object in the way), planned from where the robot can stop (`plan.replan`), with the events
applied (`io.replan_events`).

The program's planned motion is read back as `robomax verify` reads it (a trajectory file, or any
dialect's program rebuilt from its statements); the motion up to the stop is checked against the
changed cell at its times, the rest of the work planned in the continuation's cell (`cell.start`
the stop configuration, windows in the continuation's clock), and its files proven before any is
written (`publish`), as every plan's are.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from robomax_py.errors import ProgramError
from robomax_py.io.cell_continuation import continued, spot_label
from robomax_py.io.continuation_file import ContinuationText, continuation_cell_text
from robomax_py.io.replan_events import Event, apply_events, parse_event
from robomax_py.plan import PlanOptions, PlanResult, plan_cell
from robomax_py.plan.replan import Action, ReplanInputError, Stop, stop_at
from robomax_py.program import as_written_joints
from robomax_py.robot import RobotModel, prismatic_mask
from robomax_py.spec import CellSpec
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.motion import check_motion
from robomax_py.world.scene import build_scene

__all__ = ["PlannedMotion", "ReplanOutcome", "continuation_cell", "continuation_file", "continuation_name", "planned_motion",
           "replan"]


@dataclass(frozen=True, slots=True, eq=False)
class PlannedMotion:
    """A program's planned motion: t (k,) s, q (k, n) rad, linear between samples; its actions."""

    t: np.ndarray
    q: np.ndarray
    actions: tuple[Action, ...]


@dataclass(frozen=True, slots=True, eq=False)
class ReplanOutcome:
    """What `replan` found.

    status : "planned" (result holds the continuation) or "infeasible" (message says why).
    stop : where the robot comes to rest (program clock).
    left : the actions still to do, `seam/name`, in the original program's order.
    old_finish : s, the original program's end (program clock).
    new_finish : s, the stop plus the continuation's cycle (program clock); None when infeasible.
    cell : the continuation's cell (events applied, its clock from the stop).
    as_it_stands : the program itself run on in the changed cell (its `WAIT FOR <door>_open`
        statements holding until a late door opens): (clean, finish s, first violation); None for
        a trajectory file, whose waits are fixed times.
    """

    status: Literal["planned", "infeasible"]
    message: str
    name: str
    events: tuple[Event, ...]
    stop: Stop
    left: tuple[str, ...]
    old_finish: float
    new_finish: float | None
    result: PlanResult | None
    cell: CellSpec | None
    seconds: float
    as_it_stands: tuple[bool, float, str] | None = None


def continuation_name(cell: CellSpec, at: float) -> str:
    """`<cell>_from_<T>`, T in s with its decimals joined by `_` (a dot would read as a suffix)."""
    return f"{cell.name}_from_{f'{at:.3f}'.rstrip('0').rstrip('.').replace('.', '_')}"


def planned_motion(cell: CellSpec, robot: RobotModel, path: Path) -> PlannedMotion:
    """The planned motion of a program robomax wrote for the cell: a trajectory file (.json) read,
    a dialect's program rebuilt from its statements (as `robomax verify` does)."""
    if path.suffix.lower() == ".json":
        from robomax_py.export.trajectory_json import load_trajectory_file

        data = load_trajectory_file(path, robot)
        if data.get("cell") not in (None, cell.name):
            raise ProgramError(path, "cell", f"a program of cell {data.get('cell')!r}, not of {cell.name!r}")
        t, q, spots = np.asarray(data["t"]), np.asarray(data["q"]), data["spots"]
    else:
        from robomax_py.export import controller_rebuild
        from robomax_py.verify import read_program

        dialect, main, parsed = read_program(robot, path)
        rebuilt = controller_rebuild(dialect, cell, robot, main, parsed)
        if rebuilt.trajectory is None:
            p = rebuilt.problems[0] if rebuilt.problems else None
            raise ProgramError(path, None if p is None or p.line is None else f"line {p.line}",
                               f"its motion cannot be rebuilt: {p.detail if p else 'no motion'}")
        t, q, spots = np.asarray(rebuilt.trajectory.t), np.asarray(rebuilt.trajectory.q), rebuilt.spots
    known = {(seam.name, s.name) for seam in cell.seams for s in seam.spots}
    actions = []
    for k, s in enumerate(spots):
        try:
            a = Action(str(s["seam"]), str(s["name"]), float(s["t_arrive"]), float(s["t_leave"]))
        except (KeyError, TypeError, ValueError):
            raise ProgramError(path, f"spots[{k}]", "expected seam, name, t_arrive and t_leave") from None
        if (a.seam, a.name) not in known or not (math.isfinite(a.t_arrive) and a.t_arrive <= a.t_leave):
            raise ProgramError(path, f"spots[{k}]", f"{a.label} is not a stop of cell {cell.name} "
                                                     "(or its times are not in order)")
        actions.append(a)
    return PlannedMotion(t, q, tuple(actions))


def replan(cell: CellSpec, robot: RobotModel, program: Path, at: float, events: tuple[str, ...],
           options: PlanOptions = PlanOptions(), compare: bool = True) -> ReplanOutcome:
    """The continuation of `program` (for `cell`) asked for at `at` s after the changes `events`
    (`io.replan_events` grammar). Bad input raises (EventError, ProgramError, ReplanInputError);
    an infeasible continuation is an outcome, its message naming the cause. With `compare`, the
    program as it stands is also run on in the changed cell (`ReplanOutcome.as_it_stands`)."""
    t0 = time.process_time()
    if cell.parts:
        raise ReplanInputError("pick-and-place cells are not replanned (a part held at the stop is not modelled)")
    parsed = tuple(parse_event(e, cell) for e in events)
    motion = planned_motion(cell, robot, program)
    stop = stop_at(motion.t, motion.q, motion.actions, at, robot.limits, robot.joint_names)
    changed = apply_events(cell, parsed, at)
    name = continuation_name(cell, at)
    done = {(a.seam, a.name) for a in stop.done}
    left = tuple(a.label for a in motion.actions if (a.seam, a.name) not in done)
    old_finish = float(motion.t[-1] - motion.t[0])

    def outcome(status: Literal["planned", "infeasible"], message: str, result: PlanResult | None = None,
                cont: CellSpec | None = None) -> ReplanOutcome:
        finish = None if result is None or result.trajectory is None else stop.t_stop + result.trajectory.duration
        return ReplanOutcome(status, message, name, parsed, stop, left, old_finish, finish, result, cont,
                             time.process_time() - t0)

    # The motion to the stop is the old program's: it must be clear of the cell as it now is.
    world = CollisionWorld(robot, build_scene(changed, robot), changed.process.clearance)
    if len(stop.t) >= 2:
        check = check_motion(world, robot, stop.t, stop.q_motion, stop_at_first=True)
        if not check.clean:
            v = check.violations[0]
            return outcome("infeasible", f"the robot cannot come to rest on its path clear of the changed cell: "
                                         f"{v.kind}: {v.detail} at t = {v.t:.3f} s")
    contact = world.first_contact(stop.q, stop.t_stop)
    if contact is not None:
        return outcome("infeasible", f"the stop configuration is in collision at t = {stop.t_stop:.3f} s: "
                                     f"{contact.describe()}")
    cont = continuation_cell(changed, stop, name, robot)
    result = plan_cell(cont, robot, options)
    if result.status != "planned":
        return outcome("infeasible", result.message, result, cont)
    return replace(outcome("planned", "planned", result, cont), as_it_stands=_as_it_stands(changed, robot, program) if compare else None)


def continuation_cell(changed: CellSpec, stop: Stop, name: str, robot: RobotModel) -> CellSpec:
    """The cell the rest of the work is planned in (`io.cell_continuation`): `changed` (the events
    applied) from the stop on, its start the stop configuration as the programs write it.
    ReplanInputError when nothing is left to do."""
    cont = continued(changed, stop.t_stop, {(a.seam, a.name) for a in stop.done})
    if not cont.seams:
        raise ReplanInputError(f"nothing left to do after the stop at t = {stop.t_stop:.3f} s: every "
                               f"{'station' if changed.tending else 'spot'} is done")
    return replace(cont, name=name, start=as_written_joints(stop.q, robot.prismatic))


def continuation_file(source: Path, out_dir: Path, cell: CellSpec, robot: RobotModel,
                      o: ReplanOutcome) -> ContinuationText:
    """The cell file of a planned continuation (`io.continuation_file`), to be written as
    `out_dir/<name>.cell.yaml`: `cell` read from `source`, with `o`'s events, stop and work done."""
    assert o.cell is not None and o.cell.start is not None      # planned
    changed = apply_events(cell, o.events, o.stop.t_request)
    start = np.where(prismatic_mask(robot.model), o.cell.start, np.degrees(o.cell.start))
    done = [spot_label(a.seam, a.name) for a in o.stop.done]
    header = (f"{o.name}: the cell the continuation of {cell.name}'s program runs in (robomax replan)\n"
              f"stop at t = {o.stop.t_stop:.3f} s of that program ({o.stop.how}); events:\n"
              + "\n".join(f"  {e.text}" for e in o.events)
              + "\nverify its programs against this file: robomax verify THIS_FILE PROGRAM")
    return continuation_cell_text(source, out_dir, o.name, cell, changed, o.stop.t_stop, done,
                                  [float(v) for v in start], header)


def _as_it_stands(changed: CellSpec, robot: RobotModel, program: Path) -> tuple[bool, float, str] | None:
    """The program itself run on in the changed cell, as a controller runs it: rebuilt from its
    statements (a `WAIT FOR` holds until its door opens in the changed windows) and verified against
    the changed cell. None for a trajectory file (its waits are fixed times)."""
    if program.suffix.lower() == ".json":
        return None
    from robomax_py.verify import verify_program

    report = verify_program(changed, robot, program)
    first = "" if report.clean else f"{report.violations[0].kind}: {report.violations[0].detail}"
    return report.clean, float(report.cycle_time), first


def summary(o: ReplanOutcome) -> dict[str, Any]:
    """The outcome as plain values (the command's --json and its printed lines)."""
    s = o.stop
    return {
        "name": o.name, "status": o.status, "message": o.message,
        "events": [e.text for e in o.events],
        "at": s.t_request, "stop": {"t": round(s.t_stop, 4), "how": s.how, "path_t": round(s.t_path, 4),
                                    "q_deg": [round(float(v), 4) for v in np.degrees(s.q)]},
        "done": [a.label for a in s.done], "left": list(o.left),
        "old_finish": round(o.old_finish, 4), "new_finish": None if o.new_finish is None else round(o.new_finish, 4),
        "cpu_seconds": round(o.seconds, 3),
        "as_it_stands": None if o.as_it_stands is None else {
            "clean": o.as_it_stands[0], "finish": round(o.as_it_stands[1], 4), "violation": o.as_it_stands[2]},
    }
