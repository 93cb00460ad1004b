"""A planned result -> the dialect-independent robot program (`robomax_py.program`).

PTP moves to every stop, FLYBY with the radius the planner chose and checked (detour corners, the
joins retract -> move -> approach), LIN moves through the via points of a detour of TCP lines
(`planner.detour_moves: lin`, stopping at each), LIN approach and retract along the electrode axis,
each with the configuration data of its own target (the controller brand's), a SPOT
statement per spot, and comments carrying the planned times and orientation angles. Cartesian
targets are TCP poses in the program's user frame (mm, ZYX degrees; by default the controller's
robot base frame itself), each naming the tool and user frame it is stated with; their values are
the program's frames. Waits name the cell's signal and the controller input the cell maps it to. Names are made into identifiers where a cell uses other characters.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py._version import __version__
from robomax_py.errors import ExportError
from robomax_py.export.dialect import PlannedProgram
from robomax_py.export.mount import is_tilted, mount_rotation
from robomax_py.plan import PlanResult
from robomax_py.plan.lead_in import START_LABEL
from robomax_py.plan.program_frames import ProgramFrames, program_frames
from robomax_py.plan.results import Transition
from robomax_py.plan.waiting import WaitPlan, signal_of
from robomax_py.program import (
    NULL_FRAME,
    Comment,
    FrameDef,
    Gripper,
    Header,
    Instruction,
    LinMove,
    Program,
    ProgramSetup,
    PtpMove,
    SetSignal,
    Spot,
    Wait,
    WaitFor,
    identifier,
    stated_joints,
)
from robomax_py.spec import ControllerSetup


def program_from_plan(result: PlanResult, cell_sha256: str = "", stamp: str = "") -> Program:
    """The dialect-free program of a complete plan (`planned_program` without the joint values)."""
    return planned_program(result, cell_sha256, stamp).program


def planned_program(result: PlanResult, cell_sha256: str = "", stamp: str = "") -> PlannedProgram:
    """The dialect-free program of a complete plan, and the planned joint values at each statement.

    cell_sha256 : SHA-256 of the cell file, for the header; stamp : a date for the header, or "".
    """
    traj = result.trajectory
    if traj is None or result.T_flange_tcp is None or result.T_world_base is None or result.home is None \
            or len(result.prismatic) != len(result.home):
        raise ExportError(f"cell {result.cell} has no complete plan to export")
    opts = result.options
    setup = result.controller
    prismatic = result.prismatic

    def stated(q: FloatArray) -> tuple[float, ...]:
        return stated_joints(q, prismatic)      # deg, or mm for a prismatic joint (a track)
    # Cartesian targets are stated in the program's user frame (docs/cell-files.md, "Controller programs"): by default the
    # controller's robot base frame itself; never the robot's placement in the cell.
    C = np.eye(4) if result.T_root_controller is None else result.T_root_controller
    given = program_frames(result.tool, result.T_flange_tcp, result.T_world_base, C, setup)
    frames = frame_defs(given)
    tool = frames[0]
    base_name = frames[1].name if len(frames) > 1 else NULL_FRAME

    def lin(T_root_tcp: FloatArray, config: str, speed_mm_s: float, **kw: Any) -> LinMove:
        xyz, zyx = given.stated(T_root_tcp)
        return LinMove(xyz, zyx, config, speed_mm_s, tool=tool.name, base=base_name, **kw)

    t0 = float(traj.t[0])
    out: list[Instruction] = []
    joints: list[FloatArray] = []

    def emit(q: FloatArray, *items: Instruction) -> None:
        out.extend(items)
        joints.extend(np.asarray(q, dtype=float) for _ in items)

    home = np.asarray(result.home, dtype=float)
    transitions = result.transitions
    # A continuation (`robomax replan`) starts where the robot stopped, not at home.
    where = "stop" if transitions and transitions[0].label.startswith(f"{START_LABEL} ->") else "home"
    emit(home, Comment(f"start at {'the stop configuration' if where == 'stop' else 'home'}; {len(result.spots)} "
                       f"spots, planned cycle {traj.duration:.3f} s"),
         PtpMove(stated(home), opts.speed, 1.0, comment=where))
    if result.spots and result.spots[0].interlocks:
        emit(home, *_interlocks(result.spots[0].interlocks, setup))
    if transitions and transitions[0].wait is not None:
        emit(home, *_wait(transitions[0].wait, setup))
    lin_mm_s = opts.tcp_speed * opts.speed * 1000.0     # the override scales LIN speeds too
    for k, trans in enumerate(transitions):
        phases = traj.phases_of(trans.kind, trans.label)
        start = f"t {phases[0].t_start - t0:.3f} s" if phases else ""
        approach_follows = k < len(result.spots)
        if trans.spline is not None:
            # One smooth TCP path (`planner.cartesian_moves: spline`), a spline block: the straight
            # retract (written with the spot before), the spline points up to the approach point,
            # the straight approach (written with the spot after).
            moves = trans.spline
            for j in range(1, len(moves.targets) - 1):
                note = f"{trans.label}, {start}, spline" if j == 1 else ""
                emit(moves.q[j], lin(moves.targets[j], moves.configs[j], float(moves.speeds[j]) * 1000.0,
                                     comment=note, accel=trans.accel, spline="spl"))
        for w, q in enumerate(trans.waypoints[1:] if trans.spline is None else (), start=1):
            last = w == len(trans.waypoints) - 1
            if last and approach_follows and trans.approach_q is not None:
                q = trans.approach_q             # the approach line continued for the fly-by
            note = f"{trans.label}, {start}" if w == 1 else ""
            note = note if last or trans.kind == "move" else (note + ", " if note else "") + f"detour point {w}"
            # Radii as planned: detour corners and the join into the approach (joint space, deg).
            radius = (trans.flyby_radius if approach_follows else 0.0) if last else trans.blend_radius
            if any(stage.index == w for stage in trans.stages):
                radius = 0.0                     # the robot stops there to wait
            speed = opts.speed * (opts.detour_speed if trans.kind == "detour" else 1.0) if trans.speed is None \
                else trans.speed
            if trans.lin_targets is not None:
                # A detour of TCP lines (`planner.detour_moves: lin`): a LIN to each via point, stopping there.
                emit(q, lin(trans.lin_targets[w - 1], trans.lin_configs[w - 1], trans.lin_speed * 1000.0,
                            comment=note.strip(", "), accel=trans.accel))
            else:
                emit(q, PtpMove(stated(q), speed, trans.accel, flyby=math.degrees(radius),
                                comment=note.strip(", ")))
            for stage in trans.stages:
                if stage.index == w and stage.wait is not None:
                    emit(q, *_wait(stage.wait, setup))
        if not approach_follows:
            break
        spot = result.spots[k]
        alpha, beta, gamma = (math.degrees(v) for v in spot.angles)
        q_before = joints[-1]
        emit(q_before, Comment(f"{spot.seam}/{spot.name}: arrive {spot.t_arrive - t0:.3f} s, leave "
                               f"{spot.t_leave - t0:.3f} s, alpha {alpha:.1f} beta {beta:.1f} gamma {gamma:.1f} deg"))
        act: Instruction = Spot(identifier(spot.name), identifier(spot.seam), spot.weld_time, spot.gun, spot.schedule) \
            if spot.action is None else Gripper(spot.action, identifier(spot.name), identifier(spot.seam), spot.weld_time)
        if trans.spline is None:
            emit(spot.q_spot, lin(spot.T_spot, spot.config, _lin_mm_s(trans, lin_mm_s), comment="approach",
                                  accel=trans.accel), act)
        else:
            emit(spot.q_spot, lin(spot.T_spot, spot.config, float(trans.spline.speeds[-1]) * 1000.0,
                                  comment="approach", accel=trans.accel, spline="slin"), act)
        after = transitions[k + 1] if k + 1 < len(transitions) else None
        # The retract ends where the next move's extended retract does, else at the approach point.
        T_retract, q_end = spot.T_app, spot.q_app
        if after is not None and after.retract_T is not None and after.retract_q is not None:
            T_retract, q_end = after.retract_T, after.retract_q
        if k + 1 < len(result.spots) and result.spots[k + 1].interlocks:
            emit(spot.q_spot, *_interlocks(result.spots[k + 1].interlocks, setup))
        if after is not None and after.wait is not None:
            emit(spot.q_spot, *_wait(after.wait, setup))
        retract_radius = after.flyby_radius if after is not None else 0.0
        if after is not None and after.spline is not None:
            moves = after.spline
            emit(moves.q[0], lin(moves.targets[0], moves.configs[0], float(moves.speeds[0]) * 1000.0,
                                 comment="retract, spline", accel=after.accel, spline="slin"))
            continue
        emit(q_end, lin(T_retract, spot.config_app, lin_mm_s if after is None else _lin_mm_s(after, lin_mm_s),
                        flyby=math.degrees(retract_radius), comment="retract", accel=1.0 if after is None else after.accel))
    header = Header(identifier(result.cell), identifier(result.robot), identifier(result.tool), traj.duration,
                    tuple(identifier(j) for j in result.joint_names), f"robomax_py {__version__}", cell_sha256, stamp)
    handed = ProgramSetup(setup.position_registers, setup.numeric_registers, setup.weld, tool_load=result.tool_load,
                          tilted_mount=is_tilted(mount_rotation(result.T_world_base, C)))
    return PlannedProgram(Program(identifier(result.cell), header, frames, tuple(out), handed), tuple(joints), setup)


def frame_defs(frames: ProgramFrames) -> tuple[FrameDef, ...]:
    """The tool and (when the cell names one) user frame of a program, named as identifiers."""
    out = [dataclasses.replace(frames.tool, name=identifier(frames.tool.name))]
    if frames.base is not None:
        out.append(dataclasses.replace(frames.base, name=identifier(frames.base.name)))
    return tuple(out)


def _lin_mm_s(trans: Transition, default: float) -> float:
    """The TCP speed of the lines a transition joins (its retract and approach), mm/s."""
    return default if trans.tcp_speed is None else trans.tcp_speed * 1000.0


def _wait_for(signal: str, setup: ControllerSetup) -> WaitFor:
    """A wait for a cell signal, on the input the cell maps it to (none: named only)."""
    mapped = setup.input_of(signal)
    return WaitFor(identifier(signal), None if mapped is None else mapped.number)


def _interlocks(signals: tuple[str, ...], setup: ControllerSetup) -> list[Instruction]:
    """Waits for clamp inputs before moving to the first weld near each clamp (at rest)."""
    out: list[Instruction] = []
    for signal in signals:
        out += [Comment(f"wait for clamp input {signal}"), _wait_for(signal, setup)]
    return out


def _wait(w: WaitPlan, setup: ControllerSetup) -> list[Instruction]:
    """A wait for a dynamic obstacle: for its clear signal when it is there as the wait begins."""
    note = Comment(f"wait {w.seconds:.3f} s for {w.obstacle} to {'open' if w.door else 'clear'}")
    if w.for_signal:
        return [note, _wait_for(signal_of(w.obstacle, w.door), setup)]
    return [note, Wait(w.seconds)]


def set_signal(signal: str, setup: ControllerSetup, value: bool = True) -> SetSignal:
    """A station's interlock: the robot sets `signal` for the other robots (on when it has left
    their shared zone), on the output the cell maps it to (`robot.controller.outputs`; none:
    named only, as SRCL and RAPID set it)."""
    mapped = setup.output_of(signal)
    return SetSignal(identifier(signal), None if mapped is None else mapped.number, value)


def wait_for(signal: str, setup: ControllerSetup) -> WaitFor:
    """A wait for a signal (another robot's interlock, a clamp's, a door's), on the input the cell
    maps it to (none: named only)."""
    return _wait_for(signal, setup)
