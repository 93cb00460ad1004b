"""KUKA, ABB and FANUC configuration data computed a second time, from the vendors' definitions and
Pinocchio forward kinematics alone, to test `robomax_py.robot.ik.config` against.

Nothing here calls robomax_py's configuration code: the postures are read off the joint frames and
axes Pinocchio computes from the URDF, and each vendor's words are turned into a test on them.

Definitions (SPEC §6 and the sources it names):

KUKA Status and Turn (KUKA System Software 8.x operating and programming instructions for system
integrators, "Status" and "Turn"; the geometric reading of bit 1 is Beckhoff's KUKA-compatible one,
TF5200 manual):

- Status bit 0: the wrist point (intersection of the wrist axes) has x < 0 in the A1 coordinate
  system (the base frame turned with A1); 0 = basic area, 1 = overhead area.
- Status bit 1: the wrist point lies in front of the line through the A2 and A3 axes (on KUKA arms:
  A3 >= phi, phi the A3 value of the stretched arm).
- Status bit 2: the manual's table: 0 for 0 <= A5 < 180 deg and A5 < -180 deg, 1 for
  -180 <= A5 < 0 deg and A5 >= 180 deg.
- Turn bit i (i = 0..5): axis i+1 < 0.

ABB robtarget confdata [cf1, cf4, cf6, cfx] (Technical reference manual, RAPID Instructions,
Functions and Data types, data type confdata, "Robot configuration data for 6 axis robots"):

- cf1, cf4, cf6: the quadrant of axes 1, 4, 6, numbered 0, 1, 2, ... for positive angles (0 for
  [0, 90) deg) and -1, -2, ... for negative ones (-1 for [-90, 0) deg): floor(angle / 90 deg).
- cfx from the manual's table: 4 if the wrist centre is behind axis 1, + 2 if it is behind the
  lower arm (ABB's "lower arm" is the link axis 2 turns, from axis 2 to axis 3), + 1 if the axis-5
  angle is negative.

FANUC CONFIG 'F|N U|D T|B, t4, t5, t6' (SPEC §6; the RoboDK FANUC R-30iA post processor,
ros-industrial-attic/robodk_postprocessors@d7e6c1c07758d67d2906cfd638049bdff88cca72
Fanuc_R30iA.py line 616: "F means axis 5 >= 0, N means axis 5 < 0"; Tesseract's robot
configuration, tesseract-robotics/tesseract@f079ff409b733aeef78610d50f87fbacfb1385fe
tesseract/tesseract_planning/tesseract_motion_planners/include/tesseract_motion_planners/robot_config.h
lines 87-97: F for J5 >= 0, N for J5 < 0, U for J3 < 90 deg, T for x >= 0 in the frame turned by J1):

- F (flip) when J5 >= 0, N when J5 < 0, J5 as the controller counts it and within its turn
  (-180, 180] deg: the turn number t5 holds the rest;
- U when the elbow (the J3 axis) is above the line from the shoulder (the J2 axis) to the wrist
  point, D when below; "above" is the side the A1 frame's z points to when the line points to the
  arm's front, carried round with the arm (so a posture keeps its letter when J2 alone swings it
  over the top, as with Tesseract's joint rule "J3 < 90 deg");
- T when the wrist point is in front of J1 (x >= 0 in the J1 frame), B when behind;
- t4, t5, t6: the turn numbers of J4, J5, J6, the integer t with angle - 360 t in (-180, 180] deg.

The arm plane: the definitions above assume axes 2 and 3 parallel to each other and at right angles
to axis 1 (every arm tested here); `arm_geometry` checks it. The A1 frame is joint 1's frame from
the URDF (x towards the arm at A1 = 0, z along axis 1, up).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

# A parallelism check on unit vectors from Pinocchio, whose round-off is ~1e-15.
PARALLEL_TOL = 1e-9


@dataclass(frozen=True)
class ArmGeometry:
    """World positions and directions of one joint vector, metres.

    x1, y1, z1 : (3,) float
        Axes of the A1 (joint-1) frame.
    o1 : (3,) float
        A point on axis 1.
    shoulder, elbow : (3,) float
        Points on axes 2 and 3 (the joint origins).
    points, axes : (6, 3) float
        A point on each joint axis and the axis direction.
    """

    x1: np.ndarray
    y1: np.ndarray
    z1: np.ndarray
    o1: np.ndarray
    shoulder: np.ndarray
    elbow: np.ndarray
    points: np.ndarray
    axes: np.ndarray


@dataclass(frozen=True)
class Posture:
    """The three geometric facts the vendors' configuration data encode, for one wrist point.

    margin_deg : float
        Angular distance from the nearest boundary where one of the facts changes, degrees; near 0
        the fact is not decided by a program's decimals.
    """

    wrist_behind_axis1: bool
    wrist_in_front_of_lower_arm: bool
    elbow_above_shoulder_wrist_line: bool
    margin_deg: float


def arm_geometry(model: Any, q: np.ndarray) -> ArmGeometry:
    """Joint frames and axes of the first six joints of `model` at q (6,), rad, by Pinocchio FK."""
    data = model.createData()
    q = np.asarray(q, dtype=float)
    pin.computeJointJacobians(model, data, q)
    points = np.array([data.oMi[j].translation for j in range(1, 7)])
    # The angular part of a revolute joint's column of the world Jacobian is its axis in the world.
    axes = np.array([data.J[3:, model.joints[j].idx_v] for j in range(1, 7)])
    R1 = data.oMi[1].rotation
    x1, y1, z1 = R1[:, 0], R1[:, 1], R1[:, 2]
    if np.linalg.norm(np.cross(axes[0], z1)) > PARALLEL_TOL:
        raise ValueError("joint 1 does not turn about its frame's z axis")
    for k in (1, 2):
        if np.linalg.norm(np.cross(axes[k], y1)) > PARALLEL_TOL:
            raise ValueError(f"axis {k + 1} is not along the A1 frame's y axis: no arm plane")
    return ArmGeometry(x1, y1, z1, points[0], points[1], points[2], points, axes)


def wrist_point(geom: ArmGeometry, wrist_axes: tuple[int, ...] = (3, 4, 5)) -> tuple[np.ndarray, float]:
    """The point closest to the given axes (indices from 0; default axes 4, 5, 6) in the least-squares
    sense, and its largest distance from one of them, m (0 for a spherical wrist)."""
    A = np.zeros((3, 3))
    b = np.zeros(3)
    projectors = []
    for k in wrist_axes:
        P = np.eye(3) - np.outer(geom.axes[k], geom.axes[k])    # removes the component along axis k
        projectors.append((P, geom.points[k]))
        A += P
        b += P @ geom.points[k]
    p = np.linalg.solve(A, b)
    spread = max(float(np.linalg.norm(P @ (p - o))) for P, o in projectors)
    return p, spread


def _side_angle_deg(direction: np.ndarray, offset: np.ndarray, normal: np.ndarray) -> float:
    """Signed angle from `direction` to `offset` about `normal`, degrees, in the plane normal to it."""
    return float(np.degrees(np.arctan2(np.dot(np.cross(direction, offset), normal), np.dot(direction, offset))))


def posture(geom: ArmGeometry, wrist: np.ndarray) -> Posture:
    """The vendors' geometric facts for a wrist point (3,), m."""
    # Wrist point in the A1 frame: x < 0 is behind axis 1. The margin is the wrist's angle from the
    # A1 frame's y-z plane as seen from axis 1.
    rel = wrist - geom.o1
    x, y = float(np.dot(rel, geom.x1)), float(np.dot(rel, geom.y1))
    behind = x < 0
    margin_1 = abs(float(np.degrees(np.arctan2(x, abs(y))))) if (x, y) != (0.0, 0.0) else 0.0
    # The lower arm runs from the A2 axis to the A3 axis. Looking along +y1, the front is where the
    # A1 frame's x points when the lower arm points along its z (KUKA home, A2 = -90 deg): the wrist
    # is in front when the lower arm turns clockwise about y1 to reach it, i.e. the angle from the
    # lower arm to the wrist about y1 is positive (z turns into x about +y).
    lower_arm = geom.elbow - geom.shoulder
    to_wrist = wrist - geom.shoulder
    angle = _side_angle_deg(lower_arm, to_wrist, geom.y1)
    in_front = 0.0 < angle < 180.0
    # The elbow is above the shoulder-wrist line when, with the line pointing along the A1 frame's
    # x, the elbow is on its z side: the angle from the line to the elbow about y1 is negative
    # (x turns into z about -y1).
    up_angle = _side_angle_deg(to_wrist, lower_arm, geom.y1)
    above = -180.0 < up_angle < 0.0
    margin_2 = min(abs(angle), 180.0 - abs(angle), abs(up_angle), 180.0 - abs(up_angle))
    return Posture(bool(behind), bool(in_front), bool(above), min(margin_1, margin_2))


