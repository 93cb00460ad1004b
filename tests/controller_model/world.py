"""Written programs judged in the world: each dialect's controller model run on a planned cell's
files, its targets placed in the world as the controller places them, against the plan.

Used by test_against_robomax.py and tests/bench/bench_controller_frames.py. Independent of
robomax's code: the arm comes from its URDF (pinocchio) and robot.yaml, the tool from tool.yaml,
the plan from the trajectory file (SPEC §5), the cell from its YAML; the programs are read by the
models of this package.

A target the controller commands is a TCP pose in its robot base frame (the user frame composed in
by the model) with the tool frame the program put in force. The controller moves the flange to
target · tool⁻¹, so the physical TCP (the gun's real tcp) lands at target · tool⁻¹ · tcp, placed in
the world by the cell's robot placement and the controller's base in the URDF root (SPEC §6). A
wrong tool frame in the program shows up there, even when the target itself is right.
"""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import yaml
from scipy.spatial.transform import Rotation

from .common import (
    Call,
    FanucConfig,
    FloatArray,
    Issue,
    KrlConfig,
    Motion,
    ProgramRun,
    RapidConfig,
)
from .fanuc import controller_joints_deg, run_fanuc
from .inform import run_inform
from .kawasaki_as import run_as
from .krl import run_krl
from .rapid import run_rapid
from .urscript import run_urscript

REPO = Path(__file__).resolve().parents[2]
ROBOTS = REPO / "robomax_py" / "robots"
DIALECTS = ("krl", "rapid", "fanuc", "urscript", "as", "inform")
MAIN_FILE = {"krl": ".src", "rapid": ".mod", "fanuc": ".ls", "urscript": ".script", "as": ".as",
             "inform": ".jbi"}


# ------------------------------------------------------------------------------------------ frames
def T_from(xyz: Any = (0.0, 0.0, 0.0), rpy_deg: Any = (0.0, 0.0, 0.0)) -> FloatArray:
    """(4, 4) from xyz (m) and roll, pitch, yaw (deg) about the fixed x, y, z axes (SPEC §3)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy_deg, degrees=True).as_matrix()
    T[:3, 3] = xyz
    return T


def xyz_rpy(T: FloatArray) -> dict[str, list[float]]:
    return {"xyz": [float(v) for v in T[:3, 3]],
            "rpy": [float(v) for v in Rotation.from_matrix(T[:3, :3]).as_euler("xyz", degrees=True)]}


def angle_deg(R1: FloatArray, R2: FloatArray) -> float:
    return float(np.degrees(Rotation.from_matrix(R1.T @ R2).magnitude()))


def _pose(data: dict[str, Any] | None) -> FloatArray:
    data = data or {}
    return T_from(data.get("xyz", (0, 0, 0)), data.get("rpy", (0, 0, 0)))


# ------------------------------------------------------------------------------------ the arm (FK)
@dataclass(frozen=True)
class Arm:
    """The robot as its URDF and robot.yaml define it, for FK and configuration geometry."""

    model: Any                 # pin.Model
    joint_ids: tuple[int, ...]
    q_index: tuple[int, ...]
    flange_id: int
    T_flange_tcp: FloatArray
    T_root_base: FloatArray    # the controller's robot base frame in the URDF root
    j23_coupling: bool
    pulses_per_degree: tuple[float, ...] = ()     # Yaskawa: robot.yaml controller.pulses_per_degree

    def _q(self, q_urdf: FloatArray) -> FloatArray:
        q = pin.neutral(self.model)
        q[list(self.q_index)] = q_urdf
        return np.asarray(q)

    def flange(self, q_urdf: FloatArray) -> FloatArray:
        """(4, 4) flange in the URDF root."""
        data = self.model.createData()
        pin.framesForwardKinematics(self.model, data, self._q(q_urdf))
        return np.asarray(data.oMf[self.flange_id].homogeneous)

    def tcp(self, q_urdf: FloatArray) -> FloatArray:
        """(4, 4) TCP in the URDF root."""
        return self.flange(q_urdf) @ self.T_flange_tcp

    def a1_frame(self, q_urdf: FloatArray) -> FloatArray:
        """(3, 3) orientation of axis 1's joint frame (turning with A1), in the URDF root."""
        data = self.model.createData()
        pin.forwardKinematics(self.model, data, self._q(q_urdf))
        return np.asarray(data.oMi[self.joint_ids[0]].rotation)

    def axes(self, q_urdf: FloatArray) -> list[tuple[FloatArray, FloatArray]]:
        """(point on the axis, unit axis direction) of each joint, in the URDF root."""
        model, data = self.model, self.model.createData()
        q = self._q(q_urdf)
        J = pin.computeJointJacobians(model, data, q)
        out = []
        for jid in self.joint_ids:
            v = model.joints[jid].idx_v
            axis = np.asarray(J[3:, v])
            out.append((np.asarray(data.oMi[jid].translation), axis / np.linalg.norm(axis)))
        return out


