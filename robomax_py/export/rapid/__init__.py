r"""ABB RAPID, both directions: a program module `<name>.mod` and a data module `<name>_frames.mod`.

Sources, cited below by tag:
- [R3] ABB RAPID Reference Manual, BaseWare OS 3.x ("Basic Characteristics RAPID",
  https://www.yumpu.com/en/document/view/5679047/basic-characteristics-rapid/<page>): p. 96 (5.1 data
  scope), 98 (5.3 persistent declaration), 183 (loaddata), 225-226 (tooldata), 233-234 (wobjdata),
  665 (gundata), 675-676 (SpotL), 699 (SWUSRF).
- [PS4] ABB Product Specification "RobotWare Options for BaseWare OS 4.0", SpotWare
  (https://www.easymanua.ls/abb/irb-6650-125-3-2/manual?p=186).
- [DRV] ros-industrial/abb_driver @ f3068b92 (BSD): rapid/ROS_common.sys:1 `MODULE
  ROS_common(SYSMODULE)`, :40-43 its PERS declarations; rapid/ROS_motionServer.mod:112-115 writes
  them ("Sending ... points to MOTION task"), rapid/ROS_motion.mod:82-86 reads them in another
  task: neither module declares them again.
- [MSG] ros-industrial/abb_robot_driver_interfaces @ f5d7d117 abb_rapid_msgs/msg/*.msg (ABB's
  messages citing the "Technical reference manual - RAPID Instructions, Functions and Data types").

What a program states, in RAPID's terms:
- joint targets as `jointtarget` (deg), Cartesian targets as `robtarget`: [x, y, z] mm, a unit
  quaternion [q1, q2, q3, q4] with q1 = w, confdata [cf1, cf4, cf6, cfx] of the planned
  configuration (docs/cell-files.md, "Controller programs"), external axes 9E9;
- every MoveL names its `tooldata` and, when the targets are in a user frame, its `wobjdata`
  (`\WObj:=`; without it RAPID uses wobj0). The TCP pose in the world is the work object's
  uframe · oframe · target ([R3] p. 233-234: "The object coordinate system is defined in the user
  coordinate system", the user frame in the world; [MSG] RobTarget.msg). With factory settings the
  robot base frame is the world (the controller knows nothing of the cell); the robot's placement
  in the cell is never written;
- PTP moves as `MoveAbsJ ... vmax` under `VelSet` (the speed fraction, %) and `AccSet` (which holds
  for the `MoveL`s after it too, as on the controller); LIN moves as `MoveL` with a `speeddata`
  whose v_tcp is the planned TCP speed (mm/s, at `VelSet 100`);
- blends as `zonedata` with pzone_tcp the TCP distance (mm) of the planned radius (the other
  zone sizes in the proportions of ABB's predefined zones), `fine` at every stop and weld;
- `WaitTime t;` and `WaitDI <signal>, 1;`, the signal named as the controller's I/O configuration
  names it (`robot.controller.inputs`, else the cell's signal name).

Welds. With `weld: call` (the default, docs/cell-files.md, "Controller programs") a weld is `MoveL ... fine` followed by
`spot_weld n, weld_time;  ! seam/name gun G schedule S`, with `PROC spot_weld` defined in the module
(rest for weld_time; the integrator replaces it). With `weld: package` it is the spot welding
option's instruction, which moves to the spot and welds there ([PS4]: SpotL "Move the TCP along a
linear path and perform a spot welding at the end position"; [R3] p. 675: "The start signal is sent
to the timer as soon as the robot has reached the end position", a stop point):

    SpotL p4, v_lin1, sd4, gun2, tool1 \WObj:=fixture;  ! flange/s7
    PERS spotdata sd4 := [4, 1];       (in the program module: the schedule's program number)

The argument list ToPoint, Speed, Spot [\InPos] [\NoConc] [\Retract], Gun, Tool [\WObj] is the
closest published form found, not ABB's syntax page itself: [R3] p. 676 names the `\Retract`
switch, p. 699 hands user routines "spot of type spotdata: actual spot given in the
SpotL-instruction" and "gun of type gundata" in that order, [R3] p. 675 puts "A maximum of four
discrete gun pressures" in the spot data. The spotdata written is [program number = the spot's
schedule, pressure level 1] (level 1 exists on every gun: [R3] p. 665, gundata nof_plevels "Number
of pressure levels (1 - 4)"), the form of public controller backups in the search tool's code index
(repository not shown there: `PERS spotdata RA696SOLD011:=[1,1];`, the gun opened by
`OpenHighLift GUN1;`). UNCONFIRMED: the argument order and the spotdata fields of
RobotWare 6 / OmniCore Spot options (whose spotdata may hold more, such as tip force and plate
thickness): the integrator completes the declaration to the installed option's record (a RAPID
aggregate must match its type, so a mismatch should show when the module is loaded, not at the
weld; not tried on a controller). The gundata is the option's, on the controller, named
by the cell's gun number (`gun2`, not declared); a tool or work object of that name is refused
(RAPID names data uniquely). The weld time is the schedule's on the controller: rebuild takes it
from the cell's spots of that schedule.

The data module. The frames' values are PERS data in `<name>_frames.mod` (tooldata, wobjdata with
oframe identity); a tool or work object the cell names (`robot.controller`) exists on the
controller and is not declared again. RAPID data declared at module level without LOCAL is global:
"The scope of predefined or global program data may include any module" of the task, and "all
data used must be declared" ([R3] p. 96; [DRV]). Hence the integrator's procedure:
1. load `<name>_frames.mod` into the same task as `<name>.mod` (compare its values with the
   calibrated ones first); without it, and without the named data on the controller, the program
   module refers to undeclared data and cannot run (verify reports such a frame: it then knows
   only the frames the cell names, never the values of the missing module);
2. a persistent is one object per name: RAPID updates its declared value whenever the object
   changes ([R3] p. 96, 98: "if the value of a persistent is updated, this automatically causes
   the initialisation value of the persistent declaration to be updated"), and a module carrying a
   persistent of a name already in the task refers to that same object ([DRV]: one persistent
   written in one task is read in another). Which value then wins, the loaded module's
   initial value or the one in memory, is UNCONFIRMED from an ABB document: check the frames on the
   pendant after loading (Program data), and delete a stale module of the same frames first;
3. the data module is a program module, not `(SYSMODULE)` ([DRV] shows the attribute, but a system
   module is loaded at start-up from the system parameters and outlives programs; frames the
   integrator wants kept belong in the controller's own calibration module, named in the cell).

The tool's load is the tooldata's tload, loaddata [mass kg, cog [x, y, z] mm, aom, ix, iy, iz]
with the centre of gravity "of a tool load expressed in the wrist coordinate system" ([R3] p. 183;
robomax's flange frame, in which the tool file states it). A tool file that states `load` gets
its mass and centre of gravity, as a point mass ("If all components are defined as being 0 kgm2,
the tool is handled as if it were a spot load", [R3] p. 226; aom [1, 0, 0, 0]); one that states
none gets a point load of 1 kg at the TCP with a comment: replace it with the gun's
(LoadIdentify). Either way a comment says what it is; a wrong load impairs path accuracy
(p. 183). A tool the cell names on the controller is not declared, so its load is the
controller's.

The reader takes the motion subset of any module as the controller executes it: MoveAbsJ (tool,
`\WObj` and `\TLoad` do not change a joint target), MoveL and SpotL with declared or in-place targets
in the tool and work object they name (\TLoad changes no path), predefined and declared speed and
zone data, VelSet, AccSet, WaitTime, WaitDI and calls of spot_weld; a work object held by the robot
or moved by a mechanical unit (robhold TRUE, ufprog FALSE, ufmec) is reported, not placed; other
motions (MoveJ, MoveC, SpotJ ...) are reported as not simulated, everything else as ignored.

The reader follows `main` as the controller runs it (`export.flow`): RETURN, EXIT and EXITCYCLE
end it, Stop and Break stop it until it is started again (the verified cycle ends there), GOTO
continues at its label (a label is a statement of its own: the statement after it on the line, or
on the next line, is not part of it); a call of a PROC of the module or of the data module runs
its body in place (its ERROR, BACKWARD and UNDO handlers do not). A call of any other routine
(instructions that change no motion or flow aside, `_INERT`), a compact IF, WaitUntil, interrupts,
error handling, calls by name, and a jump, end or call inside IF / WHILE / FOR / TEST are
reported, never skipped. spot_weld, grip and release are the weld and gripper actions they name
while their PROC does nothing but ``WaitTime [\\InPos,]`` of its time parameter; the weld time is
the call's second argument, in s. Speeds: speeddata v_tcp in mm/s (v5000 is 5000 mm/s) times
VelSet's override, PTP speeds and accelerations as VelSet's and AccSet's percentages (rebuild
reports them above 100 %, and lines above the cell's line speed).
"""

from __future__ import annotations

from robomax_py.export.dialect import Parsed as Parsed
from robomax_py.export.rapid.read import parse
from robomax_py.export.rapid.write import FRAMES_FILE, adapt, program_name, write

__all__ = ["FRAMES_FILE", "adapt", "parse", "program_name", "write"]
