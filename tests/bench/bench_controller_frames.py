"""Per arm and dialect, how far the motion each controller executes is from the plan (a script, not
a test).

    python tests/bench/bench_controller_frames.py --quick [--out FILE.md]
    python tests/bench/bench_controller_frames.py --packages DIR [--arms a,b,...] [--out FILE.md]

For every arm: `import-urdf` it (ROS-Industrial support packages, with the MoveIt SRDF where one
exists; the shipped kr16, kr125 and ur10 are used as they are), generate a seeded panel cell around
it as a station places a robot (1.1 to 1.8 m off the cell origin, turned; about every second arm,
by its name's hash, on a riser tilted 2 deg), plan it and write every dialect (`plan --format all`:
plan_cell + publish, the programs proven by robomax's own readers before writing), then run each
written program through the independent controller models (tests/controller_model, written from
vendor documentation) and compare what they execute with the trajectory file (FK with pinocchio
from the URDF): the gun's real TCP at every weld (mm, deg: the flange at target · tool⁻¹ in force,
the user frame composed in, placed by the cell's placement and the controller's base), each joint
stop point (deg), and the configuration data.

The cell: four spots on the robot-side face of a sheet standing on a fixture plate, at 50-70 % of
the arm's reach in front of it (the row turned up to 25 deg about the robot's axis 1), at 5 % of
the reach above the shoulder (at least 0.2 m above the base); the plate is user frame 3..5 of the
program, the gun tool 1..4, position registers 40 and 41 for the FANUC setup program. The C-gun
(spot_gun_c) on arms reaching 1.4 m or more, the light gun below. Home: of the postures with J1,
J4, J6 = 0 and J5 = +-30, 60 or 90 deg, the collision-free one whose wrist point is nearest to
40 % of the reach in front of and 45 % above the shoulder.

Quick mode (CI; no network): the arms kept in tests/data/rosi (FANUC m20ia, ABB irb2400, KUKA
kr120) and the shipped kr16, kr125, ur10. Full mode also imports the arms of `FULL_ARMS` found
under --packages (a folder of checked-out ROS-Industrial support packages, e.g. filled with
`git --git-dir=<mirror> archive HEAD <pkg> | tar -x -C DIR`), or those --arms names.

CPU seconds of this process (time.process_time); OMP/BLAS pinned to one thread. Prints a table and
writes it as markdown to --out, with the findings: any weld more than 0.1 mm / 0.01 deg off, a
joint stop point more than 0.01 deg off, a configuration the data misnames, or a program a model
cannot run faithfully (its issues).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import math
import re
import sys
import tempfile
import time
import traceback
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "tests"))

from controller_model.world import (
    DIALECTS,
    Deviation,
    T_from,
    deviation,
    load_arm,
    read_plan,
    xyz_rpy,
)

from robomax_py.errors import RobomaxError

ROSI = REPO / "tests" / "data" / "rosi"
ROBOTS = REPO / "robomax_py" / "robots"
TOOLS = ROBOTS / "tools"
POS_TOL_MM = 0.1
ANGLE_TOL_DEG = 0.01
JOINT_TOL_DEG = 0.01
BIG_GUN_REACH_M = 1.4

# name -> (brand, source, SRDF): the URDF/xacro under tests/data/rosi ("rosi:") or a shipped robot
# folder ("shipped:"); the MoveIt SRDF whose disabled collision pairs the import takes ("" if none).
QUICK_ARMS: dict[str, tuple[str, str, str]] = {
    "m20ia": ("fanuc", "rosi:fanuc_m20ia_support/urdf/m20ia.xacro", ""),
    "irb2400": ("abb", "rosi:abb_irb2400_support/urdf/irb2400.xacro",
                "rosi:abb_irb2400_moveit_config/config/abb_irb2400.srdf"),
    "kr120r2500pro": ("kuka", "rosi:kuka_kr120_support/urdf/kr120r2500pro.xacro", ""),
    "kr16": ("kuka", "shipped:kr16", ""),
    "kr125": ("kuka", "shipped:kr125", ""),
    "ur10": ("ur", "shipped:ur10", ""),
}
# name -> (brand, source, SRDF) under --packages: ROS-Industrial support packages (abb, fanuc,
# fanuc_experimental, kuka_experimental, motoman, staubli, staubli_experimental, abb_experimental,
# universal_robot) and their MoveIt configurations' SRDFs.
_FANUC_SRDF = "moveit_cfgs/fanuc_{0}_moveit_config/config/fanuc_{0}.srdf"
FULL_ARMS: dict[str, tuple[str, str, str]] = {
    "irb120_3_58": ("abb", "abb_irb120_support/urdf/irb120_3_58.xacro",
                    "abb_irb120_moveit_config/config/abb_irb120_3_58.srdf"),
    "irb1600_6_12": ("abb", "abb_irb1600_support/urdf/irb1600_6_12.xacro",
                     "abb_irb1600_6_12_moveit_config/config/abb_irb1600_6_12.srdf"),
    "irb2400": ("abb", "abb_irb2400_support/urdf/irb2400.xacro", "abb_irb2400_moveit_config/config/abb_irb2400.srdf"),
    "irb4400l_30_243": ("abb", "abb_irb4400_support/urdf/irb4400l_30_243.xacro", ""),
    "irb4600_60_205": ("abb", "abb_irb4600_support/urdf/irb4600_60_205.xacro", ""),
    "irb6640_185_280": ("abb", "abb_irb6640_support/urdf/irb6640_185_280.xacro",
                        "abb_irb6640_moveit_config/config/abb_irb6640_185_280.srdf"),
    "m10ia": ("fanuc", "fanuc_m10ia_support/urdf/m10ia.xacro", _FANUC_SRDF.format("m10ia")),
    "m16ib20": ("fanuc", "fanuc_m16ib_support/urdf/m16ib20.xacro", _FANUC_SRDF.format("m16ib20")),
    "m20ia": ("fanuc", "fanuc_m20ia_support/urdf/m20ia.xacro", _FANUC_SRDF.format("m20ia")),
    "lrmate200ic": ("fanuc", "fanuc_lrmate200ic_support/urdf/lrmate200ic.xacro", _FANUC_SRDF.format("lrmate200ic")),
    "lrmate200id": ("fanuc", "fanuc_lrmate200id_support/urdf/lrmate200id.xacro", _FANUC_SRDF.format("lrmate200id")),
    "r2000ib210f": ("fanuc", "fanuc_r2000ib_support/urdf/r2000ib210f.xacro", ""),
    "m900ia260l": ("fanuc", "fanuc_m900ia_support/urdf/m900ia260l.xacro", ""),
    "kr5_arc": ("kuka", "kuka_kr5_support/urdf/kr5_arc.xacro", ""),
    "kr6r900sixx": ("kuka", "kuka_kr6_support/urdf/kr6r900sixx.xacro", ""),
    "kr10r1420": ("kuka", "kuka_kr10_support/urdf/kr10r1420.xacro", ""),
    "kr16_2": ("kuka", "kuka_kr16_support/urdf/kr16_2.xacro", ""),
    "kr120r2500pro": ("kuka", "kuka_kr120_support/urdf/kr120r2500pro.xacro", ""),
    "kr150_2": ("kuka", "kuka_kr150_support/urdf/kr150_2.xacro", ""),
    "kr210l150": ("kuka", "kuka_kr210_support/urdf/kr210l150.xacro", ""),
    "gp7": ("yaskawa", "motoman_gp7_support/urdf/gp7.xacro", ""),
    "gp12": ("yaskawa", "motoman_gp12_support/urdf/gp12.xacro", ""),
    "gp25": ("yaskawa", "motoman_gp25_support/urdf/gp25.xacro", ""),
    "gp180": ("yaskawa", "motoman_gp180_support/urdf/gp180.xacro", ""),
    "tx60": ("staubli", "staubli_tx60_support/urdf/tx60.xacro", ""),
    "rx160": ("staubli", "staubli_rx160_support/urdf/rx160.xacro", "staubli_rx160_moveit_config/config/staubli_rx160.srdf"),
    "ur5": ("ur", "ur_description/urdf/ur5.xacro", "ur5_moveit_config/config/ur5.srdf"),
    "ur10_rosi": ("ur", "ur_description/urdf/ur10.xacro", "ur10_moveit_config/config/ur10.srdf"),
}


def cpu() -> float:
    return time.process_time()


# ---------------------------------------------------------------------------------------- the arm
@dataclass
class Row:
    arm: str
    brand: str
    source: str
    imported: str = ""
    solver: str = ""
    reach_m: float = math.nan
    import_cpu_s: float = math.nan
    placement: str = ""
    tool: str = ""
    planned: str = ""
    cycle_s: float = math.nan
    plan_cpu_s: float = math.nan
    judge_cpu_s: float = math.nan
    dialects: dict[str, Deviation | str] = field(default_factory=dict)


def _located(given: str, packages: Path | None) -> Path | None:
    kind, _, rel = given.partition(":")
    if kind == "rosi":
        return ROSI / rel
    return packages / given if packages else None


# Values for launch arguments a support package's launch file requires without a default, as a user
# gives them (`--xacro-arg NAME:=VALUE`): Motoman's `controller` picks the joint-velocity file of
# the controller generation (motoman_*_support/launch/load_*.launch: "dx100, dx200"); DX200 is the
# newer of the two the ES family's files name.
LAUNCH_CHOICES = {"controller": "dx200"}


def import_arm(name: str, source: str, srdf: str, packages: Path | None, library: Path, row: Row) -> Path | None:
    """robot.yaml of the arm: a shipped folder, or `import-urdf` of the source (with the SRDF's
    disabled pairs when one is given) into `library`.

    Link pairs whose convex hulls touch in every posture (an ABB wrist's link_4 hull holds link_6:
    robomax checks hulls, MoveIt's SRDFs were made with the meshes) are added to the SRDF as the
    MoveIt Setup Assistant adds pairs always in collision, and the arm imported again; the import
    column names them."""
    from robomax_py.app.import_urdf import import_urdf

    kind, _, rel = source.partition(":")
    if kind == "shipped":
        row.imported = "shipped"
        return ROBOTS / rel / "robot.yaml"
    path = _located(source, packages)
    if path is None or not path.is_file():
        row.imported = f"not found: {source}"
        return None
    srdf_path = _located(srdf, packages) if srdf else None
    if srdf_path is not None and not srdf_path.is_file():
        srdf_path = None
    roots = [ROSI] if kind == "rosi" else [packages] if packages else []
    added: list[tuple[str, str]] = []
    xacro_args: dict[str, str] = {}
    flange = "tool0"
    t0 = cpu()
    for _ in range(5):
        try:
            result = import_urdf(path, library / name, roots, srdf=srdf_path, force=True, xacro_args=xacro_args,
                                 flange=flange)
        except (RobomaxError, LookupError) as exc:
            # A launch argument the package's launch file requires and does not default (Motoman's
            # `controller`, which picks the joint-velocity file): given as a user would give it.
            needed = re.search(r"the launch argument (\w+) has no default", str(exc))
            if needed and needed[1] in LAUNCH_CHOICES and needed[1] not in xacro_args:
                xacro_args[needed[1]] = LAUNCH_CHOICES[needed[1]]
                continue
            # No `tool0` (older Motoman packages end their chain at link_t): the chain's last link,
            # as a user names it with --flange.
            links = re.search(r"the URDF has no frame 'tool0' \(links: ([^)]*)\)", str(exc))
            if links and flange == "tool0":
                names = [n.strip() for n in links[1].split(",") if n.strip() and not n.strip().endswith("…")]
                tips = [n for n in names if re.fullmatch(r"link_(\d+_)?t", n)]
                if tips:
                    flange = tips[0]
                    continue
            row.import_cpu_s = cpu() - t0
            row.imported = f"failed: {one_line(exc)}"
            return None
        except Exception as exc:  # noqa: BLE001 -- an importer crash is a finding, reported with its place
            row.import_cpu_s = cpu() - t0
            tb = traceback.extract_tb(exc.__traceback__)[-1]
            row.imported = f"crashed: {type(exc).__name__}: {one_line(exc, 80)} ({Path(tb.filename).name}:{tb.lineno})"
            return None
        pair = always_in_contact(result.folder / "robot.yaml", library)
        if pair is None:
            break
        added.append(pair)
        srdf_path = with_disabled_pairs(srdf_path, added, library / f"{name}_always.srdf", name)
    row.import_cpu_s = cpu() - t0
    row.imported = "ok" + (" (SRDF)" if srdf and srdf_path else "") + \
        (f" (+ always touching: {', '.join('/'.join(p) for p in added)})" if added else "") + \
        "".join(f" (--xacro-arg {k}:={v})" for k, v in xacro_args.items()) + \
        (f" (--flange {flange})" if flange != "tool0" else "")
    return result.folder / "robot.yaml"


def always_in_contact(robot_yaml: Path, scratch: Path) -> tuple[str, str] | None:
    """A pair of the arm's links in contact in at least 95 % of 60 seeded benign postures, or None."""
    from collections import Counter

    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.io.robot import load_robot_spec
    from robomax_py.robot import load_robot
    from robomax_py.world.collision import KIND_LINK, CollisionWorld
    from robomax_py.world.scene import build_scene

    # Home inside the limits for any number of joints (zero where the limits allow it).
    arm = load_robot(load_robot_spec(robot_yaml))
    home = np.degrees(np.clip(0.0, arm.limits.lower, arm.limits.upper)).round(6).tolist()
    cell_path = scratch / "_self_check.yaml"
    cell_path.write_text(yaml.safe_dump({
        "robomax": 1, "robot": {"model": str(robot_yaml), "home": home}, "tool": "spot_gun_light",
        "objects": [], "seams": [{"name": "a", "spots": [{"name": "s", "xyz": [1, 0, 1], "normal": [-1, 0, 0],
                                                          "direction": [0, 1, 0]}]}],
        "process": {"weld_time": 0.3, "approach": 0.03, "clearance": 0.0}}), encoding="utf-8")
    cell = load_cell(cell_path)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), 0.0)
    # Benign postures (shoulder and elbow within 30 deg of zero, the wrist bent 30 to 90 deg), where
    # no two links of an arm touch unless their hulls always do.
    rng = np.random.default_rng(0)
    qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(60, robot.dof))
    if robot.dof >= 5:                    # an arm; a positioner's few axes are taken as drawn
        qs[:, 1:3] = rng.uniform(-np.radians(30), np.radians(30), size=(60, 2))
        qs[:, 4] = rng.choice([-1.0, 1.0], size=60) * rng.uniform(np.radians(30), np.radians(90), size=60)
    qs = np.clip(qs, robot.limits.lower, robot.limits.upper)
    seen: Counter[tuple[str, str]] = Counter()
    for q in qs:
        c = world.first_contact(q)
        if c is not None and c.kind_a == KIND_LINK and c.kind_b == KIND_LINK:
            seen[(c.body_a, c.body_b)] += 1
    if not seen:
        return None
    pair, count = seen.most_common(1)[0]
    return pair if count >= 0.95 * len(qs) else None