def _urdf_path(robot_yaml: Path, urdf: str) -> Path:
    """robot.yaml's `urdf`: relative to the file, or package://<pkg>/... of an installed package
    (example-robot-data installs its share folder with its Python distribution)."""
    if not urdf.startswith("package://"):
        return robot_yaml.parent / urdf
    package, _, rest = urdf[len("package://"):].partition("/")
    for f in metadata.files(package) or []:
        parts = Path(str(f)).parts
        if "share" in parts and package in parts:
            share = Path(str(f.locate())).resolve().parents[len(parts) - parts.index("share") - 2]
            return share / package / rest
    raise FileNotFoundError(f"{urdf}: package {package} is not installed")


def load_arm(robot_yaml: Path, tool_yaml: Path, joints: list[str]) -> Arm:
    robot = yaml.safe_load(robot_yaml.read_text())
    tool = yaml.safe_load(tool_yaml.read_text())
    model = pin.buildModelFromUrdf(str(_urdf_path(robot_yaml, robot["urdf"])))
    joint_ids = tuple(model.getJointId(name) for name in joints)
    controller = robot.get("controller", {})
    if "base" in controller:
        T_root_base = _pose(controller["base"])
    elif model.existFrame("base"):     # a ROS-Industrial `base` link: the vendor's base frame (SPEC §6)
        data = model.createData()
        pin.framesForwardKinematics(model, data, pin.neutral(model))
        T_root_base = np.asarray(data.oMf[model.getFrameId("base")].homogeneous)
    else:
        T_root_base = np.eye(4)
    return Arm(model, joint_ids, tuple(model.joints[j].idx_q for j in joint_ids), model.getFrameId(robot["flange"]),
               _pose(tool["tcp"]), T_root_base, bool(controller.get("j23_coupling", False)),
               tuple(float(v) for v in controller.get("pulses_per_degree") or ()))


# --------------------------------------------------------------------------- configuration data
@dataclass(frozen=True)
class Geometry:
    """Where the wrist point is, as the vendors' configuration definitions need it."""

    wrist_behind_axis1: bool       # KUKA Status bit 0, ABB cfx 'behind axis 1', FANUC B
    wrist_before_a2_a3_line: bool  # KUKA Status bit 1, ABB cfx 'in front of the lower arm', FANUC U


def _closest_point(p1: FloatArray, a1: FloatArray, p2: FloatArray, a2: FloatArray) -> FloatArray:
    """Midpoint of the closest points of two (non-parallel) lines p + s·a."""
    w = p1 - p2
    b, d, e = a1 @ a2, a1 @ w, a2 @ w
    s = (b * e - d) / (1 - b * b)
    t = (e - b * d) / (1 - b * b)
    return np.asarray((p1 + s * a1 + p2 + t * a2) / 2)


