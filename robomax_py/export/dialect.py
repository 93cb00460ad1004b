"""What the controller dialects share (docs/cell-files.md, "Controller programs"): the program a plan becomes before a dialect
states it, the header every program carries, and the conversions of blends and configuration
data into the terms of a controller brand.

A dialect module owns both directions for its files: `adapt` (the dialect-free `Program` as
this dialect can state it: its decimals, its kind of blend, its brand's configuration data),
`write` (that program -> file texts) and `parse` (file texts -> `Parsed`: the program and the line
of each statement). `robomax_py.publish` proves, before anything is written, that parsing the written
text gives back the adapted program and that its rebuilt motion is the planned one.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Literal

from lark import Token, Tree

from robomax_py._typing import FloatArray
from robomax_py.errors import ControllerSetupError, ExportError, ProgramError
from robomax_py.program import (
    Comment,
    FrameDef,
    Gripper,
    Header,
    Instruction,
    LinMove,
    Program,
    PtpMove,
    SetSignal,
    Spot,
    WaitFor,
    spelled_out,
)
from robomax_py.robot import RobotModel
from robomax_py.robot.solve import brand_text_of
from robomax_py.spec import ControllerSetup
from robomax_py.timing import TimingError
from robomax_py.timing.chain import flyby_tcp_distance

__all__ = [
    "Dialect",
    "Parsed",
    "PlannedProgram",
    "header_lines",
    "in_controller_joints",
    "in_controller_terms",
    "is_header_comment",
    "read_header",
    "spot_label",
    "with_brand_configs",
    "with_tcp_blends",
    "without_comments",
]


@dataclass(frozen=True, slots=True, eq=False)
class PlannedProgram:
    """A plan as a dialect-free program, with the planned joint values at each instruction.

    joints[i] is the configuration (rad) the robot is in at the end of instruction i: the
    target of a move, the rest point of a weld or wait; it lets a dialect state a blend as a TCP
    distance and a target's configuration data in another brand's terms.
    """

    program: Program
    joints: tuple[FloatArray, ...]
    controller: ControllerSetup = field(default_factory=ControllerSetup)     # the cell's `robot.controller`


@dataclass(frozen=True, slots=True)
class Parsed:
    """A program read from a dialect's files.

    lines[i] is the line (1-based, in the main file) of instruction i; `ignored` are the statements
    (line, text) read but not simulated: the motion is rebuilt without them and verify reports them.
    brand is whose configuration data the program's Cartesian targets carry. `problems` are what
    the statements themselves say is wrong, as the controller executes them, (line, kind, detail):
    an end that leaves statements unexecuted ("flow"), a speed outside its range ("speed").
    """

    program: Program
    lines: tuple[int, ...]
    brand: str
    ignored: tuple[tuple[int, str], ...] = ()
    problems: tuple[tuple[int, str, str], ...] = ()
    # rad per axis: the finest step the program's joint values can state, where coarser than any
    # check's tolerance (INFORM: one encoder pulse); () otherwise.
    joint_step: tuple[float, ...] = ()



def controller_identifier(name: str, *, upper: bool, max_chars: int, reserved: Sequence[str] = ()) -> str:
    """A cell's name as a program name a controller takes: letters of one case, digits and `_`, a
    letter first (`P` put in front otherwise), at most `max_chars`; a name one of the dialect's own
    routines has gets `_PROG` (`_prog`) after it.

    >>> controller_identifier("door-L 2", upper=True, max_chars=8), controller_identifier("7up", upper=False, max_chars=15)
    ('DOOR_L_2', 'p7up')
    """
    letters, first, suffix = ("A-Z", "P", "_PROG") if upper else ("a-z", "p", "_prog")
    plain = spelled_out(name, "_")
    ident = re.sub(f"[^{letters}0-9_]", "_", plain.upper() if upper else plain.lower()) or first
    if not re.match(f"[{letters}]", ident):
        ident = first + ident
    ident = ident[:max_chars]
    return ident + suffix if ident in reserved else ident

# A long name keeps its last words when they are this short (a station robot's `_r1`, a variant's
# `_4_r1`): what tells two programs of one station apart is at the end of their names.
TAIL_CHARS = 6


def fitted_identifier(name: str, *, max_chars: int, reserved: Sequence[str] = (), keep: Sequence[str] = ()) -> str:
    """A program's name as a controller that ties the file to it takes it (KRL's DEF and file,
    RAPID's MODULE and file, FANUC's program and file): letters, digits and `_`, a letter first
    (`P` put in front otherwise), at most `max_chars`. A name in `reserved` (case-insensitively: the
    dialect's own routines and keywords) gets `_prog` after it. A longer name keeps its head, then
    `_` and 4 hexadecimal digits of its SHA-256 (two long names stay two programs), then its ending:
    one in `keep` (a baseline's `_teach_in`), else its last words up to TAIL_CHARS characters.

    >>> fitted_identifier("7 door-L", max_chars=17), fitted_identifier("spot_weld", max_chars=17, reserved=["SPOT_WELD"])
    ('P7_door_L', 'spot_weld_prog')
    >>> fitted_identifier("cabin_flange_rear_left_teach_in", max_chars=17, keep=["_teach_in"])
    'cab_5E67_teach_in'
    >>> fitted_identifier("side_frame_station_4_r1", max_chars=17)
    'side_fr_B7E6_4_r1'
    """
    ident = re.sub(r"[^A-Za-z0-9_]", "_", spelled_out(name, "_")) or "P"
    if not ("A" <= ident[0] <= "Z" or "a" <= ident[0] <= "z"):
        ident = "P" + ident
    if ident.upper() in {r.upper() for r in reserved}:
        ident += "_prog"
    if len(ident) > max_chars:
        kept = next((k for k in keep if ident.upper().endswith(k.upper())), "")
        kept = ident[len(ident) - len(kept):] if kept else "_" + _last_words(ident[1:], TAIL_CHARS)
        digest = hashlib.sha256(name.encode()).hexdigest()[:4].upper()
        ident = ident[:max_chars - len(kept.rstrip("_")) - 5] + "_" + digest + kept.rstrip("_")
    return ident


def _last_words(ident: str, most: int) -> str:
    """The `_`-separated words at the end of `ident`, as many as fit in `most` characters ("" when
    even the last does not)."""
    tail = ""
    for word in reversed(ident.split("_")):
        joined = f"{word}_{tail}" if tail else word
        if not word or len(joined) > most:
            break
        tail = joined
    return tail


def own_name(frame: FrameDef) -> str:
    """A frame's name as the program states it, for dialects that refer to frames by name."""
    return frame.name


@dataclass(frozen=True, slots=True)
class SignalNumbers:
    """The controller inputs and outputs a dialect's programs address by number (ends included),
    the dialect's name in messages, and what a number out of range most likely means there (`hint`,
    added to the message: e.g. a dialect that states input k under another number)."""

    label: str
    inputs: tuple[int, int]
    outputs: tuple[int, int]
    hint: str = ""


@dataclass(frozen=True, slots=True)
class NumberedSignal:
    """A number the cell (or station) file gives a controller input or output, and its key there."""

    key: str
    kind: Literal["input", "output"]
    number: int


def setup_signals(setup: ControllerSetup, prefix: str = "robot.controller") -> tuple[NumberedSignal, ...]:
    """The numbered inputs and outputs of a cell's controller section (`prefix`: its key in the file)."""
    return (*(NumberedSignal(f"{prefix}.inputs.{i.signal}", "input", i.number) for i in setup.inputs),
            *(NumberedSignal(f"{prefix}.outputs.{o.signal}", "output", o.number) for o in setup.outputs))


def needs_nothing(robot: RobotModel) -> tuple[tuple[str, str], ...]:
    """What a dialect that can write a program for any arm needs of robot.yaml: nothing."""
    return ()


@dataclass(frozen=True, slots=True)
class Dialect:
    """A controller dialect: its files (the first is the main one; keys starting with "_" are
    companions named `<program>_...`, such as a frames setup file), its brand, both directions,
    how it refers to a numbered frame (`frame_name`: e.g. KRL "TOOL_DATA[1]"), the encoding its
    files are read in when they are not UTF-8 (`fallback_encoding`, "" for none), which frames a
    controller set up for the cell holds (`named_frames_only`), and what its files are named after."""

    name: str
    extensions: tuple[str, ...]
    brand: str
    adapt: Callable[[PlannedProgram, RobotModel], Program]
    write: Callable[[Program, RobotModel], dict[str, str]]
    parse: Callable[[dict[str, str], str, RobotModel], Parsed]
    frame_name: Callable[[FrameDef], str] = own_name
    companions: tuple[str, ...] = ()
    fallback_encoding: str = ""
    # The controller holds only the frames the cell names (`ControllerFrame.existing`), as RAPID
    # data exist only where a loaded module declares them; otherwise every frame slot it selects.
    named_frames_only: bool = False
    # The name the dialect gives a program of a given name (`adapt` names it so), when its files are
    # named after it rather than after the cell: FANUC, whose programs are named as their files.
    program_name: Callable[[str], str] | None = None
    # Whole file names every program of the dialect writes alike (FANUC's default routines).
    shared: tuple[str, ...] = ()
    # Each of its extensions names a whole program of its own (AS's `.as` and `.pg`), read as the first.
    any_extension: bool = False
    # The robot.yaml keys the dialect needs that `robot` does not state, (key, what it is for): the
    # controller's calibration data a program counts in (INFORM's encoder pulses per degree). A
    # dialect asked for by name on such a robot is an error; `--format all` passes it over and says so.
    needs: Callable[[RobotModel], tuple[tuple[str, str], ...]] = needs_nothing
    # It states spline blocks (`LinMove.spline`: KRL SPLINE, SRCL SPL / SLIN); the others get a
    # spline block as lines flown by (`spline_lines`).
    splines: bool = False
    # Whether `--format all` takes it in (a dialect left out is written only when named).
    in_all: bool = True
    # Its programs drive six axes (every vendor dialect here): a robot with another number of
    # joints is refused before planning when it is named, and passed over by `--format all`.
    six_axes: bool = True
    # The inputs and outputs its programs address by number (None: it names signals, as SRCL, or
    # addresses them otherwise, as RAPID's I/O configuration).
    signals: SignalNumbers | None = None

    def unfit(self, robot: RobotModel) -> str:
        """Why this dialect cannot state `robot`'s programs at all ("" when it can)."""
        return not_six_axes(robot, self.name) if self.six_axes else ""

    def signal_problem(self, numbered: Sequence[NumberedSignal]) -> tuple[str, str] | None:
        """The first number the file gives that this dialect's programs cannot address, as (key,
        problem); None when every one fits."""
        if self.signals is None:
            return None
        for s in numbered:
            low, high = self.signals.inputs if s.kind == "input" else self.signals.outputs
            if not low <= s.number <= high:
                hint = f" ({self.signals.hint})" if self.signals.hint else ""
                return s.key, f"{s.kind} {s.number} is outside {self.signals.label}'s {s.kind}s {low}..{high}{hint}"
        return None


def with_frame_names(program: Program, name_of: Callable[[FrameDef], str]) -> Program:
    """The program with its frames named as a dialect names them, and every LIN's tool and base
    renamed alike."""
    renamed = {(f.kind, f.name): name_of(f) for f in program.frames}
    frames = tuple(dataclasses.replace(f, name=renamed[(f.kind, f.name)]) for f in program.frames)
    out: list[Instruction] = []
    for ins in program.instructions:
        if isinstance(ins, LinMove):
            ins = dataclasses.replace(ins, tool=renamed.get(("tool", ins.tool), ins.tool),
                                      base=renamed.get(("base", ins.base), ins.base))
        out.append(ins)
    return dataclasses.replace(program, frames=frames, instructions=tuple(out))


def numbered_inputs(program: Program, dialect: str, low: int, high: int) -> None:
    """Every wait names a controller input in [low, high]: ControllerSetupError otherwise (a
    dialect that waits on input numbers cannot guess one)."""
    for ins in program.instructions:
        if not isinstance(ins, WaitFor):
            continue
        key = f"robot.controller.inputs.{ins.signal}"
        if ins.number is None:
            raise ControllerSetupError(key, f"the program waits for signal {ins.signal}; {dialect} waits on an input "
                                            "number: map the signal to the controller's input")
        if not low <= ins.number <= high:
            raise ControllerSetupError(key, f"input {ins.number} is outside {dialect}'s inputs {low}..{high}")


def numbered_outputs(program: Program, dialect: str, low: int, high: int) -> None:
    """Every set signal names a controller output in [low, high]: ControllerSetupError otherwise,
    naming the cell key `robot.controller.outputs.<signal>` (a dialect that sets outputs by
    number cannot guess one)."""
    for ins in program.instructions:
        if not isinstance(ins, SetSignal):
            continue
        key = f"robot.controller.outputs.{ins.signal}"
        if ins.number is None:
            raise ControllerSetupError(key, f"the program sets signal {ins.signal}; {dialect} sets an output "
                                            "number: map the signal to the controller's output")
        if not low <= ins.number <= high:
            raise ControllerSetupError(key, f"output {ins.number} is outside {dialect}'s outputs {low}..{high}")


def with_package_welds(program: Program, dialect: str) -> Program:
    """With `weld: package` (the cell's `robot.controller.weld`), every weld as the controller's
    process package states it: gun and schedule, the weld time the schedule's on the controller
    (so every weld of one gun and schedule must take the same time). Otherwise unchanged."""
    if program.setup.weld != "package":
        return program
    times: dict[tuple[int, int], tuple[float, str]] = {}
    out: list[Instruction] = []
    for ins in program.instructions:
        if isinstance(ins, Spot):
            key = (ins.gun, ins.schedule)
            first = times.setdefault(key, (ins.time_s, f"{ins.seam}/{ins.name}"))
            if first[0] != ins.time_s:
                raise ControllerSetupError("robot.controller.weld", f"{dialect}'s process package takes the weld time "
                                           f"from the schedule: gun {key[0]} schedule {key[1]} welds {first[1]} for "
                                           f"{first[0]:.3f} s and {ins.seam}/{ins.name} for {ins.time_s:.3f} s; give "
                                           "each weld time its own schedule")
            ins = dataclasses.replace(ins, time_s=0.0, package=True)
        out.append(ins)
    return dataclasses.replace(program, instructions=tuple(out))


def numbered_frames(program: Program, dialect: str, tools: int, bases: int) -> None:
    """Every frame's number within the controller's slots (1..tools, 1..bases)."""
    for f in program.frames:
        high = tools if f.kind == "tool" else bases
        if not 1 <= f.number <= high:
            key = "robot.controller." + ("tool" if f.kind == "tool" else "frame") + ".number"
            raise ControllerSetupError(key, f"{dialect} has {f.kind} slots 1..{high}, got {f.number}")


# ------------------------------------------------------------------ the header


_GEN = re.compile(r"^(?P<gen>\S+ \S+) \| cell (?P<cell>\S+) \| cell file sha256 (?P<sha>[0-9a-f]+|unknown) "
                  r"\| planned cycle (?P<cycle>[0-9]+\.[0-9]+) s$")
_ROBOT = re.compile(r"^robot (?P<robot>\S+) \| tool (?P<tool>\S+) \| axes (?P<axes>\S+(?: \S+)*)$")
_STAMP = re.compile(r"^written (?P<stamp>\S.*)$")


def header_lines(h: Header) -> list[str]:
    """The header as comment texts (without the dialect's comment marks), in every dialect alike."""
    lines = [
        (f"{h.generator or 'robomax_py ?'} | cell {h.cell} | cell file sha256 {h.cell_sha256 or 'unknown'} "
         f"| planned cycle {h.cycle_time_s:.3f} s"),
        f"robot {h.robot} | tool {h.tool} | axes {' '.join(h.joints)}",
    ]
    if h.stamp:
        lines.append(f"written {h.stamp}")
    return lines


def is_header_comment(text: str) -> bool:
    """Whether a comment text is one of the header's lines."""
    return any(p.match(text.strip()) for p in (_GEN, _ROBOT, _STAMP))


def read_header(comments: Sequence[str]) -> Header:
    """The header from a program's comment texts; a program without one (written by others) gets
    an empty header: it is then taken to be for the cell's robot (`rebuild`)."""
    found: dict[str, str] = {}
    for text in comments:
        for pattern in (_GEN, _ROBOT, _STAMP):
            match = pattern.match(text.strip())
            if match:
                found.update(match.groupdict())
    if "robot" not in found:
        return Header("", "", "", 0.0, ())
    sha = found.get("sha", "")
    return Header(found.get("cell", ""), found["robot"], found["tool"], float(found.get("cycle", 0.0)),
                  tuple(found["axes"].split()), found.get("gen", ""), "" if sha == "unknown" else sha,
                  found.get("stamp", ""))


# ------------------------------------------------------------------ conversions


_LABEL = re.compile(r"^(?P<seam>[^/\s]+)/(?P<name>[^/\s]+)(?: gun (?P<gun>[0-9]+) schedule (?P<schedule>[0-9]+))?$")


def spot_label(spot: Spot) -> str:
    """`seam/name gun G schedule S`, the comment a weld call carries (docs/cell-files.md, "Controller programs": `seam/name` first)."""
    return f"{spot.seam}/{spot.name} gun {spot.gun} schedule {spot.schedule}"


def read_spot_label(text: str, n: int, time_s: float, file: str, line: int) -> Spot:
    """A weld call's comment -> Spot; a call without one is weld n of an unnamed seam."""
    text = text.strip()
    if not text:
        return Spot(f"spot{n}", "unnamed", time_s)
    match = _LABEL.match(text)
    if match is None:
        raise ProgramError(file, f"line {line}", f"the weld call's comment must be 'seam/name' "
                                                 f"(optionally 'gun G schedule S'), got {text!r}")
    gun, schedule = int(match["gun"] or 1), int(match["schedule"] or 1)
    return Spot(match["name"], match["seam"], time_s, gun, schedule)


def gripper_label(ins: Gripper) -> str:
    """`seam/name`, the comment a gripper call carries."""
    return f"{ins.seam}/{ins.name}"


def read_gripper(action: str, text: str, n: int, time_s: float, file: str, line: int) -> Gripper:
    """A gripper call (`grip` / `release`) and its comment -> Gripper; without one, station n of an
    unnamed job."""
    text = text.strip()
    if action not in ("grip", "release"):
        raise ProgramError(file, f"line {line}", f"unknown gripper action {action!r}")
    if not text:
        return Gripper(action, f"station{n}", "unnamed", time_s)      # type: ignore[arg-type]
    match = _LABEL.match(text)
    if match is None or match["gun"] is not None:
        raise ProgramError(file, f"line {line}", f"the {action} call's comment must be 'job/station', got {text!r}")
    return Gripper(action, match["name"], match["seam"], time_s)      # type: ignore[arg-type]


def with_tcp_blends(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program with every joint-space fly-by radius stated as a TCP distance (mm), as KRL
    `C_DIS`, RAPID zones and URScript `r` state blends (`timing.chain.tcp_flyby_radius`)."""
    program = planned.program
    out: list[Instruction] = []
    q_prev = planned.joints[0]
    for i, ins in enumerate(program.instructions):
        q = planned.joints[i]
        if isinstance(ins, (PtpMove, LinMove)) and ins.flyby > 0:
            try:
                mm = 1000.0 * flyby_tcp_distance(robot, q_prev, q, math.radians(ins.flyby))
            except TimingError as exc:
                raise ExportError(f"instruction {i + 1} ({ins.comment or 'move'}): {exc}") from None
            ins = dataclasses.replace(ins, flyby=0.0, flyby_mm=mm)
        out.append(ins)
        q_prev = q
    return dataclasses.replace(program, instructions=tuple(out))


def with_brand_configs(program: Program, joints: Sequence[FloatArray], robot: RobotModel, brand: str) -> Program:
    """Every Cartesian target's configuration data in `brand`'s terms (docs/cell-files.md, "Controller programs"), from the joints as
    the controller counts them; the robot's own brand keeps the data the program has (the
    planner's, in the controller's terms since `in_controller_terms`, taken from the unrounded
    joints)."""
    if brand == robot.controller.brand:
        return program
    return _configs_of(program, joints, robot, brand)


def _configs_of(program: Program, joints: Sequence[FloatArray], robot: RobotModel, brand: str) -> Program:
    out: list[Instruction] = []
    for ins, q in zip(program.instructions, joints):
        if isinstance(ins, LinMove):
            ins = dataclasses.replace(ins, config=brand_text_of(robot, q, brand, controller=True))
        out.append(ins)
    return dataclasses.replace(program, instructions=tuple(out))


def in_controller_terms(planned: PlannedProgram, robot: RobotModel) -> PlannedProgram:
    """The plan as a controller program states it: its joint targets as the controller counts its
    joints (`in_controller_joints`) and its Cartesian targets' configuration data computed from
    those joint values (turn bits, wrist bit, quadrants, turn numbers: `solve.brand_text_of` with
    `controller`), in the robot's brand; a dialect of another brand restates them from the same
    values (`with_brand_configs`). The one conversion point of what publishing writes; the joints
    (`planned.joints`) stay the URDF's. Without the keys the plan is returned as it is."""
    c = robot.controller
    if not c.joint_signs and not c.joint_zeros:
        return planned
    program = in_controller_joints(planned.program, robot)
    return dataclasses.replace(planned, program=_configs_of(program, planned.joints, robot, c.brand))


def in_controller_joints(program: Program, robot: RobotModel, inverse: bool = False) -> Program:
    """The program's joint targets as the controller counts its joints (robot.yaml
    `controller.joint_signs`, `controller.joint_zeros_deg`): controller = sign * URDF + zero, in
    degrees; `inverse` takes them back to the URDF's. The one place controller dialects' joint
    values are converted: publishing applies it before a dialect adapts the plan (so every dialect
    writes, rounds and reads back controller values) and its inverse before the motion is rebuilt
    from what was read, as `verify` does. Without the keys the program is returned as it is."""
    c = robot.controller
    if not c.joint_signs and not c.joint_zeros:
        return program
    n = robot.dof
    signs = c.joint_signs or (1.0,) * n
    zeros = tuple(math.degrees(z) for z in c.joint_zeros) or (0.0,) * n

    def convert(values: tuple[float, ...]) -> tuple[float, ...]:
        if len(values) != n:
            return values               # rebuild reports the wrong axis count
        if inverse:
            return tuple((v - z) * s for v, s, z in zip(values, signs, zeros))
        return tuple(s * v + z for v, s, z in zip(values, signs, zeros))

    out = tuple(dataclasses.replace(i, target_deg=convert(i.target_deg)) if isinstance(i, PtpMove) else i
                for i in program.instructions)
    return dataclasses.replace(program, instructions=out)


def ascii_text(text: str) -> str:
    """`text` in ASCII (`program.spelled_out`, '?' for what has no spelling): 'Schweißpunkt' ->
    'Schweisspunkt', '点1' -> '?1'."""
    return spelled_out(text, "?")


def ascii_comments(program: Program) -> Program:
    """The program with its comment lines and move notes in ASCII (`ascii_text`), for controllers
    that read their files in a code page of their own: KSS writes and reads Windows-1252, where the
    two bytes of a UTF-8 'ß' show as two other letters; an ASCII comment reads alike everywhere."""
    def plain(i: Instruction) -> Instruction:
        if isinstance(i, Comment):
            return Comment(ascii_text(i.text))
        if isinstance(i, (PtpMove, LinMove)) and not i.comment.isascii():
            return dataclasses.replace(i, comment=ascii_text(i.comment))
        return i
    return dataclasses.replace(program, instructions=tuple(plain(i) for i in program.instructions))


def without_comments(program: Program) -> Program:
    """The program without its comment lines and move notes (for dialects that cannot carry them)."""
    kept = tuple(dataclasses.replace(i, comment="") if isinstance(i, (PtpMove, LinMove)) else i
                 for i in program.instructions if not isinstance(i, Comment))
    return dataclasses.replace(program, instructions=kept)


def tree_numbers(node: object, file: str, line: int, lists: tuple[str, ...] = ("list",)) -> list[float]:
    """The finite numbers of a parsed value: a NUMBER token, or a tree named one of `lists`
    (nested) of them; ProgramError naming the line for anything else."""
    if isinstance(node, Token) and node.type == "NUMBER":
        value = float(node)
        if not math.isfinite(value):
            raise ProgramError(file, f"line {line}", f"number {node} is not finite")
        return [value]
    if isinstance(node, Tree) and node.data in lists:
        return [v for c in node.children for v in tree_numbers(c, file, line, lists)]
    raise ProgramError(file, f"line {line}", f"expected numbers, got {node}")


def percent(fraction: float) -> int:
    """A speed or acceleration fraction as the whole percentage KRL and TP state (1 to 100)."""
    return max(1, min(100, int(round(fraction * 100))))


def not_six_axes(robot: RobotModel, dialect: str) -> str:
    """Why `dialect`'s programs, which drive six revolute axes, cannot be `robot`'s ("" when they can)."""
    if robot.dof != 6:
        return f"{dialect} programs are for 6-axis arms; {robot.name} has {robot.dof} joints"
    linear = robot.prismatic_joints
    if linear:
        # These dialects state every joint of the arm in deg; a linear axis is an external axis
        # there (KRL E1, RAPID extax, a FANUC extended axis), configured on the controller.
        return f"{dialect} programs are for arms of six revolute axes; {robot.name}'s {', '.join(linear)} is prismatic"
    return ""


def require_six_axes(robot: RobotModel, dialect: str) -> None:
    why = not_six_axes(robot, dialect)
    if why:
        raise ExportError(why)
