"""KRL read: the statements that set frames, move, weld, grip and wait, and `parse`, a program from its
texts."""

from __future__ import annotations

import re

from lark import Token, Tree

from robomax_py.errors import ProgramError
from robomax_py.export.dialect import (
    Parsed,
    is_header_comment,
    read_gripper,
    read_header,
    read_spot_label,
)
from robomax_py.export.flow import Routine, Statement, follow
from robomax_py.export.krl.flow import (
    _REST_ROUTINES,
    _classifier,
    _not_resting,
    _routines,
)
from robomax_py.export.krl.grammar import _SPLINE_SEGMENT, _statement
from robomax_py.export.krl.reader import _DataReader
from robomax_py.export.krl.write import (
    _AXES,
    _DATA_TYPES,
    _NAME_CHARS,
    _NOTE,
    FRAMES_FILE,
)
from robomax_py.program import (
    NULL_FRAME,
    Comment,
    FrameDef,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Wait,
    WaitFor,
)
from robomax_py.robot import RobotModel
from robomax_py.robot.ik.config import ConfigIndicator


def _linked(value: Tree[Token] | Token) -> str | None:
    """The system variable a frame value is stated on (`$ROBROOT` of `$ROBROOT : {...}` or of a
    plain `$ROBROOT`, upper case), None for an aggregate or anything else."""
    if isinstance(value, Tree) and value.data == "linked":
        return str(value.children[0]).upper()
    if isinstance(value, Token) and value.type == "SYSVAR":
        return str(value).upper()
    return None


