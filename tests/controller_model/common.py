"""What every dialect's model returns, and the rotation conventions the vendors define.

Records
-------
A run (`ProgramRun`) is the program's events in execution order — `Motion`, `Call` (a process or
subroutine call, the FANUC ``SPOT[...]`` option and ABB ``SpotL``/``SpotJ`` included), `Wait` and
`SetOutput` (a digital output switched: the other half of a wait between robots) —
plus `Issue`s: statements outside the modelled subset (``unsupported``), controller alarms
(``alarm``) and data the program uses but neither it nor the caller defines (``undefined``). After
an issue the model goes on with the next statement, as straight-line execution would; a run with
issues is not a faithful model of the controller and tests must say so.

Flow, in every dialect's model: the run stops at an end of the program or at a pause that waits
for the operator (`ProgramRun.stopped`); an unconditional jump goes forward to its label in the
same routine (a jump back repeats what ran, without end: an issue, and the run stops there); a
call of a routine the texts define, without arguments, runs its body where it is called (a call
with arguments is recorded as a `Call`, as are calls of routines the texts do not give).
Conditions are not evaluated: IF, loops and the like stay ``unsupported``.

Units: every matrix is 4x4 in metres; joint values stay in degrees as the controller counts them
(``joints_deg``); configuration data stays as written.

Rotations (each dialect cites its vendor source)
------------------------------------------------
- KUKA A, B, C and FANUC R, P, W: R = Rz(A)·Ry(B)·Rx(C), resp. Rz(R)·Ry(P)·Rx(W), angles in degrees
  (`rot_zyx_deg`).
- ABB orient: unit quaternion [q1, q2, q3, q4] with q1 the scalar part (`rot_quat_wxyz`).
- UR: rotation vector [rx, ry, rz] in radians, axis times angle (`rot_vector`).

The matrices here are written out from those definitions (no scipy), so that tests can check them
against scipy's `Rotation` as an independent implementation.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Literal, TypeAlias

import numpy as np
import numpy.typing as npt

FloatArray: TypeAlias = npt.NDArray[np.float64]

MM = 1e-3   # metres per millimetre

MotionKind = Literal["joint", "linear"]
IssueKind = Literal["unsupported", "alarm", "undefined"]


# ----------------------------------------------------------------------------------------- rotations
def rot_x_deg(angle_deg: float) -> FloatArray:
    """(3, 3) rotation about x by `angle_deg` degrees (right hand)."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y_deg(angle_deg: float) -> FloatArray:
    """(3, 3) rotation about y by `angle_deg` degrees (right hand)."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z_deg(angle_deg: float) -> FloatArray:
    """(3, 3) rotation about z by `angle_deg` degrees (right hand)."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_zyx_deg(z_deg: float, y_deg: float, x_deg: float) -> FloatArray:
    """(3, 3) R = Rz(z)·Ry(y)·Rx(x): KUKA (A, B, C) and FANUC (R, P, W), degrees."""
    return rot_z_deg(z_deg) @ rot_y_deg(y_deg) @ rot_x_deg(x_deg)


