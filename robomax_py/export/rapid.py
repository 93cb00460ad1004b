r"""ABB RAPID, both directions: one module `<name>.mod`.

What a program states, in RAPID's terms (RAPID Reference Manual, data types robtarget,
jointtarget, speeddata, zonedata, tooldata, wobjdata; instructions MoveAbsJ, MoveL, VelSet, AccSet):
- joint targets as `jointtarget` (deg), Cartesian targets as `robtarget`: [x, y, z] mm, a unit
  quaternion [q1, q2, q3, q4] with q1 = w, confdata [cf1, cf4, cf6, cfx] of the planned
  configuration (SPEC §6), external axes 9E9;
- every MoveL names its `tooldata` and, when the targets are in a user frame, its `wobjdata`
  (`\WObj:=`; without it RAPID uses wobj0). With factory settings the robot base frame is the
  world (the controller knows nothing of the cell), so a robtarget's TCP pose in the robot base
  frame is the work object's uframe · oframe · target; the robot's placement in the cell is never
  written. The frames' values are declared in a data module `<name>_frames.mod` (PERS tooldata,
  PERS wobjdata with oframe identity) that the integrator loads with the program; a tool or work
  object the cell names (`robot.controller`) exists on the controller and is not declared again;
- PTP moves as `MoveAbsJ ... vmax` under `VelSet` (the speed fraction, %) and `AccSet` (which holds
  for the `MoveL`s after it too, as on the controller); LIN moves as
  `MoveL` with a `speeddata` whose v_tcp is the planned TCP speed (mm/s, at `VelSet 100`);
- blends as `zonedata` with pzone_tcp the TCP distance (mm) of the planned radius (the other
  zone sizes in the proportions of ABB's predefined zones), `fine` at every stop and weld;
- a weld as `MoveL ... fine` followed by `spot_weld n, weld_time;  ! seam/name`, with `PROC
  spot_weld` defined in the module (rest for weld_time; the integrator replaces it);
- `WaitTime t;` and `WaitDI <signal>, 1;`, the signal named as the controller's I/O configuration
  names it (`robot.controller.inputs`, else the cell's signal name).

The tool's load is not known to robomax: tooldata carries a 1 kg load at the TCP that the
integrator must replace with the gun's (LoadIdentify). The reader takes the motion subset of any
module: MoveAbsJ and MoveL with declared or in-place targets, predefined and declared speed and
zone data, VelSet, AccSet, WaitTime, WaitDI and calls of spot_weld; other motions (MoveJ, MoveC ...)
are reported as not simulated, everything else as ignored.
"""

from __future__ import annotations

import dataclasses
import math
import re
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
    with_tcp_blends,
)
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
    cell names exist on the controller and are not declared), inputs by signal name."""
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
    program = dataclasses.replace(program, frames=frames, instructions=tuple(out))
    program = with_brand_configs(program, planned.joints, robot, "abb")
    return with_tcp_blends(dataclasses.replace(planned, program=program), robot)


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
            lines.append(f"  PERS tooldata {f.name} := [TRUE, [{_xyz(f.xyz_mm)}, {_q(f.zyx_deg)}], "
                         "[1, [0, 0, 0.001], [1, 0, 0, 0], 0, 0, 0]];  ! load: replace with the gun's (LoadIdentify)")
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
    override = accel = None
    n_point = n_weld = 0
    grips: dict[str, int] = {}
    for ins in program.instructions:
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
                body.append(f"    MoveL {name}, {speeds[ins.speed_mm_s]}, {zone}{_tail(ins.tool, ins.base)}{note}")
        elif isinstance(ins, Spot):
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
    lines += decl
    lines += ["", "  PROC main()", *body, "  ENDPROC"]
    if n_weld or not grips:
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
MOVE.2: /(MoveAbsJ|MoveL)\b/i
GRIPPER.2: /(grip|release)\b/i
BOOL.2: /(TRUE|FALSE)\b/i
NAME: /[A-Za-z_][A-Za-z0-9_]*/
STRING: /"[^"]*"/
NUMBER: /[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?/
%ignore /[ \t\r\n]+/
"""

_UNSIMULATED = re.compile(r"^(MoveJ|MoveC|MoveLDO|MoveJDO|MoveLSync|MoveJSync|MoveCSync|MoveExtJ|SearchL|SearchC|"
                          r"TriggL|TriggJ|TriggC|MoveLRel|MoveAbsJDO|MoveAbsJSync|SpotL|SpotJ)\b", re.I)