def geometry(arm: Arm, q_urdf: FloatArray) -> Geometry:
    """KUKA's definitions (the Sinumerik copy of KUKA's Status table, vendor_research §1.5): bit 0 is
    the wrist point (axes 4, 5, 6) at negative x of the A1 coordinate system; bit 1 the wrist point
    on the A3 >= phi side of the line through the A2 and A3 axes ('elbow up'). ABB cfx and FANUC
    U/D, T/B use the same geometry (vendor_research §2.3, §3.1).

    The A1 coordinate system is the controller's robot base frame turned with axis 1: its x is the
    base's x turned as far as A1 has turned from zero, its z (up) the A1 axis pointing the way the
    base's z does. Neither comes from the arm's shape: a ROS-Industrial KUKA URDF puts the A1 joint
    at shoulder height and turns it about -z, and an arm without a shoulder offset (Staubli, UR)
    has no offset to tell front from back."""
    (p1, a1), (p2, _), (p3, _), (p4, a4), (p5, a5), _ = arm.axes(q_urdf)
    wrist = _closest_point(p4, a4, p5, a5)
    base_x, base_z = arm.T_root_base[:3, 0], arm.T_root_base[:3, 2]
    up = a1 if a1 @ base_z >= 0 else -a1
    turned = arm.a1_frame(q_urdf) @ arm.a1_frame(np.zeros_like(q_urdf)).T
    forward = turned @ base_x
    forward = forward - (forward @ up) * up
    forward = forward / np.linalg.norm(forward)
    behind = float((wrist - p1) @ forward) < 0

    def plane(v: FloatArray) -> tuple[float, float]:
        return float(v @ forward), float(v @ up)

    (bx, bz), (wx, wz) = plane(p3 - p2), plane(wrist - p2)
    return Geometry(behind, bx * wz - bz * wx < 0)


def kuka_config(arm: Arm, q_urdf: FloatArray) -> KrlConfig:
    g = geometry(arm, q_urdf)
    deg = np.degrees(q_urdf)
    status = int(g.wrist_behind_axis1) | int(g.wrist_before_a2_a3_line) << 1 | int(deg[4] < 0) << 2
    return KrlConfig(status, sum(int(v < 0) << i for i, v in enumerate(deg)))


def abb_config(arm: Arm, q_urdf: FloatArray) -> RapidConfig:
    g = geometry(arm, q_urdf)
    deg = np.degrees(q_urdf)
    cfx = 4 * int(g.wrist_behind_axis1) + 2 * int(not g.wrist_before_a2_a3_line) + int(deg[4] < 0)
    cf1, cf4, cf6 = (math.floor(deg[i] / 90.0) for i in (0, 3, 5))   # the quadrant: floor(angle / 90 deg)
    return RapidConfig(cf1, cf4, cf6, cfx)


def fanuc_letters(arm: Arm, q_urdf: FloatArray) -> tuple[str, str, str]:
    g = geometry(arm, q_urdf)
    j5 = controller_joints_deg(tuple(np.degrees(q_urdf)), arm.j23_coupling)[4]
    return ("F" if j5 > 0 else "N", "U" if g.wrist_before_a2_a3_line else "D", "B" if g.wrist_behind_axis1 else "T")


# A planned joint this close to a sign or quadrant boundary names both sides: the trajectory file
# rounds to 1e-9 rad (6e-8 deg), so a joint planned at -1e-12 rad is written -0.0 there, while the
# writer, which saw the unrounded value, may state the negative side. Both name the same posture.
BOUNDARY_DEG = 1e-6


def _near(value: float, step: float) -> bool:
    """`value` within BOUNDARY_DEG of a multiple of `step` (0 for the sign alone)."""
    if step == 0.0:
        return abs(value) < BOUNDARY_DEG
    return abs(value - step * round(value / step)) < BOUNDARY_DEG


def _quadrants(value: float) -> set[int]:
    """ABB quadrants floor(angle / 90 deg) the value names: both neighbours on a boundary."""
    k = round(value / 90.0)
    return {k - 1, k} if _near(value, 90.0) else {math.floor(value / 90.0)}