def rot_quat_wxyz(q: tuple[float, float, float, float]) -> FloatArray:
    """(3, 3) rotation of the quaternion (w, x, y, z), normalised first (the caller checks the norm)."""
    w, x, y, z = (v / math.sqrt(sum(u * u for u in q)) for v in q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def rot_vector(rx: float, ry: float, rz: float) -> FloatArray:
    """(3, 3) rotation of the rotation vector (rx, ry, rz): axis times angle in radians (Rodrigues)."""
    angle = math.sqrt(rx * rx + ry * ry + rz * rz)
    if angle < 1e-15:
        return np.eye(3)
    k = np.array([rx, ry, rz]) / angle
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.asarray(np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * (K @ K), dtype=np.float64)


def homogeneous(R: FloatArray, xyz_m: tuple[float, float, float] | FloatArray) -> FloatArray:
    """(4, 4) transform from a (3, 3) rotation and a translation in metres."""
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = xyz_m
    return T


def pose_mm_zyx_deg(x_mm: float, y_mm: float, z_mm: float, z_deg: float, y_deg: float, x_deg: float) -> FloatArray:
    """(4, 4) metres: translation in mm, R = Rz(z_deg)·Ry(y_deg)·Rx(x_deg) (KUKA A,B,C; FANUC R,P,W)."""
    return homogeneous(rot_zyx_deg(z_deg, y_deg, x_deg), (x_mm * MM, y_mm * MM, z_mm * MM))


# ------------------------------------------------------------------------------------------ records
@dataclass(frozen=True, slots=True)
class Where:
    """A statement's place: the text's name (file name or the caller's label) and its 1-based line."""

    source: str
    line: int


@dataclass(frozen=True, slots=True)
class KrlConfig:
    """KUKA Status and Turn as written (``S 'B010'`` or ``S 2``); None when the point has none."""

    status: int | None
    turn: int | None


@dataclass(frozen=True, slots=True)
class RapidConfig:
    """ABB confdata [cf1, cf4, cf6, cfx] as written."""

    cf1: int
    cf4: int
    cf6: int
    cfx: int


@dataclass(frozen=True, slots=True)
class FanucConfig:
    """FANUC CONFIG as written, e.g. ``'N U T, 0, 0, 0'``, and its parts."""

    text: str
    flip: str          # "F" or "N"
    elbow: str         # "U" or "D"
    front: str         # "T" or "B"
    turns: tuple[int, int, int]   # turn numbers of J4, J5, J6


Config: TypeAlias = KrlConfig | RapidConfig | FanucConfig


@dataclass(frozen=True, slots=True, eq=False)
class Motion:
    """One executed motion statement.

    Attributes
    ----------
    statement : str
        The instruction as written (``PTP``, ``LIN``, ``MoveJ``, ``J``, ``movel`` ...).
    kind : "joint" or "linear"
        Joint interpolation (PTP, MoveJ, MoveAbsJ, FANUC J, movej) or a straight TCP line.
    target : str
        The target as written (a name or a literal).
    joints_deg : tuple of float or None
        A joint target, degrees as the controller counts them (None for a Cartesian target).
    T_base_tcp : (4, 4) float or None
        A Cartesian target: the TCP the controller commands, in its robot base frame, metres
        (the user frame already composed in). None for a joint target, or when a frame it needs
        is undefined (then an `Issue` says which).
    T_flange_tcp : (4, 4) float or None
        The tool frame in force (flange to TCP), metres; None when neither the program nor the
        caller defines it.
    T_base_user : (4, 4) float or None
        The user frame in force in the robot base frame (KUKA $BASE, ABB uframe·oframe, FANUC
        UFRAME, UR identity), metres; None when undefined.
    config : KrlConfig, RapidConfig, FanucConfig or None
        Configuration data as written, for Cartesian targets that carry it.
    blend : str or None
        The approximation as written (``C_DIS``, ``z10``, ``CNT50``, ``r=0.01``); None for an
        exact stop point.
    """

    where: Where
    statement: str
    kind: MotionKind
    target: str
    joints_deg: tuple[float, ...] | None
    T_base_tcp: FloatArray | None
    T_flange_tcp: FloatArray | None
    T_base_user: FloatArray | None
    config: Config | None
    blend: str | None

    @property
    def stops(self) -> bool:
        """True at an exact stop point (no approximation)."""
        return self.blend is None


@dataclass(frozen=True, slots=True)
class Call:
    """A call of a subroutine, program or process instruction: its name and arguments as written
    (numbers converted to float). The model records calls; it does not follow them."""

    where: Where
    name: str
    args: tuple[float | str, ...]


@dataclass(frozen=True, slots=True)
class Wait:
    """A wait: `seconds` for a timed wait, else the digital input (`signal` as written, its number
    when the statement or a declaration names one, and the awaited `state`)."""

    where: Where
    seconds: float | None = None
    signal: str | None = None
    input_number: int | None = None
    state: bool | None = None


@dataclass(frozen=True, slots=True)
class SetOutput:
    """A digital output switched: `signal` as written, its number when the statement or a
    declaration names one, and the state it is set to. Where the vendor executes it only once the
    motion before has ended (KRL without CONTINUE, RAPID and FANUC after a stop point, URScript
    after a move without blend), `after_stop` says the robot is at rest then."""

    where: Where
    signal: str
    output_number: int | None
    state: bool
    after_stop: bool = True


Event: TypeAlias = Motion | Call | Wait | SetOutput


@dataclass(frozen=True, slots=True)
class Issue:
    """A statement the model cannot execute faithfully: ``unsupported`` (outside the subset),
    ``alarm`` (the controller would stop with an error) or ``undefined`` (data neither the program
    nor the caller defines; the model never guesses it)."""

    where: Where
    kind: IssueKind
    text: str
    reason: str


@dataclass(frozen=True, slots=True)
class ProgramRun:
    """The model's account of one program: events in execution order, and issues in text order."""

    dialect: str
    events: tuple[Event, ...]
    issues: tuple[Issue, ...]
    j23_coupling: bool = False   # FANUC: joint positions count J3 from the horizontal (see export/fanuc)
    # Where the program stopped before its last statement: an end (RETURN of the main routine,
    # EXIT, ABORT, halt()) or a pause that waits for the operator (HALT, Stop, PAUSE), after which
    # nothing runs in the cycle; None when it ran to its end.
    stopped: Where | None = None

    @property
    def motions(self) -> tuple[Motion, ...]:
        return tuple(e for e in self.events if isinstance(e, Motion))

    @property
    def calls(self) -> tuple[Call, ...]:
        return tuple(e for e in self.events if isinstance(e, Call))

    @property
    def waits(self) -> tuple[Wait, ...]:
        return tuple(e for e in self.events if isinstance(e, Wait))

    @property
    def unsupported(self) -> tuple[Issue, ...]:
        return tuple(i for i in self.issues if i.kind == "unsupported")

    @property
    def clean(self) -> bool:
        """No issue of any kind: the run is what the controller executes."""
        return not self.issues


# ------------------------------------------------------------------------------------------- parsing
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_NUMBER_RE = re.compile(rf"^\s*{NUMBER}\s*$")


def is_number(text: str) -> bool:
    return bool(_NUMBER_RE.match(text))


def split_top(text: str, sep: str = ",", brackets: str = "[]{}()") -> list[str]:
    """Splits `text` at `sep` outside brackets and double-quoted strings; items stripped."""
    opening = brackets[0::2]
    closing = brackets[1::2]
    depth = 0
    quoted = False
    items: list[str] = []
    start = 0
    for i, ch in enumerate(text):
        if ch == '"':
            quoted = not quoted
        elif quoted:
            continue
        elif ch in opening:
            depth += 1
        elif ch in closing:
            depth -= 1
        elif ch == sep and depth == 0:
            items.append(text[start:i].strip())
            start = i + 1
    items.append(text[start:].strip())
    return items


def strip_comment(line: str, marker: str) -> str:
    """The part of `line` before `marker`, ignoring markers inside double-quoted strings."""
    quoted = False
    for i, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif ch == marker and not quoted:
            return line[:i]
    return line


def arg_value(text: str) -> float | str:
    """A call argument as written: a float when it is a number literal, else the text."""
    return float(text) if is_number(text) else text.strip()
