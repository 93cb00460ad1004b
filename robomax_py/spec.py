"""Frozen, checked descriptions of robots, tools and cells, in SI units (m, rad, s).

`cell_io` builds these from files and is the only module that knows file keys or file units; every
other module reads these values. Arrays held here are read-only copies.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.program_instructions import (
    ToolLoad,  # a tool spec's load, which programs carry too
)


def frozen_array(values: Any) -> FloatArray:
    """A float64 copy that cannot be written to, so frozen specs stay frozen."""
    arr = np.array(values, dtype=float)
    arr.setflags(write=False)
    return arr


Brand = Literal["kuka", "abb", "fanuc", "ur", "yaskawa", "kawasaki", "staubli", "comau", "nachi"]
# Every controller brand robot.yaml may name (docs/cell-files.md, "Controller programs"); a brand whose dialect robomax lacks
# (Stäubli VAL 3, Comau PDL2, Nachi FD) gets no native program.
BRANDS: tuple[str, ...] = ("kuka", "abb", "fanuc", "ur", "yaskawa", "kawasaki", "staubli", "comau", "nachi")


# The input a program waits for before moving through a dynamic object's space: `<name>_open` for a
# machine's door, `<name>_clear` for any other dynamic object (cell keys `dynamic`, `tending`).
CLEAR_SUFFIX = "_clear"
OPEN_SUFFIX = "_open"


def dynamic_signal(obstacle: str, door: bool) -> str:
    """The input a program waits for: `<name>_open` for a machine's door, else `<name>_clear`."""
    return obstacle + (OPEN_SUFFIX if door else CLEAR_SUFFIX)


def _identity() -> FloatArray:
    return frozen_array(np.eye(4))


@dataclass(frozen=True, slots=True, eq=False)
class ControllerSpec:
    """The robot's controller (docs/cell-files.md, "Controller programs"): whose configuration data programs carry, and its frames."""

    brand: Brand = "kuka"
    j23_coupling: bool = False        # FANUC: J3 as the controller counts it = J3 - J2 of the URDF
    T_root_base: FloatArray = field(default_factory=_identity)   # (4, 4) controller base in the URDF root
    # Yaskawa: encoder pulses per degree of each axis, as INFORM counts joint positions; () unknown.
    pulses_per_degree: tuple[float, ...] = ()
    # The controller's joint value = joint_signs[i] * q[i] + joint_zeros[i] (rad), for the joint
    # targets of controller programs; () = the URDF's own (+1, 0) for every joint.
    joint_signs: tuple[float, ...] = ()
    joint_zeros: tuple[float, ...] = ()


@dataclass(frozen=True, slots=True, eq=False)
class RobotSpec:
    """A robot.yaml, checked. Velocity and position limits live in the URDF."""

    name: str
    source: Path                      # the robot.yaml
    urdf: Path
    flange: str                       # URDF frame the tool mounts on
    ik_solver: str                    # "opw" | "ur" | "numeric"
    ik_params: Any                    # typed params (robomax_py.robot.ik); None: fitted from the URDF
    acceleration: FloatArray | None   # (n,) rad/s^2, None: derived from velocity limits
    jerk: FloatArray | None           # (n,) rad/s^3, None: derived from acceleration limits
    payload_kg: float | None = None   # rated payload, for listings only
    description: str = ""
    controller: ControllerSpec = field(default_factory=ControllerSpec)
    disabled_links: tuple[tuple[str, str], ...] = ()        # robot.yaml collision.disable: never checked
    srdf_disabled_links: tuple[tuple[str, str], ...] = ()   # the SRDF's disable_collisions
    package_dirs: tuple[Path, ...] = ()   # folders P with P/NAME the package of the URDF's package://NAME meshes
    loaded: JointLoadLimits | None = None    # joint limits carrying the rated payload (robot.yaml `loaded`)
    warnings: tuple[str, ...] = ()        # what the checks at load found worth saying (io.robot.check_urdf)


