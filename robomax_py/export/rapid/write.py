"""RAPID written: the adapter (the program as RAPID states it), the weld data's names and the writer of
`<name>.mod` and its data module (the package's docstring gives the sources)."""

from __future__ import annotations

import dataclasses

from robomax_py.errors import ControllerSetupError, ExportError
from robomax_py.export.dialect import (
    PlannedProgram,
    ascii_comments,
    fitted_identifier,
    gripper_label,
    header_lines,
    require_six_axes,
    spot_label,
    with_brand_configs,
    with_package_welds,
    with_tcp_blends,
)
from robomax_py.export.quaternions import quaternion_from_zyx
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
    ToolLoad,
    Wait,
    WaitFor,
    identifier,
)
from robomax_py.robot import RobotModel

# The data module declaring the program's tooldata and wobjdata (a companion of `<name>.mod`).
FRAMES_FILE = "_frames.mod"
# RAPID identifiers name modules, routines and data: a letter first, then letters, digits and `_`,
# at most 32 characters (ABB Technical reference manual, RAPID kernel, 3HAC050946-001,
# "Identifiers"); reserved words are not identifiers. The file carries the module's name, as
# RobotStudio names a module it saves (the controller takes the name from the MODULE line), and
# `<name>_frames` must be an identifier too.
PROGRAM_CHARS = 32 - len("_frames")
_RESERVED = ("main", "spot_weld", "grip", "release", "MODULE", "ENDMODULE", "PROC", "ENDPROC", "FUNC", "ENDFUNC",
             "TRAP", "ENDTRAP", "CONST", "PERS", "VAR", "LOCAL", "TASK", "IF", "THEN", "ELSE", "ELSEIF", "ENDIF", "FOR",
             "FROM", "TO", "STEP", "DO", "ENDFOR", "WHILE", "ENDWHILE", "TEST", "CASE", "DEFAULT", "ENDTEST", "RETURN",
             "GOTO", "RAISE", "RETRY", "TRYNEXT", "ERROR", "BACKWARD", "UNDO", "AND", "OR", "XOR", "NOT", "DIV",
             "MOD", "TRUE", "FALSE", "WITH", "ALIAS", "RECORD", "ENDRECORD", "CONNECT", "NOSTEPIN", "NOVIEW",
             "READONLY", "SYSMODULE", "VIEWONLY", "INOUT", "OPTIONAL")


def program_name(name: str) -> str:
    """The MODULE and file name a cell's program `name` becomes (`PROGRAM_CHARS` at most; see
    `dialect.fitted_identifier`).

    >>> program_name("Kabine Flansch"), program_name("_7_door"), program_name("main")
    ('Kabine_Flansch', 'P_7_door', 'main_prog')
    """
    return fitted_identifier(name, max_chars=PROGRAM_CHARS, reserved=_RESERVED, keep=("_published", "_teach_in"))