def with_disabled_pairs(srdf: Path | None, pairs: list[tuple[str, str]], out: Path, name: str) -> Path:
    """An SRDF with the given one's disable_collisions and `pairs` (reason "Always")."""
    import xml.etree.ElementTree as ET

    root = ET.parse(srdf).getroot() if srdf is not None else ET.Element("robot", name=name)
    have = {(e.get("link1"), e.get("link2")) for e in root.iter("disable_collisions")}
    for a, b in pairs:
        if (a, b) not in have and (b, a) not in have:
            ET.SubElement(root, "disable_collisions", link1=a, link2=b, reason="Always")
    out.write_text(ET.tostring(root, encoding="unicode"), encoding="utf-8")
    return out


def one_line(exc: BaseException, width: int = 140) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= width else text[:width - 1] + "…"


# --------------------------------------------------------------------------------------- the cell
@dataclass(frozen=True)
class ArmShape:
    reach_m: float               # the flange's largest distance from the axis-1 line
    shoulder_z_m: float          # axis 2 above the URDF root at zero
    homes_deg: tuple[tuple[float, ...], ...]   # home candidates, best first


def arm_shape(robot_yaml: Path, joints: list[str], lower: np.ndarray, upper: np.ndarray,
              rng: np.random.Generator) -> ArmShape:
    """Reach, shoulder height and home candidates from the URDF (pinocchio FK via the models' arm):
    postures with J1, J4, J6 at 0 and J5 off the wrist singularity, the flange above the shoulder,
    nearest first to a ready point 40 % of the reach in front of and 45 % above the shoulder."""
    arm = load_arm(robot_yaml, TOOLS / "spot_gun_light" / "tool.yaml", joints)
    qs = rng.uniform(lower, upper, size=(1500, len(joints)))
    reach = max(float(np.linalg.norm(arm.flange(q)[:2, 3])) for q in qs)
    axes = arm.axes(np.zeros(len(joints)))
    shoulder = float(axes[1][0][2])
    ready = np.array([0.4 * reach, 0.0, shoulder + 0.45 * reach])
    scored: list[tuple[float, tuple[float, ...]]] = []
    grid = np.arange(-135.0, 136.0, 15.0)
    for j2 in grid:
        for j3 in grid:
            for j5 in (30.0, -30.0, 60.0, -60.0, 90.0, -90.0):
                deg = np.zeros(len(joints))
                deg[1], deg[2], deg[4] = j2, j3, j5
                q = np.radians(deg)
                if np.any(q < lower) or np.any(q > upper):
                    continue
                wrist = arm.axes(q)[4][0]
                if arm.flange(q)[2, 3] < shoulder:        # the flange above the shoulder: out of the cell's way
                    continue
                scored.append((float(np.linalg.norm(wrist - ready)) + 0.001 * abs(j5), tuple(float(v) for v in deg)))
    scored.sort()
    return ArmShape(reach, shoulder, tuple(h for _, h in scored))


