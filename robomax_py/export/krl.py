"""KUKA KRL (KSS 8.x), both directions: `<name>.src` (the motion) and `<name>.dat` (its points).

What a program states, in KRL's own terms:
- joint targets as E6AXIS (deg), Cartesian targets as E6POS: X, Y, Z mm; A, B, C deg with
  R = Rz(A)·Ry(B)·Rx(C); S and T the KUKA Status and Turn of the planned configuration (SPEC §6);
- frames selected by number before the first Cartesian motion, as the controller stores them:
  `$TOOL = TOOL_DATA[t]` and `$BASE = BASE_DATA[b]`, or `$BASE = $NULLFRAME` when the targets are
  in the robot base frame itself. With factory settings `$ROBROOT` = `$WORLD` (the controller knows
  nothing of the cell), so `$BASE` is the user frame in the robot base frame and a target's TCP
  pose in the robot base frame is `$BASE` · target; the robot's placement in the cell is never
  written. The frames' values go into a setup program `<name>_frames.src` (`TOOL_DATA[t] = {...}`,
  `BASE_DATA[b] = {...}`) that the integrator runs once or compares with the calibrated values;
  KSS declares TOOL_DATA[16] and BASE_DATA[32] in $config.dat;
- `$VEL_AXIS[i]` / `$ACC_AXIS[i]` in whole percent for PTP, `$VEL.CP` in m/s for LIN (and
  `$ACC_AXIS[i]`, which this subset applies to a LIN's axes too, as KSS does for spline CP motions);
- blends as `C_DIS` with `$APO.CDIS` in mm, for PTP moves too, as KSS 8.2 and later write them
  from inline forms (`$APO.CPTP` is a whole percentage of half the move, too coarse to state the
  planned radius; `$APO.CDIS` is a REAL distance: KUKA.PLC mxAutomation manual, "APO" structure);
- a weld as an exact LIN to the spot followed by `spot_weld(n, weld_time) ; seam/name`, and
  `spot_weld` defined after the main program (rest for `weld_time`; the integrator replaces it);
- `WAIT SEC t`, and `WAIT FOR <signal>` with `SIGNAL <signal> $IN[k]` declared, k the input the
  cell maps the signal to (`robot.controller.inputs`).

The reader takes the motion subset of any KRL program: PTP and LIN to points declared in the
.dat or the .src, or written in place (E6AXIS/AXIS, E6POS/POS/FRAME aggregates, missing
components keeping their last value), `$VEL`, `$ACC`, `$APO` assignments, `C_DIS`/`C_PTP`,
`WAIT SEC`, `WAIT FOR` and calls of `spot_weld`, the frames in force at each motion (`$TOOL` /
`$BASE` set to literals, to `TOOL_DATA[n]` / `BASE_DATA[n]` or to `$NULLFRAME`; the values of
`TOOL_DATA` / `BASE_DATA` from a setup program when given); other motions (CIRC, SPTP, *_REL ...)
are reported as not simulated, everything else as ignored.
"""

from __future__ import annotations

import dataclasses
import math
import re
from functools import lru_cache

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedInput

from robomax_py.errors import ExportError, ProgramError
from robomax_py.export.dialect import (
    Parsed,
    PlannedProgram,
    gripper_label,
    header_lines,
    is_header_comment,
    numbered_frames,
    numbered_inputs,
    percent,
    read_gripper,
    read_header,
    read_spot_label,
    require_six_axes,
    spot_label,
    with_brand_configs,
    with_frame_names,
    with_tcp_blends,
)
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
)
from robomax_py.robot import RobotModel
from robomax_py.robot.ik.config import ConfigIndicator

__all__ = ["FRAMES_FILE", "adapt", "frame_name", "parse", "write"]

# The setup program holding the frames' values (a companion of `<name>.src`).
FRAMES_FILE = "_frames.src"
# KSS 8.x declares TOOL_DATA[16] and BASE_DATA[32] ($config.dat), and 4096 digital inputs.
TOOL_SLOTS, BASE_SLOTS, INPUTS = 16, 32, 4096

