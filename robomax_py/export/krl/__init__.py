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
- A robot mounted tilted (ceiling, wall; `export.mount`) has its mounting in $ROBROOT, and $BASE is
  relative to $WORLD: its base frames are ``BASE_DATA[b] = $ROBROOT : {...}`` (KRL's geometric
  operator, the right frame stated in the left one), the robot base frame ``BASE_DATA[1] =
  $ROBROOT`` in place of BASE_NO 0 (which would be $WORLD), and the program's note line says so.
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
or by an FDAT; ``$BASE = $ROBROOT`` or ``$ROBROOT : {...}``; the values of TOOL_DATA / BASE_DATA from
a setup program when given, literals relative to $WORLD and those on $ROBROOT to the robot base). A fold's text
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

from robomax_py.export.krl.read import parse
from robomax_py.export.krl.write import (
    FILE_ENCODING,
    FRAMES_FILE,
    SIGNALS,
    adapt,
    frame_name,
    program_name,
    write,
)

__all__ = ["FILE_ENCODING", "FRAMES_FILE", "SIGNALS", "adapt", "frame_name", "parse", "program_name", "write"]
