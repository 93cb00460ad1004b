"""An AS program from a planned program: `adapt` states it in AS's terms (frames as variables, OAT
angles, ACCURACY blends with 3 decimals, speeds with 1), `write` prints the `.as` file with its routines."""

from __future__ import annotations

import dataclasses

from robomax_py.errors import ControllerSetupError, ExportError
from robomax_py.export.dialect import (
    PlannedProgram,
    SignalNumbers,
    controller_identifier,
    gripper_label,
    header_lines,
    numbered_inputs,
    numbered_outputs,
    require_six_axes,
    spot_label,
    with_frame_names,
    with_tcp_blends,
    without_comments,
)
from robomax_py.export.kawasaki_as.oat import ANGLE_DECIMALS, oat_from_zyx, zyx_from_oat
from robomax_py.program import (
    UNSET_FRAME,
    Comment,
    FrameDef,
    Gripper,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Spot,
    Wait,
    WaitFor,
)
from robomax_py.robot import RobotModel

INPUT_BASE = 1000            # external input k is signal 1000 + k
# External inputs and outputs 1-999 (input k read as signal 1000 + k).
SIGNALS = SignalNumbers("AS", (1, 999), (1, 999),
                        hint=f"give external input k, which AS waits for as signal {INPUT_BASE} + k: 1 for SWAIT 1001")
# ACCURACY's distance (mm) as RoboDK's Kawasaki post states it: `'ACCURACY %.3f ALWAYS'`
# (ros-industrial-attic/robodk_postprocessors@d7e6c1c0 Kawasaki.py:178-180, setZoneData). With one
# decimal a blend of a big arm came back up to 0.02 deg off the plan at the wrist, beyond the
# proof's tolerance of 0.01 deg.
ACCURACY_DECIMALS = 3
EXT = ".as"
ROUTINES = ("spot_weld", "grip", "release")


def frame_name(frame: FrameDef) -> str:
    """The AS variable a program holds a frame in: `tool<n>` / `base<n>`."""
    return f"{'tool' if frame.kind == 'tool' else 'base'}{frame.number}"


def _program_name(name: str) -> str:
    return controller_identifier(name, upper=False, max_chars=15, reserved=tuple(ROUTINES))    # AS names: 15 characters


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as AS states it: frames as variables, OAT angles, ACCURACY blends (mm, 3
    decimals), speeds with 1 decimal, no configuration on transformation locations."""
    require_six_axes(robot, "AS")
    if planned.program.setup.weld == "package":
        raise ControllerSetupError("robot.controller.weld", "AS programs weld with a call of spot_weld (weld: call)")
    numbered_inputs(planned.program, SIGNALS.label, *SIGNALS.inputs)
    numbered_outputs(planned.program, SIGNALS.label, *SIGNALS.outputs)
    program = without_comments(with_frame_names(with_tcp_blends(planned, robot), frame_name))
    out: list[Instruction] = []
    for ins in program.instructions:
        if isinstance(ins, PtpMove):
            ins = dataclasses.replace(ins, speed=max(0.001, round(ins.speed * 100, 1) / 100), accel=_accel(ins.accel),
                                      flyby_mm=round(ins.flyby_mm, ACCURACY_DECIMALS))
        elif isinstance(ins, LinMove):
            ins = dataclasses.replace(ins, zyx_deg=zyx_from_oat(oat_from_zyx(ins.zyx_deg)), config="",
                                      speed_mm_s=max(0.1, round(ins.speed_mm_s, 1)), accel=_accel(ins.accel),
                                      flyby_mm=round(ins.flyby_mm, ACCURACY_DECIMALS))
        out.append(ins)
    frames = tuple(dataclasses.replace(f, zyx_deg=zyx_from_oat(oat_from_zyx(f.zyx_deg))) for f in program.frames)
    return dataclasses.replace(program, name=_program_name(program.name), frames=frames, instructions=tuple(out))


def _accel(fraction: float) -> float:
    """An acceleration share as ACCEL states it: % with 1 decimal, 0.1 to 100."""
    return max(0.1, min(100.0, round(fraction * 100, 1))) / 100



def _num(value: float, decimals: int) -> str:
    return f"{value + 0.0:.{decimals}f}"


def _trans(xyz: tuple[float, ...], zyx: tuple[float, ...]) -> str:
    values = [*(_num(v, 3) for v in xyz), *(_num(v, ANGLE_DECIMALS) for v in oat_from_zyx(zyx))]
    return f"TRANS({','.join(values)})"


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    body = [f"; {line}" for line in header_lines(program.header)]
    for f in program.frames:
        body.append(f"POINT {f.name} = {_trans(f.xyz_mm, f.zyx_deg)}")
    tool = base = UNSET_FRAME
    calls: dict[str, int] = {}
    for ins in program.instructions:
        if isinstance(ins, (PtpMove, LinMove)):
            accuracy = f"ACCURACY {_num(ins.flyby_mm, ACCURACY_DECIMALS)}" if ins.flyby_mm > 0 else "ACCURACY 1 FINE"
            if ins.accel < 1.0:
                body += [f"ACCEL {_num(ins.accel * 100, 1)}", f"DECEL {_num(ins.accel * 100, 1)}"]
            if isinstance(ins, PtpMove):
                body += [f"SPEED {_num(ins.speed * 100, 1)}", accuracy,
                         "JMOVE #[" + ",".join(_num(v, 4) for v in ins.target_deg) + "]"]
            else:
                if ins.tool != tool:
                    tool = ins.tool
                    body.append(f"TOOL {tool or 'NULL'}")
                if ins.base != base:
                    base = ins.base
                    body.append(f"BASE {base or 'NULL'}")
                body += [f"SPEED {_num(ins.speed_mm_s, 1)} MM/S", accuracy,
                         f"LMOVE {_trans(ins.position_mm, ins.zyx_deg)}"]
        elif isinstance(ins, Spot):
            calls["spot_weld"] = calls.get("spot_weld", 0) + 1
            body.append(f"CALL spot_weld({calls['spot_weld']},{_num(ins.time_s, 3)}) ; {spot_label(ins)}")
        elif isinstance(ins, Gripper):
            calls[ins.action] = calls.get(ins.action, 0) + 1
            body.append(f"CALL {ins.action}({calls[ins.action]},{_num(ins.time_s, 3)}) ; {gripper_label(ins)}")
        elif isinstance(ins, Wait):
            body.append(f"TWAIT {_num(ins.seconds, 3)}")
        elif isinstance(ins, WaitFor):
            body.append(f"SWAIT {INPUT_BASE + (ins.number or 0)} ; {ins.signal}")
        elif isinstance(ins, SetSignal):
            # AS reads ahead of the motion: BREAK holds the program until the robot has stopped,
            # then SIGNAL k turns external output k on (SIGNAL -k off).
            body += ["BREAK", f"SIGNAL {'' if ins.value else '-'}{ins.number} ; {ins.signal}"]
        elif not isinstance(ins, Comment):
            raise ExportError(f"AS cannot write {type(ins).__name__}")
    lines = [f".PROGRAM {program.name}()", *(f"  {b}" for b in body), ".END"]
    for routine in ("spot_weld", *sorted(k for k in calls if k != "spot_weld")):
        note = f"  ; default {routine.replace('_', ' ')}: rests t s, for the integrator to replace"
        lines += [f".PROGRAM {routine}(n,t)", note, "  TWAIT t", ".END"]
    return {EXT: "\r\n".join(lines) + "\r\n"}