def free_home(cell_path: Path, candidates: tuple[tuple[float, ...], ...]) -> tuple[float, ...] | None:
    """The first home candidate the cell's collision world (robot, gun, objects) finds free."""
    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.world.collision import CollisionWorld
    from robomax_py.world.scene import build_scene

    cell = load_cell(cell_path)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    for home in candidates:
        if world.first_contact(np.radians(home)) is None:
            return home
    return None


def panel_cell(name: str, robot_yaml: Path, shape: ArmShape, arm: str, seed: int) -> tuple[dict[str, Any], str, str]:
    """The cell file (a dict), a description of the placement, and the tool's name; seeded by the
    seed and the arm's name, so that an arm gets the same cell whichever arms run with it."""
    key = zlib.crc32(arm.encode())
    rng = np.random.default_rng([seed, key])
    R = shape.reach_m
    tool = "spot_gun_c" if R >= BIG_GUN_REACH_M else "spot_gun_light"
    d = rng.uniform(0.5, 0.7) * R
    turn = rng.uniform(-25.0, 25.0)
    zs = max(shape.shoulder_z_m + 0.05 * R, 0.2)     # a table-top arm (UR5): room for the plate and its stand
    pitch = float(np.clip(0.06 * R, 0.05, 0.1))
    riser = key % 2 == 1
    riser_h = float(rng.uniform(0.3, 0.5)) if riser else 0.0
    # Everything in the robot's URDF root frame first, then placed with the robot (G).
    W = T_from((0, 0, 0), (0, 0, turn))                     # the row's frame: x away from the robot
    plate_top = zs - 0.11
    local: list[tuple[str, list[float], np.ndarray, bool]] = [
        ("fixture_plate", [0.3, 4 * pitch + 0.3, 0.03], W @ T_from((d + 0.05, 0, plate_top - 0.015)), False),
        ("panel_flange", [0.002, 4 * pitch + 0.1, 0.12], W @ T_from((d + 0.001, 0, zs - 0.05)), True),
    ]
    stand_h = plate_top - 0.03 + riser_h
    local.append(("stand", [0.12, 0.12, stand_h], W @ T_from((d + 0.1, 0, plate_top - 0.03 - stand_h / 2)), False))
    if riser:
        local.append(("riser", [0.7, 0.7, riser_h], T_from((0, 0, -riser_h / 2 - 0.002)), False))
    r_off = rng.uniform(1.1, 1.8)
    phi = rng.uniform(0, 360)
    yaw = rng.uniform(-180, 180)
    xy = (r_off * math.cos(math.radians(phi)), r_off * math.sin(math.radians(phi)))
    G = T_from((xy[0], xy[1], riser_h), (2.0 if riser else 0.0, 0.0, yaw))
    objects = []
    for obj_name, box, T, workpiece in local:
        entry: dict[str, Any] = {"name": obj_name, "box": [round(v, 4) for v in box], "pose": xyz_rpy(G @ T)}
        if workpiece:
            entry["workpiece"] = True
        objects.append(entry)
    spots = []
    for k in range(4):
        y = (k - 1.5) * pitch + rng.uniform(-0.004, 0.004)
        p = G @ W @ np.array([d, y, zs + rng.uniform(-0.004, 0.004), 1.0])
        n = G[:3, :3] @ W[:3, :3] @ np.array([-1.0, 0.0, 0.0])
        t = G[:3, :3] @ W[:3, :3] @ np.array([0.0, 1.0, 0.0])
        spots.append({"name": f"s{k + 1}", "xyz": [round(float(v), 6) for v in p[:3]],
                      "normal": [round(float(v), 9) for v in n], "direction": [round(float(v), 9) for v in t]})
    cell = {
        "robomax": 1,
        "name": name,
        "robot": {"model": str(robot_yaml), "base": xyz_rpy(G), "home": [round(v, 3) for v in shape.homes_deg[0]],
                  "controller": {"tool": {"number": int(rng.integers(1, 5))},
                                 "frame": {"number": int(rng.integers(3, 6)), "object": "fixture_plate"},
                                 "registers": {"position": [40, 41]}}},
        "tool": tool,
        "objects": objects,
        "seams": [{"name": "panel", "ordered": False, "tolerance": {"alpha": 10, "beta": 10, "gamma": [-180, 180]},
                   "grid": 3, "spots": spots}],
        "process": {"weld_time": 0.3, "approach": 0.03, "clearance": 0.0},
        "planner": {"seed": seed},
    }
    where = f"{r_off:.2f} m, yaw {yaw:.0f}°" + (f", riser {riser_h:.2f} m tilted 2°" if riser else "")
    return cell, where, tool