@dataclass(frozen=True, slots=True)
class ControllerFrame:
    """A frame as the robot's controller stores it (docs/cell-files.md, "Controller programs", cell key `robot.controller`).

    number : int
        Its slot: KUKA TOOL_DATA[n] / BASE_DATA[n], FANUC UTOOL[n] / UFRAME[n].
    name : str
        Its name: ABB RAPID tooldata / wobjdata, UR variable, KUKA TOOL_NAME / BASE_NAME.
    existing : bool
        The cell named it, so it exists on the controller: RAPID refers to it without declaring it.
    """

    number: int
    name: str
    existing: bool = False


@dataclass(frozen=True, slots=True, eq=False)
class UserFrame:
    """The user frame programs state their Cartesian targets in (KUKA base, ABB work object,
    FANUC user frame), where the cell puts it: T_world_frame (4, 4) in the cell's world, m."""

    frame: ControllerFrame
    T_world_frame: FloatArray


@dataclass(frozen=True, slots=True)
class ControllerInput:
    """A cell signal as the controller reads it: input `number` (KUKA $IN, FANUC DI, UR standard
    digital input), and for RAPID the signal's `name` in the controller's I/O configuration."""

    signal: str
    number: int
    name: str | None = None


@dataclass(frozen=True, slots=True)
class ControllerOutput:
    """A signal the robot sets for others (a station's interlocks) as the controller writes it:
    output `number` (KUKA $OUT, FANUC DO, UR standard digital output), and for RAPID the signal's
    `name` in the controller's I/O configuration."""

    signal: str
    number: int
    name: str | None = None


@dataclass(frozen=True, slots=True, eq=False)
class ControllerSetup:
    """The integrator's numbers on the robot's controller (cell key `robot.controller`): which tool
    and user frame programs select, the registers a program may use, the inputs each cell signal
    arrives on, the outputs of the signals the robot sets (a station's interlocks), and whether welds call the default routine or the controller's process package.

    tool : ControllerFrame | None
        None: tool 1, named after the tool (`<tool>_tcp`), declared by the programs.
    frame : UserFrame | None
        None: targets in the robot base frame itself (KRL base 0, RAPID wobj0, FANUC UF 0).
    """

    tool: ControllerFrame | None = None
    frame: UserFrame | None = None
    position_registers: tuple[int, ...] = ()
    numeric_registers: tuple[int, ...] = ()
    inputs: tuple[ControllerInput, ...] = ()
    weld: Literal["call", "package"] = "call"
    outputs: tuple[ControllerOutput, ...] = ()

    def input_of(self, signal: str) -> ControllerInput | None:
        """The input a cell signal is mapped to; None when the cell maps none."""
        return next((i for i in self.inputs if i.signal == signal), None)

    def output_of(self, signal: str) -> ControllerOutput | None:
        """The output a signal the robot sets is mapped to; None when the cell maps none."""
        return next((o for o in self.outputs if o.signal == signal), None)


@dataclass(frozen=True, slots=True, eq=False)
class JointLoadLimits:
    """Per joint, the limits with the rated payload at the flange: velocity (rad/s), acceleration
    (rad/s^2), jerk (rad/s^3), each (n,). A lighter part gets limits interpolated by its mass."""

    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray


@dataclass(frozen=True, slots=True, eq=False)
class ToolSpec:
    """A tool.yaml, checked: meshes in the flange frame (with the units, scale and STEP tolerance
    the file gives them), TCP pose in the flange frame, and its load when the file states one."""

    name: str
    source: Path
    body: MeshShape
    tips: MeshShape
    T_flange_tcp: FloatArray          # (4, 4)
    load: ToolLoad | None = None      # mass, kg; centre of gravity in the flange frame, m


@dataclass(frozen=True, slots=True)
class Box:
    extents: tuple[float, float, float]       # full side lengths, m


