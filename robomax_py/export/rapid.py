r"""ABB RAPID, both directions: a program module `<name>.mod` and a data module `<name>_frames.mod`.

Sources, cited below by tag:
- [R3] ABB RAPID Reference Manual, BaseWare OS 3.x ("Basic Characteristics RAPID",
  https://www.yumpu.com/en/document/view/5679047/basic-characteristics-rapid/<page>): p. 96 (5.1 data
  scope), 98 (5.3 persistent declaration), 183 (loaddata), 225-226 (tooldata), 233-234 (wobjdata),
  665 (gundata), 675-676 (SpotL), 699 (SWUSRF).
- [PS4] ABB Product Specification "RobotWare Options for BaseWare OS 4.0", SpotWare
  (https://www.easymanua.ls/abb/irb-6650-125-3-2/manual?p=186).
- [DRV] ros-industrial/abb_driver @ f3068b92 (BSD): rapid/ROS_common.sys:1 `MODULE
  ROS_common(SYSMODULE)`, :40-43 its PERS declarations; rapid/ROS_motionServer.mod:112-115 writes
  them ("Sending ... points to MOTION task"), rapid/ROS_motion.mod:82-86 reads them in another
  task: neither module declares them again.
- [MSG] ros-industrial/abb_robot_driver_interfaces @ f5d7d117 abb_rapid_msgs/msg/*.msg (ABB's
  messages citing the "Technical reference manual - RAPID Instructions, Functions and Data types").

What a program states, in RAPID's terms:
- joint targets as `jointtarget` (deg), Cartesian targets as `robtarget`: [x, y, z] mm, a unit
  quaternion [q1, q2, q3, q4] with q1 = w, confdata [cf1, cf4, cf6, cfx] of the planned
  configuration (docs/cell-files.md, "Controller programs"), external axes 9E9;
- every MoveL names its `tooldata` and, when the targets are in a user frame, its `wobjdata`
  (`\WObj:=`; without it RAPID uses wobj0). The TCP pose in the world is the work object's
  uframe · oframe · target ([R3] p. 233-234: "The object coordinate system is defined in the user
  coordinate system", the user frame in the world; [MSG] RobTarget.msg). With factory settings the
  robot base frame is the world (the controller knows nothing of the cell); the robot's placement
  in the cell is never written;
- PTP moves as `MoveAbsJ ... vmax` under `VelSet` (the speed fraction, %) and `AccSet` (which holds
  for the `MoveL`s after it too, as on the controller); LIN moves as `MoveL` with a `speeddata`
  whose v_tcp is the planned TCP speed (mm/s, at `VelSet 100`);
- blends as `zonedata` with pzone_tcp the TCP distance (mm) of the planned radius (the other
  zone sizes in the proportions of ABB's predefined zones), `fine` at every stop and weld;
- `WaitTime t;` and `WaitDI <signal>, 1;`, the signal named as the controller's I/O configuration
  names it (`robot.controller.inputs`, else the cell's signal name).

Welds. With `weld: call` (the default, docs/cell-files.md, "Controller programs") a weld is `MoveL ... fine` followed by
`spot_weld n, weld_time;  ! seam/name gun G schedule S`, with `PROC spot_weld` defined in the module
(rest for weld_time; the integrator replaces it). With `weld: package` it is the spot welding
option's instruction, which moves to the spot and welds there ([PS4]: SpotL "Move the TCP along a
linear path and perform a spot welding at the end position"; [R3] p. 675: "The start signal is sent
to the timer as soon as the robot has reached the end position", a stop point):

    SpotL p4, v_lin1, sd4, gun2, tool1 \WObj:=fixture;  ! flange/s7
    PERS spotdata sd4 := [4, 1];       (in the program module: the schedule's program number)

The argument list ToPoint, Speed, Spot [\InPos] [\NoConc] [\Retract], Gun, Tool [\WObj] is the
closest published form found, not ABB's syntax page itself: [R3] p. 676 names the `\Retract`
switch, p. 699 hands user routines "spot of type spotdata: actual spot given in the
SpotL-instruction" and "gun of type gundata" in that order, [R3] p. 675 puts "A maximum of four
discrete gun pressures" in the spot data. The spotdata written is [program number = the spot's
schedule, pressure level 1] (level 1 exists on every gun: [R3] p. 665, gundata nof_plevels "Number
of pressure levels (1 - 4)"), the form of public controller backups in the search tool's code index
(repository not shown there: `PERS spotdata RA696SOLD011:=[1,1];`, the gun opened by
`OpenHighLift GUN1;`). UNCONFIRMED: the argument order and the spotdata fields of
RobotWare 6 / OmniCore Spot options (whose spotdata may hold more, such as tip force and plate
thickness): the integrator completes the declaration to the installed option's record (a RAPID
aggregate must match its type, so a mismatch should show when the module is loaded, not at the
weld; not tried on a controller). The gundata is the option's, on the controller, named
by the cell's gun number (`gun2`, not declared); a tool or work object of that name is refused
(RAPID names data uniquely). The weld time is the schedule's on the controller: rebuild takes it
from the cell's spots of that schedule.

The data module. The frames' values are PERS data in `<name>_frames.mod` (tooldata, wobjdata with
oframe identity); a tool or work object the cell names (`robot.controller`) exists on the
controller and is not declared again. RAPID data declared at module level without LOCAL is global:
"The scope of predefined or global program data may include any module" of the task, and "all
data used must be declared" ([R3] p. 96; [DRV]). Hence the integrator's procedure:
1. load `<name>_frames.mod` into the same task as `<name>.mod` (compare its values with the
   calibrated ones first); without it, and without the named data on the controller, the program
   module refers to undeclared data and cannot run (verify reports such a frame: it then knows
   only the frames the cell names, never the values of the missing module);
2. a persistent is one object per name: RAPID updates its declared value whenever the object
   changes ([R3] p. 96, 98: "if the value of a persistent is updated, this automatically causes
   the initialisation value of the persistent declaration to be updated"), and a module carrying a
   persistent of a name already in the task refers to that same object ([DRV]: one persistent
   written in one task is read in another). Which value then wins, the loaded module's
   initial value or the one in memory, is UNCONFIRMED from an ABB document: check the frames on the
   pendant after loading (Program data), and delete a stale module of the same frames first;
3. the data module is a program module, not `(SYSMODULE)` ([DRV] shows the attribute, but a system
   module is loaded at start-up from the system parameters and outlives programs; frames the
   integrator wants kept belong in the controller's own calibration module, named in the cell).

The tool's load is not known to robomax: tooldata carries a point load of 1 kg at the TCP ("If all
components are defined as being 0 kgm2, the tool is handled as if it were a spot load", [R3]
p. 226; the centre of gravity of a tool in the wrist coordinate system, p. 183), with a comment:
replace it with the gun's (LoadIdentify); a wrong load impairs path accuracy (p. 183).

The reader takes the motion subset of any module as the controller executes it: MoveAbsJ (tool,
`\WObj` and `\TLoad` do not change a joint target), MoveL and SpotL with declared or in-place targets
in the tool and work object they name (\TLoad changes no path), predefined and declared speed and
zone data, VelSet, AccSet, WaitTime, WaitDI and calls of spot_weld; a work object held by the robot
or moved by a mechanical unit (robhold TRUE, ufprog FALSE, ufmec) is reported, not placed; other
motions (MoveJ, MoveC, SpotJ ...) are reported as not simulated, everything else as ignored.

The reader follows `main` as the controller runs it (`export.flow`): RETURN, EXIT and EXITCYCLE
end it, Stop and Break stop it until it is started again (the verified cycle ends there), GOTO
continues at its label (a label is a statement of its own: the statement after it on the line, or
on the next line, is not part of it); a call of a PROC of the module or of the data module runs
its body in place (its ERROR, BACKWARD and UNDO handlers do not). A call of any other routine
(instructions that change no motion or flow aside, `_INERT`), a compact IF, WaitUntil, interrupts,
error handling, calls by name, and a jump, end or call inside IF / WHILE / FOR / TEST are
reported, never skipped. spot_weld, grip and release are the weld and gripper actions they name
while their PROC does nothing but ``WaitTime [\\InPos,]`` of its time parameter; the weld time is
the call's second argument, in s. Speeds: speeddata v_tcp in mm/s (v5000 is 5000 mm/s) times
VelSet's override, PTP speeds and accelerations as VelSet's and AccSet's percentages (rebuild
reports them above 100 %, and lines above the cell's line speed).
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Callable, Sequence
from functools import lru_cache

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedInput

from robomax_py.errors import ControllerSetupError, ExportError, ProgramError
from robomax_py.export.dialect import (
    Parsed,
    PlannedProgram,
    gripper_label,
    header_lines,
    is_header_comment,
    read_gripper,
    read_header,
    read_spot_label,
    require_six_axes,
    spot_label,
    tree_numbers,
    with_brand_configs,
    with_package_welds,
    with_tcp_blends,
)
from robomax_py.export.flow import Flow, Routine, Statement, follow
from robomax_py.export.plan_program import identifier
from robomax_py.export.quaternions import quaternion_from_zyx, zyx_from_quaternion
from robomax_py.program import (
    NULL_FRAME,
    UNSET_FRAME,
    Comment,
    FrameDef,
    Gripper,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    Spot,
    Wait,
    WaitFor,
    pose_mm_zyx,
)
from robomax_py.robot import RobotModel

__all__ = ["FRAMES_FILE", "adapt", "parse", "write"]

# The data module declaring the program's tooldata and wobjdata (a companion of `<name>.mod`).
FRAMES_FILE = "_frames.mod"

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
        out.append(ins)
    # RAPID refers to data by name: the frames carry no slot number.
    frames = tuple(dataclasses.replace(f, number=0) for f in program.frames if (f.kind, f.name) not in existing)
    program = with_package_welds(dataclasses.replace(program, frames=frames, instructions=tuple(out)), "RAPID")
    _check_weld_data_names(program)
    program = with_brand_configs(program, planned.joints, robot, "abb")
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


def _frames_module(program: Program) -> str:
    """The data module declaring the frames the program uses and does not find on the controller."""
    lines = ["%%%", "  VERSION:1", "  LANGUAGE:ENGLISH", "%%%", "", f"MODULE {program.name}_frames"]
    lines += [f"  ! {text}" for text in header_lines(program.header)]
    lines.append(f"  ! the frames {program.name} uses: load with it, or compare with the calibrated ones "
                 "(mm, quaternions [w, x, y, z]; work objects in the robot base frame, which is the world)")
    for f in program.frames:
        if f.kind == "tool":
            # tload: a 1 kg point load at the TCP (centre of gravity in the wrist frame, no inertia).
            lines.append(f"  PERS tooldata {f.name} := [TRUE, [{_xyz(f.xyz_mm)}, {_q(f.zyx_deg)}], "
                         f"[1, {_xyz(f.xyz_mm)}, [1, 0, 0, 0], 0, 0, 0]];  "
                         "! load: 1 kg at the TCP, a placeholder: replace with the gun's (LoadIdentify)")
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


# ================================================================================== reading

_GRAMMAR = r"""
?start: decl | move | velset | accset | waittime | waitdi | weld | gripper
decl: ("CONST"i | "PERS"i | "VAR"i) NAME NAME (":=" value)?
move: MOVE arg ("," arg | opt)*
velset: "VelSet"i NUMBER "," NUMBER
accset: "AccSet"i NUMBER "," NUMBER ("\\" NAME ":=" NUMBER)?
waittime: "WaitTime"i ("\\" NAME ",")? NUMBER
waitdi: "WaitDI"i NAME "," NUMBER ("\\" NAME (":=" value)?)*
weld: "spot_weld"i NUMBER "," NUMBER
gripper: GRIPPER NUMBER "," NUMBER
?arg: value | opt
opt: "\\" NAME (":=" value)?
?value: NUMBER | NAME | STRING | list | BOOL
list: "[" [value ("," value)*] "]"
MOVE.2: /(MoveAbsJ|MoveL|SpotL)\b/i
GRIPPER.2: /(grip|release)\b/i
BOOL.2: /(TRUE|FALSE)\b/i
NAME: /[A-Za-z_][A-Za-z0-9_]*/
STRING: /"[^"]*"/
NUMBER: /[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?/
%ignore /[ \t\r\n]+/
"""

_UNSIMULATED = re.compile(r"^(MoveJ|MoveC|MoveLDO|MoveJDO|MoveLSync|MoveJSync|MoveCSync|MoveExtJ|SearchL|SearchC|"
                          r"TriggL|TriggJ|TriggC|MoveLRel|MoveAbsJDO|MoveAbsJSync|SpotJ|SpotML|SpotMJ)\b", re.I)
_KNOWN = re.compile(r"^(MoveAbsJ|MoveL|SpotL|VelSet|AccSet|WaitTime|WaitDI|spot_weld|grip|release)\b", re.I)
# Lines that end a statement without ';': routine heads and ends, a routine's handler sections,
# and control-flow lines.
_HEADLINE = re.compile(r"^(MODULE|ENDMODULE|(LOCAL\s+)?PROC|ENDPROC|(LOCAL\s+)?FUNC|ENDFUNC|(LOCAL\s+)?TRAP|ENDTRAP|"
                       r"ERROR|BACKWARD|UNDO)\b", re.I)
# A label `name:` opening a line (RAPID reference, GOTO: "GOTO next; ... next:"); a statement may
# follow it on the same line. CASE ...: and DEFAULT: open a TEST's branches instead.
_LABEL = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*:(?!=)\s*(.*)$")
_OPENS = re.compile(r"\b(THEN|DO)\s*$|^(TEST\b.*|ELSE|DEFAULT\s*:|CASE\b.*:)\s*$", re.I)
_CLOSES = re.compile(r"^(ENDIF|ENDWHILE|ENDFOR|ENDTEST|ELSE)\s*$", re.I)
# The declarations the motion depends on (spotdata: a package weld's schedule); others (num,
# confdata, syncident, arrays ...) are ignored.
_MOTION_DATA = re.compile(r"^((LOCAL|TASK)\s+)*(CONST|PERS|VAR)\s+(robtarget|jointtarget|speeddata|zonedata|tooldata|wobjdata|spotdata)\b",
                          re.I)
_PREDEFINED_SPEED = re.compile(r"^v([0-9]+)$", re.I)
_PREDEFINED_ZONE = re.compile(r"^z([0-9]+)$", re.I)
# The spot option's gundata of gun n (`gun_data`); another name leaves the gun unknown (0).
_GUN_DATA = re.compile(r"^gun([0-9]+)$", re.IGNORECASE)


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return Lark(_GRAMMAR, parser="lalr", lexer="contextual")


def _statements(text: str) -> list[tuple[int, str, str]]:
    """(line, statement, comment) for every ';'-terminated statement; comment lines as ("", text)."""
    out: list[tuple[int, str, str]] = []
    pending: list[str] = []
    start = 0
    for number, raw in enumerate(text.splitlines(), start=1):
        if re.match(r"^\s*(%%%|VERSION:|LANGUAGE:)", raw):
            continue
        code, comment = _split_comment(raw)
        if not code.strip():
            if comment is not None and not pending:
                out.append((number, "", comment))
            continue
        label = _LABEL.match(code) if not pending else None
        if label and label.group(1).upper() not in ("DEFAULT", "CASE"):
            # A label is a statement of its own: the statement after it is not part of it.
            out.append((number, f"{label.group(1)}:", comment or "" if not label.group(2).strip() else ""))
            code = label.group(2)
            if not code.strip():
                continue
        if not pending:
            start = number
        pending.append(code)
        joined = " ".join(pending).strip()
        if joined.endswith(";") or _HEADLINE.match(joined) or _OPENS.search(joined) or _CLOSES.match(joined):
            out.append((start, joined.rstrip(";").strip(), comment or ""))
            pending = []
    return out


def _split_comment(raw: str) -> tuple[str, str | None]:
    in_string = False
    for i, c in enumerate(raw):
        if c == '"':
            in_string = not in_string
        elif c == "!" and not in_string:
            return raw[:i], raw[i + 1:].strip()
    return raw, None


class _Reader:
    def __init__(self, file: str) -> None:
        self.file = file
        self.data: dict[str, tuple[str, object, int]] = {}   # name -> (type, value, line)
        self.instructions: list[Instruction] = []
        self.lines: list[int] = []
        self.ignored: list[tuple[int, str]] = []
        self.frames: list[FrameDef] = []
        self.override = 100.0
        self.accel = 100.0
        self.depth = 0                        # of IF / WHILE / FOR / TEST blocks
        self.package_welds = 0

    def error(self, line: int, problem: str) -> ProgramError:
        return ProgramError(self.file, f"line {line}", problem)

    def add(self, ins: Instruction, line: int) -> None:
        self.instructions.append(ins)
        self.lines.append(line)

    def tree(self, text: str, line: int) -> Tree[Token]:
        try:
            return _parser().parse(text)
        except UnexpectedInput as exc:
            raise self.error(line, f"cannot read {text!r} (column {getattr(exc, 'column', '?')})") from None

    def quaternion(self, node: object, line: int) -> tuple[float, float, float]:
        q = tree_numbers(node, self.file, line)
        if len(q) != 4:
            raise self.error(line, f"an orientation needs 4 quaternion values, got {len(q)}")
        norm = math.sqrt(sum(v * v for v in q))
        if abs(norm - 1.0) > UNIT_QUATERNION_TOL:
            raise self.error(line, f"quaternion {q} is not unit (norm {norm:.9f}; at most {UNIT_QUATERNION_TOL:g} from 1)")
        return zyx_from_quaternion(tuple(q))

    def pose(self, node: object, line: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
        if not (isinstance(node, Tree) and node.data == "list" and len(node.children) >= 2):
            raise self.error(line, "a frame needs [[x, y, z], [q1, q2, q3, q4]]")
        xyz = tree_numbers(node.children[0], self.file, line)
        if len(xyz) != 3:
            raise self.error(line, f"a position needs 3 values, got {len(xyz)}")
        return tuple(xyz), self.quaternion(node.children[1], line)

    def declare(self, tree: Tree[Token], comment: str, line: int) -> None:
        kind, name, *rest = tree.children
        value = rest[0] if rest else None
        kind_l = str(kind).lower()
        self.data[str(name).lower()] = (kind_l, value, line)
        if kind_l == "tooldata" and isinstance(value, Tree) and len(value.children) >= 2:
            xyz, zyx = self.pose(value.children[1], line)
            self.declare_frame(FrameDef(str(name), "tool", xyz, zyx))
        elif kind_l == "wobjdata" and isinstance(value, Tree) and len(value.children) >= 5:
            robhold, ufprog, ufmec = (str(v).strip('"').upper() for v in value.children[:3])
            if robhold == "TRUE" or ufprog == "FALSE" or ufmec:
                # Held by the robot or moved by a mechanical unit: not a fixed frame this reader places.
                self.ignored.append((line, f"wobjdata {name}: a moving work object (robhold, ufprog, ufmec)"))
                return
            # The work object's frame in the world (= the robot base): uframe · oframe.
            uframe = FrameDef("", "base", *self.pose(value.children[3], line)).pose
            oframe = FrameDef("", "base", *self.pose(value.children[4], line)).pose
            xyz, zyx = pose_mm_zyx(uframe @ oframe)
            self.declare_frame(FrameDef(str(name), "base", xyz, zyx))

    def declare_frame(self, frame: FrameDef) -> None:
        self.frames = [f for f in self.frames if (f.kind, f.name.lower()) != (frame.kind, frame.name.lower())]
        self.frames.append(frame)

    def resolve(self, node: object, kind: str, line: int) -> object:
        if isinstance(node, Token) and node.type == "NAME":
            entry = self.data.get(str(node).lower())
            if entry is None:
                raise self.error(line, f"{node} is not declared in the module")
            if entry[0] != kind:
                raise self.error(line, f"{node} is a {entry[0]}, expected a {kind}")
            if entry[1] is None:
                raise self.error(line, f"{node} is declared without a value (line {entry[2]})")
            return entry[1]
        return node

    def speed(self, node: object, line: int) -> float | None:
        """v_tcp (mm/s) of a speeddata; None for vmax."""
        if isinstance(node, Token) and node.type == "NAME":
            if str(node).lower() == "vmax":
                return None
            match = _PREDEFINED_SPEED.match(str(node))
            if match and str(node).lower() not in self.data:
                return float(match.group(1))
        values = tree_numbers(self.resolve(node, "speeddata", line), self.file, line)
        return values[0]

    def zone(self, node: object, line: int) -> float:
        if isinstance(node, Token) and node.type == "NAME":
            if str(node).lower() == "fine":
                return 0.0
            match = _PREDEFINED_ZONE.match(str(node))
            if match and str(node).lower() not in self.data:
                return float(match.group(1))
        value = self.resolve(node, "zonedata", line)
        if isinstance(value, Tree) and len(value.children) >= 2:
            fine = str(value.children[0]).upper() == "TRUE"
            return 0.0 if fine else tree_numbers(value.children[1], self.file, line)[0]
        raise self.error(line, f"cannot read zone {node}")

    def move(self, tree: Tree[Token], comment: str, line: int) -> None:
        kind = str(tree.children[0]).lower()
        args = [c for c in tree.children[1:] if not (isinstance(c, Tree) and c.data == "opt")]
        if kind == "spotl":
            self.spot_move(tree, args, comment, line)
            return
        if len(args) < 3:
            raise self.error(line, f"{tree.children[0]} needs a target, a speed and a zone")
        target, speed, zone = args[0], args[1], args[2]
        flyby_mm = self.zone(zone, line)
        v = self.speed(speed, line)
        if kind == "moveabsj":
            value = self.resolve(target, "jointtarget", line)
            if not (isinstance(value, Tree) and value.children):
                raise self.error(line, "a jointtarget needs [[j1, ..., j6], [external axes]]")
            joints = tree_numbers(value.children[0], self.file, line)
            self.add(PtpMove(tuple(joints), self.override / 100.0, self.accel / 100.0, comment=comment,
                             flyby_mm=flyby_mm), line)
            return
        tool = args[3] if len(args) > 3 else None
        if not (isinstance(tool, Token) and tool.type == "NAME"):
            raise self.error(line, "a MoveL names its tooldata after the zone")
        self.add(self.line_to(tree, target, v, tool, line, comment, flyby_mm), line)

    def line_to(self, tree: Tree[Token], target: object, v: float | None, tool: Token, line: int, comment: str,
                flyby_mm: float) -> LinMove:
        """The line to a robtarget with the tool and work object (\\WObj) the statement names."""
        wobj = next((o.children[1] for o in tree.children[1:] if isinstance(o, Tree) and o.data == "opt"
                     and str(o.children[0]).lower() == "wobj" and len(o.children) > 1), None)
        if wobj is not None and not (isinstance(wobj, Token) and wobj.type == "NAME"):
            raise self.error(line, "\\WObj names a wobjdata")
        tool_name = NULL_FRAME if str(tool).lower() == "tool0" else self.frame_ref("tool", str(tool))
        base_name = NULL_FRAME if wobj is None or str(wobj).lower() == "wobj0" else self.frame_ref("base", str(wobj))
        value = self.resolve(target, "robtarget", line)
        if not (isinstance(value, Tree) and len(value.children) >= 3):
            raise self.error(line, "a robtarget needs [[x, y, z], [q1, q2, q3, q4], [confdata], [external axes]]")
        xyz, zyx = self.pose(value, line)
        conf = [int(round(c)) for c in tree_numbers(value.children[2], self.file, line)]
        config = "[" + ",".join(str(c) for c in conf) + "]"
        v_tcp = VMAX_TCP_MM_S if v is None else v
        return LinMove(xyz, zyx, config, v_tcp * self.override / 100.0, comment=comment, flyby_mm=flyby_mm,
                       accel=self.accel / 100.0, tool=tool_name, base=base_name)

    def spot_move(self, tree: Tree[Token], args: Sequence[object], comment: str, line: int) -> None:
        """SpotL ToPoint, Speed, Spot, Gun, Tool [\\WObj]: a line to the spot, stopping there (the
        weld starts at the end position), then the weld of the spotdata's program number with the
        gun the gundata names (`gun_data`); the comment names the spot."""
        if len(args) != 5:
            raise self.error(line, f"SpotL needs ToPoint, Speed, Spot, Gun and Tool, got {len(args)} arguments")
        target, speed, spot, gun, tool = args
        if not (isinstance(tool, Token) and tool.type == "NAME" and isinstance(gun, Token) and gun.type == "NAME"):
            raise self.error(line, "SpotL names its gundata and tooldata")
        values = tree_numbers(self.resolve(spot, "spotdata", line), self.file, line)
        if not values or values[0] != int(values[0]) or values[0] < 0:
            raise self.error(line, f"spotdata {spot}: its first value is the weld program number, got {values[:1]}")
        match = _GUN_DATA.match(str(gun))
        self.add(self.line_to(tree, target, self.speed(speed, line), tool, line, "", 0.0), line)
        self.package_welds += 1
        named = read_spot_label(comment, self.package_welds, 0.0, self.file, line)
        self.add(dataclasses.replace(named, gun=int(match.group(1)) if match else 0, schedule=int(values[0]),
                                     package=True), line)

    def frame_ref(self, kind: str, name: str) -> str:
        """A frame named by a move, spelt as declared (RAPID names are case-insensitive)."""
        return next((f.name for f in self.frames if f.kind == kind and f.name.lower() == name.lower()), name)

    def statement(self, text: str, comment: str, line: int) -> None:
        if _CLOSES.match(text) and not text.upper().startswith("ELSE"):
            self.depth = max(0, self.depth - 1)
            return
        if re.match(r"^(IF|WHILE|FOR|TEST)\b", text, re.I) and (_OPENS.search(text) or text.upper().startswith("TEST")):
            self.depth += 1
            self.ignored.append((line, text))
            return
        if _MOTION_DATA.match(text):
            self.declare(self.tree(re.sub(r"^((LOCAL|TASK)\s+)*", "", text, flags=re.I), line), comment, line)
            return
        conditional = self.depth > 0 and (_KNOWN.match(text) or _UNSIMULATED.match(text))
        if _UNSIMULATED.match(text) or conditional:
            # A motion inside IF / WHILE / FOR / TEST: the reader does not follow control flow.
            self.ignored.append((line, text))
            self.add(Comment(f"not simulated: {text}"), line)
            return
        if not _KNOWN.match(text):
            self.ignored.append((line, text))
            return
        tree = self.tree(text, line)
        if tree.data == "move":
            self.move(tree, comment, line)
        elif tree.data == "velset":
            self.override = float(str(tree.children[0]))
        elif tree.data == "accset":
            self.accel = float(str(tree.children[0]))
        elif tree.data == "waittime":
            self.add(Wait(float(str(tree.children[-1]))), line)
        elif tree.data == "waitdi":
            if float(str(tree.children[1])) != 1.0:
                self.ignored.append((line, text))
                self.add(Comment(f"not simulated: {text} (waits for the input to be 0)"), line)
            else:
                self.add(WaitFor(str(tree.children[0])), line)
        elif tree.data == "weld":
            n, seconds = (float(str(t)) for t in tree.children)
            self.add(read_spot_label(comment, int(n), seconds, self.file, line), line)
        elif tree.data == "gripper":
            action, number, held_s = (str(t) for t in tree.children)
            self.add(read_gripper(action.lower(), comment, int(float(number)), float(held_s), self.file, line), line)


# ------------------------------------------------------------------ control flow

# What RAPID statements do to the flow (ABB, RAPID Reference Manual, instructions RETURN, EXIT,
# EXITCYCLE, Stop, Break, GOTO and the labels it jumps to; procedure calls "Name arg, ...;"; the
# handlers after ERROR / BACKWARD / UNDO run only on an error, a backward step or an undo). Stop
# and Break stop the program until it is started again (RoboDK's IRC5 post writes `STOP;` to
# "Pause the robot program", ros-industrial-attic/robodk_postprocessors@d7e6c1c0
# ABB_RAPID_IRC5.py:381-386); flow.py: a pause ends the verified cycle.
_PROC_HEAD = re.compile(r"^(?:LOCAL\s+)?PROC\s+([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*$", re.IGNORECASE)
_FUNC_HEAD = re.compile(r"^(?:LOCAL\s+)?(FUNC|TRAP)\s+(?:[A-Za-z_]\w*\s+)?([A-Za-z_][A-Za-z0-9_]*)\b", re.IGNORECASE)
_HANDLER = re.compile(r"^(ERROR|BACKWARD|UNDO)\b", re.IGNORECASE)
_BLOCK_OPEN = re.compile(r"^((IF|WHILE|FOR)\b.*\b(THEN|DO)|TEST\b.*)$", re.IGNORECASE)
_BLOCK_CLOSE = re.compile(r"^(ENDIF|ENDWHILE|ENDFOR|ENDTEST)$", re.IGNORECASE)
# Instructions that change no motion and no flow: outputs, FlexPendant text, counters and clocks,
# configuration and singularity handling (the lines keep their configuration in robomax's
# rebuild, which checks it), the gripped load, the trigger data TriggL uses (TriggL itself is not
# simulated).
_INERT = frozenset(s.lower() for s in (
    "SetDO", "SetAO", "SetGO", "Set", "Reset", "PulseDO", "InvertDO", "TPWrite", "TPErase", "ErrWrite", "Incr", "Decr",
    "Add", "Clear", "ClkStart", "ClkStop", "ClkReset", "ConfJ", "ConfL", "SingArea", "GripLoad", "TriggIO",
    "TriggEquip", "TriggInt"))
# The default routines whose call is a weld or a gripper action (their bodies rest their time).
_REST_ROUTINES = frozenset({"spot_weld", "grip", "release"})


def _params(text: str) -> tuple[str, ...]:
    """A PROC's parameter names: `num n, num weld_time` -> ("n", "weld_time")."""
    return tuple(part.split()[-1].lstrip("\\") for part in re.split(r"[,|]", text) if part.split())


def _classifier(functions: set[str]) -> Callable[[Statement], Flow]:
    """What a RAPID statement does to the flow; `functions`: the FUNCs the texts define (lower
    case), whose calls in expressions run their bodies (not followed: reported)."""
    def classify(st: Statement) -> Flow:
        text = st.text
        if not text:
            return Flow()
        word = re.match(r"^%|^[A-Za-z_][A-Za-z0-9_]*", text)
        first = word.group(0).lower() if word else ""
        if first == "return":
            return Flow("end", "RETURN")
        if first in ("exit", "exitcycle"):
            return Flow("end", text, scope="program")
        if first in ("stop", "break"):
            return Flow("end", text, scope="program", pause=True)
        if first == "goto":
            target = re.fullmatch(r"GOTO\s+([A-Za-z_][A-Za-z0-9_]*)", text, re.IGNORECASE)
            return Flow("goto", target.group(1)) if target else Flow("unsupported", why="a jump to an expression")
        label = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*):", text)
        if label:
            return Flow("label", label.group(1))
        if _BLOCK_OPEN.match(text):
            return Flow("open")
        if _BLOCK_CLOSE.match(text):
            return Flow("close")
        if first == "if":
            return Flow("unsupported", why="a statement under a condition (IF without THEN)")
        if first in ("else", "elseif", "case", "default"):
            return Flow()
        if first in ("raise", "retry", "trynext", "callbyvar", "%", "connect", "waituntil", "stopmove", "startmove"):
            return Flow("unsupported", why={"connect": "an interrupt: its TRAP runs whenever its signal changes",
                                            "waituntil": "a wait for a condition",
                                            "stopmove": "the robot waits for StartMove",
                                            "startmove": "the robot waits for StartMove"}.get(
                                                first, "error handling or a call by name"))
        if _MOTION_DATA.match(text) or re.match(r"^((LOCAL|TASK)\s+)*(CONST|PERS|VAR)\b", text, re.IGNORECASE):
            return Flow()
        assign = re.match(r"^[A-Za-z_][\w.{}\[\], ]*:=(.*)$", text)
        if assign:
            for name in re.findall(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(", assign.group(1)):
                if name.lower() in functions:
                    return Flow("unsupported", why=f"a call of {name}, a function of the program (not followed)")
            return Flow()
        if _KNOWN.match(text) or _UNSIMULATED.match(text) or first in _INERT:
            return Flow()
        rest = text[len(first):].strip()
        return Flow("call", word.group(0) if word else text, arguments=bool(rest))
    return classify


def _routines(text: str, source: str) -> list[Routine]:
    """The PROCs of a module text (a FUNC's or TRAP's body is not a procedure), each without its
    ERROR / BACKWARD / UNDO handler."""
    out: list[Routine] = []
    head: tuple[str, tuple[str, ...]] | None = None
    body: list[Statement] = []
    handler = False
    for line, stmt, comment in _statements(text):
        proc = _PROC_HEAD.match(stmt)
        if proc:
            head, body, handler = (proc.group(1), _params(proc.group(2))), [], False
            continue
        if re.match(r"^END(PROC|FUNC|TRAP)\b", stmt, re.IGNORECASE):
            if head is not None:
                out.append(Routine(head[0], tuple(body), head[1], source))
            head = None
            continue
        if head is None:
            continue
        if _HANDLER.match(stmt):
            handler = True
        if not handler:
            body.append(Statement(line, stmt, comment, source=source))
    return out


def _not_resting(routine: Routine) -> list[tuple[int, str, str]]:
    """(line, statement, why) of what a default routine (spot_weld, grip, release) does besides
    resting for its second parameter: comments and one `WaitTime [\\InPos,] <it>` (the routine
    `write` gives); anything else (a motion, another time, another unit) is reported."""
    time = routine.params[1] if len(routine.params) == 2 else None
    waits = 0
    out: list[tuple[int, str, str]] = []
    for st in routine.body:
        wait = re.fullmatch(r"WaitTime\s+(\\InPos\s*,\s*)?([A-Za-z_]\w*)", st.text, re.IGNORECASE)
        if not st.text:
            continue
        if wait and time is not None and wait.group(2).lower() == time.lower() and waits == 0:
            waits += 1
            continue
        out.append((st.line, st.text, (f"{routine.name}: a weld or gripper routine that does more than rest its time "
                                       "(verify takes a call of it for the weld or action it names)")))
    if waits == 0:
        line = routine.body[0].line if routine.body else 0
        out.append((line, routine.name, f"{routine.name}: it does not rest its time (WaitTime of its second parameter)"))
    return out


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """A RAPID module's motion (the `main` procedure, else the first one)."""
    reader = _Reader(file)
    for line, stmt, comment in _statements(texts.get(FRAMES_FILE, "")):
        if _MOTION_DATA.match(stmt):
            reader.statement(stmt, comment, line)
    module = ""
    header_comments: list[str] = []
    in_routine = False
    for line, stmt, comment in _statements(texts.get(".mod", "")):
        head = re.match(r"^MODULE\s+([A-Za-z_][A-Za-z0-9_]*)", stmt, re.IGNORECASE)
        if head:
            module = head.group(1)
            continue
        if _PROC_HEAD.match(stmt) or _FUNC_HEAD.match(stmt):
            in_routine = True
            continue
        if re.match(r"^END(PROC|FUNC|TRAP)\b", stmt, re.IGNORECASE):
            in_routine = False
            continue
        if in_routine:
            continue
        if stmt:
            reader.statement(stmt, comment, line)
        elif is_header_comment(comment) or comment.startswith(_NOTE):
            header_comments.append(comment)
    if not module:
        raise ProgramError(file, None, "no MODULE line: not a RAPID module")
    routines = _routines(texts.get(".mod", ""), "")
    defined = {r.name.lower(): r for r in [*_routines(texts.get(FRAMES_FILE, ""), FRAMES_FILE), *routines]}
    main = next((r for r in routines if r.name.lower() == "main"), None) or next(
        (r for r in routines if r.name.lower() not in _REST_ROUTINES), None)
    if main is None:
        raise ProgramError(file, None, "the module has no PROC main()")
    functions = {m.group(2).lower() for _, stmt, _ in _statements(texts.get(".mod", ""))
                 for m in [_FUNC_HEAD.match(stmt)] if m}
    followed = follow(main, defined, _classifier(functions))
    for step in followed.steps:
        st, line = step.statement, step.line
        if step.unsupported:
            reader.ignored.append((line, st.text))
            reader.add(Comment(f"not simulated: {st.text} ({step.unsupported})"), line)
        elif st.text:
            reader.statement(st.text, st.comment, line)
        else:
            reader.add(Comment(st.comment), line)
    for routine in routines:
        if routine.name.lower() in _REST_ROUTINES:
            for line, text, why in _not_resting(routine):
                reader.ignored.append((line, text))
                reader.add(Comment(f"not simulated: {text} ({why})"), line)
    header = read_header(header_comments)
    return Parsed(Program(module, header, tuple(reader.frames), tuple(reader.instructions)), tuple(reader.lines),
                  "abb", tuple(reader.ignored), tuple(followed.problems))