_NOTE = "KRL of KSS 8.x"
_AXES = ("A1", "A2", "A3", "A4", "A5", "A6")
_EXTERNAL = ", ".join(f"E{i} 0.0" for i in range(1, 7))


def frame_name(frame: FrameDef) -> str:
    """How KRL refers to a stored frame: `TOOL_DATA[n]` or `BASE_DATA[n]`."""
    return f"{'TOOL' if frame.kind == 'tool' else 'BASE'}_DATA[{frame.number}]"


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as KRL states it: frames by number, KUKA configuration data, TCP-distance
    blends, whole-percent PTP speeds and accelerations, waits on input numbers."""
    require_six_axes(robot, "KRL")
    numbered_frames(planned.program, "KRL", TOOL_SLOTS, BASE_SLOTS)
    numbered_inputs(planned.program, "KRL", 1, INPUTS)
    program = with_frame_names(planned.program, frame_name)
    program = with_brand_configs(program, planned.joints, robot, "kuka")
    program = with_tcp_blends(dataclasses.replace(planned, program=program), robot)
    out: list[Instruction] = []
    for ins in program.instructions:
        if isinstance(ins, PtpMove):
            ins = dataclasses.replace(ins, speed=percent(ins.speed) / 100, accel=percent(ins.accel) / 100)
        elif isinstance(ins, LinMove):
            ins = dataclasses.replace(ins, accel=percent(ins.accel) / 100)
        out.append(ins)
    return dataclasses.replace(program, instructions=tuple(out))


# ================================================================================== writing


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    """`.src` and `.dat` texts of an adapted program."""
    name = program.name
    src: list[str] = ["&ACCESS RVP", "&REL 1", f"DEF {name}( )"]
    src += [f"; {text}" for text in header_lines(program.header)]
    src.append(f"; {_NOTE}: mm, deg, $VEL.CP m/s, $VEL_AXIS and $ACC_AXIS %, blends C_DIS with $APO.CDIS mm")
    signals = _signals(program)
    src += [f"SIGNAL {sig} $IN[{k}]" for sig, k in signals.items()]
    dat: list[str] = [f"DEFDAT {name}", *(f"; {text}" for text in header_lines(program.header)),
                      f"; points of {name}.src"]
    # The frames are selected before the first motion (a PTP's C_DIS is a distance of the TCP too).
    first = next((i for i in program.instructions if isinstance(i, LinMove)), None)
    tool, base = (UNSET_FRAME, UNSET_FRAME) if first is None else (first.tool, first.base)
    if first is not None:
        src += [f"$TOOL = {tool or '$NULLFRAME'}", f"$BASE = {base or '$NULLFRAME'}"]
    speed = accel = None
    cp_speed = None
    lin_note = False
    apo = None
    n_point = n_weld = 0
    grips: dict[str, int] = {}
    for ins in program.instructions:
        if isinstance(ins, Comment):
            src.append(f"; {ins.text}" if ins.text else ";")
            continue
        if isinstance(ins, (PtpMove, LinMove)):
            n_point += 1
            point = f"XP{n_point}"
            if isinstance(ins, PtpMove):
                if ins.speed != speed:
                    speed = ins.speed
                    src += [f"$VEL_AXIS[{i}] = {percent(speed)}" for i in range(1, 7)]
                if ins.accel != accel:
                    accel = ins.accel
                    src += [f"$ACC_AXIS[{i}] = {percent(accel)}" for i in range(1, 7)]
                values = ", ".join(f"{a} {v:.4f}" for a, v in zip(_AXES, ins.target_deg))
                dat.append(f"DECL E6AXIS {point}={{{values}, {_EXTERNAL}}}")
            else:
                if ins.tool != tool:
                    tool = ins.tool
                    src.append(f"$TOOL = {tool or '$NULLFRAME'}")
                if ins.base != base:
                    base = ins.base
                    src.append(f"$BASE = {base or '$NULLFRAME'}")
                if ins.speed_mm_s != cp_speed:
                    cp_speed = ins.speed_mm_s
                    src.append(f"$VEL.CP = {cp_speed / 1000:.6f}")
                if ins.accel != (1.0 if accel is None else accel):
                    # Our subset's convention (as KSS for spline CP motions): $ACC_AXIS bounds
                    # the axes on a LIN too; a line carrying a part states its own. A classical
                    # LIN on the controller is bounded by $ACC.CP instead: the comment says so.
                    if ins.accel < 1.0 and not lin_note:
                        lin_note = True
                        dat.append("; LIN moves with $ACC_AXIS below 100 % carry a part: set $ACC.CP to its a_T too")
                    accel = ins.accel
                    src += [f"$ACC_AXIS[{i}] = {percent(accel)}" for i in range(1, 7)]
                dat.append(f"DECL E6POS {point}={_pose(ins)}")
            if ins.flyby_mm > 0 and ins.flyby_mm != apo:
                apo = ins.flyby_mm
                src.append(f"$APO.CDIS = {apo:.6f}")
            motion = "PTP" if isinstance(ins, PtpMove) else "LIN"
            line = f"{motion} {point}" + (" C_DIS" if ins.flyby_mm > 0 else "")
            src.append(line + (f" ; {ins.comment}" if ins.comment else ""))
        elif isinstance(ins, Spot):
            n_weld += 1
            src.append(f"spot_weld({n_weld}, {ins.time_s:.3f}) ; {spot_label(ins)}")
        elif isinstance(ins, Gripper):
            grips[ins.action] = grips.get(ins.action, 0) + 1
            src.append(f"{ins.action}({grips[ins.action]}, {ins.time_s:.3f}) ; {gripper_label(ins)}")
        elif isinstance(ins, Wait):
            src.append(f"WAIT SEC {ins.seconds:.3f}")
        elif isinstance(ins, WaitFor):
            src.append(f"WAIT FOR {ins.signal}")
        else:
            raise ExportError(f"KRL cannot write {type(ins).__name__}")
    if n_weld or not grips:
        src += ["END", "", "DEF spot_weld(n:IN, weld_time:IN)", "  INT n", "  REAL weld_time",
                "  ; default weld: rest for weld_time s; replace with the gun's technology package",
                "  WAIT SEC weld_time", "END"]
    else:
        src.append("END")
    for action in sorted(grips):
        src += ["", f"DEF {action}(n:IN, {action}_time:IN)", "  INT n", f"  REAL {action}_time",
                f"  ; default {action}: rest for {action}_time s; replace with the gripper's outputs and sensors",
                f"  WAIT SEC {action}_time", "END"]
    dat.append("ENDDAT")
    return {".src": "\n".join(src) + "\n", ".dat": "\n".join(dat) + "\n", FRAMES_FILE: _frames_program(program)}


def _frames_program(program: Program) -> str:
    """The setup program: the frames' values in the controller's TOOL_DATA / BASE_DATA."""
    lines = ["&ACCESS RVP", "&REL 1", f"DEF {program.name}_frames( )", *(f"; {t}" for t in header_lines(program.header)),
             f"; the frames {program.name}.src selects: run once to store them, or compare them with the calibrated ones",
             "; (mm, deg; BASE_DATA in the robot base frame, $ROBROOT = $WORLD)"]
    for f in program.frames:
        what = "tool (TCP in the flange frame)" if f.kind == "tool" else "user frame in the robot base frame"
        lines.append(f"{f.name} = {_frame(f.xyz_mm, f.zyx_deg)} ; {what}")
    lines.append("END")
    return "\n".join(lines) + "\n"


def _signals(program: Program) -> dict[str, int]:
    """Each waited-for signal and its input number (`numbered_inputs` has checked there is one)."""
    out: dict[str, int] = {}
    for ins in program.instructions:
        if isinstance(ins, WaitFor) and ins.signal not in out:
            out[ins.signal] = int(ins.number or 0)
    return out


def _frame(xyz: tuple[float, ...], zyx: tuple[float, ...]) -> str:
    x, y, z = xyz
    a, b, c = zyx
    return f"{{X {x:.3f}, Y {y:.3f}, Z {z:.3f}, A {a:.4f}, B {b:.4f}, C {c:.4f}}}"


def _pose(move: LinMove) -> str:
    x, y, z = move.position_mm
    a, b, c = move.zyx_deg
    ind = ConfigIndicator.parse(move.config)
    return (f"{{X {x:.3f}, Y {y:.3f}, Z {z:.3f}, A {a:.4f}, B {b:.4f}, C {c:.4f}, "
            f"S {ind.status}, T {ind.turn}, {_EXTERNAL}}}")


# ================================================================================== reading

_GRAMMAR = r"""
?start: motion | assign | frame_data | weld | gripper | wait_sec | wait_for | signal | decl
motion: MOTION target APPROX?
target: NAME | aggregate
aggregate: "{" (NAME ":")? [field ("," field)*] "}"
field: NAME value
?value: NUMBER | BITS | NAME
assign: SYSVAR ("." NAME)? ("[" NUMBER "]")? "=" (NUMBER | aggregate | SYSVAR | indexed)
indexed: NAME "[" NUMBER "]"
frame_data: NAME "[" NUMBER "]" "=" aggregate
weld: "spot_weld"i "(" NUMBER "," NUMBER ")"
gripper: GRIPPER "(" NUMBER "," NUMBER ")"
wait_sec: "WAIT"i "SEC"i NUMBER
wait_for: "WAIT"i "FOR"i (NAME | SYSVAR "[" NUMBER "]")
signal: "SIGNAL"i NAME SYSVAR "[" NUMBER "]"
decl: "DECL"i NAME NAME "=" aggregate