def config_mismatch(arm: Arm, dialect: str, config: object, q_urdf: FloatArray) -> str | None:
    """Why the configuration data written does not name the planned joints' configuration as the
    vendor defines it (None when it does; URScript and AS transformation values carry none). A joint within
    BOUNDARY_DEG of a sign or quadrant boundary is accepted on either side."""
    deg = np.degrees(q_urdf)
    if dialect == "krl":
        want = kuka_config(arm, q_urdf)
        loose_turn = sum(1 << i for i, v in enumerate(deg) if _near(v, 0.0))
        loose_status = 4 if _near(deg[4], 0.0) else 0
        if not (isinstance(config, KrlConfig) and config.status is not None and config.turn is not None
                and ((config.status & 7) ^ (want.status or 0)) & ~loose_status == 0     # bit 4: KSS 8 teaching
                and (config.turn ^ (want.turn or 0)) & ~loose_turn == 0):
            return f"S/T {config} where the joints are S {want.status} T {want.turn}"
    elif dialect == "rapid":
        want_abb = abb_config(arm, q_urdf)
        if not isinstance(config, RapidConfig):
            return f"confdata {config} where the joints are {want_abb}"
        quadrants_ok = all(got in _quadrants(deg[i]) for got, i in ((config.cf1, 0), (config.cf4, 3), (config.cf6, 5)))
        cfx_ok = config.cfx == want_abb.cfx or (_near(deg[4], 0.0) and config.cfx ^ want_abb.cfx == 1)
        if not (quadrants_ok and cfx_ok):
            return f"confdata {config} where the joints are {want_abb}"
    elif dialect == "fanuc":
        letters = fanuc_letters(arm, q_urdf)
        ctrl = controller_joints_deg(tuple(deg), arm.j23_coupling)
        if not isinstance(config, FanucConfig) or (config.elbow, config.front) != letters[1:] \
                or (config.flip != letters[0] and not _near(ctrl[4], 0.0)):
            return f"CONFIG {getattr(config, 'text', config)} where the joints are {' '.join(letters)}"
        if all(-180.0 < ctrl[i] < 180.0 for i in (0, 3, 4, 5)) and config.turns != (0, 0, 0):
            return f"CONFIG turns {config.turns} where every axis is within +-180 deg"
    return None


# -------------------------------------------------------------------------------------- the plan
@dataclass(frozen=True)
class Plan:
    folder: Path
    name: str
    G: FloatArray                      # (4, 4) robot base in the world (the cell's robot.base)
    spots: dict[str, FloatArray]       # spot name -> xyz in the world
    t: FloatArray
    q: FloatArray
    spot_times: list[tuple[str, float]]    # (name, t_arrive) in weld order
    arm: Arm
    cell: dict[str, Any]               # the cell file as written
    _tcp_cache: list[FloatArray] = field(default_factory=list, repr=False, compare=False)

    def q_at(self, t: float) -> FloatArray:
        return np.asarray([np.interp(t, self.t, self.q[:, j]) for j in range(self.q.shape[1])])

    def world(self, T_base: FloatArray) -> FloatArray:
        """A pose in the controller's robot base frame, in the world."""
        return np.asarray(self.G @ self.arm.T_root_base @ T_base)

    def planned_tcp(self, t: float) -> FloatArray:
        """(4, 4) the planned TCP in the world at time t."""
        return np.asarray(self.G @ self.arm.tcp(self.q_at(t)))

    def tcp_path(self) -> FloatArray:
        """(n, 4, 4) the planned TCP in the world at every trajectory sample."""
        if not self._tcp_cache:
            self._tcp_cache.append(np.asarray([self.G @ self.arm.tcp(q) for q in self.q]))
        return self._tcp_cache[0]

    def text(self, name: str) -> str:
        return (self.folder / name).read_text(encoding="utf-8")

    @property
    def controller(self) -> dict[str, Any]:
        """The cell's `robot.controller` (empty: the controller's default frames)."""
        return dict(self.cell["robot"].get("controller") or {})

    def user_frame_world(self) -> FloatArray | None:
        """The user frame the cell names, in the world (its object's pose or its own pose); None
        when the cell names none (the robot base frame is the user frame)."""
        frame = self.controller.get("frame")
        if frame is None:
            return None
        if "object" in frame:
            return _pose(next(o for o in self.cell["objects"] if o["name"] == frame["object"]).get("pose"))
        return _pose(frame["pose"])


