"""Configuration indicators: which of the IK solutions a pose means, in KUKA, ABB and Fanuc terms.

These strings go into robot programs, so the definitions are spelled out here.

KUKA Status (S, 3 bits) and Turn (T, one bit per axis), after the KUKA System Software 8.x
operating and programming instructions for system integrators ("Status", "Turn"):

- S bit 0 (overhead): the wrist point has x < 0 in the A1 coordinate system (the base frame turned
  with axis 1). 0 = basic area, 1 = overhead area.
- S bit 1 (elbow): the wrist point lies in front of the line through the A2 and A3 axes (docs/cell-files.md, "Controller programs",
  the KUKA-compatible definition of Beckhoff's TF5200 manual), seen in the arm plane turned with
  A1, whichever way the URDF turns A3. On KUKA arms this is KUKA's A3 >= phi, phi the A3 value of
  the stretched arm (forearm in line with the upper arm, measured at the wrist point), taken
  modulo 360 deg: 1 for the usual elbow-up postures (e.g. A2 = -90 deg, A3 = +90 deg).
- S bit 2 (wrist): the manual's table: 1 for -180 <= A5 < 0 deg and A5 >= 180 deg, 0 for
  0 <= A5 < 180 deg and A5 < -180 deg; i.e. 1 iff A5 modulo 360 deg lies in [180, 360).
- T bit i: 1 iff joint i+1 < 0 (the raw joint value, turns included).

The wrist point is the KUKA "wrist root point", the intersection of the wrist axes (for a URDF whose
joint-5 origin lies there, as usual, that origin). Arms without a spherical wrist (UR type, axis 4
parallel to axis 3) use the intersection of axes 5 and 6 for bit 0 and of axes 4 and 5 for bit 1, so
that the bits split the eight IK branches as they do for spherical wrists; see `status_generic`.

Joint values here are those the caller passes: the URDF's for the planner, SRCL and the trajectory
file; the controller's (robot.yaml `controller.joint_signs`, `controller.joint_zeros_deg`) for the
configuration data of controller programs (`solve.brand_text_of` with `controller`). S bits 0 and 1
are where the wrist point lies and do not depend on how the joints are counted.

String form `S110 T010011`: three status bits then six turn bits, each written most significant
first, like KRL's 'B110' binary literals (leftmost = bit 2 resp. bit 5 = A6).

ABB robtarget `confdata [cf1, cf4, cf6, cfx]` (Technical reference manual RAPID Instructions,
Functions and Data types, data type confdata, robot configuration data for 6-axis robots):

- cf1, cf4, cf6: quadrant of axis 1, 4, 6: floor(q / 90 deg) (0 for [0, 90), 1 for [90, 180),
  -1 for [-90, 0), -2 for [-180, -90), and onwards beyond +-180 deg).
- cfx = 4 * (wrist point behind axis 1 = S bit 0) + 2 * (wrist point behind the lower arm =
  not S bit 1; ABB's lower arm is the link from axis 2 to axis 3) + (axis 5 negative = S bit 2):
  the manual's 0..7 table.

FANUC configuration string `F|N U|D T|B, t4, t5, t6` (docs/cell-files.md, "Controller programs"):

- F (flip) when J5 >= 0, N when J5 < 0, J5 as the controller counts it, within its turn (the
  turn number t5 holds whole turns). FANUC's flip is not KUKA's 'A5 < 0' bit: the RoboDK FANUC
  post processor (ros-industrial-attic/robodk_postprocessors@d7e6c1c07758d67d2906cfd638049bdff88cca72,
  Fanuc_R30iA.py line 616: "F means axis 5 >= 0, N means axis 5 < 0") and Tesseract's robot
  configuration (tesseract-robotics/tesseract@f079ff409b733aeef78610d50f87fbacfb1385fe,
  tesseract/tesseract_planning/tesseract_motion_planners/include/tesseract_motion_planners/robot_config.h,
  lines 87-97: FUT for J5 >= 0, NUT for J5 < 0) agree.
- U (up) when the elbow is above the shoulder-wrist line, D below: the same fact as S bit 1
  (elbow above the line from the A2 axis to the wrist point = wrist point in front of the line
  through the A2 and A3 axes), measured in the arm plane turned with J1, so a posture keeps its
  letter when J2 alone swings the arm over the top (Tesseract's rule there: U for J3 < 90 deg).
- T (front) when the wrist point is in front of J1 (not S bit 0), B (back) when behind.
- t4, t5, t6: turn numbers of J4, J5, J6: the integer t with q - 360 deg * t in (-180, 180] deg.
  A J2/J3 coupling (J3 counted from the horizontal) changes none of these.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.errors import ProgramError
from robomax_py.robot.ik._chain import active_positions, chain_to_frame, joint_frames
from robomax_py.robot.ik.opw import OpwParams, to_paper_angles
from robomax_py.transforms import closest_on_line

TWO_PI = 2.0 * np.pi
_PATTERN = re.compile(r"S([01]{3}) T([01]{1,6})")


@dataclass(frozen=True, slots=True)
class ConfigIndicator:
    """KUKA-style status and turn bits of one joint configuration.

    status : int, 0..7 (bit 0 overhead, bit 1 elbow, bit 2 wrist)
    turn : int, 0..63 (bit i: joint i+1 < 0)
    """

    status: int
    turn: int

    def __post_init__(self) -> None:
        if not (0 <= self.status <= 7 and 0 <= self.turn <= 63):
            raise ValueError(f"status must be 0..7 and turn 0..63, got {self.status}, {self.turn}")

    @property
    def overhead(self) -> bool:
        return bool(self.status & 1)

    @property
    def elbow(self) -> bool:
        return bool(self.status & 2)

    @property
    def wrist(self) -> bool:
        return bool(self.status & 4)

    def __str__(self) -> str:
        return f"S{self.status:03b} T{self.turn:06b}"

    @classmethod
    def parse(cls, text: str) -> ConfigIndicator:
        """Inverse of `str`; a turn field shorter than six digits is read with leading zeros."""
        match = _PATTERN.fullmatch(text.strip())
        if match is None:
            raise ProgramError(None, None, f"configuration must look like 'S110 T010011', got {text!r}")
        return cls(status=int(match.group(1), 2), turn=int(match.group(2), 2))

    def to_kuka(self) -> str:
        """KRL E6POS fields, e.g. `S 'B110',T 'B010011'`."""
        return f"S 'B{self.status:03b}',T 'B{self.turn:06b}'"

    def to_abb(self, q: FloatArray) -> tuple[int, int, int, int]:
        """ABB confdata [cf1, cf4, cf6, cfx] for joint values q (6,), rad, this indicator describes."""
        q = np.asarray(q, dtype=float)
        quadrant = [int(np.floor(q[i] / (np.pi / 2.0))) for i in (0, 3, 5)]
        cfx = 4 * self.overhead + 2 * (not self.elbow) + self.wrist
        return quadrant[0], quadrant[1], quadrant[2], int(cfx)

    def to_fanuc(self, q: FloatArray) -> str:
        """FANUC configuration string, e.g. `N U T, 0, 0, -1`, for joint values q (6,), rad, that this
        indicator describes (J4, J5, J6 as the controller counts them; see the module docstring)."""
        q = np.asarray(q, dtype=float)
        turns = [fanuc_turn(float(q[i])) for i in (3, 4, 5)]
        # FANUC's flip is J5 >= 0 within its turn, not KUKA's wrist bit (A5 < 0).
        flip = float(q[4]) - TWO_PI * turns[1] >= 0.0
        letters = ("F" if flip else "N", "U" if self.elbow else "D", "B" if self.overhead else "T")
        return f"{' '.join(letters)}, {turns[0]}, {turns[1]}, {turns[2]}"


def fanuc_turn(angle: float) -> int:
    """FANUC turn number of a joint value, rad: the integer t with angle - 2 pi t in (-pi, pi]."""
    return int(np.ceil((angle - np.pi) / TWO_PI))


def turn_bits(q: FloatArray) -> IntArray:
    """(..., n) joint values -> (...) int: bit i set when joint i+1 < 0 (first six joints); -1 for NaN rows.

    -0.0 counts as negative (its sign bit): a joint at -1e-12 rad written with fixed decimals reads
    back as -0.0, and must keep the indicator the planner stated for it.
    """
    q = np.asarray(q, dtype=float)
    k = min(q.shape[-1], 6)
    bits = np.sum(np.signbit(q[..., :k]) * (1 << np.arange(k)), axis=-1).astype(np.int64)
    return np.where(np.isnan(q).any(axis=-1), -1, bits)


def _wrist_bit(q5: FloatArray) -> BoolArray:
    bit: BoolArray = np.mod(q5, TWO_PI) >= np.pi
    return bit


def status_opw(params: OpwParams, q: FloatArray) -> IntArray:
    """Status bits of an OPW arm from its joint values alone.

    Parameters
    ----------
    q : (..., 6) float
        Robot joint values, rad.

    Returns
    -------
    (...) int
        0..7 as defined in the module docstring; -1 for rows containing NaN. The A1 frame is the
        link-1 frame: the paper's frame turned by theta1, x towards the arm's front (the a1 offset),
        which splits the shoulder branches exactly also when b != 0. The elbow
        bit is geometric (docs/cell-files.md, "Controller programs"): the wrist point in front of the line through the A2 and A3
        axes, whichever way the URDF's axis 3 turns (ROS-Industrial FANUC arms turn it about -y).
    """
    q = np.asarray(q, dtype=float)
    th = to_paper_angles(params, q)
    psi3 = np.arctan2(params.a2, params.c3)
    k = np.hypot(params.a2, params.c3)
    beta = th[..., 2] + psi3                                            # 0 = stretched arm
    x_wrist = params.c2 * np.sin(th[..., 1]) + k * np.sin(th[..., 1] + beta) + params.a1
    elbow_angle = np.mod(beta, TWO_PI)                                  # forearm from the upper arm, about y
    status = (x_wrist < 0) * 1 + (elbow_angle < np.pi) * 2 + _wrist_bit(q[..., 4]) * 4
    return np.where(np.isnan(q).any(axis=-1), -1, status).astype(np.int64)


def status_generic(model: pin.Model, frame_id: int, q: FloatArray) -> IntArray:
    """Status bits of any arm whose first five joints (towards `frame_id`) are revolute.

    Geometry from the model's joint placements: the A1 frame is joint 1's frame; for bit 0 the wrist
    point is where axis 5 meets axis 6, for bit 1 where axis 5 meets axis 4 (points of closest
    approach); phi is the A3 value at which upper arm (joint-2 origin -> joint-3 origin) and forearm
    (joint-3 origin -> that point), both projected along axis 3, are in line. For a spherical wrist
    both points are the wrist centre. For a UR-type wrist they are DH origins 5 and 4 (the wrist-3
    point, whose position decides the shoulder branch, and the wrist-1 point on axis 4, whose side
    of the upper arm the elbow angle decides).

    Parameters
    ----------
    q : (..., nq) float
        Joint values, rad.

    Returns
    -------
    (...) int
        0..7; -1 for rows containing NaN; 0 for models with fewer than five revolute arm joints.
    """
    q = np.asarray(q, dtype=float)
    batch = q.shape[:-1]
    chain = chain_to_frame(model, frame_id)
    act = active_positions(chain)                  # the arm's axes (passive joints left out)
    if len(act) < 5 or not np.all(chain.revolute[act[:5]]):
        return np.where(np.isnan(q).any(axis=-1), -1, 0).astype(np.int64)
    flat = q.reshape(-1, q.shape[-1])
    nan_rows: BoolArray = np.asarray(np.isnan(flat).any(axis=-1), dtype=bool)
    F = joint_frames(chain, np.where(nan_rows[:, None], 0.0, flat))     # (m, J, 4, 4)
    n_axes = min(len(act), 6)
    axis = [F[:, act[i], :3, :3] @ (chain.A[act[i], :3, 2]) for i in range(n_axes)]   # world joint axes
    origin = [F[:, act[i], :3, 3] for i in range(n_axes)]
    wrist = closest_on_line(origin[4], axis[4], origin[3], axis[3])           # axes 4 and 5
    wrist_56 = wrist if n_axes < 6 else closest_on_line(origin[4], axis[4], origin[5], axis[5])

    x1 = F[:, 0, :3, 0]
    bit0 = np.einsum("mi,mi->m", wrist_56 - origin[0], x1) < 0

    # The arm plane's normal from the A1 frame (up x front), not from axis 3 as the URDF turns it:
    # the elbow bit is geometric (docs/cell-files.md, "Controller programs"), the same on arms whose axis 3 points the other way.
    up = np.where((axis[0][:, 2] >= 0)[:, None], axis[0], -axis[0])
    a3 = np.cross(up, x1)
    a3 = a3 / np.maximum(np.linalg.norm(a3, axis=1, keepdims=True), 1e-300)
    upper = origin[2] - origin[1]
    fore = wrist - origin[2]
    upper = upper - np.einsum("mi,mi->m", upper, a3)[:, None] * a3
    fore = fore - np.einsum("mi,mi->m", fore, a3)[:, None] * a3
    sin_b = np.einsum("mi,mi->m", np.cross(upper, fore), a3)
    cos_b = np.einsum("mi,mi->m", upper, fore)
    bit1 = (sin_b > 0) | ((sin_b == 0) & (cos_b > 0))

    bit2 = _wrist_bit(flat[:, chain.q_index[act[4]]])
    status = bit0 * 1 + bit1 * 2 + bit2 * 4
    return np.where(nan_rows, -1, status).astype(np.int64).reshape(batch)


# ------------------------------------------------------------------ the controllers' own words

def brand_text(brand: str, status: int, turn: int, q: FloatArray) -> str:
    """The configuration data a `brand`'s controller writes for joint values q (6,), rad (docs/cell-files.md, "Controller programs").

    kuka: Status and Turn, `S110 T010011` (KUKA System Software 8.x manual, "Status" and "Turn").
    abb: robtarget confdata `[cf1,cf4,cf6,cfx]`: quadrants floor(q / 90 deg) of axes 1, 4, 6 and
    cfx = 4 (wrist centre behind axis 1) + 2 (behind the lower arm) + (axis 5 negative), the
    configuration table of the RAPID reference manual (data type confdata, 6-axis robots).
    fanuc: `F|N U|D T|B, t4, t5, t6`: flip when J5 >= 0 (within its turn), up when the elbow is
    above the shoulder-wrist line (the same fact as KUKA's S bit 1), T when the wrist point is in
    front of J1, and the turn numbers of J4, J5, J6 (0 for -180 < q <= 180 deg); the module
    docstring gives the sources. ur: no configuration data ("").
    """
    ind = ConfigIndicator(status, turn)
    if brand == "kuka":
        return str(ind)
    if brand == "abb":
        cf1, cf4, cf6, cfx = ind.to_abb(q)
        return f"[{cf1},{cf4},{cf6},{cfx}]"
    if brand == "fanuc":
        return ind.to_fanuc(q)
    if brand == "ur":
        return ""
    if brand == "yaskawa":
        return yaskawa_rconf(ind, q)
    if brand == "kawasaki":
        return kawasaki_config(ind)
    if brand in ("staubli", "comau", "nachi"):
        # Brands without a program dialect: robomax's own status and turn form (SRCL).
        return str(ind)
    raise ValueError(f"unknown controller brand {brand!r}")


def _half_turn_bit(angle: float) -> int:
    """Yaskawa's '< 180' (0) / '>= 180' (1) of an axis angle, rad: 0 for -180 < angle <= 180 deg,
    the half-open ranges of the manual's Flip / No Flip table (module docstring)."""
    return 0 if -np.pi < angle <= np.pi else 1


def yaskawa_rconf(ind: ConfigIndicator, q: FloatArray) -> str:
    """Yaskawa's manipulator type as a job's `///RCONF l,m,n,o,p,q,0,0` states it.

    DX100 "Options: Instructions for Interface with an Easy Offline Teaching System" (156191-1CD,
    HW0482494) §4.1 Job Data Format, RCONF: l 0 Flip / 1 No-flip, m 0 Upper arm / 1 Lower arm,
    n 0 Front / 1 Rear, o 0 R < 180 / 1 R >= 180, p the same for T, q for S, the rest unused (0).
    NX100 operator's manual (149235-1CD) §3.9 "Manipulator Types": Flip / No Flip is the R-axis
    (axis 4) position, Flip for -90 < R <= 90 deg and for 270 < |R| <= 360 deg, No Flip for
    90 < |R| <= 270 deg; Upper / Lower arm the posture of the L- and U-axes (the elbow above or
    below the shoulder-wrist line, KUKA's S bit 1); Front / Rear the wrist point in front of or
    behind the S-axis (S bit 0). 'R < 180' is read as -180 < R <= 180 deg, the table's ranges.
    """
    q = np.asarray(q, dtype=float)
    r = float(np.mod(q[3] + np.pi / 2.0, TWO_PI))           # Flip: R in (-90, 90] mod 360
    flip = 0.0 < r <= np.pi
    fields = (0 if flip else 1, 0 if ind.elbow else 1, 1 if ind.overhead else 0,
              _half_turn_bit(float(q[3])), _half_turn_bit(float(q[5])), _half_turn_bit(float(q[0])), 0, 0)
    return ",".join(str(f) for f in fields)


def kawasaki_config(ind: ConfigIndicator) -> str:
    """Kawasaki AS's configuration words, `RIGHTY|LEFTY ABOVE|BELOW UWRIST|DWRIST` (Kawasaki AS
    Language Reference Manual, D series 902091017DEB, configuration instructions LEFTY, RIGHTY,
    ABOVE, BELOW, UWRIST, DWRIST): RIGHTY with the wrist point in front of JT1 (not S bit 0),
    ABOVE with the elbow above the shoulder-wrist line (S bit 1), UWRIST with JT5 >= 0 within its
    turn (not S bit 2). The words name the branch; the turns come from the joint values a joint
    location states."""
    return " ".join(("LEFTY" if ind.overhead else "RIGHTY", "ABOVE" if ind.elbow else "BELOW",
                     "DWRIST" if ind.wrist else "UWRIST"))


def same_config(written: str, actual: str) -> bool:
    """Whether two configuration texts say the same (spaces do not count)."""
    return "".join(written.split()).upper() == "".join(actual.split()).upper()