MOTION.2: /(PTP|LIN)\b/i
GRIPPER.2: /(grip|release)\b/i
APPROX.2: /C_(DIS|PTP|VEL|ORI)\b/i
SYSVAR: /\$[A-Za-z_][A-Za-z0-9_]*/
NAME: /[A-Za-z_][A-Za-z0-9_]*/
BITS: /'[Bb][01]+'/
NUMBER: /[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?/
%ignore /[ \t]+/
"""

# Motions KRL has that this reader does not simulate: a program with one is not verified clean.
_UNSIMULATED = re.compile(r"^(CIRC|SPTP|SLIN|SCIRC|PTP_REL|LIN_REL|CIRC_REL|SPTP_REL|SLIN_REL|SPLINE|PTP_SPLINE|RSI_MOVECORR)\b",
                          re.I)
_KNOWN = re.compile(r"^(PTP|LIN|\$|spot_weld\s*\(|(grip|release)\s*\(|WAIT\s+(SEC|FOR)\b|SIGNAL\b|"
                    r"DECL\s+(E6AXIS|AXIS|E6POS|POS|FRAME)\b|(TOOL|BASE)_DATA\s*\[)", re.I)


_BLOCK_START = re.compile(r"^(IF\b.*\bTHEN|LOOP|WHILE\b.*|FOR\b.*|REPEAT|SWITCH\b.*)$", re.I)
_BLOCK_END = re.compile(r"^(ENDIF|ENDLOOP|ENDWHILE|ENDFOR|UNTIL\b.*|ENDSWITCH)$", re.I)


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return Lark(_GRAMMAR, parser="lalr", lexer="contextual")


def _statement(text: str) -> tuple[str, str]:
    """A KRL line -> (statement, comment): the comment is what follows the first ';' outside quotes."""
    in_quote = False
    for i, c in enumerate(text):
        if c == "'":
            in_quote = not in_quote
        elif c == ";" and not in_quote:
            return text[:i].strip(), text[i + 1:].strip()
    return text.strip(), ""


class _Reader:
    def __init__(self, file: str, robot: RobotModel) -> None:
        self.file, self.robot = file, robot
        self.points: dict[str, dict[str, object]] = {}
        self.instructions: list[Instruction] = []
        self.lines: list[int] = []
        self.ignored: list[tuple[int, str]] = []
        self.frames: list[FrameDef] = []       # whose values the program's texts state
        self.tool, self.base = UNSET_FRAME, UNSET_FRAME    # in force: names of frames
        self.inputs: dict[str, int] = {}       # SIGNAL name -> $IN number
        self.vel_axis = [100.0] * 6
        self.acc_axis = [100.0] * 6
        self.vel_cp = 2.0                      # m/s, KSS default $VEL.CP
        self.cdis = 0.0
        self.depth = 0                         # of control-flow blocks
        self.last_axes: dict[str, float] = {}
        self.last_pose: dict[str, float] = {}

    def error(self, line: int, problem: str) -> ProgramError:
        return ProgramError(self.file, f"line {line}", problem)

    def tree(self, text: str, line: int) -> Tree[Token]:
        try:
            return _parser().parse(text)
        except UnexpectedInput as exc:
            raise self.error(line, f"cannot read {text!r} (column {getattr(exc, 'column', '?')})") from None

    def aggregate(self, node: Tree[Token], line: int) -> dict[str, object]:
        out: dict[str, object] = {}
        for f in node.children:
            if isinstance(f, Tree) and f.data == "field":
                key, value = f.children
                out[str(key).upper()] = self.value(value, line)
        return out

    def value(self, tok: object, line: int) -> object:
        text = str(tok)
        if isinstance(tok, Token) and tok.type == "BITS":
            return int(text[2:-1], 2)
        if isinstance(tok, Token) and tok.type == "NUMBER":
            value = float(text)
            if not math.isfinite(value):
                raise self.error(line, f"number {text} is not finite")
            return value
        return text

    def declare(self, text: str, line: int) -> None:
        tree = self.tree(text, line)
        _, name, agg = tree.children
        self.points[str(name).upper()] = self.aggregate(agg, line)

    def add(self, ins: Instruction, line: int) -> None:
        self.instructions.append(ins)
        self.lines.append(line)

    def statement(self, text: str, comment: str, line: int) -> None:
        if _BLOCK_END.match(text):
            self.depth = max(0, self.depth - 1)
            return
        if _BLOCK_START.match(text):
            self.depth += 1
            self.ignored.append((line, text))
            return
        if self.depth > 0 and (_UNSIMULATED.match(text) or _KNOWN.match(text)) and not text.upper().startswith("DECL"):
            # Inside IF / LOOP / WHILE / FOR / REPEAT / SWITCH: the reader does not follow control flow.
            self.ignored.append((line, text))
            self.add(Comment(f"not simulated: {text}"), line)
            return
        if _UNSIMULATED.match(text):
            self.ignored.append((line, text))
            self.add(Comment(f"not simulated: {text}"), line)
            return
        if not _KNOWN.match(text):
            self.ignored.append((line, text))
            return
        if text.upper().startswith("DECL"):
            self.declare(text, line)
            return
        tree = self.tree(text, line)
        getattr(self, "on_" + tree.data)(tree, comment, line)

    def on_signal(self, tree: Tree[Token], comment: str, line: int) -> None:
        name, var, number = tree.children
        if str(var).upper() == "$IN":
            self.inputs[str(name).upper()] = int(float(str(number)))

    def declare_frame(self, name: str, kind: str, node: Tree[Token], line: int, number: int = 0) -> None:
        """A frame's value as the program states it (missing components are 0, as in $NULLFRAME)."""
        agg = self.aggregate(node, line)
        xyz = tuple(float(agg.get(k, 0.0)) for k in "XYZ")       # type: ignore[arg-type]
        zyx = tuple(float(agg.get(k, 0.0)) for k in "ABC")       # type: ignore[arg-type]
        self.frames = [f for f in self.frames if (f.kind, f.name) != (kind, name)]
        self.frames.append(FrameDef(name, kind, xyz, zyx, number))      # type: ignore[arg-type]

    def on_frame_data(self, tree: Tree[Token], comment: str, line: int) -> None:
        """`TOOL_DATA[n] = {...}` / `BASE_DATA[n] = {...}`: the controller's stored frame n."""
        array, index, value = tree.children
        kind = {"TOOL_DATA": "tool", "BASE_DATA": "base"}.get(str(array).upper())
        if kind is None:
            self.ignored.append((line, f"{array}[{index}] = ..."))
            return
        n = int(float(str(index)))
        self.declare_frame(f"{str(array).upper()}[{n}]", kind, value, line, n)      # type: ignore[arg-type]

    def on_assign(self, tree: Tree[Token], comment: str, line: int) -> None:
        toks = [c for c in tree.children if isinstance(c, Token)]
        var = str(toks[0]).upper()
        member = str(toks[1]).upper() if len(toks) > 2 and toks[1].type == "NAME" else ""
        index = next((int(float(t)) for t in toks[1:-1] if t.type == "NUMBER"), None)
        rhs = tree.children[-1]
        number = float(rhs) if isinstance(rhs, Token) and rhs.type == "NUMBER" else None
        if var in ("$TOOL", "$BASE"):
            kind = "tool" if var == "$TOOL" else "base"
            if isinstance(rhs, Tree) and rhs.data == "aggregate":
                name = f"{var} of line {line}"
                self.declare_frame(name, kind, rhs, line)
            elif isinstance(rhs, Tree):                  # TOOL_DATA[n] / BASE_DATA[n]
                array, n = rhs.children
                name = f"{str(array).upper()}[{int(float(str(n)))}]"
            elif str(rhs).upper() == "$NULLFRAME":
                name = NULL_FRAME
            else:
                name = str(rhs).upper()                  # another variable: its value is not known here
            if kind == "tool":
                self.tool = name
            else:
                self.base = name
        elif number is None:
            return
        elif var in ("$VEL_AXIS", "$ACC_AXIS") and index is not None and 1 <= index <= 6:
            (self.vel_axis if var == "$VEL_AXIS" else self.acc_axis)[index - 1] = number
        elif var == "$VEL" and member == "CP":
            self.vel_cp = number
        elif var == "$APO" and member == "CDIS":
            self.cdis = number

    def on_motion(self, tree: Tree[Token], comment: str, line: int) -> None:
        kind = str(tree.children[0]).upper()
        target = tree.children[1]
        approx = str(tree.children[2]).upper() if len(tree.children) > 2 and tree.children[2] is not None else ""
        node = target.children[0]
        if isinstance(node, Token):
            key = str(node).upper()
            if key not in self.points:
                raise self.error(line, f"point {node} is not declared in the .dat or the .src")
            values = self.points[key]
        else:
            values = self.aggregate(node, line)
        flyby_mm = self.cdis if approx in ("C_DIS", "C_PTP", "C_VEL", "C_ORI") else 0.0
        if approx == "C_DIS" and self.cdis <= 0:
            flyby_mm = 0.0
        if kind == "PTP" and any(a in values for a in _AXES):
            self.last_axes.update({k: float(v) for k, v in values.items() if k in _AXES})  # type: ignore[arg-type]
            missing = [a for a in _AXES if a not in self.last_axes]
            if missing:
                raise self.error(line, f"the first joint target must give every axis; {', '.join(missing)} missing")
            speed = min(self.vel_axis) / 100.0
            accel = min(self.acc_axis) / 100.0
            self.add(PtpMove(tuple(self.last_axes[a] for a in _AXES), speed, accel, comment=comment,
                             flyby_mm=flyby_mm), line)
            return
        if kind == "PTP":
            raise self.error(line, "a PTP to a Cartesian point is not simulated: robomax programs state joint targets for PTP")
        self.last_pose.update({k: float(v) for k, v in values.items() if k in ("X", "Y", "Z", "A", "B", "C", "S", "T")})  # type: ignore[arg-type]
        missing = [k for k in "XYZABC" if k not in self.last_pose]
        if missing:
            raise self.error(line, f"the first Cartesian target must give {', '.join(missing)}")
        config = ""
        if "S" in values and "T" in values:
            config = str(ConfigIndicator(int(self.last_pose["S"]), int(self.last_pose["T"])))
        xyz = tuple(self.last_pose[k] for k in "XYZ")
        zyx = tuple(self.last_pose[k] for k in "ABC")
        self.add(LinMove(xyz, zyx, config, self.vel_cp * 1000.0, comment=comment, flyby_mm=flyby_mm,
                         accel=min(self.acc_axis) / 100.0, tool=self.tool, base=self.base), line)

    def on_weld(self, tree: Tree[Token], comment: str, line: int) -> None:
        n, seconds = (float(t) for t in tree.children)
        self.add(read_spot_label(comment, int(n), seconds, self.file, line), line)

    def on_gripper(self, tree: Tree[Token], comment: str, line: int) -> None:
        action, n, seconds = tree.children
        self.add(read_gripper(str(action).lower(), comment, int(float(n)), float(seconds), self.file, line), line)

    def on_wait_sec(self, tree: Tree[Token], comment: str, line: int) -> None:
        self.add(Wait(float(tree.children[0])), line)

    def on_wait_for(self, tree: Tree[Token], comment: str, line: int) -> None:
        """`WAIT FOR <signal>` (its SIGNAL declaration gives the input) or `WAIT FOR $IN[k]`."""
        if len(tree.children) == 1:
            name = str(tree.children[0])
            self.add(WaitFor(name, self.inputs.get(name.upper())), line)
            return
        var, number = tree.children
        if str(var).upper() != "$IN":
            self.ignored.append((line, f"WAIT FOR {var}[{number}]"))
            self.add(Comment(f"not simulated: WAIT FOR {var}[{number}]"), line)
            return
        k = int(float(str(number)))
        name = next((n for n, i in self.inputs.items() if i == k), f"IN_{k}")
        self.add(WaitFor(name, k), line)


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """A KRL program from its `.src` (and `.dat`, when given) texts."""
    reader = _Reader(file, robot)
    for number, raw in enumerate(texts.get(FRAMES_FILE, "").splitlines(), start=1):
        stmt, _ = _statement(raw)
        if re.match(r"^(TOOL|BASE)_DATA\s*\[", stmt, re.I):
            reader.statement(stmt, "", number)
    for raw in texts.get(".dat", "").splitlines():
        stmt, _ = _statement(raw)
        if re.match(r"^DECL\s+(E6AXIS|AXIS|E6POS|POS|FRAME)\b", stmt, re.I):
            reader.declare(stmt, 0)
    src = texts.get(".src", "").splitlines()
    main_name = ""
    in_main = False
    header_comments: list[str] = []
    for number, raw in enumerate(src, start=1):
        stmt, comment = _statement(raw)
        head = re.match(r"^(GLOBAL\s+)?DEF\s+([A-Za-z_][A-Za-z0-9_]*)\s*\(", stmt, re.I)
        if head:
            if main_name:
                break                                   # the main program ends; local routines follow
            main_name, in_main = head.group(2), True
            continue
        if not in_main or stmt.startswith("&"):
            continue
        if re.match(r"^END\b", stmt, re.I):
            in_main = False
            continue
        if not stmt:
            if raw.strip().startswith(";"):
                if is_header_comment(comment) or comment.startswith(_NOTE):
                    header_comments.append(comment)
                else:
                    reader.add(Comment(comment), number)
            continue
        reader.statement(stmt, comment, number)
    if not main_name:
        raise ProgramError(file, None, "no DEF line: not a KRL program")
    header = read_header(header_comments)
    instructions = reader.instructions
    return Parsed(Program(main_name, header, tuple(reader.frames), tuple(instructions)), tuple(reader.lines),
                  "kuka", tuple(reader.ignored))