def _reference(cell: Path, given: str, library: Path, file: str) -> Path:
    """A robot or tool reference (SPEC §3): a folder name in the library, or a path to the file
    (relative to the cell file)."""
    path = Path(given) if Path(given).is_absolute() else cell.parent / given
    if given.endswith(".yaml") or path.is_file():
        return path
    if path.is_dir():
        return path / file
    return library / given / file


def read_plan(cell: Path, folder: Path, name: str) -> Plan:
    """The plan of `cell` whose files (`name`.json and the programs) are in `folder`."""
    data = yaml.safe_load(cell.read_text())
    trajectory = json.loads((folder / f"{name}.json").read_text())
    robot_yaml = _reference(cell, data["robot"]["model"], ROBOTS, "robot.yaml")
    tool_yaml = _reference(cell, data["tool"], ROBOTS / "tools", "tool.yaml")
    spots = {s["name"]: np.asarray(s["xyz"]) for seam in data["seams"] for s in seam["spots"]}
    order = sorted(((s["name"], float(s["t_arrive"])) for s in trajectory["spots"]), key=lambda s: s[1])
    return Plan(folder, name, _pose(data["robot"].get("base")), spots, np.asarray(trajectory["t"]),
                np.asarray(trajectory["q"]), order, load_arm(robot_yaml, tool_yaml, trajectory["joints"]), data)


# ------------------------------------------------------------------------------ running programs
def rapid_held(plan: Plan) -> dict[str, str]:
    """A tool the cell names exists on the controller (the integrator calibrated it), so the
    program refers to it without declaring it: the controller's system module holding it, with the
    tool.yaml tcp (quaternion [w, x, y, z] from scipy, mm)."""
    tool = plan.controller.get("tool") or {}
    if "name" not in tool:
        return {}
    T = plan.arm.T_flange_tcp
    x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
    mm = ", ".join(f"{v * 1000.0:.6f}" for v in T[:3, 3])
    return {"user.sys": f"MODULE user(SYSMODULE)\n  PERS tooldata {tool['name']} := [TRUE, [[{mm}], "
                        f"[{w:.12f}, {x:.12f}, {y:.12f}, {z:.12f}]], [1, [0, 0, 0.001], [1, 0, 0, 0], 0, 0, 0]];\n"
                        "ENDMODULE\n"}


def fanuc_held(plan: Plan) -> tuple[dict[int, FloatArray], dict[int, FloatArray]]:
    """(utools, uframes) the controller holds before the setup program runs. With position
    registers the setup program sets every frame the program uses, so none; without, the
    integrator calibrated the cell's tool (number 1 unless the cell names one) and user frame (in
    the robot base frame) into the controller."""
    if (plan.controller.get("registers") or {}).get("position"):
        return {}, {}
    return calibrated_frames(plan)


def calibrated_frames(plan: Plan) -> tuple[dict[int, FloatArray], dict[int, FloatArray]]:
    """(tools, user frames) by number that an integrator calibrated into a controller for the cell:
    the cell's tool (number 1 unless the cell names one) and its user frame (in the robot base)."""
    tools = {int((plan.controller.get("tool") or {}).get("number", 1)): plan.arm.T_flange_tcp}
    users = {}
    frame = plan.controller.get("frame")
    world = plan.user_frame_world()
    if frame is not None and world is not None:
        users[int(frame.get("number", 1))] = np.linalg.inv(plan.world(np.eye(4))) @ world
    return tools, users


def inform_held(plan: Plan) -> tuple[dict[int, FloatArray], dict[int, FloatArray]]:
    """(tools, user frames) a Yaskawa controller calibrated for the cell holds: a job names them
    by number only."""
    return calibrated_frames(plan)