@dataclass(frozen=True, slots=True)
class Cylinder:
    radius: float
    length: float                             # along local z, m


@dataclass(frozen=True, slots=True)
class Sphere:
    radius: float


@dataclass(frozen=True, slots=True)
class Capsule:
    radius: float
    length: float                             # cylindrical part along local z; caps add radius each end


@dataclass(frozen=True, slots=True)
class MeshShape:
    path: Path
    # Factor per axis from the file's numbers to metres: the cell file's `units` (mm: 0.001) times
    # its `scale` (docs/cad.md). A STEP file is read in metres already, so only `scale` counts.
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    tolerance: float | None = None            # m: a STEP's meshing tolerance; None: the default


Shape = Box | Cylinder | Sphere | Capsule | MeshShape


@dataclass(frozen=True, slots=True, eq=False)
class PathMotion:
    """A rigid object carried along timed poses (cell key `dynamic[i].path`): position linear and
    rotation slerped between them, held at the end poses outside them while present.

    t : (k,) s, strictly increasing; T_world_object : (k, 4, 4); repeat : s between passes (None:
    one pass); count : passes; sweep : m, how far the object may move within the span one of its
    sampled poses stands for (`world.moving`).
    """

    t: FloatArray
    T_world_object: FloatArray
    repeat: float | None = None
    count: int = 1
    sweep: float = 0.02


@dataclass(frozen=True, slots=True, eq=False)
class RobotMotion:
    """Another robot replaying a trajectory file (cell key `dynamic[i].robot` + `trajectory`): its
    links (and tool) follow q(t), linear in joint space between samples, held at the first sample
    before it and at the last after it.

    t : (k,) s from program start; q : (k, n) rad (m for a prismatic joint) in the order `joints`
    names (checked against the model when the scene is built); key : where the cell states it.
    """

    robot: RobotSpec
    T_world_base: FloatArray
    tool: ToolSpec | None
    joints: tuple[str, ...]
    t: FloatArray
    q: FloatArray
    source: Path                             # the trajectory file
    key: str
    sweep: float = 0.02


@dataclass(frozen=True, slots=True, eq=False)
class ObjectSpec:
    """A static obstacle, or a dynamic one when `present` is not None."""

    name: str
    shape: Shape
    T_world_object: FloatArray                # (4, 4)
    workpiece: bool = False
    # Time windows (s from program start) in which a dynamic obstacle exists; None: always.
    present: tuple[tuple[float, float], ...] | None = None
    # Clamp interlock: the input the program waits for before the first weld near this object.
    signal: str | None = None
    # A machine's door (tending cells): present while closed; the program waits for `<name>_open`.
    door: bool = False
    # A moving dynamic object (cell keys `dynamic[i].path`, `.robot`): its pose follows the motion
    # while present; `shape` and `T_world_object` are then its shape and first pose (a robot: unused).
    motion: PathMotion | RobotMotion | None = None


@dataclass(frozen=True, slots=True, eq=False)
class SpotSpec:
    name: str
    xyz: FloatArray                           # (3,) world, m
    normal: FloatArray                        # (3,) unit, outward: the moving electrode's side
    direction: FloatArray                     # (3,) unit, orthogonal to normal
    # Per-spot overrides (cell-file extensions): None takes the process's or the planner's choice.
    weld_time: float | None = None            # s
    schedule: int | None = None               # weld schedule number
    angles: tuple[float, float, float] | None = None   # pinned alpha, beta, gamma, rad
    config: str | None = None                 # pinned configuration data (the controller brand's)
    # Tending stations (cell-file `tending`): the gripper action at rest here instead of a weld,
    # and the machine whose door the station lies behind.
    action: Literal["grip", "release"] | None = None
    machine: str | None = None
    key: str | None = None                    # where the cell file states it, when not seams[i].spots[j]
    part: str | None = None                   # pick and place: the part gripped or released here