_NOTE = "RAPID module"
_EAX = "[9E9, 9E9, 9E9, 9E9, 9E9, 9E9]"
# A quaternion is unit when its norm is within this of 1: robomax writes 9 decimals (~1e-9 off);
# programs with 4-decimal quaternions, as many ABB programs carry, are within 1e-4. It is then normalised.
UNIT_QUATERNION_TOL = 1e-4
# `vmax` in a MoveL: the largest predefined TCP speed (v7000, RAPID reference "speeddata").
VMAX_TCP_MM_S = 7000.0


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as RAPID states it: ABB confdata, TCP-distance zones, frames by name (those the
    cell names exist on the controller and are not declared), inputs by signal name, and with
    `weld: package` every weld as the spot option's SpotL at the end of its approach line."""
    require_six_axes(robot, "RAPID")
    setup = planned.controller
    existing = set()
    if setup.tool is not None and setup.tool.existing:
        existing.add(("tool", identifier(setup.tool.name)))
    if setup.frame is not None and setup.frame.frame.existing:
        existing.add(("base", identifier(setup.frame.frame.name)))
    program = planned.program
    for f in program.frames:
        if f.name.lower() in ("tool0", "wobj0"):
            raise ControllerSetupError("robot.controller." + ("tool" if f.kind == "tool" else "frame") + ".name",
                                       f"{f.name} is RAPID's predefined null frame; name the calibrated one")
    out: list[Instruction] = []
    for ins in program.instructions:
        if isinstance(ins, WaitFor):
            mapped = setup.input_of(ins.signal) or next((i for i in setup.inputs if identifier(i.signal) == ins.signal),
                                                        None)
            ins = WaitFor(mapped.name if mapped is not None and mapped.name else ins.signal)
        elif isinstance(ins, SetSignal):
            # SetDO names the output as the I/O configuration does: the cell's name for it, else the signal's.
            given = setup.output_of(ins.signal) or next((o for o in setup.outputs if identifier(o.signal) == ins.signal),
                                                        None)
            ins = SetSignal(given.name if given is not None and given.name else ins.signal, None, ins.value)
        out.append(ins)
    # RAPID refers to data by name: the frames carry no slot number.
    frames = tuple(dataclasses.replace(f, number=0) for f in program.frames if (f.kind, f.name) not in existing)
    program = with_package_welds(dataclasses.replace(program, frames=frames, instructions=tuple(out)), "RAPID")
    program = ascii_comments(program)         # comments read alike in any code page the controller uses
    _check_weld_data_names(program)
    program = with_brand_configs(program, planned.joints, robot, "abb")
    program = dataclasses.replace(program, name=program_name(program.name))
    return with_tcp_blends(dataclasses.replace(planned, program=_without_approach_notes(program)), robot)


def gun_data(gun: int) -> str:
    """The spot option's gundata of gun n on the controller (not declared by the program)."""
    return f"gun{gun}"


def spot_data(schedule: int) -> str:
    """The spotdata a package weld of `schedule` names (declared in the program module)."""
    return f"sd{schedule}"


def _check_weld_data_names(program: Program) -> None:
    """A frame named like a gundata or spotdata the welds use: RAPID names data uniquely, and the
    gundata exists on the controller already."""
    welds = [i for i in program.instructions if isinstance(i, Spot) and i.package]
    taken = {gun_data(w.gun).lower(): f"gun {w.gun}'s gundata" for w in welds}
    taken |= {spot_data(w.schedule).lower(): f"schedule {w.schedule}'s spotdata" for w in welds}
    names: set[tuple[str, str]] = {(f.kind, f.name) for f in program.frames}
    names |= {(k, n) for i in program.instructions if isinstance(i, LinMove) for k, n in (("tool", i.tool),
                                                                                         ("base", i.base))}
    for kind, name in sorted(names):
        if name.lower() in taken:
            key = "robot.controller." + ("tool" if kind == "tool" else "frame") + ".name"
            raise ControllerSetupError(key, f"{name} is also the name of {taken[name.lower()]} (weld: package); "
                                            "RAPID names data uniquely: name the frame otherwise")


def _without_approach_notes(program: Program) -> Program:
    """The line to a package weld without its note: its statement (SpotL) carries the weld's."""
    out = list(program.instructions)
    for k in range(1, len(out)):
        ins, before = out[k], out[k - 1]
        if isinstance(ins, Spot) and ins.package and isinstance(before, LinMove):
            out[k - 1] = dataclasses.replace(before, comment="")
    return dataclasses.replace(program, instructions=tuple(out))


# ================================================================================== writing


def _q(zyx: tuple[float, ...]) -> str:
    return "[" + ", ".join(f"{v:.9f}" for v in quaternion_from_zyx(zyx)) + "]"


def _xyz(xyz: tuple[float, ...]) -> str:
    return "[" + ", ".join(f"{v:.3f}" for v in xyz) + "]"


def _zone(mm: float) -> str:
    # ABB's predefined zones keep pzone_ori = pzone_eout = 1.5 pzone_tcp, zone_ori = 0.15 pzone_tcp (deg).
    return f"[FALSE, {mm:.6f}, {1.5 * mm:.6f}, {1.5 * mm:.6f}, {0.15 * mm:.6f}, {1.5 * mm:.6f}, {0.15 * mm:.6f}]"


def _tail(tool: str, base: str) -> str:
    """A move's tool and work object arguments (the null frames are RAPID's tool0 and wobj0)."""
    if UNSET_FRAME in (tool, base):
        raise ExportError("a RAPID move names its tool and work object: the program selects none")
    return f", {tool or 'tool0'}" + (f" \\WObj:={base}" if base else "") + ";"


