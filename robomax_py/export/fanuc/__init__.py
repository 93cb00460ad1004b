"""FANUC TP (ASCII `.ls`), both directions: the program `<NAME>.ls`, its frames setup program
`<NAME>_FRAMES.ls` and the default routines `SPOT_WELD.ls`, `GRIP.ls`, `RELEASE.ls`.

What a program states, in TP's terms:
- `/MN` with `J P[i] n% FINE|CNTn` and `L P[i] n mm/sec FINE|CNTn`; `/POS` with `GP1`, `UF : u`,
  `UT : t`, and either `CONFIG : 'F|N U|D T|B, t4, t5, t6'` with X, Y, Z mm and W, P, R deg
  (R = Rz(R)·Ry(P)·Rx(W)) or J1..J6 in deg as the controller counts them: with robot.yaml
  `controller.j23_coupling: true` J3 is measured from the horizontal, J3 = J3(URDF) - J2(URDF)
  (the ROS-Industrial fanuc_driver's joint streamer, J23_factor = 1);
- frames selected by number before the first motion, `UFRAME_NUM=u` and `UTOOL_NUM=t`, and each
  position's `UF : u, UT : t` the same: changing the numbers under a taught position "may cause a
  frame mismatch error and stop the TP program" (FANUC B-84184EN/03, Remote Motion Interface
  operator's manual, §2.3.6; INTP-251 / INTP-253 "Tool frame number mismatch" in a ROBOGUIDE
  probe, LeroyDu56/CrossArm docs/fanuc_ls_format.md). With factory settings the world frame is the
  robot base (the controller knows nothing of the cell), so `UF : 0` targets are in the robot base
  frame and a user frame is given in it; the robot's placement in the cell is never written. The
  frames' values go into the setup program (`PR[k]` set element by element, `UTOOL[t]=PR[k]`,
  `UFRAME[u]=PR[k]`) from the position registers the cell hands (`robot.controller.registers`);
  without them it lists the values as remarks for the SETUP Frames screen. The main program writes
  no register and no frame;
- mm with 3 decimals, W, P, R and joint values with 4, speeds in whole % and mm/sec, waits in 0.01 s (rounded up);
- blends as `CNTn`: robomax's model of CNT flies by with the joint-space radius n x 0.12 deg
  (CNT100 = 12 deg, the largest radius the planner uses), so the planner's radii are whole CNTs;
- a weld (`weld: call`, the default) as `L ... FINE`, then `CALL SPOT_WELD(n,weld_time)`, then the
  `!seam/name gun G schedule S` remark (TP has no comment at the end of a statement); SPOT_WELD is
  its own program (TP defines one program per file) that rests `weld_time` s: `WAIT AR[2]`, an
  argument register as a wait time (loaded and run in ROBOGUIDE, CrossArm docs/fanuc_ls_format.md
  "Call with arguments"; accepted by the JTremblayAGT/fanuc-lsp grammar, TpWaitInstructionTests.cs
  47), so it writes no register. With `weld: package` the weld is SpotTool+'s: the motion carries
  `SPOT[SD=1,P=1,S=<schedule>,ED=1]` on the continuation line the controller prints it on (S the
  weld schedule; SD / ED the start and end distance schedules and P the pressure schedule, all
  schedule 1 of the controller's tables), and the program's `/APPL` names the gun as SpotTool+'s
  `SPOT Welding Equipment Number` (one gun per program);
- `WAIT t(sec)` and `WAIT DI[k:<signal>]=ON`.

As a controller prints a program and loads it again (its own exports; FANUC B-84184EN/03 §5: "A
Teach Pendant program can be printed out as a LS file ... When loading an LS file into the
controller, the LS file goes through an ASCII to binary conversion"):
- program names of capital letters, digits and `_`, starting with a letter, at most NAME_CHARS =
  36 characters (B-84184EN/03 §2.4.6: "The ProgramName string can be up to 36 bytes"; R-30iB
  V8.30 exports hold 16-character names, kamilkozdro/FanucProgramAnalyze@e585a61d
  fanucPrograms/odbierzprzedmuch.ls). A cell's name becomes `program_name(name)`: capitals, `_`
  for other characters, a `P` before a leading digit or `_`, and past 29 characters (so that
  `<NAME>_FRAMES` fits) cut to 24 with `_` and 4 hexadecimal digits of its SHA-256, so that two long
  names stay apart. Each file is named as its program (`<NAME>.ls`): MakeTP turns `<NAME>.LS` into
  `<NAME>.TP`, and PrintTP "expects the .TP filename to match the internal program name"
  (djfacio/fanuc-ai-tp@ebec2792 AGENTS.md 170). `FILE_NAME` is left empty: in exports it names the
  program a copy was made from (`/PROG  REQMENU` with `FILE_NAME = SENDDATA`, FanucProgramAnalyze
  reqmenu.ls), and RoboDK's post (ros-industrial-attic/robodk_postprocessors@d7e6c1c0
  Fanuc_R30iA.py 182) writes it empty too;
- remarks `!text` of at most REMARK_CHARS = 32 characters: of 4566 remarks in 807 programs exported
  by controllers (mitchtown98/FANUC_LS_Examples@9948f158) 676 are exactly 32 characters long and
  none of the exported ones longer. Longer texts (the header's lines, a long seam or spot name)
  continue on the next remarks, each starting with `+` and followed by the rest of the text exactly
  as it goes on (a line breaks before a space, which the continuation keeps after its `+`); the
  reader joins them. The header's ` | ` separators are written `, ` (no `|` occurs in those
  remarks);
- `/ATTR` as exports have it: `COMMENT` of at most 16 characters (the exports' longest; ROBOGUIDE
  pads it to 16, CrossArm roboguide_export/PLACE.LS), `CREATE` / `MODIFIED` the `--stamp` date,
  else DATE 00-01-01 (the controller sets its own dates on loading, CrossArm), `PROG_SIZE` and
  `MEMORY_SIZE` 0 (recomputed on loading; RoboDK writes 0), `LINE_COUNT` the number of statements,
  `DEFAULT_GROUP = 1,*,*,*,*;` (R-30iB V8.30 and ROBOGUIDE exports; `*,*,*,*,*` for the routines,
  which hold no motion group);
- statements numbered `   1:  `, a motion's letter right after the colon (`   3:J P[1] 100% FINE
  ;`), CRLF line ends (ros-industrial/fanuc@8fee5e30 fanuc_driver/tpe/ros_movesm.ls; "MakeTP may
  reject" LF-only files, djfacio/fanuc-ai-tp tools/Invoke-FanucToolTests.ps1 1079); numbers below 1
  without their leading zero (`WAIT    .30(sec)`, `CALL SPOT_WELD(1,.500)`, `P =     -.234 deg`);
  the position blocks with the exports' spacing (`\\tX =   485.864  mm,`, `\\tJ1=    62.188 deg,`);
  a weld position carries the spot's name as its comment, cut to 16 characters (`P[4:s7]`, as
  `P[12:W_PT00045027_017]` in SpotTool+ exports).

The reader takes both these files and other writers' (any spacing, LF or CRLF, `/APPL`, position
comments, continuation lines). Remarks: TP remarks are short; the notes other dialects carry on
each move are left out.

It follows the program as the controller runs it (`export.flow`): END and ABORT end it, PAUSE
stops it until it is started again (the verified cycle ends there), JMP LBL[n] continues at
LBL[n]; a CALL of the frames setup program runs it in place. A CALL of any other program (the
default routines aside), RUN, conditional jumps and calls (IF ..., SELECT, WAIT ... TIMEOUT,LBL),
a speed OVERRIDE, waits other than `WAIT t(sec)` and `WAIT DI[k]=ON` (on a register, a flag, an
expression), and what runs inside IF ... THEN / FOR blocks are reported, never skipped. A
CALL SPOT_WELD / GRIP / RELEASE is the weld or gripper action it names while the routine shipped
beside the program (SPOT_WELD.ls ...) does nothing but `WAIT AR[2]`; the time is the call's second
argument, in s. Linear speeds in mm/sec, cm/min or inch/min are read in their units; a move
stated by its time (sec, msec) or its orientation speed (deg/sec) is reported; joint speeds in %
(rebuild reports them above 100 %, and lines above the cell's line speed).
"""

from __future__ import annotations

from robomax_py.export.fanuc.read import parse
from robomax_py.export.fanuc.write import (
    CNT_DEG,
    FRAMES_FILE,
    NAME_CHARS,
    REMARK_CHARS,
    ROUTINES,
    SIGNALS,
    adapt,
    frame_name,
    program_name,
    remarks,
    write,
)
from robomax_py.export.fanuc.write import FRAMES_SUFFIX as FRAMES_SUFFIX
from robomax_py.program import FrameDef as FrameDef

__all__ = ["CNT_DEG", "FRAMES_FILE", "NAME_CHARS", "REMARK_CHARS", "ROUTINES", "SIGNALS", "adapt", "frame_name", "parse",
           "program_name", "remarks", "write"]
