"""KRL read: the reader's state, the program's data (DECL, *_ACT, BAS), inline forms and the frames
they select."""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field

from lark import Token, Tree
from lark.exceptions import UnexpectedInput

from robomax_py.errors import ProgramError
from robomax_py.export.dialect import read_spot_label
from robomax_py.export.krl.grammar import (
    _BLOCK_END,
    _BLOCK_START,
    _KNOWN,
    _MOTION_FOLD,
    _PLAIN_MOTION,
    _PLAIN_WAIT_FOR,
    _SPLINE,
    _TEMPLATE,
    _UNSIMULATED,
    _parser,
)
from robomax_py.export.krl.write import DEF_APO_CDIS_MM, DEF_VEL_CP_M_S, _plain
from robomax_py.program import NULL_FRAME, UNSET_FRAME, Comment, FrameDef, Instruction
from robomax_py.robot import RobotModel


@dataclass(slots=True)
class _Fold:
    """An inline form being read: what its text says (`params`: %P n -> value) and what its
    statements do (`done`), compared at its ;ENDFOLD."""

    line: int
    kind: str
    params: dict[str, str]
    depth: int                      # of folds, counting its own
    done: dict[str, str] = field(default_factory=dict)


class _DataReader:
    def __init__(self, file: str, robot: RobotModel) -> None:
        self.file, self.robot = file, robot
        self.data: dict[str, tuple[str, dict[str, object]]] = {}    # name -> (KRL type, fields)
        self.instructions: list[Instruction] = []
        self.lines: list[int] = []
        self.ignored: list[tuple[int, str]] = []
        self.problems: list[tuple[int, str, str]] = []     # (line, kind, detail): see `Parsed`
        self.frames: list[FrameDef] = []       # whose values the program's texts state
        self.tool, self.base = UNSET_FRAME, UNSET_FRAME    # in force: names of frames
        self.external_tcp = False              # $IPO_MODE = #TCP
        self.inputs: dict[str, int] = {}       # SIGNAL name -> $IN number
        self.outputs: dict[int, str] = {}      # $OUT number -> its SIGNAL name
        self.vel_axis = [100.0] * 6            # %
        self.acc_axis = [100.0] * 6            # %
        self.vel_cp = DEF_VEL_CP_M_S           # m/s, KSS default $VEL.CP
        self.lin_accel = 1.0                   # fraction a LIN may use (robomax's model, see the docstring)
        self.cdis = 0.0
        self.act: dict[str, str | None] = {"PDAT": None, "LDAT": None, "FDAT": None}   # *_ACT: a data name
        self.depth = 0                         # of control-flow blocks
        self.fold: _Fold | None = None
        self.n_package = 0
        self.last_axes: dict[str, float] = {}
        self.last_pose: dict[str, float] = {}
        self.spline_open = False               # inside SPLINE ... ENDSPLINE

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
        return text.upper() if isinstance(tok, Token) and tok.type in ("ENUM", "NAME") else text

    def declare(self, text: str, line: int) -> None:
        tree = self.tree(text, line)
        kind, name, agg = tree.children
        self.data[str(name).upper()] = (str(kind).upper(), self.aggregate(agg, line))   # type: ignore[arg-type]

    def add(self, ins: Instruction, line: int) -> None:
        self.instructions.append(ins)
        self.lines.append(line)

    def on_spline(self, text: str, comment: str, line: int) -> None:
        """A statement of a spline block (`read._Reader` reads them)."""
        self.unsimulated(text, line)

    def unsimulated(self, text: str, line: int, why: str = "") -> None:
        self.ignored.append((line, text))
        self.add(Comment(f"not simulated: {text}" + (f" ({why})" if why else "")), line)

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
            self.unsimulated(text, line)
            return
        if _SPLINE.match(text):
            self.on_spline(text, comment, line)
            return
        if _UNSIMULATED.match(text):
            self.unsimulated(text, line)
            return
        if _TEMPLATE.match(text):
            return
        if not _KNOWN.match(text):
            self.ignored.append((line, text))
            return
        if re.match(r"^(PTP|LIN)\b", text, re.IGNORECASE) and not _PLAIN_MOTION.match(text):
            self.unsimulated(text, line, "a motion to an expression")
            return
        if re.match(r"^WAIT\s+FOR\b", text, re.IGNORECASE) and not _PLAIN_WAIT_FOR.match(text):
            self.unsimulated(text, line, "a wait for a condition other than an input")
            return
        if text.upper().startswith("DECL"):
            self.declare(text, line)
            return
        tree = self.tree(text, line)
        getattr(self, "on_" + tree.data)(tree, comment, line)

    # ------------------------------------------------------------------ inline forms

    def open_fold(self, text: str, line: int, depth: int) -> None:
        match = _MOTION_FOLD.match(text)
        if match and self.fold is None:
            params = {k: v.strip() for k, v in re.findall(r"(\d+):([^,]*)", match[2])}
            self.fold = _Fold(line, match[1].upper(), params, depth)

    def close_fold(self, depth: int) -> None:
        """At a motion fold's ;ENDFOLD: what its text says that its statements do not (the
        statements run; the text is a comment to the controller)."""
        fold = self.fold
        if fold is None or fold.depth != depth:
            return
        self.fold = None
        said, done = fold.params, fold.done
        differ = []
        if "2" in said and "target" in done and done["target"] != "X" + said["2"].upper():
            differ.append(f"point {said['2']} (the motion is to {done['target']})")
        if "3" in said and "approx" in done and " ".join(said["3"].upper().split()) != done["approx"]:
            differ.append(f"approximation '{said['3']}' (the motion has '{done['approx']}')")
        if "5" in said and "vel" in done:
            try:
                shown = float(said["5"])
            except ValueError:
                shown = math.nan
            tol = 0.0 if fold.kind == "PTP" else 0.0005 + 1e-9        # the fold shows LIN Vel to 3 decimals
            if not abs(shown - float(done["vel"])) <= tol:
                differ.append(f"Vel {said['5']} (BAS sets {done['vel']})")
        prefix = "P" if fold.kind == "PTP" else "L"
        if "7" in said and "data" in done and done["data"] != prefix + said["7"].upper():
            differ.append(f"data {said['7']} (the statements use {done['data']})")
        if differ:
            self.ignored.append((fold.line, (f"the fold's text is not what its statements do: {'; '.join(differ)}; "
                                             "the statements run")))

    def fields(self, kind: str, line: int) -> dict[str, object] | None:
        """The PDAT / LDAT / FDAT that *_ACT names; None when the program has not set it (the
        controller's value from an earlier run) or it is not declared in the program."""
        name = self.act[kind]
        if name is None:
            return None
        found = self.data.get(name)
        if found is None or found[0] != kind:
            self.ignored.append((line, f"{kind}_ACT={name}: {name} is not declared as {kind} in the program"))
            return None
        return found[1]

    def on_data_act(self, tree: Tree[Token], comment: str, line: int) -> None:
        var, name = (str(c).upper() for c in tree.children)
        self.act[var[:4]] = name
        if self.fold is not None and var[:4] != "FDAT":
            self.fold.done["data"] = name

    def bas_value(self, node: object, line: int) -> float | None:
        """BAS's REAL argument: a number, or a data field (`PDATWork.VEL`, KSS 5)."""
        if not isinstance(node, Tree):
            return None
        parts = [str(c) for c in node.children]
        if len(parts) == 1 and isinstance(node.children[0], Token) and node.children[0].type == "NUMBER":
            return float(parts[0])
        if len(parts) == 2:
            found = self.data.get(parts[0].upper())
            value = None if found is None else found[1].get(parts[1].upper())
            return float(value) if isinstance(value, float) else None
        return None

    def on_bas(self, tree: Tree[Token], comment: str, line: int) -> None:
        """BAS.SRC's commands (module docstring); others have no modelled effect (ignored)."""
        command = str(tree.children[0]).upper()
        v = self.bas_value(tree.children[1], line)
        if self.fold is not None and v is not None:
            self.fold.done["vel"] = _plain(v, 6)
        if command == "#INITMOV":
            self.acc_axis, self.vel_axis = [100.0] * 6, [100.0] * 6
            self.lin_accel, self.vel_cp, self.cdis = 1.0, DEF_VEL_CP_M_S, DEF_APO_CDIS_MM
            self.tool, self.base, self.external_tcp = "TOOL_DATA[1]", NULL_FRAME, False
        elif command == "#PTP_PARAMS" and v is not None:
            self.ptp_dat(line)
            self.frames_of_fdat(line)
            self.vel_axis = [min(v, 100.0)] * 6
        elif command == "#CP_PARAMS" and v is not None:
            self.cp_dat(line)
            self.frames_of_fdat(line)
            self.vel_cp = min(v, DEF_VEL_CP_M_S)
        elif command == "#PTP_DAT":
            pdat = self.fields("PDAT", line)
            if pdat is not None and isinstance(pdat.get("VEL"), float):
                self.vel_axis = [min(float(pdat["VEL"]), 100.0)] * 6      # type: ignore[arg-type]
            self.ptp_dat(line)
        elif command == "#CP_DAT":
            ldat = self.fields("LDAT", line)
            if ldat is not None and isinstance(ldat.get("VEL"), float):
                self.vel_cp = min(float(ldat["VEL"]), DEF_VEL_CP_M_S)    # type: ignore[arg-type]
            self.cp_dat(line)
        elif command == "#FRAMES":
            self.frames_of_fdat(line)
        elif command in ("#TOOL", "#BASE") and v is not None:
            self.select(command[1:].lower(), int(v))
        elif command == "#VEL_PTP" and v is not None:
            self.vel_axis = [min(v, 100.0)] * 6
        elif command == "#ACC_PTP" and v is not None:
            self.acc_axis = [self.percent("BAS(#ACC_PTP)", v, line)] * 6
        elif command == "#VEL_CP" and v is not None:
            self.vel_cp = min(v, DEF_VEL_CP_M_S)
        elif command == "#ACC_CP" and v is not None:
            self.lin_accel = min(v, 100.0) / 100.0
        else:
            self.ignored.append((line, f"BAS({command}{'' if v is None else f',{v}'})"))

    def percent(self, what: str, value: float, line: int) -> float:
        """An axis speed or acceleration in % of the axis' maximum: $VEL_AXIS[i] and $ACC_AXIS[i]
        range over 0..100 (KUKA, System Variables for KSS 8.1-8.4, $VEL_AXIS and $ACC_AXIS; the
        open reference openkuka.github.io/krl/reference/system.variables gives `$ACC_AXIS[] INT[6] %
        [0,100]`). BAS.SRC caps what it computes (VEL_PTP, NAQIU bas.src 362-376), a program's own
        assignment is not capped: a value outside the range is reported, and the motion rebuilt at
        the nearest end of it."""
        if 0.0 < value <= 100.0:
            return value
        self.problems.append((line, "speed", (f"{what} = {value:g} %: an axis' speed or acceleration is 0..100 % "
                                              "of its maximum")))
        return min(max(value, 1.0), 100.0)

    def ptp_dat(self, line: int) -> None:
        """PTP_DAT: $ACC_AXIS = ACC ($ADAP_ACC #STEP2), $APO.CDIS = APO_DIST with APO_MODE #CDIS
        (otherwise $APO.CPTP, which C_DIS does not use)."""
        pdat = self.fields("PDAT", line)
        if pdat is None:
            return
        if isinstance(pdat.get("ACC"), float):
            # With $ADAP_ACC #STEP2 ACC_PTP assigns the PDAT's ACC to $ACC_AXIS uncapped.
            self.acc_axis = [self.percent(f"{self.act['PDAT']}.ACC", float(pdat["ACC"]), line)] * 6  # type: ignore[arg-type]
        if pdat.get("APO_MODE") == "#CDIS" and isinstance(pdat.get("APO_DIST"), float):
            self.cdis = float(pdat["APO_DIST"])             # type: ignore[arg-type]

    def cp_dat(self, line: int) -> None:
        """CP_DAT: the LIN's acceleration share from ACC, $APO.CDIS = APO_DIST."""
        ldat = self.fields("LDAT", line)
        if ldat is None:
            return
        if isinstance(ldat.get("ACC"), float):
            self.lin_accel = min(float(ldat["ACC"]), 100.0) / 100.0     # type: ignore[arg-type]
        if isinstance(ldat.get("APO_DIST"), float):
            self.cdis = float(ldat["APO_DIST"])             # type: ignore[arg-type]

    def select(self, kind: str, number: int) -> None:
        """BAS.SRC TOOL(n) / BASE(n): TOOL_DATA[n] / BASE_DATA[n], the null frame / $WORLD for 0."""
        name = f"{kind.upper()}_DATA[{number}]" if number > 0 else NULL_FRAME
        if kind == "tool":
            self.tool = name
        else:
            self.base = name

    def frames_of_fdat(self, line: int) -> None:
        """FRAMES: $TOOL, $BASE and $IPO_MODE from FDAT_ACT; unknown when the program has not set it."""
        fdat = self.fields("FDAT", line)
        tool_no = None if fdat is None else fdat.get("TOOL_NO")
        base_no = None if fdat is None else fdat.get("BASE_NO")
        if not isinstance(tool_no, float) or not isinstance(base_no, float):
            self.tool = self.base = UNSET_FRAME
            return
        self.select("tool", int(tool_no))
        self.select("base", int(base_no))
        self.external_tcp = fdat is not None and fdat.get("IPO_FRAME") == "#TCP"

    def on_userspot(self, tree: Tree[Token], comment: str, line: int) -> None:
        """`USERSPOT(#SPOT,SDATn)`: the spot package's weld, gun and schedule from the SPOT_TYPE (its
        comment names the spot; gun and schedule there are for the reader, the data holds)."""
        command, name = str(tree.children[0]).upper(), tree.children[1]
        if command != "#SPOT":
            self.ignored.append((line, f"USERSPOT({command}{'' if name is None else f',{name}'})"))
            return
        found = self.data.get(str(name).upper()) if name is not None else None
        if found is None or found[0] != "SPOT_TYPE":
            self.unsimulated(f"USERSPOT(#SPOT{'' if name is None else f',{name}'})", line,
                             "its SPOT_TYPE is not declared in the program")
            return
        gun, schedule = found[1].get("GUN"), found[1].get("PGNO1")
        if not isinstance(gun, float) or not isinstance(schedule, float):
            raise self.error(line, f"{name} gives no GUN and PGNO1")
        self.n_package += 1
        said = read_spot_label(comment, self.n_package, 0.0, self.file, line)
        spot = dataclasses.replace(said, gun=int(gun), schedule=int(schedule), package=True)
        if comment and re.search(r"\bgun\b", comment) and (said.gun, said.schedule) != (spot.gun, spot.schedule):
            self.ignored.append((line, (f"the comment says gun {said.gun} schedule {said.schedule}, {name} has GUN "
                                        f"{spot.gun} PGNO1 {spot.schedule}: the data holds")))
        self.add(spot, line)
