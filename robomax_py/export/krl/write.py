"""KRL written: the adapter (the program as KRL states it) and the writer of `<name>.src`, `<name>.dat`
and the frames' setup program (the package's docstring gives the sources)."""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field

from robomax_py.errors import ExportError
from robomax_py.export.dialect import (
    PlannedProgram,
    SignalNumbers,
    ascii_comments,
    fitted_identifier,
    gripper_label,
    header_lines,
    numbered_frames,
    numbered_inputs,
    numbered_outputs,
    percent,
    require_six_axes,
    spot_label,
    with_brand_configs,
    with_frame_names,
    with_package_welds,
    with_tcp_blends,
)
from robomax_py.program import (
    NULL_FRAME,
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
from robomax_py.robot.ik.config import ConfigIndicator

# The setup program holding the frames' values (a companion of `<name>.src`).
FRAMES_FILE = "_frames.src"
# KSS writes its files in Windows-1252 (e.g. ZINK KRC/R1/Program/Work/C1_pickConveyorBP.src).
FILE_ENCODING = "cp1252"
# KSS 8.x declares TOOL_DATA[16] and BASE_DATA[32] ($config.dat), and 4096 digital inputs.
TOOL_SLOTS, BASE_SLOTS, INPUTS = 16, 32, 4096
# ... and 4096 digital outputs $OUT[1..4096] (KSS 8 system variables).
OUTPUTS = 4096
SIGNALS = SignalNumbers("KRL", (1, INPUTS), (1, OUTPUTS))
# $config.dat factory values (NAQIU KRC/R1/System/$config.dat 18-41) that BAS.SRC applies.
DEF_VEL_CP_M_S = 2.0
DEF_APO_CDIS_MM = 3.0
# The version inline forms carry (CHINA amm_periphery.src), and KSS's name lengths ($config.dat
# TOOL_NAME[16,24]).
_KSS = "8.3.48"
_NAME_CHARS = 24
# The inline form's approximation distance for a new point (every exact-stop PDAT/LDAT in CHINA and
# CELL3 carries it): unused until a person makes the point CONT.
_APO_DEFAULT_MM = 100.0

_NOTE = "KRL of KSS 8.x"
# The name the robot base frame gets on a tilted mount (`_robot_base_slot`), shown in the folds.
ROBOT_BASE_FRAME = "robot_base"
_AXES = ("A1", "A2", "A3", "A4", "A5", "A6")
_EXTERNAL = ",".join(f"E{i} 0.0" for i in range(1, 7))
_DATA_TYPES = ("E6AXIS", "AXIS", "E6POS", "POS", "FRAME", "FDAT", "PDAT", "LDAT", "SPOT_TYPE")


# KSS names (KSS 8.x Operating and Programming Instructions for System Integrators, "Names in
# KRL", as restated in Hungsiu/WtRobotTraining @ c92b8435 03_Syntax.md, "naming and variables"): at
# most 24 characters, letters, digits, `_` and `$`, not a digit first, not a keyword. A DEF beyond
# them does not compile. The module's files carry the DEF's name, as a module made on the smartPAD
# has them and as RoboDK's KUKA post writes them (ros-industrial-attic/robodk_postprocessors @
# d7e6c1c0 KUKA_KRC4.py 146-188: `DEF progname` into `progname.src`); a published program may
# differ (kuka_experimental's ros_rsi.src holds DEF RSI_AxisCorr), so the reader does not require
# it. The setup program `<name>_frames` must be a name too.
PROGRAM_CHARS = _NAME_CHARS - len("_frames")
# The routines the program defines after its own DEF, and the keywords of the statements robomax
# reads and writes (a DEF so named would not compile).
_RESERVED = ("spot_weld", "grip", "release", "DEF", "END", "DEFDAT", "ENDDAT", "DEFFCT", "ENDFCT", "DECL", "GLOBAL",
             "PTP", "LIN", "CIRC", "SPLINE", "ENDSPLINE", "SPL", "SLIN", "SCIRC", "WAIT", "FOR", "SEC", "IF", "THEN",
             "ELSE", "ENDIF", "LOOP", "ENDLOOP", "WHILE", "ENDWHILE", "REPEAT", "UNTIL", "SWITCH", "CASE", "DEFAULT",
             "ENDSWITCH", "GOTO", "HALT", "RETURN", "EXIT", "INTERRUPT", "TRIGGER", "SIGNAL", "INT", "REAL", "BOOL",
             "CHAR", "TRUE", "FALSE", "AND", "OR", "NOT", "EXOR", "CONTINUE", "BRAKE", "INI")
_BASELINES = ("_published", "_teach_in")


def program_name(name: str) -> str:
    """The DEF and file name a cell's program `name` becomes (`PROGRAM_CHARS` at most; see
    `dialect.fitted_identifier`).

    >>> program_name("Kabine Flansch"), program_name("7up"), program_name("lin")
    ('Kabine_Flansch', 'P7up', 'lin_prog')
    """
    return fitted_identifier(name, max_chars=PROGRAM_CHARS, reserved=_RESERVED, keep=_BASELINES)


def frame_name(frame: FrameDef) -> str:
    """How KRL refers to a stored frame: `TOOL_DATA[n]` or `BASE_DATA[n]`."""
    return f"{'TOOL' if frame.kind == 'tool' else 'BASE'}_DATA[{frame.number}]"


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as KRL states it: frames by number (with the cell's names for the folds), KUKA
    configuration data, TCP-distance blends, whole-percent PTP speeds and accelerations, waits on
    input numbers, the package's welds with `weld: package`, and each move's note as a comment
    line before its fold (the smartPAD shows the fold line, not the statements inside). On a
    tilted mount the base frames are relative to $ROBROOT, the robot base frame itself in a slot
    of its own (`_robot_base_slot`)."""
    require_six_axes(robot, "KRL")
    numbered_frames(planned.program, "KRL", TOOL_SLOTS, BASE_SLOTS)
    numbered_inputs(planned.program, SIGNALS.label, *SIGNALS.inputs)
    numbered_outputs(planned.program, SIGNALS.label, *SIGNALS.outputs)
    tilted = planned.program.setup.tilted_mount
    program = _robot_base_slot(planned.program) if tilted else planned.program
    # $BASE is relative to $WORLD (mount.py); on a tilted mount the frames are stated relative to
    # $ROBROOT, which is the robot base frame.
    program = dataclasses.replace(program, frames=tuple(dataclasses.replace(f, in_world=f.kind == "base" and not tilted)
                                                        for f in program.frames))
    names = tuple((frame_name(f), f.name) for f in program.frames)
    program = with_frame_names(program, frame_name)
    program = with_brand_configs(program, planned.joints, robot, "kuka")
    program = with_tcp_blends(dataclasses.replace(planned, program=program), robot)
    program = with_package_welds(program, "KRL")
    program = ascii_comments(program)         # KSS reads its files in Windows-1252 (FILE_ENCODING)
    out: list[Instruction] = []
    for ins in program.instructions:
        if isinstance(ins, (PtpMove, LinMove)) and ins.comment:
            out.append(Comment(ins.comment))
            ins = dataclasses.replace(ins, comment="")
        if isinstance(ins, PtpMove):
            ins = dataclasses.replace(ins, speed=percent(ins.speed) / 100, accel=percent(ins.accel) / 100)
        elif isinstance(ins, LinMove):
            if ins.speed_mm_s > DEF_VEL_CP_M_S * 1000.0:
                raise ExportError(f"KRL: a LIN at {ins.speed_mm_s / 1000:.3f} m/s is faster than KSS's DEF_VEL_CP "
                                  f"{DEF_VEL_CP_M_S:.0f} m/s, where BAS.SRC caps $VEL.CP")
            ins = dataclasses.replace(ins, accel=percent(ins.accel) / 100)
        out.append(ins)
    setup = dataclasses.replace(program.setup, frame_names=names)
    return dataclasses.replace(program, name=program_name(program.name), instructions=tuple(out), setup=setup)


def _robot_base_slot(program: Program) -> Program:
    """The program with the robot base frame as a base frame of its own when it names no user
    frame: on a tilted mount BASE_NO 0 would select $WORLD (BAS.SRC BASE(0)), which the
    integrator's $ROBROOT turns away from the robot base; BASE_DATA[n] = $ROBROOT is the robot
    base frame whatever the mounting. It takes the lowest base slot (the program uses none)."""
    if any(f.kind == "base" for f in program.frames):
        return program
    frame = FrameDef(ROBOT_BASE_FRAME, "base", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 1)
    moves = tuple(dataclasses.replace(i, base=ROBOT_BASE_FRAME) if isinstance(i, LinMove) and i.base == NULL_FRAME
                  else i for i in program.instructions)
    return dataclasses.replace(program, frames=(*program.frames, frame), instructions=moves)


# ================================================================================== writing


def _real(value: float, decimals: int = 6) -> str:
    """A REAL as KSS writes motion data (six significant digits: `100.000`, `50.0000`, `2.00000`),
    or with the program's decimals when six digits would not state it exactly."""
    six = f"{value:#.6g}"
    if "e" not in six and float(six) == round(value, decimals):
        return six
    return _plain(value, decimals)


def _plain(value: float, decimals: int) -> str:
    """`value` with at most `decimals` places and no trailing zeros: `0.5`, `2`, `0.123456`."""
    text = f"{value:.{decimals}f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def _frame_number(name: str, kind: str) -> int:
    """The controller's slot of a frame the program refers to (0: the null frame / $WORLD)."""
    if name == NULL_FRAME:
        return 0
    match = re.fullmatch(rf"{'TOOL' if kind == 'tool' else 'BASE'}_DATA\[(\d+)\]", name)
    if match is None:
        raise ExportError(f"KRL selects frames by number: cannot select {kind} {name or '?'!r}")
    return int(match[1])


@dataclass(slots=True)
class _Writer:
    program: Program
    src: list[str] = field(default_factory=list)
    dat: list[str] = field(default_factory=list)
    n_point: int = 0
    n_pdat: int = 0
    n_ldat: int = 0

    def shown(self, kind: str, number: int) -> str:
        """`Tool[2]:gun2`, `Base[0]`: a frame as the fold shows it (its name is display only)."""
        label = "Tool" if kind == "tool" else "Base"
        names = dict(self.program.setup.frame_names)
        name = names.get(f"{label.upper()}_DATA[{number}]", "") if number else ""
        return f"{label}[{number}]" + (f":{name[:_NAME_CHARS]}" if name else "")

    def point(self, ins: PtpMove | LinMove, tool: int, base: int) -> None:
        """One motion: its fold in the .src, its point, frame and motion data in the .dat."""
        self.n_point += 1
        p = f"P{self.n_point}"
        frames = f"{self.shown('tool', tool)} {self.shown('base', base)}"
        apo = ins.flyby_mm if ins.flies else _APO_DEFAULT_MM
        cont = " CONT" if ins.flies else ""
        if isinstance(ins, PtpMove):
            self.n_pdat += 1
            data, v = f"PDAT{self.n_pdat}", str(percent(ins.speed))
            approx = "C_DIS" if ins.flies else ""
            self.src.append(f";FOLD PTP {p}{cont} Vel={v} % {data} {frames};%{{PE}}%R {_KSS},%MKUKATPBASIS,%CMOVE,"
                            f"%VPTP,%P 1:PTP, 2:{p}, 3:{approx}, 5:{v}, 7:{data}")
            self.src += ["$BWDSTART=FALSE", f"PDAT_ACT=P{data}", f"FDAT_ACT=F{p}", f"BAS(#PTP_PARAMS,{v})",
                         f"PTP X{p} {approx}", ";ENDFOLD"]
            values = ",".join(f"{a} {value:.4f}" for a, value in zip(_AXES, ins.target_deg))
            self.dat.append(f"DECL E6AXIS X{p}={{{values},{_EXTERNAL}}}")
            self.dat.append(self.fdat(p, tool, base))
            self.dat.append(f"DECL PDAT P{data}={{VEL {_real(percent(ins.speed))},ACC {_real(percent(ins.accel))},"
                            f"APO_DIST {_real(apo)},APO_MODE #CDIS,GEAR_JERK 50.0000,EXAX_IGN 0}}")
            return
        self.n_ldat += 1
        data = f"CPDAT{self.n_ldat}"
        exact = _plain(ins.speed_mm_s / 1000.0, 6)          # what BAS and the LDAT state
        shown = _plain(ins.speed_mm_s / 1000.0, 3)          # what the fold shows
        approx = "C_DIS C_DIS" if ins.flies else ""
        self.src.append(f";FOLD LIN {p}{cont} Vel={shown} m/s {data} {frames};%{{PE}}%R {_KSS},%MKUKATPBASIS,"
                        f"%CMOVE,%VLIN,%P 1:LIN, 2:{p}, 3:{approx}, 5:{shown}, 7:{data}")
        self.src += ["$BWDSTART=FALSE", f"LDAT_ACT=L{data}", f"FDAT_ACT=F{p}", f"BAS(#CP_PARAMS,{exact})",
                     f"LIN X{p} {approx}", ";ENDFOLD"]
        self.dat.append(f"DECL E6POS X{p}={_pose(ins)}")
        self.dat.append(self.fdat(p, tool, base))
        self.dat.append(f"DECL LDAT L{data}={{VEL {_real(ins.speed_mm_s / 1000.0)},ACC {_real(percent(ins.accel))},"
                        f"APO_DIST {_real(apo)},APO_FAC 50.0000,AXIS_VEL 100.000,AXIS_ACC 100.000,ORI_TYP #VAR,"
                        "CIRC_TYP #BASE,JERK_FAC 50.0000,GEAR_JERK 50.0000,EXAX_IGN 0}")

    def spline_point(self, ins: LinMove, tool: int, base: int, first: bool, last: bool) -> None:
        """One segment of a spline block (KSS 8.x, Operating and Programming Instructions for
        System Integrators, "Spline motion type": `SPLINE ... ENDSPLINE` with `SPL` points and
        `SLIN` straight segments; `WITH $VEL.CP` the segment's path speed in m/s; without
        `C_SPL` the block ends at an exact stop): the frames selected before the block, the
        point declared in the .dat."""
        self.n_point += 1
        p = f"P{self.n_point}"
        if first:
            self.src += [f"$TOOL = TOOL_DATA[{tool}]", f"$BASE = BASE_DATA[{base}]" if base else "$BASE = $NULLFRAME",
                         "SPLINE"]
        word = "SLIN" if ins.spline == "slin" else "SPL"
        self.src.append(f"  {word} X{p} WITH $VEL.CP = {_plain(ins.speed_mm_s / 1000.0, 6)}")
        self.dat.append(f"DECL E6POS X{p}={_pose(ins)}")
        if last:
            self.src.append("ENDSPLINE")

    @staticmethod
    def fdat(p: str, tool: int, base: int) -> str:
        return f'DECL FDAT F{p}={{TOOL_NO {tool},BASE_NO {base},IPO_FRAME #BASE,POINT2[] " ",TQ_STATE FALSE}}'


def _frames_in_force(program: Program) -> list[tuple[int, int]]:
    """The (TOOL_NO, BASE_NO) of each motion's fold: a LIN's own, a joint target's those in force
    (the first LIN's until a LIN selects others, as the plain program selected them before the
    first motion; the program's frames when it has no LIN)."""
    lins = [i for i in program.instructions if isinstance(i, LinMove)]
    if lins:
        current = (_frame_number(lins[0].tool, "tool"), _frame_number(lins[0].base, "base"))
    else:
        numbers = {f.kind: f.number for f in program.frames}
        current = (numbers.get("tool", 0), numbers.get("base", 0))
    out = []
    for ins in program.instructions:
        if isinstance(ins, LinMove):
            current = (_frame_number(ins.tool, "tool"), _frame_number(ins.base, "base"))
        if isinstance(ins, (PtpMove, LinMove)):
            out.append(current)
    return out


def write(program: Program, robot: RobotModel) -> dict[str, str]:
    """`.src`, `.dat` and frames setup texts of an adapted program."""
    name = program.name
    package = any(isinstance(i, Spot) and i.package for i in program.instructions)
    w = _Writer(program)
    w.src = ["&ACCESS RVP", "&REL 1", "&PARAM EDITMASK = *", r"&PARAM TEMPLATE = C:\KRC\Roboter\Template\vorgabe",
             f"DEF {name}( )", *(f"; {text}" for text in header_lines(program.header)),
             (f"; {_NOTE}: inline forms; mm, deg; PTP Vel %, LIN Vel m/s; blends C_DIS with the APO_DIST (mm) of "
              "each point's PDAT / LDAT")]
    if program.setup.tilted_mount:
        w.src.append(f"; {_NOTE}, {_TILTED}")      # read as the note (read.py), not as a statement
    w.src += [f"SIGNAL {sig} $IN[{k}]" for sig, k in _signals(program).items()]
    w.src += [f"SIGNAL {sig} $OUT[{k}]" for sig, k in _outputs(program).items()]
    w.src += [";FOLD INI;%{PE}", "  ;FOLD BASISTECH INI", "    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
              "    INTERRUPT ON 3 ", "    BAS (#INITMOV,0 )", "  ;ENDFOLD (BASISTECH INI)"]
    if package:
        w.src += ["  ;FOLD SPOTTECH INI", "    USERSPOT(#INIT)", "  ;ENDFOLD (SPOTTECH INI)"]
    w.src += ["  ;FOLD USER INI", "    ;Make your modifications here", "", "  ;ENDFOLD (USER INI)", ";ENDFOLD (INI)"]
    w.dat = ["&ACCESS RVP", "&REL 1", "&PARAM EDITMASK = *", r"&PARAM TEMPLATE = C:\KRC\Roboter\Template\vorgabe",
             f"DEFDAT  {name}", *(f"; {text}" for text in header_lines(program.header)),
             ";FOLD EXTERNAL DECLARATIONS;%{PE}%MKUKATPBASIS,%CEXT,%VCOMMON,%P",
             ";FOLD BASISTECH EXT;%{PE}%MKUKATPBASIS,%CEXT,%VEXT,%P", "EXT  BAS (BAS_COMMAND  :IN,REAL  :IN )",
             "DECL INT SUCCESS", ";ENDFOLD (BASISTECH EXT)"]
    if package:
        w.dat += [";FOLD SPOTTECH EXT", "EXT  USERSPOT (S_COMMAND  :IN,SPOT_TYPE  :IN )", ";ENDFOLD (SPOTTECH EXT)"]
    w.dat += [";FOLD USER EXT;%{E}%MKUKATPUSER,%CEXT,%VEXT,%P", ";Make your modifications here", "",
              ";ENDFOLD (USER EXT)", ";ENDFOLD (EXTERNAL DECLARATIONS)", f"; points of {name}.src"]
    if any(isinstance(i, LinMove) and i.accel < 1.0 for i in program.instructions):
        w.dat.append("; LIN points with ACC below 100 % carry a part: robomax planned them with that share of the "
                     "axes' accelerations; KSS bounds a LIN by $ACC.CP = DEF_ACC_CP * ACC / 100: check its a_T")
    frames = iter(_frames_in_force(program))
    n_call = n_spot = 0
    grips: dict[str, int] = {}
    moves = [i for i in program.instructions if isinstance(i, (PtpMove, LinMove))]
    in_block = [isinstance(m, LinMove) and bool(m.spline) for m in moves]
    k = -1
    for ins in program.instructions:
        if isinstance(ins, Comment):
            w.src.append(f"; {ins.text}" if ins.text else ";")
        elif isinstance(ins, LinMove) and ins.spline:
            k += 1
            w.spline_point(ins, *next(frames), not (k > 0 and in_block[k - 1]),
                           not (k + 1 < len(moves) and in_block[k + 1]))
        elif isinstance(ins, (PtpMove, LinMove)):
            k += 1
            w.point(ins, *next(frames))
        elif isinstance(ins, Spot) and ins.package:
            n_spot += 1
            w.src.append(f"USERSPOT(#SPOT,SDAT{n_spot}) ; {spot_label(ins)}")
            w.dat.append(f"DECL SPOT_TYPE SDAT{n_spot}={{GUN {ins.gun},PAIR #FIRST,RETR #OPN,CLO_TM 0,PGNO1 "
                         f"{ins.schedule},PRESS1 0.0,PGNO2 0,PRESS2 0.0}}")
        elif isinstance(ins, Spot):
            n_call += 1
            w.src.append(f"spot_weld({n_call}, {ins.time_s:.3f}) ; {spot_label(ins)}")
        elif isinstance(ins, Gripper):
            grips[ins.action] = grips.get(ins.action, 0) + 1
            w.src.append(f"{ins.action}({grips[ins.action]}, {ins.time_s:.3f}) ; {gripper_label(ins)}")
        elif isinstance(ins, Wait):
            w.src.append(f"WAIT SEC {ins.seconds:.3f}")
        elif isinstance(ins, WaitFor):
            w.src.append(f"WAIT FOR {ins.signal}")
        elif isinstance(ins, SetSignal):
            # A plain $OUT assignment stops the advance run (KSS 8.x operating and programming
            # instructions, inline form OUT: only CONT sets it in the advance run): the output is
            # set once the motion before it has ended.
            w.src.append(f"$OUT[{ins.number}]={'TRUE' if ins.value else 'FALSE'}")
        else:
            raise ExportError(f"KRL cannot write {type(ins).__name__}")
    w.src.append("END")
    if n_call or not (grips or n_spot):
        w.src += ["", "DEF spot_weld(n:IN, weld_time:IN)", "  INT n", "  REAL weld_time",
                  "  ; default weld: rest for weld_time s; replace with the gun's technology package",
                  "  WAIT SEC weld_time", "END"]
    for action in sorted(grips):
        w.src += ["", f"DEF {action}(n:IN, {action}_time:IN)", "  INT n", f"  REAL {action}_time",
                  f"  ; default {action}: rest for {action}_time s; replace with the gripper's outputs and sensors",
                  f"  WAIT SEC {action}_time", "END"]
    w.dat.append("ENDDAT")
    return {".src": "\n".join(w.src) + "\n", ".dat": "\n".join(w.dat) + "\n", FRAMES_FILE: _frames_program(program)}


def _frames_program(program: Program) -> str:
    """The setup program: the frames' values in the controller's TOOL_DATA / BASE_DATA. On a
    tilted mount each base frame is `$ROBROOT : {...}` (KRL's geometric operator: the frame on
    the right stated in the one on the left), or `$ROBROOT` itself for the robot base frame."""
    tilted = program.setup.tilted_mount
    lines = ["&ACCESS RVP", "&REL 1", f"DEF {program.name}_frames( )", *(f"; {t}" for t in header_lines(program.header)),
             f"; the frames {program.name}.src selects: run once to store them, or compare them with the calibrated ones",
             f"; {_TILTED}" if tilted else "; (mm, deg; BASE_DATA in the robot base frame, $ROBROOT = $WORLD)"]
    for f in program.frames:
        what = "tool (TCP in the flange frame)" if f.kind == "tool" else "user frame in the robot base frame"
        value = _frame(f.xyz_mm, f.zyx_deg)
        if tilted and f.kind == "base":
            value = "$ROBROOT" if not any(f.xyz_mm) and not any(f.zyx_deg) else f"$ROBROOT : {value}"
        lines.append(f"{f.name} = {value} ; {what}")
    lines.append("END")
    return "\n".join(lines) + "\n"


# Why a tilted robot's program states its base frames relative to $ROBROOT (mount.py gives the sources).
_TILTED = ("mounted tilted (ceiling, wall): $BASE is relative to $WORLD, and $ROBROOT holds the mounting, so "
           "the base frames are BASE_DATA[n] = $ROBROOT : {...} in the robot base frame (mm, deg), the robot base "
           "itself $ROBROOT")


def _signals(program: Program) -> dict[str, int]:
    """Each waited-for signal and its input number (`numbered_inputs` has checked there is one)."""
    out: dict[str, int] = {}
    for ins in program.instructions:
        if isinstance(ins, WaitFor) and ins.signal not in out:
            out[ins.signal] = int(ins.number or 0)
    return out


def _outputs(program: Program) -> dict[str, int]:
    """Each set signal and its output number (`numbered_outputs` has checked there is one)."""
    out: dict[str, int] = {}
    for ins in program.instructions:
        if isinstance(ins, SetSignal) and ins.signal not in out:
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
    return f"{{X {x:.3f},Y {y:.3f},Z {z:.3f},A {a:.4f},B {b:.4f},C {c:.4f},S {ind.status},T {ind.turn},{_EXTERNAL}}}"