_KNOWN = re.compile(r"^(MoveAbsJ|MoveL|VelSet|AccSet|WaitTime|WaitDI|spot_weld|grip|release)\b", re.I)
# Lines that end a statement without ';': routine heads and ends, and control-flow lines.
_HEADLINE = re.compile(r"^(MODULE|ENDMODULE|(LOCAL\s+)?PROC|ENDPROC|(LOCAL\s+)?FUNC|ENDFUNC|(LOCAL\s+)?TRAP|ENDTRAP)\b", re.I)
_OPENS = re.compile(r"\b(THEN|DO)\s*$|^(TEST\b.*|ELSE|DEFAULT\s*:|CASE\b.*:)\s*$", re.I)
_CLOSES = re.compile(r"^(ENDIF|ENDWHILE|ENDFOR|ENDTEST|ELSE)\s*$", re.I)
# The declarations the motion depends on; others (num, confdata, syncident, arrays ...) are ignored.
_MOTION_DATA = re.compile(r"^((LOCAL|TASK)\s+)*(CONST|PERS|VAR)\s+(robtarget|jointtarget|speeddata|zonedata|tooldata|wobjdata)\b",
                          re.I)
_PREDEFINED_SPEED = re.compile(r"^v([0-9]+)$", re.I)
_PREDEFINED_ZONE = re.compile(r"^z([0-9]+)$", re.I)


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
        self.add(LinMove(xyz, zyx, config, v_tcp * self.override / 100.0, comment=comment, flyby_mm=flyby_mm,
                         accel=self.accel / 100.0, tool=tool_name, base=base_name), line)

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
            self.override = float(tree.children[0])
        elif tree.data == "accset":
            self.accel = float(tree.children[0])
        elif tree.data == "waittime":
            self.add(Wait(float(tree.children[-1])), line)
        elif tree.data == "waitdi":
            if float(tree.children[1]) != 1.0:
                self.ignored.append((line, text))
                self.add(Comment(f"not simulated: {text} (waits for the input to be 0)"), line)
            else:
                self.add(WaitFor(str(tree.children[0])), line)
        elif tree.data == "weld":
            n, seconds = (float(t) for t in tree.children)
            self.add(read_spot_label(comment, int(n), seconds, self.file, line), line)
        elif tree.data == "gripper":
            action, n, seconds = tree.children
            self.add(read_gripper(str(action).lower(), comment, int(float(n)), float(seconds), self.file, line), line)


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """A RAPID module's motion (the `main` procedure, else the first one)."""
    reader = _Reader(file)
    for line, stmt, comment in _statements(texts.get(FRAMES_FILE, "")):
        if _MOTION_DATA.match(stmt):
            reader.statement(stmt, comment, line)
    module = ""
    header_comments: list[str] = []
    procs: dict[str, list[tuple[int, str, str]]] = {}
    current: str | None = None
    for line, stmt, comment in _statements(texts.get(".mod", "")):
        head = re.match(r"^MODULE\s+([A-Za-z_][A-Za-z0-9_]*)", stmt, re.I)
        if head:
            module = head.group(1)
            continue
        proc = re.match(r"^(?:LOCAL\s+)?PROC\s+([A-Za-z_][A-Za-z0-9_]*)", stmt, re.I)
        if proc:
            current = proc.group(1).lower()
            procs[current] = []
            continue
        if re.match(r"^END(PROC|FUNC|TRAP)\b", stmt, re.I):
            current = None
            continue
        if current is not None:
            procs[current].append((line, stmt, comment))
        elif stmt:
            reader.statement(stmt, comment, line)
        elif is_header_comment(comment) or comment.startswith(_NOTE):
            header_comments.append(comment)
    if not module:
        raise ProgramError(file, None, "no MODULE line: not a RAPID module")
    main = procs.get("main") or next((body for name, body in procs.items()
                                      if name not in ("spot_weld", "grip", "release")), None)
    if main is None:
        raise ProgramError(file, None, "the module has no PROC main()")
    for line, stmt, comment in main:
        if stmt:
            reader.statement(stmt, comment, line)
        else:
            reader.add(Comment(comment), line)
    header = read_header(header_comments)
    return Parsed(Program(module, header, tuple(reader.frames), tuple(reader.instructions)), tuple(reader.lines),
                  "abb", tuple(reader.ignored))