def _tool_load(frame: FrameDef, load: ToolLoad | None) -> str:
    """A tooldata's tload and the statement's end: loaddata [mass kg, cog [x, y, z] mm in the wrist
    (flange) frame, aom, ix, iy, iz kgm2] ([R3] p. 183); with every inertia 0 "the tool is handled
    as if it were a spot load" ([R3] p. 226), the axes of moment then the identity [1, 0, 0, 0]."""
    if load is None:
        # A 1 kg point load at the TCP: the tool file states none.
        return (f"[1, {_xyz(frame.xyz_mm)}, [1, 0, 0, 0], 0, 0, 0]];  "
                "! load: 1 kg at the TCP, a placeholder: replace with the gun's (LoadIdentify)")
    cog_mm = tuple(1000.0 * v for v in load.cog)
    return (f"[{load.mass:.3f}, {_xyz(cog_mm)}, [1, 0, 0, 0], 0, 0, 0]];  "
            "! load: the tool file's mass and centre of gravity, a point mass: LoadIdentify adds its inertia")


def _frames_module(program: Program) -> str:
    """The data module declaring the frames the program uses and does not find on the controller."""
    lines = ["%%%", "  VERSION:1", "  LANGUAGE:ENGLISH", "%%%", "", f"MODULE {program.name}_frames"]
    lines += [f"  ! {text}" for text in header_lines(program.header)]
    lines.append(f"  ! the frames {program.name} uses: load with it, or compare with the calibrated ones "
                 "(mm, quaternions [w, x, y, z]; work objects in the robot base frame, which is the world)")
    for f in program.frames:
        if f.kind == "tool":
            lines.append(f"  PERS tooldata {f.name} := [TRUE, [{_xyz(f.xyz_mm)}, {_q(f.zyx_deg)}], "
                         f"{_tool_load(f, program.setup.tool_load)}")
        else:
            lines.append(f"  PERS wobjdata {f.name} := [FALSE, TRUE, \"\", [{_xyz(f.xyz_mm)}, {_q(f.zyx_deg)}], "
                         "[[0, 0, 0], [1, 0, 0, 0]]];")
    lines.append("ENDMODULE")
    return "\n".join(lines) + "\n"


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    decl: list[str] = []
    body: list[str] = []
    first = next((i for i in program.instructions if isinstance(i, LinMove)), None)
    joint_tail = _tail(first.tool, "") if first is not None else ", tool0;"
    speeds: dict[float, str] = {}
    zones: dict[float, str] = {}
    schedules: set[int] = set()
    override = accel = None
    n_point = n_weld = 0
    grips: dict[str, int] = {}
    instructions = program.instructions
    for k, ins in enumerate(instructions):
        if isinstance(ins, Comment):
            body.append(f"    ! {ins.text}" if ins.text else "    !")
            continue
        note = f"  ! {ins.comment}" if isinstance(ins, (PtpMove, LinMove)) and ins.comment else ""
        if isinstance(ins, (PtpMove, LinMove)):
            n_point += 1
            zone = "fine"
            if ins.flyby_mm > 0:
                if ins.flyby_mm not in zones:
                    zones[ins.flyby_mm] = f"z_{len(zones) + 1}"
                    decl.append(f"  CONST zonedata {zones[ins.flyby_mm]} := {_zone(ins.flyby_mm)};")
                zone = zones[ins.flyby_mm]
            want = ins.speed if isinstance(ins, PtpMove) else 1.0
            if want != override:
                override = want
                body.append(f"    VelSet {100 * want:.1f}, 5000;")
            # AccSet holds for every later move, MoveL too (RAPID reference, "AccSet").
            if ins.accel != accel and (isinstance(ins, PtpMove) or accel is not None or ins.accel != 1.0):
                accel = ins.accel
                body.append(f"    AccSet {100 * accel:.1f}, 100;")
            if isinstance(ins, PtpMove):
                name = f"jt{n_point}"
                joints = ", ".join(f"{v:.4f}" for v in ins.target_deg)
                decl.append(f"  CONST jointtarget {name} := [[{joints}], {_EAX}];")
                body.append(f"    MoveAbsJ {name}, vmax, {zone}{joint_tail}{note}")
            else:
                if ins.speed_mm_s not in speeds:
                    speeds[ins.speed_mm_s] = f"v_lin{len(speeds) + 1}"
                    decl.append(f"  CONST speeddata {speeds[ins.speed_mm_s]} := [{ins.speed_mm_s:.3f}, 500, 5000, 1000];")
                name = f"p{n_point}"
                decl.append(f"  CONST robtarget {name} := [{_xyz(ins.position_mm)}, {_q(ins.zyx_deg)}, "
                            f"{ins.config.replace(',', ', ')}, {_EAX}];")
                weld = instructions[k + 1] if k + 1 < len(instructions) else None
                if isinstance(weld, Spot) and weld.package:
                    # The spot option's instruction moves to the spot and welds there: always a stop.
                    if zone != "fine":
                        raise ExportError(f"{weld.seam}/{weld.name}: a SpotL welds at a stop point; its line flies by")
                    if weld.schedule not in schedules:
                        schedules.add(weld.schedule)
                        decl.append(f"  PERS spotdata {spot_data(weld.schedule)} := [{weld.schedule}, 1];"
                                    "  ! [program number, pressure level]: check against the spot option's spotdata")
                    body.append(f"    SpotL {name}, {speeds[ins.speed_mm_s]}, {spot_data(weld.schedule)}, "
                                f"{gun_data(weld.gun)}{_tail(ins.tool, ins.base)}  ! {weld.seam}/{weld.name}")
                else:
                    body.append(f"    MoveL {name}, {speeds[ins.speed_mm_s]}, {zone}{_tail(ins.tool, ins.base)}{note}")
        elif isinstance(ins, Spot):
            if ins.package:
                if not (k and isinstance(instructions[k - 1], LinMove)):
                    raise ExportError(f"{ins.seam}/{ins.name}: RAPID's SpotL welds at the end of a line; the weld "
                                      "follows no line")
                continue                                          # written with its line
            n_weld += 1
            body.append(f"    spot_weld {n_weld}, {ins.time_s:.3f};  ! {spot_label(ins)}")
        elif isinstance(ins, Gripper):
            grips[ins.action] = grips.get(ins.action, 0) + 1
            body.append(f"    {ins.action} {grips[ins.action]}, {ins.time_s:.3f};  ! {gripper_label(ins)}")
        elif isinstance(ins, Wait):
            body.append(f"    WaitTime {ins.seconds:.3f};")
        elif isinstance(ins, WaitFor):
            body.append(f"    WaitDI {ins.signal}, 1;")
        elif isinstance(ins, SetSignal):
            # SetDO Signal, Value (RAPID instructions reference): after a fine point the robot has
            # stopped before the next instruction runs (zonedata fine: a stop point).
            body.append(f"    SetDO {ins.signal}, {1 if ins.value else 0};")
        else:
            raise ExportError(f"RAPID cannot write {type(ins).__name__}")
    lines = ["%%%", "  VERSION:1", "  LANGUAGE:ENGLISH", "%%%", "", f"MODULE {program.name}"]
    lines += [f"  ! {text}" for text in header_lines(program.header)]
    lines.append(f"  ! {_NOTE}: mm, deg, quaternions [w, x, y, z], speeddata mm/s, zonedata mm")
    if schedules:
        lines.append("  ! welds: SpotL of the spot welding option with the controller's gundata; the weld time is "
                     "the schedule's")
    lines += decl
    lines += ["", "  PROC main()", *body, "  ENDPROC"]
    if n_weld or not (grips or schedules):
        lines += ["", "  PROC spot_weld(num n, num weld_time)",
                  "    ! default weld: rest for weld_time s; replace with the gun's technology package",
                  "    WaitTime \\InPos, weld_time;", "  ENDPROC"]
    for action in sorted(grips):
        lines += ["", f"  PROC {action}(num n, num {action}_time)",
                  f"    ! default {action}: rest for {action}_time s; replace with the gripper's SetDO and sensor checks",
                  f"    WaitTime \\InPos, {action}_time;", "  ENDPROC"]
    lines.append("ENDMODULE")
    return {".mod": "\n".join(lines) + "\n", FRAMES_FILE: _frames_module(program)}