@dataclass(frozen=True, slots=True, eq=False)
class SeamSpec:
    name: str
    ordered: bool
    alpha_max: float                          # rad, |alpha| <= alpha_max
    beta_max: float                           # rad
    gamma_range: tuple[float, float]          # rad, min <= max
    grid: int                                 # samples per angle, ends included
    spots: tuple[SpotSpec, ...]
    # The gun may also stand on the sheet's other side: the grid again, turned 180 deg about the
    # seam direction (tolerance.sides: either; `plan.poses.orientation_grid`).
    either_side: bool = False


@dataclass(frozen=True, slots=True)
class ProcessSpec:
    weld_time: float = 0.5                    # s
    approach: float = 0.03                    # m, along the electrode axis
    clearance: float = 0.0                    # m, safety margin to obstacles
    gun: int = 1                              # weld gun number the programs name
    schedule: int = 1                         # default weld schedule
    interlock_distance: float = 0.2           # m: a spot this close to a clamp with a signal waits for it

    def weld_time_of(self, spot: SpotSpec) -> float:
        """The weld time of a spot: its own, else the process's."""
        return self.weld_time if spot.weld_time is None else spot.weld_time

    def schedule_of(self, spot: SpotSpec) -> int:
        return self.schedule if spot.schedule is None else spot.schedule


@dataclass(frozen=True, slots=True)
class LearnedMapSpec:
    """The learned C-space map detours are searched in under `planner.detours: learned`."""

    resolution: int = 40          # samples per axis of the A1-A3 map
    spacing: float = 0.1          # m between the surface points the objects become
    inflation: float = 0.06       # m added to the points' cover radius and the clearance
    training: str = "coarse"      # the model's training grid: "coarse" or "standard"
    neurons: int | None = None    # most hidden neurons of the network; None: grown until it fits


@dataclass(frozen=True, slots=True)
class PlannerSpec:
    seed: int = 0
    speed: float = 1.0            # override of every programmed speed, fraction in (0, 1]
    tcp_speed: float = 0.5        # m/s on the LIN approach and retract lines
    detour_speed: float = 1.0     # speed fraction of PTP moves through detours (near clamps)
    # Where detours are searched: "roadmap", "cspace" (local A1-A3 map), "both", or "learned" (the
    # learned C-space map alone, `learned`).
    detours: str = "both"
    # How a detour moves: "ptp" (joint-space straight moves between its points) or "lin" (straight
    # TCP lines through via points, as paper 003 builds them; joint-space where none exists).
    detour_moves: str = "ptp"
    detour_tcp_speed: float = 1.0  # m/s on the LIN lines of a detour (`detour_moves: lin`)
    learned: LearnedMapSpec = LearnedMapSpec()
    # Dynamic obstacles: "timed" searches the roadmap with their windows (waiting where it pays,
    # or going round); "rest" plans them as absent and waits at rest before the blocked move.
    dynamic: str = "timed"
    max_wait: float = 600.0       # s: a search that would wait longer at one place has no solution
    # Pick and place: carried moves planned as every move ("moves") or by Diane and Anikina's
    # associative memory, k-NN graph, Dijkstra route and Jacobian interpolation ("associative").
    transfers: str = "moves"
    # "lin": approach, retract and detour lines as straight LIN moves with fly-by; "spline": a
    # junction between two spots as one smooth Bézier TCP path where that is faster.
    cartesian_moves: str = "lin"


@dataclass(frozen=True, slots=True, eq=False)
class MachineSpec:
    """A machine of a tending cell: its door (a dynamic object) closed while it machines."""

    name: str
    door: str                                 # the dynamic object's name
    windows: tuple[tuple[float, float], ...]  # s from program start: door closed (machining)


@dataclass(frozen=True, slots=True)
class TcpLimits:
    """Limits on the TCP's path motion: speed v (m/s), tangential and radial acceleration a_T, a_R
    (m/s^2) and the rates of change of those accelerations j_T, j_R (m/s^3)."""

    v: float
    a_T: float
    a_R: float
    j_T: float
    j_R: float