def joint_margin_deg(q: np.ndarray) -> float:
    """Smallest distance of a joint of q (6,), rad, from a multiple of 90 deg, degrees: every joint
    value where a vendor's data changes (turn signs, quadrants, FANUC turns and flip) is one."""
    deg = np.degrees(np.asarray(q, dtype=float))
    return float(np.min(np.abs(deg - 90.0 * np.round(deg / 90.0))))


def kuka_text(p: Posture, q: np.ndarray) -> str:
    """KUKA Status and Turn in robomax's text form 'S<bit2 bit1 bit0> T<bit5 .. bit0>'
    (KRL's 'B110'-style binary literals, most significant bit first); q (6,), rad."""
    deg = np.degrees(np.asarray(q, dtype=float))
    a5 = deg[4]
    bit2 = (-180.0 <= a5 < 0.0) or a5 >= 180.0
    status = (4 if bit2 else 0) + (2 if p.wrist_in_front_of_lower_arm else 0) + (1 if p.wrist_behind_axis1 else 0)
    turn = sum(1 << i for i in range(6) if deg[i] < 0.0)
    return f"S{status:03b} T{turn:06b}"


def abb_text(p: Posture, q: np.ndarray) -> str:
    """ABB confdata '[cf1,cf4,cf6,cfx]'; q (6,), rad."""
    deg = np.degrees(np.asarray(q, dtype=float))
    cf1, cf4, cf6 = (int(np.floor(deg[i] / 90.0)) for i in (0, 3, 5))
    # ABB arms turn axis 5 less than 180 deg either way, where this is the plain sign; a whole
    # turn more leaves the wrist as it was, so the sign is taken within the turn [-180, 180).
    a5 = (deg[4] + 180.0) % 360.0 - 180.0
    cfx = 4 * p.wrist_behind_axis1 + 2 * (not p.wrist_in_front_of_lower_arm) + 1 * (a5 < 0.0)
    return f"[{cf1},{cf4},{cf6},{int(cfx)}]"


def fanuc_turn(angle_deg: float) -> int:
    """FANUC turn number: the integer t with angle - 360 t in (-180, 180] deg."""
    return -int(np.floor((180.0 - angle_deg) / 360.0))


def fanuc_text(p: Posture, j_deg: np.ndarray) -> str:
    """FANUC CONFIG 'F|N U|D T|B, t4, t5, t6' for J1..J6 (6,) in degrees as the controller counts
    them (only J4, J5, J6 enter, which a J2/J3 coupling leaves as they are)."""
    t4, t5, t6 = (fanuc_turn(float(j_deg[i])) for i in (3, 4, 5))
    j5 = float(j_deg[4]) - 360.0 * t5
    letters = ("F" if j5 >= 0.0 else "N", "U" if p.elbow_above_shoulder_wrist_line else "D",
               "B" if p.wrist_behind_axis1 else "T")
    return f"{' '.join(letters)}, {t4}, {t5}, {t6}"