def run_program(plan: Plan, dialect: str) -> ProgramRun:
    """The dialect's controller model run on the plan's program, after its frames setup file."""
    files = sorted(p.name for p in plan.folder.iterdir())
    if dialect == "krl":
        setup = {f: plan.text(f) for f in files if f.endswith(".src") and "frames" in f.lower()}
        return run_krl(plan.text(f"{plan.name}.src"), plan.text(f"{plan.name}.dat"), src_name=f"{plan.name}.src",
                       dat_name=f"{plan.name}.dat", setup=setup)
    if dialect == "rapid":
        return run_rapid({**rapid_held(plan), **{f: plan.text(f) for f in files if f.endswith(".mod")}})
    if dialect == "fanuc":
        # A TP program is named as its file, in capitals (PLACED_CELL.ls, PLACED_CELL_FRAMES.ls).
        main = f"{plan.name.upper()}.ls"
        others = [f for f in files if f.endswith(".ls") and f != main]
        utools, uframes = fanuc_held(plan)
        return run_fanuc(plan.text(main), name=main,
                         setup={f: plan.text(f) for f in others if "frames" in f.lower()},
                         called={f: plan.text(f) for f in others if "frames" not in f.lower()},
                         utools=utools, uframes=uframes, j23_coupling=plan.arm.j23_coupling)
    if dialect == "inform":
        # A job is named in capitals (PROCESS_CELL.JBI); its weld job SPOTWELD is called, not run.
        job = next((f for f in files if f.lower() == f"{plan.name}.jbi"), None)
        if job is None:          # none written: the robot file states no pulses per degree
            raise FileNotFoundError(f"{plan.folder / plan.name}.jbi")
        tools, users = inform_held(plan)
        return run_inform(plan.text(job), name=job, pulses_per_degree=plan.arm.pulses_per_degree,
                          tools=tools, users=users)
    if dialect == "as":
        # The program and its weld routine in one file; its tool and base values stated in it.
        return run_as(plan.text(f"{plan.name}.as"), name=f"{plan.name}.as")
    return run_urscript(plan.text(f"{plan.name}.script"), name=f"{plan.name}.script")


@dataclass(frozen=True)
class Weld:
    spot: str
    t_arrive: float
    motion: Motion


def welds(plan: Plan, run: ProgramRun) -> list[Weld]:
    """The motion right before each ``spot_weld(n, ...)`` call (INFORM: ``CALL JOB:SPOTWELD ARGF n``),
    paired with the n-th spot welded."""
    out = []
    events = run.events
    for i, event in enumerate(events):
        if not (isinstance(event, Call) and event.name.lower() in ("spot_weld", "spotweld")):
            continue
        previous = events[i - 1] if i else None
        assert isinstance(previous, Motion), f"spot_weld at {event.where} does not follow a motion"
        assert event.args and isinstance(event.args[0], float), f"spot_weld at {event.where} without its number"
        n = int(event.args[0])
        assert 1 <= n <= len(plan.spot_times), f"spot_weld({n}) at {event.where}: the plan has {len(plan.spot_times)}"
        name, t_arrive = plan.spot_times[n - 1]
        out.append(Weld(name, t_arrive, previous))
    assert [w.spot for w in out] == [s for s, _ in plan.spot_times], "one spot_weld per planned spot, in order"
    return out


def physical_tcp(plan: Plan, motion: Motion) -> FloatArray:
    """(4, 4) where the gun's real TCP lands in the world for a Cartesian target: the controller
    puts the flange at target · tool⁻¹ (the tool frame in force), the gun's tcp is fixed to it."""
    assert motion.T_base_tcp is not None and motion.T_flange_tcp is not None
    flange = motion.T_base_tcp @ np.linalg.inv(motion.T_flange_tcp)
    return plan.world(flange @ plan.arm.T_flange_tcp)


