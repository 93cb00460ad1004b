"""Kawasaki AS (a program file `<name>.as`, as `.pg` files hold too), both directions.

What a program states, in AS's terms (Kawasaki Robot Controller D Series, AS Language Reference
Manual, 902091017DEB; RoboDK's Kawasaki post, ros-industrial-attic/robodk_postprocessors@d7e6c1c0
Kawasaki.py:49-60, 85-91, 105-185, and its example RoboDK/Industrial-Robots-VSCode@6b1e43c3
examples/Kawasaki.pg):
- `.PROGRAM name()` ... `.END` blocks, one file holding the program and its weld and gripper
  routines; comments after `;`;
- joint moves `JMOVE #[j1, ..., j6]` to joint locations (deg, 4 decimals): the joint values are
  the configuration, turns included; linear moves `LMOVE TRANS(x, y, z, o, a, t)`, mm and the
  Euler angles O, A, T in deg with R = Rz(O)·Ry(A)·Rz(T) (z, y', z''; RoboDK robomath
  Adept_2_Pose, RoboDK/RoboDK-API@84099bba Python/robodk/robomath.py:815-835, and Roboception's
  "Kawasaki XYZ-OAT format" page agree), mm with 3 decimals and O, A, T with 5. RoboDK's post
  writes 4 (Kawasaki.py:55), too few: the ZYX angles (4 decimals) turned into OAT rounded to 4
  come back changed by up to 1e-4 deg, beyond verify's orientation tolerance of 1e-6 rad
  (5.7e-5 deg) for a spot the planner put at its tolerance's edge; rounded to 5 (at most 3e-7
  rad off) they come back as written away from ZYX's gimbal lock (|B| < 60 deg). A transformation location carries no
  configuration: along a straight line the arm keeps its own (the configuration instructions
  LEFTY ... DWRIST act on the next joint-interpolated motion), so LMOVE targets state none
  (`robot.ik.config.kawasaki_config` names the branch for SRCL);
- frames: `TOOL <name>` with `POINT <name> = TRANS(...)` the TCP in the flange frame, and
  `BASE <name>` / `BASE NULL`. AS's BASE is "the base coordinates relative to the null base
  coordinates": the null base is the robot's own base frame, and every transformation location is
  relative to the base coordinates. AS has no user frame besides it, so BASE is the program's user
  frame of docs/cell-files.md, "Controller programs": the cell's user frame in the robot base frame, or NULL (the robot base frame
  itself); the robot's placement in the cell is never written. Names `tool<n>` / `base<n>` after
  the cell's frame numbers;
- per motion (no ALWAYS: "applies to the next motion only"): `SPEED <%>` (joint moves, whole % of
  the maximum, 1 decimal) or `SPEED <v> MM/S` (linear, 1 decimal), and `ACCURACY <mm>`: a fly-by
  as the planned blend's TCP distance (3 decimals, as RoboDK's post writes it, Kawasaki.py:178-180),
  and `ACCURACY 1 FINE` at every stop; a motion
  slower to accelerate than the axes allow (a part in the gripper: robot.yaml `limits.loaded`)
  `ACCEL <%>` and `DECEL <%>` (1 decimal), the share of the maximum acceleration and deceleration
  the next motion uses (RoboDK's post writes the same statement, robodk_postprocessors@d7e6c1c0
  Kawasaki.py:163-167; without it the controller accelerates at 100 % and every later event comes
  early);
- a weld (`weld: call`) as the stop, then `CALL spot_weld(n, weld_time) ; seam/name gun G
  schedule S`, `.PROGRAM spot_weld(n, t)` resting `TWAIT t`; grippers `CALL grip(n, t)` /
  `CALL release(n, t)` alike; `weld: package` has no AS form here;
- waits `TWAIT t` (3 decimals) and `SWAIT <1000 + k> ; <signal>`, external input k (AS numbers
  external inputs from 1001); a station's interlock output `BREAK` then `SIGNAL k ; <signal>`
  (`SIGNAL -k` off), external output k: AS runs the program ahead of the motion, and BREAK holds
  it until the robot has stopped.

The reader takes these programs and other writers' (RoboDK's: `SPEED ... ALWAYS`, `ACCURACY ...
ALWAYS`, `TWAIT`, `WAIT SIG(n)`, `BASE TRANS(...)`, `TOOL TRANS(...)`); JMOVE to a transformation
location, circular moves, calls of other programs and control flow are reported, not simulated.
"""

from robomax_py.export.kawasaki_as.oat import (
           matrix_from_oat,
           oat_from_matrix,
           oat_from_zyx,
           zyx_from_oat,
)
from robomax_py.export.kawasaki_as.read import parse
from robomax_py.export.kawasaki_as.write import SIGNALS, adapt, frame_name, write

__all__ = ["SIGNALS", "adapt", "frame_name", "matrix_from_oat", "oat_from_matrix", "oat_from_zyx", "parse", "write",
           "zyx_from_oat"]
