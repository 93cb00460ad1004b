"""How the robot is mounted, as a controller's frames see it: upright (floor, riser, yawed, offset)
or tilted (ceiling, wall), and the mounting a KUKA integrator configures in `$ROBROOT`.

A KUKA controller states `$BASE` relative to `$WORLD`, and places the robot in `$WORLD` by
`$ROBROOT` (machine data, `KRC:\\R1\\Mada\\$machine.dat`; factory value {X 0, Y 0, Z 0, A 0, B 0,
C 0}, NAQIU KRC/R1/Mada/$machine.dat 96). A robot hung from a ceiling or a wall is configured with
its mounting there (integrators' notes: "$ROBROOT C value 0 for floor mount and 180 for ceiling
mount"), so on such a controller `$BASE = $WORLD` (or a base frame stated in the robot base frame
as if `$ROBROOT` were `$WORLD`) is turned by the mounting. BASE_DATA are stated relative to
`$WORLD` (Beckhoff TF5120 mxAutomation for KUKA, KRC_WriteBaseData / KRC_ReadBaseData: "X, Y, Z:
Origin of the BASE coordinate system relative to the WORLD coordinate system",
infosys.beckhoff.com/content/1033/tf5120/13081584011.html), and the ROS-Industrial KUKA
descriptions take their `base` link to be "the base frame defined by the industrial controller
($ROBROOT)" (kroshu's kuka robot descriptions README, "Frame conventions"). The other brands
robomax writes state targets in frames the mounting does not turn on a controller set up as their
manuals ask: ABB sets the mounting angle as the gravity parameter `Gravity Beta` (Product manual
IRB 4600, 3HAC033453-001, 2.3.5 "Setting the system parameters for a suspended robot"), FANUC's
world frame is the robot's own (it cannot be moved), and a UR program's frames are its base, the
mounting being the gravity direction of the installation (ur_msgs SetGravity: "The UR Robot driver
will transform this to the robot frame").

robomax models `$ROBROOT` as the integrator configures it: for a tilted mount, the rotation of the
controller's robot base in the cell (the cell's `robot.base` composed with robot.yaml
`controller.base`), without translation (`$WORLD` at the robot's foot); for an upright mount the
factory `$NULLFRAME`, as integrators leave it.
"""

from __future__ import annotations

import math

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.transforms import invert, rotation_angle

# A mount whose base z axis leans from the cell's vertical by more than this is tilted: its
# integrator enters the mounting in $ROBROOT. A riser or floor plate off level by less (a few
# degrees, such as the test process cell's 2 deg riser) is taken as a floor mount whose $ROBROOT
# stays the factory $NULLFRAME, so its programs state frames as a floor-mounted robot's; a ceiling
# mount is 180 deg off and a wall mount 90 deg.
MOUNT_TILT_TOL_DEG = 5.0


def mount_rotation(T_world_root: FloatArray, T_root_controller: FloatArray) -> FloatArray:
    """(3, 3): the controller's robot base frame's axes in the cell's world (the cell's robot.base
    composed with the controller's base in the URDF root)."""
    R: FloatArray = np.asarray(T_world_root, dtype=float)[:3, :3] @ np.asarray(T_root_controller, dtype=float)[:3, :3]
    return R


def tilt_deg(R_world_base: FloatArray) -> float:
    """The angle (deg) between the robot base's z axis and the cell's vertical."""
    return math.degrees(math.acos(float(np.clip(np.asarray(R_world_base)[2, 2], -1.0, 1.0))))


def is_tilted(R_world_base: FloatArray) -> bool:
    """Whether the mount does not keep the robot base's z axis vertical (`MOUNT_TILT_TOL_DEG`)."""
    return tilt_deg(R_world_base) > MOUNT_TILT_TOL_DEG


def robroot(R_world_base: FloatArray) -> FloatArray:
    """(4, 4): the `$ROBROOT` the integrator configures: the mount rotation for a tilted mount,
    `$NULLFRAME` (identity) for an upright one."""
    T = np.eye(4)
    if is_tilted(R_world_base):
        T[:3, :3] = np.asarray(R_world_base, dtype=float)
    return T


def stated_as_if_upright(name: str, T_base_world: FloatArray, T_world_frame: FloatArray, T_expected: FloatArray,
                         tol_mm: float, tol_deg: float) -> str | None:
    """What is wrong with a user frame stated relative to the controller's world frame
    (`T_world_frame`; KUKA `$BASE`) on a robot whose world is not its base (`T_base_world`, a
    tilted mount's inv($ROBROOT)), when it is the cell's user frame (`T_expected`, in the robot
    base) stated as if $ROBROOT were $WORLD: the targets then land turned by the mounting. None
    when the frame composes to the cell's, or is not the cell's either way (the spots tell)."""
    def within(off: tuple[float, float]) -> bool:
        return off[0] <= tol_mm and off[1] <= tol_deg

    d_mm, d_deg = _off(T_expected, T_base_world @ T_world_frame)        # where the controller puts it
    if within((d_mm, d_deg)) or not within(_off(T_expected, T_world_frame)):
        return None
    return (f"user frame {name or '$WORLD (base 0)'} is stated relative to $WORLD as if $ROBROOT were $WORLD, but the "
            f"robot is mounted tilted ({tilt_deg(invert(T_base_world)[:3, :3]):.1f} deg) and the integrator sets "
            f"$ROBROOT to the mounting: the targets land {d_mm:.1f} mm, {d_deg:.1f} deg off the cell's; state the "
            "frame on $ROBROOT ($ROBROOT : {...}, or $ROBROOT itself for the robot base)")


def _off(A: FloatArray, B: FloatArray) -> tuple[float, float]:
    """The distance between two frames' origins (mm) and the angle between them (deg)."""
    return (float(np.linalg.norm(A[:3, 3] - B[:3, 3])) * 1000.0,
            math.degrees(float(rotation_angle(A[:3, :3], B[:3, :3]))))
