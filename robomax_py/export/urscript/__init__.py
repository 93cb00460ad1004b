"""URScript, both directions: one program `<name>.script` (a `def` the controller runs).

What a program states, in URScript's terms (Universal Robots, "The URScript Programming
Language", movej / movel / set_tcp / sleep / get_standard_digital_in):
- `movej([q1, ..., q6], a, v, r)` with joint values in rad, `v` and `a` the leading joint's
  speed (rad/s) and acceleration (rad/s^2): the planned fractions of the robot's slowest joint
  limits; `movel(p[x, y, z, rx, ry, rz], a, v, r)` with the TCP pose in m and a rotation vector
  (rad) in the UR controller's base frame, `v` the TCP speed in m/s, `a` the line's acceleration
  fraction times 1.2 m/s^2, UR's default (at 1.2 the line is timed under the full joint limits; a
  line carrying a part states less, and a reader takes a/1.2 as the fraction, at most 1);
- the frames as global pose variables, as PolyScope writes them: the TCP `global <tool> = p[...]`
  (in the flange frame) set with `set_tcp(<tool>)` before the first motion; targets relative to
  the robot base as the UR controller defines it (ROS-Industrial's `base` link: robot.yaml
  `controller.base`), the robot's placement in the cell never written; in a user frame (a feature)
  `movel(pose_trans(<frame>, p[...]), ...)` with `global <frame> = p[...]` its pose in the base;
- the tool's load, when its tool file states one, as `set_payload(m, [cx, cy, cz])` (kg; the
  centre of gravity in m from the tool flange: Universal Robots, "How to change payload and center
  of gravity settings using URScript") before the first motion; none stated, the installation's;
- blends as `r`, the TCP distance (m) of the planned radius; 0 at every stop and weld;
- no configuration data: the controller keeps the branch the arm is in, as robomax's LIN moves do;
- a weld as `movel(..., r=0)` followed by `spot_weld(n, weld_time)  # seam/name`, `spot_weld`
  defined in the program (sleep weld_time; the integrator replaces it);
- `sleep(t)`, and `wait_for_signal(k)  # <signal>` waiting for standard digital input k (0..7), the
  input the cell maps the signal to (`robot.controller.inputs`).

The reader takes movej with a joint vector, movel with a pose or a pose_trans of a pose variable
and a pose, pose variables, set_tcp, sleep and the calls above from any script; other motions (movep, movec, servoj, movej to a pose ...) are reported as
not simulated, everything else as ignored.

It follows the program's def as the controller runs it (`export.flow`): `halt()` ends the
program, `return` ends it (returns from a called function), a call of a function the script
defines runs its body in place. A call of any other function (built-ins that change no motion
or flow aside, `_INERT`), threads, `break` / `continue`, and a call or end inside if / while /
for are reported, never skipped. spot_weld, grip and release are the weld and gripper actions
they name while their def does nothing but `sleep` of its time parameter, wait_for_signal the
wait for an input while it is the loop `write` gives; the weld time is the call's second
argument, in s. Speeds: movel `v` in m/s, movej `v` and `a` in rad/s and rad/s^2 (rebuild reports
them above the slowest joint's limits, and lines above the cell's line speed).
"""

from __future__ import annotations

from robomax_py.export.urscript.read import parse
from robomax_py.export.urscript.write import SIGNALS, adapt, reference_limits, write

__all__ = ["SIGNALS", "adapt", "parse", "reference_limits", "write"]