# --------------------------------------------------------------------------------------- one arm
def bench_arm(name: str, brand: str, source: str, srdf: str, args: argparse.Namespace, tmp: Path) -> Row:
    from robomax_py.export import choose_formats
    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.io.robot import load_robot_spec
    from robomax_py.plan import plan_cell
    from robomax_py.publish import publish
    from robomax_py.robot import load_robot

    row = Row(name, brand, source)
    robot_yaml = import_arm(name, source, srdf, args.packages, tmp / "robots", row)
    if robot_yaml is None:
        return row
    try:
        robot = load_robot(load_robot_spec(robot_yaml))
    except RobomaxError as exc:
        row.imported = f"failed to load: {one_line(exc)}"
        return row
    row.solver = robot.ik_solver
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    shape = arm_shape(robot_yaml, list(robot.joint_names), lower, upper, np.random.default_rng(args.seed))
    row.reach_m = shape.reach_m
    cell_data, row.placement, row.tool = panel_cell(f"{name}_panel", robot_yaml, shape, name, args.seed)
    folder = tmp / "cells" / name
    folder.mkdir(parents=True)
    cell_path = folder / f"{name}_panel.yaml"
    cell_path.write_text(yaml.safe_dump(cell_data, sort_keys=False), encoding="utf-8")
    home = free_home(cell_path, shape.homes_deg)
    if home is None:
        row.planned = f"no collision-free home among {len(shape.homes_deg)} candidates"
        return row
    cell_data["robot"]["home"] = [round(v, 3) for v in home]
    cell_path.write_text(yaml.safe_dump(cell_data, sort_keys=False), encoding="utf-8")
    out = folder / "programs"
    out.mkdir()
    t0 = cpu()
    try:
        cell = load_cell(cell_path)
        result = plan_cell(cell, load_cell_robot(cell))
        if result.status != "planned":
            row.plan_cpu_s = cpu() - t0
            row.planned = f"{result.status}: {one_line(Exception(result.message), 120)}"
            return row
        robot = load_cell_robot(cell)
        written = choose_formats("all", robot).names
        files, _ = publish(result, cell, robot, written)
    except RobomaxError as exc:
        row.plan_cpu_s = cpu() - t0
        row.planned = f"failed: {one_line(exc)}"
        return row
    row.plan_cpu_s = cpu() - t0
    row.planned = "planned"
    row.cycle_s = result.cycle_time
    for file_name, text in files.items():
        (out / file_name).write_text(text, encoding="utf-8")
    t0 = cpu()
    plan = read_plan(cell_path, out, result.cell)
    for dialect in DIALECTS:
        if dialect not in written:       # INFORM on an arm whose robot.yaml states no pulses: "—"
            continue
        try:
            row.dialects[dialect] = deviation(plan, dialect)
        except (AssertionError, KeyError, FileNotFoundError) as exc:
            row.dialects[dialect] = f"n/a: {one_line(exc, 100)}"
    row.judge_cpu_s = cpu() - t0
    if args.keep:
        print(f"  kept {folder}", flush=True)
    return row


