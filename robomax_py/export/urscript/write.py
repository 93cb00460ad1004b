"""URScript written: the reference limits, the adapter (the program as URScript states it) and the
writer of `<name>.script`."""

from __future__ import annotations

import dataclasses
import math

from robomax_py.errors import ExportError
from robomax_py.export.dialect import (
    PlannedProgram,
    SignalNumbers,
    gripper_label,
    header_lines,
    numbered_inputs,
    numbered_outputs,
    require_six_axes,
    spot_label,
    with_brand_configs,
    with_tcp_blends,
)
from robomax_py.export.quaternions import rotvec_from_zyx
from robomax_py.program import (
    UNSET_FRAME,
    Comment,
    Gripper,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Spot,
    Wait,
    WaitFor,
)
from robomax_py.robot import RobotModel

_NOTE = "URScript"
LIN_ACCEL_M_S2 = 1.2            # URScript's default movel acceleration


def reference_limits(robot: RobotModel) -> tuple[float, float]:
    """(rad/s, rad/s^2): what speed and acceleration fraction 1 of a PTP move means in movej."""
    return float(min(robot.limits.velocity)), float(min(robot.limits.acceleration))


# The controller's standard digital inputs, get_standard_digital_in(0..7).
INPUTS = 7
# Its standard digital outputs: set_standard_digital_out(n, b), n in [0:7] (UR Script Manual,
# "set_standard_digital_out").
OUTPUTS = 7
SIGNALS = SignalNumbers("URScript", (0, INPUTS), (0, OUTPUTS))


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as URScript states it: no configuration data, TCP-distance blends, frames as
    pose variables, waits on standard digital inputs."""
    require_six_axes(robot, "URScript")
    numbered_inputs(planned.program, SIGNALS.label, *SIGNALS.inputs)
    numbered_outputs(planned.program, SIGNALS.label, *SIGNALS.outputs)
    program = with_brand_configs(planned.program, planned.joints, robot, "ur")
    # URScript refers to poses by variable name: the frames carry no slot number.
    program = dataclasses.replace(program, frames=tuple(dataclasses.replace(f, number=0) for f in program.frames))
    return with_tcp_blends(dataclasses.replace(planned, program=program), robot)


# ================================================================================== writing


def _pose(xyz_mm: tuple[float, ...], zyx: tuple[float, ...]) -> str:
    x, y, z = (v / 1000.0 for v in xyz_mm)
    rx, ry, rz = rotvec_from_zyx(zyx)
    return f"p[{x:.6f}, {y:.6f}, {z:.6f}, {rx:.9f}, {ry:.9f}, {rz:.9f}]"


def _tcp(name: str) -> str:
    if name == UNSET_FRAME:
        raise ExportError("a URScript program sets its TCP before a movel: the program selects none")
    return name or "p[0, 0, 0, 0, 0, 0]"


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    v_ref, a_ref = reference_limits(robot)
    out = [f"def {program.name}():"]
    out += [f"  # {text}" for text in header_lines(program.header)]
    out.append(f"  # {_NOTE}: m, rad, rotation vectors; movej v rad/s, a rad/s^2; movel v m/s; blend r m")
    what = {"tool": "TCP in the flange frame", "base": "user frame in the robot base frame"}
    out += [f"  global {f.name} = {_pose(f.xyz_mm, f.zyx_deg)}  # {what[f.kind]}" for f in program.frames]
    load = program.setup.tool_load
    if load is not None:
        # set_payload(m, cog): mass in kg, cog [CoGx, CoGy, CoGz] in m from the tool flange
        # (Universal Robots, "How to change payload and center of gravity settings using URScript";
        # "The URScript Programming Language", set_payload); the tool file states the flange frame's.
        cog = ", ".join(f"{v:.6f}" for v in load.cog)
        out.append(f"  set_payload({load.mass:.3f}, [{cog}])  # the tool's load: kg, centre of gravity m in the flange frame")
    first = next((i for i in program.instructions if isinstance(i, LinMove)), None)
    tool = UNSET_FRAME
    if first is not None:
        tool = first.tool
        out.append(f"  set_tcp({_tcp(tool)})")
    out += ["  def spot_weld(n, weld_time):",
            "    # default weld: rest for weld_time s; replace with the gun's technology package",
            "    sleep(weld_time)", "  end",
            "  def wait_for_signal(n):", "    while not get_standard_digital_in(n):", "      sync()", "    end", "  end"]
    for action in sorted({ins.action for ins in program.instructions if isinstance(ins, Gripper)}):
        out += [f"  def {action}(n, {action}_time):",
                f"    # default {action}: rest for {action}_time s; replace with the gripper's outputs and sensors",
                f"    sleep({action}_time)", "  end"]
    grips: dict[str, int] = {}
    n_weld = 0
    for ins in program.instructions:
        if isinstance(ins, Comment):
            out.append(f"  # {ins.text}" if ins.text else "  #")
            continue
        if isinstance(ins, (PtpMove, LinMove)):
            note = f"  # {ins.comment}" if ins.comment else ""
            r = ins.flyby_mm / 1000.0
            if isinstance(ins, PtpMove):
                q = ", ".join(f"{math.radians(v):.9f}" for v in ins.target_deg)
                out.append(f"  movej([{q}], a={ins.accel * a_ref:.6f}, v={ins.speed * v_ref:.6f}, r={r:.9f}){note}")
            else:
                if ins.tool != tool:
                    tool = ins.tool
                    out.append(f"  set_tcp({_tcp(tool)})")
                if ins.base == UNSET_FRAME:
                    raise ExportError("a URScript movel is relative to the base or a pose: the program selects none")
                a = f"{LIN_ACCEL_M_S2:.1f}" if ins.accel >= 1.0 else f"{ins.accel * LIN_ACCEL_M_S2:.6f}"
                target = _pose(ins.position_mm, ins.zyx_deg)
                target = f"pose_trans({ins.base}, {target})" if ins.base else target
                out.append(f"  movel({target}, a={a}, v={ins.speed_mm_s / 1000:.6f}, r={r:.9f}){note}")
        elif isinstance(ins, Spot):
            n_weld += 1
            out.append(f"  spot_weld({n_weld}, {ins.time_s:.3f})  # {spot_label(ins)}")
        elif isinstance(ins, Gripper):
            grips[ins.action] = grips.get(ins.action, 0) + 1
            out.append(f"  {ins.action}({grips[ins.action]}, {ins.time_s:.3f})  # {gripper_label(ins)}")
        elif isinstance(ins, Wait):
            out.append(f"  sleep({ins.seconds:.3f})")
        elif isinstance(ins, WaitFor):
            out.append(f"  wait_for_signal({ins.number})  # {ins.signal}")
        elif isinstance(ins, SetSignal):
            # A movel / movej without blend radius returns when the robot has stopped at its target.
            out.append(f"  set_standard_digital_out({ins.number}, {'True' if ins.value else 'False'})  # {ins.signal}")
        else:
            raise ExportError(f"URScript cannot write {type(ins).__name__}")
    out.append("end")
    return {".script": "\n".join(out) + "\n"}