class _Reader(_DataReader):
    """The reader with its statements' handlers (`_DataReader.statement` calls `on_<rule>`)."""

    # ------------------------------------------------------------------ statements

    def on_signal(self, tree: Tree[Token], comment: str, line: int) -> None:
        name, var, number = tree.children
        if str(var).upper() == "$IN":
            self.inputs[str(name).upper()] = int(float(str(number)))
        elif str(var).upper() == "$OUT":
            self.outputs[int(float(str(number)))] = str(name)

    def declare_frame(self, name: str, kind: str, node: Tree[Token] | None, line: int, number: int = 0,
                      in_world: bool = False) -> None:
        """A frame's value as the program states it (missing components are 0, as in $NULLFRAME;
        no aggregate: $NULLFRAME). A base frame is relative to $WORLD unless stated on $ROBROOT."""
        agg = {} if node is None else self.aggregate(node, line)
        xyz = tuple(float(agg.get(k, 0.0)) for k in "XYZ")       # type: ignore[arg-type]
        zyx = tuple(float(agg.get(k, 0.0)) for k in "ABC")       # type: ignore[arg-type]
        self.frames = [f for f in self.frames if (f.kind, f.name) != (kind, name)]
        self.frames.append(FrameDef(name, kind, xyz, zyx, number, in_world and kind == "base"))  # type: ignore[arg-type]

    def on_frame_data(self, tree: Tree[Token], comment: str, line: int) -> None:
        """`TOOL_DATA[n] = {...}` / `BASE_DATA[n] = {...}`: the controller's stored frame n;
        `BASE_DATA[n] = $ROBROOT : {...}` (or `$ROBROOT`): a base frame in the robot base frame."""
        array, index, value = tree.children
        kind = {"TOOL_DATA": "tool", "BASE_DATA": "base"}.get(str(array).upper())
        on = _linked(value)
        if kind is None or on not in (None, "$ROBROOT", "$NULLFRAME", "$WORLD") or (kind == "tool" and on == "$ROBROOT"):
            self.ignored.append((line, f"{array}[{index}] = ..."))
            return
        n = int(float(str(index)))
        node = value if on is None else value.children[1]          # type: ignore[union-attr]
        self.declare_frame(f"{str(array).upper()}[{n}]", kind, node, line, n, in_world=on != "$ROBROOT")  # type: ignore[arg-type]

    def on_assign(self, tree: Tree[Token], comment: str, line: int) -> None:
        rhs = tree.children[-1]
        on = _linked(rhs)
        if isinstance(rhs, Tree) and rhs.data == "linked" and rhs.children[1] is None:
            rhs = rhs.children[0]                        # a plain system variable
        toks = [c for c in (*tree.children[:-1], rhs) if isinstance(c, Token)]
        var = str(toks[0]).upper()
        member = str(toks[1]).upper() if len(toks) > 2 and toks[1].type == "NAME" else ""
        index = next((int(float(t)) for t in toks[1:-1] if t.type == "NUMBER"), None)
        number = float(rhs) if isinstance(rhs, Token) and rhs.type == "NUMBER" else None
        if var == "$OUT" and index is not None and isinstance(rhs, Token) and str(rhs).upper() in ("TRUE", "FALSE"):
            self.add(SetSignal(self.outputs.get(index, f"OUT_{index}"), index, str(rhs).upper() == "TRUE"), line)
            return
        if var in ("$TOOL", "$BASE"):
            kind = "tool" if var == "$TOOL" else "base"
            if isinstance(rhs, Tree) and rhs.data == "aggregate":
                name = f"{var} of line {line}"
                self.declare_frame(name, kind, rhs, line, in_world=True)
            elif kind == "base" and on == "$ROBROOT":     # $BASE = $ROBROOT (: {...}): in the robot base frame
                name = "$ROBROOT" if isinstance(rhs, Token) else f"{var} of line {line}"
                self.declare_frame(name, kind, None if isinstance(rhs, Token) else rhs.children[1], line)  # type: ignore[arg-type]
            elif isinstance(rhs, Tree) and rhs.data == "linked":
                name = f"{str(rhs.children[0]).upper()} : {{...}}"   # another frame's linkage: not known here
            elif isinstance(rhs, Tree):                  # TOOL_DATA[n] / BASE_DATA[n]
                array, n = rhs.children
                name = f"{str(array).upper()}[{int(float(str(n)))}]"
            elif str(rhs).upper() in ("$NULLFRAME", "$WORLD"):
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
            value = self.percent(f"{var}[{index}]", number, line)
            (self.vel_axis if var == "$VEL_AXIS" else self.acc_axis)[index - 1] = value
            if var == "$ACC_AXIS":
                # A plain program's convention (robomax's earlier writer): $ACC_AXIS bounds a LIN's axes too.
                self.lin_accel = min(self.acc_axis) / 100.0
        elif var == "$VEL" and member == "CP":
            self.vel_cp = number
        elif var == "$APO" and member == "CDIS":
            self.cdis = number

    def on_motion(self, tree: Tree[Token], comment: str, line: int) -> None:
        kind = str(tree.children[0]).upper()
        target = tree.children[1]
        approx = [str(t).upper() for t in tree.children[2:] if isinstance(t, Token)]
        node = target.children[0]     # type: ignore[union-attr]
        if self.fold is not None:
            self.fold.done["approx"] = " ".join(approx)
            if isinstance(node, Token):
                self.fold.done["target"] = str(node).upper()
        text = f"{kind} {node if isinstance(node, Token) else '{...}'}"
        if isinstance(node, Token):
            found = self.data.get(str(node).upper())
            if found is None:
                self.unsimulated(text, line, "a point not declared in the program: the controller's global data")
                return
            point_type, values = found
            if point_type not in ("E6AXIS", "AXIS", "E6POS", "POS", "FRAME"):
                raise self.error(line, f"{node} is a {point_type}, not a position")
        else:
            values = self.aggregate(node, line)
        if self.external_tcp:
            self.unsimulated(text, line, "IPO_FRAME #TCP: an external TCP")
            return
        flyby_mm = self.cdis if approx and approx[0] in ("C_DIS", "C_PTP", "C_VEL", "C_ORI") else 0.0
        if approx and approx[0] == "C_DIS" and self.cdis <= 0:
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
            self.unsimulated(text, line, "a PTP to a Cartesian point")
            return
        xyz, zyx, config = self._cartesian(values, line)
        self.add(LinMove(xyz, zyx, config, self.vel_cp * 1000.0, comment=comment, flyby_mm=flyby_mm,
                         accel=self.lin_accel, tool=self.tool, base=self.base), line)

    def _cartesian(self, values: dict[str, object], line: int) -> tuple[tuple[float, ...], tuple[float, ...], str]:
        """A Cartesian target's X, Y, Z (mm), A, B, C (deg) and configuration: the components it
        gives over the last target's (KRL keeps the rest), all six needed by the first."""
        self.last_pose.update({k: float(v) for k, v in values.items() if k in ("X", "Y", "Z", "A", "B", "C", "S", "T")})  # type: ignore[arg-type]
        missing = [k for k in "XYZABC" if k not in self.last_pose]
        if missing:
            raise self.error(line, f"the first Cartesian target must give {', '.join(missing)}")
        config = ""
        if "S" in values and "T" in values:
            # KSS 8 sets S bit 4 in taught points (vendor_research §1.5): the configuration is bits 0-2.
            config = str(ConfigIndicator(int(self.last_pose["S"]) & 7, int(self.last_pose["T"]) & 63))
        return tuple(self.last_pose[k] for k in "XYZ"), tuple(self.last_pose[k] for k in "ABC"), config

    def on_spline(self, text: str, comment: str, line: int) -> None:
        """`SPLINE`, `ENDSPLINE` and, between them, `SPL` / `SLIN` to a named point with at most its own
        `WITH $VEL.CP = v` (m/s): the block's segments (`LinMove.spline`), simulated by
        `rebuild.spline_block`. Another form (WITH on the block, C_SPL, a segment outside a block,
        another WITH) is not simulated."""
        word = text.split()[0].upper()
        if word in ("SPLINE", "ENDSPLINE"):
            if text.upper() != word or (word == "SPLINE") == self.spline_open:
                self.unsimulated(text, line, "a spline block of another form than robomax writes")
                return
            self.spline_open = word == "SPLINE"
            return
        match = _SPLINE_SEGMENT.match(text)
        if not self.spline_open or match is None:
            self.unsimulated(text, line, "a spline segment outside a SPLINE block or of another form")
            return
        found = self.data.get(match[2].upper())
        if found is None or found[0] not in ("E6POS", "POS"):
            self.unsimulated(text, line, "a spline point not declared as a position in the program")
            return
        xyz, zyx, config = self._cartesian(found[1], line)
        speed = float(match[4]) if match[4] is not None else self.vel_cp
        self.add(LinMove(xyz, zyx, config, speed * 1000.0, comment=comment, accel=self.lin_accel, tool=self.tool, base=self.base,
                         spline="slin" if match[1].upper() == "SLIN" else "spl"), line)

    def on_weld(self, tree: Tree[Token], comment: str, line: int) -> None:
        n, seconds = (float(str(t)) for t in tree.children)
        self.add(read_spot_label(comment, int(n), seconds, self.file, line), line)

    def on_gripper(self, tree: Tree[Token], comment: str, line: int) -> None:
        action, n, seconds = tree.children
        self.add(read_gripper(str(action).lower(), comment, int(float(str(n))), float(str(seconds)), self.file,
                                  line), line)

    def on_wait_sec(self, tree: Tree[Token], comment: str, line: int) -> None:
        self.add(Wait(float(str(tree.children[0]))), line)

    def on_wait_for(self, tree: Tree[Token], comment: str, line: int) -> None:
        """`WAIT FOR <signal>` (its SIGNAL declaration gives the input) or `WAIT FOR $IN[k]`, either
        optionally `== TRUE`."""
        children = [c for c in tree.children if isinstance(c, Token)]
        if len(children) == 3 or (len(children) == 2 and children[0].type == "NAME"):
            children = children[:-1]                    # `== TRUE` (_PLAIN_WAIT_FOR admits no other)
        if len(children) == 1:
            name = str(children[0])
            self.add(WaitFor(name, self.inputs.get(name.upper())), line)
            return
        var, number = children
        if str(var).upper() != "$IN":
            self.unsimulated(f"WAIT FOR {var}[{number}]", line)
            return
        k = int(float(str(number)))
        name = next((n for n, i in self.inputs.items() if i == k), f"IN_{k}")
        self.add(WaitFor(name, k), line)