# ----------------------------------------------------------------------------------------- report
def cell_text(dev: Deviation | str | None) -> str:
    if dev is None:
        return "—"
    if isinstance(dev, str):
        return dev
    if dev.issues:
        first = dev.issues[0]
        return f"n/a: {first.kind} at {first.where.source}:{first.where.line} ({first.reason})"
    return f"{dev.tcp_mm:.1e} / {dev.tcp_deg:.1e} / {dev.joint_deg:.1e}"


def number(v: float, fmt: str) -> str:
    return "—" if math.isnan(v) else format(v, fmt)


def findings(rows: list[Row]) -> list[str]:
    out = []
    for row in rows:
        for dialect, dev in row.dialects.items():
            if isinstance(dev, str):
                out.append(f"{row.arm} {dialect}: {dev}")
                continue
            for issue in dev.issues:
                out.append(f"{row.arm} {dialect}: model {issue.kind} at {issue.where.source}:{issue.where.line}: "
                           f"{issue.reason} (`{issue.text}`)")
            if dev.tcp_mm > POS_TOL_MM or dev.tcp_deg > ANGLE_TOL_DEG or dev.spot_mm > POS_TOL_MM:
                out.append(f"{row.arm} {dialect}: weld TCP {dev.tcp_mm:.4f} mm / {dev.tcp_deg:.5f} deg from the plan, "
                           f"{dev.spot_mm:.4f} mm from the spot (worst {dev.worst})")
            if dev.joint_deg > JOINT_TOL_DEG:
                out.append(f"{row.arm} {dialect}: a joint stop point {dev.joint_deg:.4f} deg off the trajectory")
            out.extend(f"{row.arm} {dialect}: configuration {c}" for c in dev.configs)
    return out


