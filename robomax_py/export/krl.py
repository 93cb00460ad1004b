"""KUKA KRL (KSS 8.x), both directions: `<name>.src` (the motion) and `<name>.dat` (its points and
their motion data), written as the smartPAD writes a program a person edits there: every motion an
inline form (a fold), the program opened by the INI fold.

Sources (vendor_research §1, quoted there; repositories read at the commits given):
CHINA = HugoDanielson/ChinaMilling @ 04c963fe, NAQIU = Naqiu06/KUKA-Robotics @ 66cb2cd0,
ZINK = Aleynikovich/Zinkerreka @ 415730cd (real KR C4 backups), CELL3 = EdgarMontielG/Cell-3_R10 @
09402c6d (KSS 8.3.43, tests/data/programs/style1app1opt1.src).

What a program states, in KRL's own terms:
- Inline forms as KSS 8.3 writes them (CHINA KRC/R1/TP/Milling/amm_periphery.src 49-63 and 235-241,
  CELL3 style1app1opt1.src 36-49): a PTP is
  ``;FOLD PTP P1 CONT Vel=100 % PDAT1 Tool[2]:gun2 Base[3]:fixture_plate;%{PE}%R 8.3.48,%MKUKATPBASIS,
  %CMOVE,%VPTP,%P 1:PTP, 2:P1, 3:C_DIS, 5:100, 7:PDAT1`` (one line) with the body ``$BWDSTART=FALSE``,
  ``PDAT_ACT=PPDAT1``, ``FDAT_ACT=FP1``, ``BAS(#PTP_PARAMS,100)``, ``PTP XP1 C_DIS``, ``;ENDFOLD``;
  a LIN the same with ``Vel=0.5 m/s CPDAT1``, ``LDAT_ACT=LCPDAT1``, ``BAS(#CP_PARAMS,0.5)`` and
  ``LIN XP2 C_DIS C_DIS``; an exact stop has no CONT, ``3:, `` and the statement ends in a space
  (``PTP XP1 ``). The .dat declares per point ``DECL E6AXIS XPn`` (joint target, deg) or
  ``DECL E6POS XPn`` (X, Y, Z mm; A, B, C deg with R = Rz(A)·Ry(B)·Rx(C); S and T the KUKA Status
  and Turn of the planned configuration, docs/cell-files.md, "Controller programs"), its ``DECL FDAT FPn`` and its own ``DECL PDAT
  PPDATk`` / ``DECL LDAT LCPDATk`` with the full KSS 8.3 field lists (CHINA amm_periphery.dat 53-55,
  64; STRUCs NAQIU KRC/R1/System/$config.dat 57-59), as the smartPAD gives every point its own data.
- Frames are selected by each fold's FDAT: TOOL_NO t and BASE_NO b of the controller's TOOL_DATA[t]
  / BASE_DATA[b] (BASE_NO 0: the robot base frame, $WORLD with the factory $ROBROOT, NAQIU
  KRC/R1/Mada/$machine.dat 96), with the names the cell gives them shown in the fold (display only).
  A joint target's fold selects the frames in force too, as the smartPAD writes every point. The
  frames' values go into a setup program `<name>_frames.src` (``TOOL_DATA[t] = {...}``, ``BASE_DATA[b]
  = {...}``) that the integrator runs once or compares with the calibrated values; KSS declares
  TOOL_DATA[16] and BASE_DATA[32] in $config.dat. The robot's placement in the cell is never written.
- Speeds: PTP ``Vel`` in whole percent; LIN ``Vel`` in m/s, stated exactly in BAS's argument (what
  the controller moves at) and the LDAT's VEL, and in the fold text (``Vel=``, ``5:``) to 3 decimals
  (1 mm/s; the inline form's own display precision is UNCONFIRMED, and a person who opens and saves
  the form gets BAS written from what it shows). Accelerations: the
  PDAT's / LDAT's ACC in whole percent. Blends: ``C_DIS`` with the TCP distance in the point's
  APO_DIST (mm; PDAT ``APO_MODE #CDIS``); an exact stop keeps the inline form's default APO_DIST 100.
- The INI fold opens the program (``;FOLD INI;%{PE}`` ... ``BAS (#INITMOV,0 )`` ... ``;ENDFOLD
  (INI)``, NAQIU KRC/R1/Program/honai.src 5-20); a move's note is a comment line before its fold.
- A weld, with the cell's ``weld: call`` (default): an exact LIN to the spot followed by
  ``spot_weld(n, weld_time) ; seam/name gun G schedule S``, and `spot_weld` defined after the main
  program (rest for `weld_time`; the integrator replaces it). With ``weld: package``, the weld is
  the spot technology package's: ``USERSPOT(#SPOT,SDATn) ; seam/name gun G schedule S`` after the
  exact-stop LIN, with ``DECL SPOT_TYPE SDATn={GUN G,PAIR #FIRST,RETR #OPN,CLO_TM 0,PGNO1 S,PRESS1
  0.0,PGNO2 0,PRESS2 0.0}`` in the .dat, the ``;FOLD SPOTTECH INI`` / ``USERSPOT(#INIT)`` fold in
  INI and ``EXT USERSPOT (S_COMMAND :IN,SPOT_TYPE :IN )`` in the .dat's SPOTTECH EXT fold.
  Confirmed from public files: the package's data type and user routine (ZINK
  KRC/R1/TP/GripperSpotTech/Spot_Data.dat 9-16: ``GLOBAL STRUC SPOT_TYPE INT GUN,S_PAIR_SLCT PAIR,
  COMMAND_RETR RETR,INT CLO_TM,INT PGNO1,REAL PRESS1,INT PGNO2,REAL PRESS2``, SDEFAULT; Spot_User.src
  13-41: ``GLOBAL DEF USERSPOT (CMD :IN,S :IN )`` with ``CASE #SPOT``), the INI and EXT folds
  (NAQIU honai.src 11-13, honai.dat 7-9). Not public, so not written: the package's own SPOT
  inline form (vendor_research §1.6); the call of its user routine with a SPOT_TYPE per weld is
  the closest published form. The weld time is the schedule's on the controller (PGNO1).
- ``WAIT SEC t``, and ``WAIT FOR <signal>`` with ``SIGNAL <signal> $IN[k]`` declared, k the input
  the cell maps the signal to (`robot.controller.inputs`).

What the statements do (NAQIU KRC/R1/System/bas.src; the same logic in CHINA and ZINK): the fold
line is a comment; the statements inside run. ``BAS(#PTP_PARAMS,v)`` (43-47) runs PTP_DAT: ACC_PTP
(PDAT_ACT.ACC) and, with ``APO_MODE #CDIS``, ``$APO.CDIS = APO_DIST`` (else ``$APO.CPTP``) (560-584);
then FRAMES; then VEL_PTP(v): ``$VEL_AXIS[i] = DEF_VEL_PTP·v/100`` with DEF_VEL_PTP = 100 (362-376).
ACC_PTP sets ``$ACC_AXIS[i] = ACC`` itself when ``$ADAP_ACC <> #NONE`` (305-324), and the machine
data of all three backups has ``$ADAP_ACC=#STEP2`` (KRC/R1/Mada/$robcor.dat: NAQIU 7, CHINA 9,
ZINK 8). ``BAS(#CP_PARAMS,v)`` (48-52) runs CP_DAT: ACC_CP(LDAT_ACT.ACC), ``$APO.CDIS = APO_DIST`` (586-599);
FRAMES; VEL_CP(v): ``$VEL.CP = v`` m/s, at most DEF_VEL_CP = 2 (331-339). FRAMES (462-557): TOOL
(TOOL_NO) gives ``$TOOL = TOOL_DATA[n]``, or ``$NULLFRAME`` for 0 (404-441); BASE(BASE_NO) gives
``$BASE = BASE_DATA[n]``, or ``$WORLD`` for 0 (159-186); ``$IPO_MODE = IPO_FRAME`` (#TCP: an external
TCP, not simulated). ``BAS(#INITMOV,0)`` (57-157): $VEL_AXIS and $ACC_AXIS 100 %, $VEL.CP =
DEF_VEL_CP, $APO.CDIS = DEF_APO_CDIS (3 mm), ``$BASE = $WORLD`` and ``$TOOL = TOOL_DATA[1]``.
A fold whose FDAT_ACT line is deleted runs BAS with the FDAT_ACT last assigned (the previous fold's);
before any assignment its value is the controller's from an earlier run: unknown (the program
selects no frame). A fold without its BAS line changes no frame, speed or blend.

robomax's model of a LIN's acceleration: the LDAT's ACC is the fraction of the axes' acceleration
(and jerk) limits the line may use, as a PTP's (a part in the gripper slows the lines that carry
it). KSS bounds a classical LIN by the path acceleration instead, ``$ACC.CP = DEF_ACC_CP·ACC/100``
(ACC_CP, bas.src 275-288): the .dat says so when a LIN's ACC is below 100 %. A plain
``$ACC_AXIS[i] = a`` (robomax's earlier KRL) bounds a LIN's axes in the same model.

The reader takes the motion subset of any KRL program, inline forms or plain statements: PTP and
LIN to points declared in the .dat or the .src, or written in place (E6AXIS/AXIS, E6POS/POS/FRAME
aggregates, missing components keeping their last value), BAS calls and the PDAT/LDAT/FDAT they
use (as above), ``$VEL``, ``$ACC_AXIS``, ``$APO`` assignments, ``C_DIS``/``C_PTP``, ``WAIT SEC``,
``WAIT FOR``, calls of ``spot_weld`` and ``USERSPOT(#SPOT,...)``, the frames in force at each motion
(``$TOOL`` / ``$BASE`` set to literals, to ``TOOL_DATA[n]`` / ``BASE_DATA[n]`` or to ``$NULLFRAME``,
or by an FDAT; the values of TOOL_DATA / BASE_DATA from a setup program when given). A fold's text
that disagrees with its statements is noted among the ignored statements: the statements run. Other
motions (CIRC, SPTP, *_REL, a PTP to a Cartesian point, a point declared outside the program, an
external TCP ...) are reported as not simulated, everything else as ignored. Files may have CRLF
line ends and be Windows-1252 (`FILE_ENCODING`), as KSS writes them.

The reader follows the program as the controller runs it (`export.flow`): RETURN ends the main
program (returns from a called one), HALT stops it until it is started again (the verified cycle
ends there), GOTO continues at its jump label; a call of a DEF (or DEFFCT) of the .src or of the
frames program runs its body in place. A call of any other routine, an interrupt or trigger that
calls one, and a jump, end or call under a condition or in a loop are reported, never skipped.
``spot_weld``, ``grip`` and ``release`` are the weld and gripper actions they name while their
DEF in the .src does nothing but ``WAIT SEC`` of its time parameter (`_not_resting`); the weld
time is the call's second argument, in s. ``$VEL_AXIS[i]``, ``$ACC_AXIS[i]`` and a PDAT's ACC
(which ACC_PTP assigns to $ACC_AXIS uncapped under $ADAP_ACC #STEP2) outside 0..100 % are
reported; ``$VEL.CP`` is in m/s (rebuild compares the lines with the cell's line speed).
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
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
    with_package_welds,
    with_tcp_blends,
)
from robomax_py.export.flow import Flow, Routine, Statement, follow
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

__all__ = ["FILE_ENCODING", "FRAMES_FILE", "adapt", "frame_name", "parse", "write"]

# The setup program holding the frames' values (a companion of `<name>.src`).
FRAMES_FILE = "_frames.src"
# KSS writes its files in Windows-1252 (e.g. ZINK KRC/R1/Program/Work/C1_pickConveyorBP.src).
FILE_ENCODING = "cp1252"
# KSS 8.x declares TOOL_DATA[16] and BASE_DATA[32] ($config.dat), and 4096 digital inputs.
TOOL_SLOTS, BASE_SLOTS, INPUTS = 16, 32, 4096
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
_AXES = ("A1", "A2", "A3", "A4", "A5", "A6")
_EXTERNAL = ",".join(f"E{i} 0.0" for i in range(1, 7))
_DATA_TYPES = ("E6AXIS", "AXIS", "E6POS", "POS", "FRAME", "FDAT", "PDAT", "LDAT", "SPOT_TYPE")


def frame_name(frame: FrameDef) -> str:
    """How KRL refers to a stored frame: `TOOL_DATA[n]` or `BASE_DATA[n]`."""
    return f"{'TOOL' if frame.kind == 'tool' else 'BASE'}_DATA[{frame.number}]"


def adapt(planned: PlannedProgram, robot: RobotModel) -> Program:
    """The program as KRL states it: frames by number (with the cell's names for the folds), KUKA
    configuration data, TCP-distance blends, whole-percent PTP speeds and accelerations, waits on
    input numbers, the package's welds with `weld: package`, and each move's note as a comment
    line before its fold (the smartPAD shows the fold line, not the statements inside)."""
    require_six_axes(robot, "KRL")
    numbered_frames(planned.program, "KRL", TOOL_SLOTS, BASE_SLOTS)
    numbered_inputs(planned.program, "KRL", 1, INPUTS)
    names = tuple((frame_name(f), f.name) for f in planned.program.frames)
    program = with_frame_names(planned.program, frame_name)
    program = with_brand_configs(program, planned.joints, robot, "kuka")
    program = with_tcp_blends(dataclasses.replace(planned, program=program), robot)
    program = with_package_welds(program, "KRL")
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
    return dataclasses.replace(program, instructions=tuple(out), setup=setup)


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
    w.src += [f"SIGNAL {sig} $IN[{k}]" for sig, k in _signals(program).items()]
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
    for ins in program.instructions:
        if isinstance(ins, Comment):
            w.src.append(f"; {ins.text}" if ins.text else ";")
        elif isinstance(ins, (PtpMove, LinMove)):
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
    return f"{{X {x:.3f},Y {y:.3f},Z {z:.3f},A {a:.4f},B {b:.4f},C {c:.4f},S {ind.status},T {ind.turn},{_EXTERNAL}}}"


# ================================================================================== reading

_GRAMMAR = r"""
?start: motion | assign | frame_data | weld | gripper | wait_sec | wait_for | signal | decl | data_act | bas
      | userspot
motion: MOTION target APPROX*
target: NAME | aggregate
aggregate: "{" (NAME ":")? [field ("," field)*] "}"
field: NAME ("[" "]")? value
?value: NUMBER | BITS | NAME | ENUM | STRING
assign: SYSVAR ("." NAME)? ("[" NUMBER "]")? "=" (NUMBER | aggregate | SYSVAR | indexed | NAME)
indexed: NAME "[" NUMBER "]"
frame_data: NAME "[" NUMBER "]" "=" aggregate
weld: "spot_weld"i "(" NUMBER "," NUMBER ")"
gripper: GRIPPER "(" NUMBER "," NUMBER ")"
wait_sec: "WAIT"i "SEC"i NUMBER
wait_for: "WAIT"i "FOR"i (NAME | SYSVAR "[" NUMBER "]") ("==" NAME)?
signal: "SIGNAL"i NAME SYSVAR "[" NUMBER "]"
decl: "DECL"i NAME NAME "=" aggregate
data_act: DATA_ACT "=" NAME
bas: "BAS"i "(" ENUM ["," bas_arg] ")"
bas_arg: NUMBER | NAME ("." NAME)?
userspot: "USERSPOT"i "(" ENUM ["," NAME] ")"

MOTION.2: /(PTP|LIN)\b/i
GRIPPER.2: /(grip|release)\b/i
APPROX.2: /C_(DIS|PTP|VEL|ORI)\b/i
DATA_ACT.2: /(PDAT|LDAT|FDAT)_ACT\b/i
SYSVAR: /\$[A-Za-z_][A-Za-z0-9_]*/
NAME: /[A-Za-z_][A-Za-z0-9_$]*/
ENUM: /#[A-Za-z_][A-Za-z0-9_]*/
STRING: /"[^"]*"/
BITS: /'[Bb][01]+'/
NUMBER: /[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?/
%ignore /[ \t]+/
"""

# Motions KRL has that this reader does not simulate: a program with one is not verified clean.
_UNSIMULATED = re.compile(r"^(CIRC|SPTP|SLIN|SCIRC|PTP_REL|LIN_REL|CIRC_REL|SPTP_REL|SLIN_REL|SPLINE|PTP_SPLINE|RSI_MOVECORR)\b",
                          re.IGNORECASE)
_KNOWN = re.compile(r"^(PTP|LIN|\$|spot_weld\s*\(|(grip|release)\s*\(|WAIT\s+(SEC|FOR)\b|SIGNAL\b|"
                    rf"DECL\s+({'|'.join(_DATA_TYPES)})\b|(TOOL|BASE)_DATA\s*\[|(PDAT|LDAT|FDAT)_ACT\b|BAS\s*\(|"
                    r"USERSPOT\s*\()", re.IGNORECASE)
# A motion to a named point or an aggregate; anything else (an array element, a system variable, an
# expression) is not simulated.
_PLAIN_MOTION = re.compile(r"^(PTP|LIN)\s+([A-Za-z_][A-Za-z0-9_$]*|\{.*\})(\s+C_(DIS|PTP|VEL|ORI))*$", re.IGNORECASE)
_PLAIN_WAIT_FOR = re.compile(r"^WAIT\s+FOR\s+([A-Za-z_]\w*|\$IN\s*\[\s*\d+\s*\])(\s*==\s*TRUE)?$", re.IGNORECASE)
# The template's stop-message interrupt (BASISTECH INI): no effect on the motion.
_TEMPLATE = re.compile(r"^((GLOBAL\s+)?INTERRUPT\s+DECL\s+3\s+WHEN\s+\$STOPMESS\s*==\s*TRUE\s+DO\s+IR_STOPM\s*\(\s*\)|"
                       r"INTERRUPT\s+ON\s+3)$", re.IGNORECASE)

_BLOCK_START = re.compile(r"^(IF\b.*\bTHEN|LOOP|WHILE\b.*|FOR\b.*|REPEAT|SWITCH\b.*)$", re.IGNORECASE)
_BLOCK_END = re.compile(r"^(ENDIF|ENDLOOP|ENDWHILE|ENDFOR|UNTIL\b.*|ENDSWITCH)$", re.IGNORECASE)
# An inline form's fold: `;FOLD PTP P1 ... ;%{PE}%R 8.3.48,...,%P 1:PTP, 2:P1, 3:C_DIS, 5:100, 7:PDAT1`.
_MOTION_FOLD = re.compile(r"^;FOLD\s+(PTP|LIN)\b.*;%\{PE\}.*%P\s+(.*)$", re.IGNORECASE)


@lru_cache(maxsize=1)
def _parser() -> Lark:
    return Lark(_GRAMMAR, parser="lalr", lexer="contextual")


def _statement(text: str) -> tuple[str, str]:
    """A KRL line -> (statement, comment): the comment is what follows the first ';' outside
    quotes ('B010' literals, "strings")."""
    quote = ""
    for i, c in enumerate(text):
        if c in "'\"":
            quote = "" if quote == c else (quote or c)
        elif c == ";" and not quote:
            return text[:i].strip(), text[i + 1:].strip()
    return text.strip(), ""


@dataclass(slots=True)
class _Fold:
    """An inline form being read: what its text says (`params`: %P n -> value) and what its
    statements do (`done`), compared at its ;ENDFOLD."""

    line: int
    kind: str
    params: dict[str, str]
    depth: int                      # of folds, counting its own
    done: dict[str, str] = field(default_factory=dict)


class _Reader:
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

    # ------------------------------------------------------------------ statements

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
        self.last_pose.update({k: float(v) for k, v in values.items() if k in ("X", "Y", "Z", "A", "B", "C", "S", "T")})  # type: ignore[arg-type]
        missing = [k for k in "XYZABC" if k not in self.last_pose]
        if missing:
            raise self.error(line, f"the first Cartesian target must give {', '.join(missing)}")
        config = ""
        if "S" in values and "T" in values:
            # KSS 8 sets S bit 4 in taught points (vendor_research §1.5): the configuration is bits 0-2.
            config = str(ConfigIndicator(int(self.last_pose["S"]) & 7, int(self.last_pose["T"]) & 63))
        xyz = tuple(self.last_pose[k] for k in "XYZ")
        zyx = tuple(self.last_pose[k] for k in "ABC")
        self.add(LinMove(xyz, zyx, config, self.vel_cp * 1000.0, comment=comment, flyby_mm=flyby_mm,
                         accel=self.lin_accel, tool=self.tool, base=self.base), line)

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


# ------------------------------------------------------------------ control flow

# Routines and statements (KUKA, KSS 8.3 Operating and Programming Instructions for System
# Integrators, "Program execution control": GOTO to a jump label `name:` in the same routine,
# HALT, RETURN; as RoboDK's KRC4 post writes them, ros-industrial-attic/robodk_postprocessors@
# d7e6c1c0 KUKA_KRC4.py:281-286 `HALT`, 345 and 354 `START_TIMER:` / `GOTO START_TIMER`). HALT stops
# the program until it is started again (flow.py: a pause ends the verified cycle).
_DEF_HEAD = re.compile(r"^(?:GLOBAL\s+)?DEF\s+([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*$", re.IGNORECASE)
_DEFFCT_HEAD = re.compile(r"^(?:GLOBAL\s+)?DEFFCT\s+\w+(?:\s*\[[^\]]*\])?\s+([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)\s*$",
                          re.IGNORECASE)
_ROUTINE_END = re.compile(r"^(END|ENDFCT)$", re.IGNORECASE)
# Statements of call form that are not calls of a routine: BAS.SRC, the spot package's user
# routine, the default weld and gripper routines (a weld or gripper action, `_not_resting` checks
# their bodies) and PULSE (an output pulse).
_STATEMENT_CALLS = frozenset({"bas", "userspot", "spot_weld", "grip", "release", "pulse"})
# robomax's default routines that rest for their second argument: a call of one is a weld or a
# gripper action; the reader takes it for that only while its body does nothing else.
_REST_ROUTINES = frozenset({"spot_weld", "grip", "release"})
_INTERRUPT_DECL = re.compile(r"^(GLOBAL\s+)?INTERRUPT\s+DECL\b", re.IGNORECASE)


def _routines(text: str, source: str) -> list[Routine]:
    """The DEF / DEFFCT routines of a .src text, in order (a routine missing its END runs to the
    end of the text)."""
    out: list[Routine] = []
    head: tuple[str, tuple[str, ...]] | None = None
    body: list[Statement] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        stmt, comment = _statement(raw)
        match = _DEF_HEAD.match(stmt) or _DEFFCT_HEAD.match(stmt)
        if match and head is None:
            params = tuple(p.split(":")[0].strip() for p in match.group(2).split(",") if p.strip())
            head, body = (match.group(1), params), []
            continue
        if head is None or stmt.startswith("&"):
            continue
        if _ROUTINE_END.match(stmt):
            out.append(Routine(head[0], tuple(body), head[1], source))
            head = None
            continue
        body.append(Statement(number, stmt, comment, raw, source))
    if head is not None:
        out.append(Routine(head[0], tuple(body), head[1], source))
    return out


def _classifier(defined: set[str]) -> Callable[[Statement], Flow]:
    """What a KRL statement does to the flow (`flow.Flow`); `defined`: the routines the texts
    define (lower case), whose calls in expressions (a DEFFCT's) run their bodies."""
    def classify(st: Statement) -> Flow:
        text = st.text
        if not text:
            return Flow()
        if re.fullmatch(r"RETURN\b.*", text, re.IGNORECASE):
            return Flow("end", "RETURN")
        if re.fullmatch(r"HALT", text, re.IGNORECASE):
            return Flow("end", "HALT", scope="program", pause=True)
        if re.fullmatch(r"EXIT", text, re.IGNORECASE):
            return Flow("unsupported", why="EXIT leaves a loop")
        if re.fullmatch(r"(RESUME|BRAKE(\s+F)?)", text, re.IGNORECASE):
            return Flow("unsupported", why="an interrupt routine's statement")
        jump = re.fullmatch(r"GOTO\s+([A-Za-z_][A-Za-z0-9_]*)", text, re.IGNORECASE)
        if jump:
            return Flow("goto", jump.group(1))
        label = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)\s*:", text)
        if label:
            return Flow("label", label.group(1))
        if _BLOCK_START.match(text):
            return Flow("open")
        if _BLOCK_END.match(text):
            return Flow("close")
        if _INTERRUPT_DECL.match(text) and not _TEMPLATE.match(text):
            return Flow("unsupported", why="an interrupt: its routine runs whenever its condition holds")
        if re.match(r"^TRIGGER\b", text, re.IGNORECASE) and re.search(r"\bDO\s+[A-Za-z_]\w*\s*\(", text, re.IGNORECASE):
            return Flow("unsupported", why="a trigger calls a routine along the path")
        call = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)\s*\((.*)\)", text)
        if call:
            if call.group(1).lower() in _STATEMENT_CALLS:
                return Flow()
            return Flow("call", call.group(1), arguments=bool(call.group(2).strip()))
        assign = re.match(r"^[$A-Za-z_][\w$.\[\], ]*=(?!=)(.*)$", text)
        if assign:
            for name, args in re.findall(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(([^()]*)\)", assign.group(1)):
                if name.lower() in defined:
                    return Flow("call", name, arguments=bool(args.strip()))
        return Flow()
    return classify


def _not_resting(routine: Routine) -> list[tuple[int, str, str]]:
    """(line, statement, why) of what a default routine (spot_weld, grip, release) does besides
    resting for its second parameter: its declarations, comments and one `WAIT SEC <it>` (the
    routine `write` gives). A call of it is then a weld or a gripper action of that time;
    anything else in it (a motion, another time, another unit) is reported."""
    head = f"{routine.name}: "
    time = routine.params[1] if len(routine.params) == 2 else None
    waits = 0
    out: list[tuple[int, str, str]] = []
    for st in routine.body:
        text = st.text
        if not text or re.fullmatch(r"(DECL\s+)?(INT|REAL)\s+[A-Za-z_]\w*(\s*,\s*[A-Za-z_]\w*)*", text, re.IGNORECASE):
            continue
        wait = re.fullmatch(r"WAIT\s+SEC\s+([A-Za-z_]\w*)", text, re.IGNORECASE)
        if wait and time is not None and wait.group(1).lower() == time.lower() and waits == 0:
            waits += 1
            continue
        out.append((st.line, text, head + "a weld or gripper routine that does more than rest its time (verify takes a "
                                          "call of it for the weld or action it names)"))
    if waits == 0:
        line = routine.body[0].line - 1 if routine.body else 0
        out.append((line, routine.name, head + "it does not rest its time (WAIT SEC of its second parameter)"))
    return out


def _dat_name(file: str) -> str:
    return re.sub(r"\.src$", ".dat", file, flags=re.IGNORECASE) if file.lower().endswith(".src") else file + " (.dat)"


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