def _dat_name(file: str) -> str:
    return re.sub(r"\.src$", ".dat", file, flags=re.IGNORECASE) if file.lower().endswith(".src") else file + " (.dat)"


def _check_names(src: str, routines: list[Routine], reader: _Reader) -> None:
    """A DEF whose name is longer than a KRL name may be (24 characters, the note at
    `write.PROGRAM_CHARS`) does not compile: a problem at its DEF line."""
    lines = src.splitlines()
    for r in routines:
        if len(r.name) > _NAME_CHARS:
            at = next((i for i, raw in enumerate(lines, start=1)
                       if re.match(rf"^\s*(GLOBAL\s+)?DEF(FCT\s+\w+)?\s+{re.escape(r.name)}\s*\(", raw, re.IGNORECASE)), 0)
            reader.problems.append((at, "format", (f"DEF {r.name}: {len(r.name)} characters, and a KRL name has "
                                                   f"at most {_NAME_CHARS}: KSS does not compile it")))


def parse(texts: dict[str, str], file: str, robot: RobotModel) -> Parsed:
    """A KRL program from its `.src` (and `.dat`, when given) texts."""
    reader = _Reader(file, robot)
    for number, raw in enumerate(texts.get(FRAMES_FILE, "").splitlines(), start=1):
        stmt, _ = _statement(raw)
        if re.match(r"^(TOOL|BASE)_DATA\s*\[", stmt, re.IGNORECASE):
            reader.statement(stmt, "", number)
    dat_reader = _Reader(_dat_name(file), robot)
    for number, raw in enumerate(texts.get(".dat", "").splitlines(), start=1):
        stmt, _ = _statement(raw)
        match = re.match(rf"^DECL\s+(GLOBAL\s+)?({'|'.join(_DATA_TYPES)})\s", stmt, re.IGNORECASE)
        if match:
            dat_reader.declare(stmt[:match.start(1)] + stmt[match.end(1):] if match[1] else stmt, number)
    reader.data.update(dat_reader.data)
    routines = _routines(texts.get(".src", ""), "")
    if not routines:
        raise ProgramError(file, None, "no DEF line: not a KRL program")
    main = routines[0]
    _check_names(texts.get(".src", ""), routines, reader)
    defined = {r.name.lower(): r for r in [*_routines(texts.get(FRAMES_FILE, ""), FRAMES_FILE), *routines]}
    followed = follow(main, defined, _classifier(set(defined)))
    folds = 0
    header_comments: list[str] = []
    previous: Statement | None = None
    for step in followed.steps:
        st, number = step.statement, step.line
        if previous is not None and (st.source != previous.source or st.line <= previous.line):
            # A jump or a call: an inline form left open there is not closed by what follows.
            reader.fold, folds = None, 0
        previous = st
        if step.unsupported:
            reader.unsimulated(st.text, number, step.unsupported)
            continue
        stmt, comment = st.text, st.comment
        if not stmt:
            line = st.raw.strip()
            if re.match(r"^;FOLD\b", line, re.IGNORECASE):
                folds += 1
                reader.open_fold(line, number, folds)
            elif re.match(r"^;ENDFOLD\b", line, re.IGNORECASE):
                reader.close_fold(folds)
                folds = max(0, folds - 1)
            elif line.startswith(";") and folds == 0:
                # A comment line of the program; inside a fold, a comment is part of what the fold hides.
                if is_header_comment(comment) or comment.startswith(_NOTE):
                    header_comments.append(comment)
                else:
                    reader.add(Comment(comment), number)
            continue
        reader.statement(stmt, comment, number)
    for routine in routines[1:]:
        if routine.name.lower() in _REST_ROUTINES:
            for at, text, why in _not_resting(routine):
                reader.unsimulated(text, at, why)
    reader.problems.extend(followed.problems)
    header = read_header(header_comments)
    main_name = main.name
    return Parsed(Program(main_name, header, tuple(reader.frames), tuple(reader.instructions)), tuple(reader.lines),
                  "kuka", tuple(reader.ignored), tuple(reader.problems))