def render(rows: list[Row], command: str, total_cpu_s: float) -> str:
    head = ["arm", "brand", "import", "IK solver", "reach m", "placement", "tool", "plan", "cycle s", "CPU s",
            *[f"{d} mm / deg / joint deg" for d in DIALECTS]]
    lines = [f"Command: `{command}`", "",
             (f"Total CPU {total_cpu_s:.1f} s (this process, time.process_time). Per dialect: the largest "
             "deviation of the gun's real TCP at a weld from the planned TCP (mm / deg), and of a joint stop "
             "point from the trajectory (deg), as the independent controller model runs the written program. "
             "CPU s = import + plan + write (proven) + judge."), "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        total = sum(v for v in (r.import_cpu_s, r.plan_cpu_s, r.judge_cpu_s) if not math.isnan(v))
        cells = [r.arm, r.brand, r.imported, r.solver or "—", number(r.reach_m, ".2f"), r.placement or "—",
                 r.tool or "—", r.planned or "—", number(r.cycle_s, ".2f"), f"{total:.1f}",
                 *[cell_text(r.dialects.get(d)) for d in DIALECTS]]
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    lines += ["", "Blends (not errors): closest approach of the trajectory to blended via points, max over dialects.", "",
              "| arm | via joint deg | via TCP mm | weld TCP from spot mm | welds |", "|---|---|---|---|---|"]
    for r in rows:
        devs = [d for d in r.dialects.values() if isinstance(d, Deviation)]
        if devs:
            lines.append(f"| {r.arm} | {max(d.via_deg for d in devs):.3f} | {max(d.via_mm for d in devs):.2f} | "
                         f"{max(d.spot_mm for d in devs):.1e} | {devs[0].welds} |")
    found = findings(rows)
    lines += ["", (f"Findings (weld > {POS_TOL_MM} mm / {ANGLE_TOL_DEG} deg, joint stop > {JOINT_TOL_DEG} deg, "
              "configuration misnamed, model issues):"), ""]
    lines += [f"- {f}" for f in found] or ["- none"]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="only the arms kept in the repository (CI)")
    parser.add_argument("--packages", type=Path, help="folder of ROS-Industrial support packages (full mode)")
    parser.add_argument("--arms", help="comma-separated arm names to run (default: all of the mode)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, help="also write the table as markdown here")
    parser.add_argument("--keep", action="store_true", help="keep the generated cells and programs")
    args = parser.parse_args()
    if not args.quick and args.packages is None:
        parser.error("give --packages DIR (full mode) or --quick")
    arms = dict(QUICK_ARMS)
    if not args.quick:
        arms.update({k: v for k, v in FULL_ARMS.items() if k not in arms})
    if args.arms:
        wanted = [a.strip() for a in args.arms.split(",") if a.strip()]
        unknown = [a for a in wanted if a not in arms]
        if unknown:
            parser.error(f"unknown arm(s) {unknown}; known: {', '.join(arms)}")
        arms = {a: arms[a] for a in wanted}
    t_start = cpu()
    tmp = Path(tempfile.mkdtemp(prefix="bench_frames_")) if args.keep else None
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_frames_") as scratch:
        root = tmp or Path(scratch)
        for name, (brand, source, srdf) in arms.items():
            print(f"{name}: ", end="", flush=True)
            try:
                row = bench_arm(name, brand, source, srdf, args, root)
            except Exception as exc:  # noqa: BLE001 -- a crash of one arm is a finding, not the end of the table
                traceback.print_exc()
                row = Row(name, brand, source, imported="crashed", planned=f"crashed: {one_line(exc)}")
            rows.append(row)
            print(f"{row.imported}; {row.planned or '-'}; " +
                  ", ".join(f"{d} {cell_text(v)}" for d, v in row.dialects.items()), flush=True)
    command = "python tests/bench/bench_controller_frames.py " + " ".join(sys.argv[1:])
    text = render(rows, command, cpu() - t_start)
    print()
    print(text)
    if args.out:
        args.out.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