# ------------------------------------------------------------------------------------ deviations
@dataclass(frozen=True)
class Deviation:
    """The largest deviations of one program, as its controller model runs it, from the plan.

    tcp_mm, tcp_deg : the physical TCP at each weld (`physical_tcp`) from the planned TCP at the
        spot's arrival (FK of the trajectory's joints).
    spot_mm : the same TCP from the cell's spot xyz.
    joint_deg : each joint stop point from the trajectory (the closest sample after the previous
        stop; FANUC J3 as the controller counts it).
    via_deg, via_mm : closest approach of the trajectory to each blended via point between its
        stop points (joint targets in deg, Cartesian targets in mm): the blend, not an error.
    configs : where the configuration data does not name the planned joints' configuration.
    issues : what the model reports (unsupported, alarm, undefined); with any, the figures are not
        the controller's.
    """

    dialect: str
    welds: int
    tcp_mm: float
    tcp_deg: float
    spot_mm: float
    joint_deg: float
    via_deg: float
    via_mm: float
    worst: str
    configs: tuple[str, ...]
    issues: tuple[Issue, ...]


def deviation(plan: Plan, dialect: str) -> Deviation:
    run = run_program(plan, dialect)
    found = welds(plan, run)
    at_weld = {id(w.motion): w for w in found}
    tcp_mm = tcp_deg = spot_mm = 0.0
    worst = ""
    configs = []
    for w in found:
        m = w.motion
        assert m.T_base_tcp is not None and m.T_flange_tcp is not None, \
            f"weld {w.spot} at {m.where}: no Cartesian target or no tool frame in force"
        got = physical_tcp(plan, m)
        want = plan.planned_tcp(w.t_arrive)
        off = float(np.linalg.norm(got[:3, 3] - want[:3, 3])) * 1e3
        turned = angle_deg(got[:3, :3], want[:3, :3])
        spot_mm = max(spot_mm, float(np.linalg.norm(got[:3, 3] - plan.spots[w.spot])) * 1e3)
        if off >= tcp_mm:
            worst = f"{w.spot} ({m.where.source}:{m.where.line})"
        tcp_mm, tcp_deg = max(tcp_mm, off), max(tcp_deg, turned)
        problem = config_mismatch(plan.arm, dialect, m.config, plan.q_at(w.t_arrive))
        if problem:
            configs.append(f"{w.spot} ({m.where.source}:{m.where.line}): {problem}")

    q_ctrl = np.asarray([controller_joints_deg(tuple(np.degrees(q)), plan.arm.j23_coupling) if dialect == "fanuc"
                         else np.degrees(q) for q in plan.q])
    motions = run.motions
    anchors: list[tuple[int, float]] = []
    joint_deg = 0.0
    t_cursor = plan.t[0]
    for k, m in enumerate(motions):
        if id(m) in at_weld:
            t_cursor = at_weld[id(m)].t_arrive
            anchors.append((k, t_cursor))
        elif m.joints_deg is not None and m.stops:
            later = plan.t >= t_cursor
            gap = np.abs(q_ctrl[later] - np.asarray(m.joints_deg)).max(axis=1)
            best = int(np.argmin(gap))
            joint_deg = max(joint_deg, float(gap[best]))
            t_cursor = float(plan.t[later][best])
            anchors.append((k, t_cursor))
    via_deg = via_mm = 0.0
    path = plan.tcp_path()
    bounds = [(-1, float(plan.t[0])), *anchors, (len(motions), float(plan.t[-1]))]
    for (k0, t0), (k1, t1) in itertools.pairwise(bounds):
        window = (plan.t >= t0) & (plan.t <= t1)
        if not window.any():
            continue
        for m in motions[k0 + 1:k1]:
            if m.joints_deg is not None:
                via_deg = max(via_deg, float(np.abs(q_ctrl[window] - np.asarray(m.joints_deg)).max(axis=1).min()))
            elif m.T_base_tcp is not None and m.T_flange_tcp is not None:
                p = physical_tcp(plan, m)[:3, 3]
                via_mm = max(via_mm, float(np.linalg.norm(path[window][:, :3, 3] - p, axis=1).min()) * 1e3)
    return Deviation(dialect, len(found), tcp_mm, tcp_deg, spot_mm, joint_deg, via_deg, via_mm, worst,
                     tuple(configs), run.issues)


def main_file(plan: Plan, dialect: str) -> Path:
    want = f"{plan.name}{MAIN_FILE[dialect]}"
    return next((p for p in plan.folder.iterdir() if p.name.lower() == want.lower()), plan.folder / want)