@dataclass(frozen=True, slots=True, eq=False)
class PartSpec:
    """A part of a pick-and-place cell: while held it moves with the TCP and collides with
    everything but the gripper; it may touch (never enter) its `supports`."""

    name: str
    shape: Shape
    mass: float                               # kg
    T_tcp_part: FloatArray                    # (4, 4) the part's frame in the TCP frame while held
    limits: TcpLimits | None                  # TCP limits while it is carried; None: the unloaded ones
    supports: tuple[str, ...] = ()            # objects it rests on at its locations
    # (3,) unit: the world's up in the part's own frame where it lies (the mean over its locations):
    # the way it comes off its supports (`world.acm`, a meshed part).
    up: FloatArray = field(default_factory=lambda: frozen_array([0.0, 0.0, 1.0]))


@dataclass(frozen=True, slots=True)
class Notice:
    """What in a cell file is valid but probably a mistake (lengths that look like millimetres, a
    spot inside an object, ...): the file, the key path and the message. A warning, never an error:
    the cell still loads and plans."""

    file: str
    key: str
    message: str

    def __str__(self) -> str:
        # A robot file's warning names no key (`app.batch_cell.robot_notices`).
        return f"{self.file}: {self.key}: {self.message}" if self.key else f"{self.file}: {self.message}"


@dataclass(frozen=True, slots=True, eq=False)
class CellSpec:
    name: str
    source: Path
    robot: RobotSpec
    T_world_base: FloatArray                  # (4, 4)
    home: FloatArray                          # (n,) rad (m for prismatic joints)
    tool: ToolSpec
    objects: tuple[ObjectSpec, ...]
    seams: tuple[SeamSpec, ...]
    process: ProcessSpec = field(default_factory=ProcessSpec)
    planner: PlannerSpec = field(default_factory=PlannerSpec)
    dynamic: tuple[ObjectSpec, ...] = ()
    digest: str = ""                          # SHA-256 (hex) of the cell file's bytes
    machines: tuple[MachineSpec, ...] = ()    # tending cells: machines and their door schedules
    parts: tuple[PartSpec, ...] = ()          # pick-and-place cells: the parts moved
    tcp_limits: TcpLimits | None = None       # pick-and-place cells: TCP limits without a part
    controller: ControllerSetup = field(default_factory=ControllerSetup)   # the integrator's numbers
    notices: tuple[Notice, ...] = ()          # probable mistakes found at load (`io.cell_lint`)
    # A continuation (`robomax replan`): the configuration (n,) rad its program starts in, at rest,
    # instead of `home`; it still ends at home. None: a whole program, from home to home.
    start: FloatArray | None = None
    # `robot.joint_limits`: the controller's software limits, (n, 2) [lower, upper] rad (m for a
    # prismatic joint), within the URDF's. None: the URDF's.
    joint_limits: FloatArray | None = None

    @property
    def q_start(self) -> FloatArray:
        """Where the program starts: `start` for a continuation, else `home`."""
        return self.home if self.start is None else self.start

    @property
    def signals(self) -> tuple[str, ...]:
        """Every input a program of this cell may wait for: clamp signals, then the dynamic
        objects' `<name>_clear` / `<name>_open`, in cell order."""
        clamps = [o.signal for o in self.objects if o.signal]
        return tuple(dict.fromkeys([*clamps, *(dynamic_signal(d.name, d.door) for d in self.dynamic)]))

    def part(self, name: str) -> PartSpec:
        """The part called `name` (KeyError when the cell has none of that name)."""
        for p in self.parts:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def tending(self) -> bool:
        """Whether the cell tends machines (its stops are gripper actions at stations, not welds)."""
        return any(spot.action is not None for seam in self.seams for spot in seam.spots)
