"""RAPID read: the reader and `parse`, a program from its module texts."""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Sequence

from lark import Token, Tree
from lark.exceptions import UnexpectedInput

from robomax_py.errors import ProgramError
from robomax_py.export.dialect import (
    Parsed,
    is_header_comment,
    read_gripper,
    read_header,
    read_spot_label,
    tree_numbers,
)
from robomax_py.export.flow import follow
from robomax_py.export.quaternions import zyx_from_quaternion
from robomax_py.export.rapid.flow import (
    _FUNC_HEAD,
    _PROC_HEAD,
    _REST_ROUTINES,
    _classifier,
    _not_resting,
    _routines,
)
from robomax_py.export.rapid.grammar import (
    _CLOSES,
    _GUN_DATA,
    _KNOWN,
    _MOTION_DATA,
    _OPENS,
    _PREDEFINED_SPEED,
    _PREDEFINED_ZONE,
    _TIMED_SET,
    _UNSIMULATED,
    _parser,
    _statements,
)
from robomax_py.export.rapid.write import (
    _NOTE,
    FRAMES_FILE,
    UNIT_QUATERNION_TOL,
    VMAX_TCP_MM_S,
)
from robomax_py.program import (
    NULL_FRAME,
    Comment,
    FrameDef,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Wait,
    WaitFor,
    pose_mm_zyx,
)
from robomax_py.robot import RobotModel


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
        if re.match(r"^(IF|WHILE|FOR|TEST)\b", text, re.IGNORECASE) and (_OPENS.search(text) or text.upper().startswith("TEST")):
            self.depth += 1
            self.ignored.append((line, text))
            return
        if _MOTION_DATA.match(text):
            self.declare(self.tree(re.sub(r"^((LOCAL|TASK)\s+)*", "", text, flags=re.IGNORECASE), line), comment, line)
            return
        conditional = self.depth > 0 and (_KNOWN.match(text) or _UNSIMULATED.match(text))
        if _UNSIMULATED.match(text) or _TIMED_SET.match(text) or conditional:
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
        elif tree.data == "setdo":
            # SetDO signal, value (RAPID instructions reference, SetDO): 1 sets, 0 resets.
            name, value = str(tree.children[0]), float(str(tree.children[1]))
            if value not in (0.0, 1.0):
                raise self.error(line, f"SetDO {name}, {tree.children[1]}: a digital output is 0 or 1")
            self.add(SetSignal(name, None, value == 1.0), line)
        elif tree.data == "setreset":
            # Set signal / Reset signal: SetDO signal, 1 / 0 (RAPID instructions reference, Set, Reset).
            self.add(SetSignal(str(tree.children[1]), None, str(tree.children[0]).lower() == "set"), line)
        elif tree.data == "weld":
            n, seconds = (float(str(t)) for t in tree.children)
            self.add(read_spot_label(comment, int(n), seconds, self.file, line), line)
        elif tree.data == "gripper":
            action, number, held_s = (str(t) for t in tree.children)
            self.add(read_gripper(action.lower(), comment, int(float(number)), float(held_s), self.file, line), line)


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
