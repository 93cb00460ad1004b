"""robot.yaml and tool.yaml (docs/cell-files.md, "The robot folder" and "The tool folder") -> checked RobotSpec / ToolSpec.

Owns the keys of those two files. A robot or tool is named either by folder name (looked up in the
robot library path: `--robots` folders, then `ROBOMAX_ROBOTS`, then the shipped library) or by a
path, relative to the file that names it.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from robomax_py._typing import FloatArray
from robomax_py.errors import RobotModelError
from robomax_py.io.yaml_files import read_yaml_mapping, validation_error
from robomax_py.safe_files import LIMITS, checked_file, named_by, read_text
from robomax_py.spec import (
    ControllerSpec,
    JointLoadLimits,
    RobotSpec,
    ToolSpec,
    frozen_array,
)
from robomax_py.transforms import pose_matrix
from robomax_py.units import degs_to_rads

Finite = Annotated[float, Field(allow_inf_nan=False)]
Vec3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
LinkName = Annotated[str, Field(min_length=1)]

# Robot library folders searched before the shipped one, separated like PATH.
ROBOTS_ENV = "ROBOMAX_ROBOTS"
# Folders a `package://NAME/...` mesh is looked for below (ROS convention).
ROS_PACKAGE_PATH_ENV = "ROS_PACKAGE_PATH"
# How deep below the robot folder's parents and ROS_PACKAGE_PATH entries a folder named NAME is
# looked for: deep enough for a checkout of a ROS-Industrial repository next to the robot folder.
PACKAGE_SEARCH_DEPTH = 3
PACKAGE_SEARCH_PARENTS = 3


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class PoseFile(_Strict):
    xyz: Vec3 = [0.0, 0.0, 0.0]
    rpy: Vec3 = [0.0, 0.0, 0.0]               # deg


class IkFile(_Strict):
    solver: str
    # Optional for opw and ur: fitted from the URDF's joint origins and axes when absent.
    params: dict[str, Any] | None = None


def _all_positive(v: list[float]) -> list[float]:
    # Positive, and neither so small that a duration overflows nor so large that it is a placeholder.
    if any(x <= 0 for x in v):
        raise ValueError(f"every value must be > 0, got {v}")
    if any(not 1e-3 <= x <= 1e9 for x in v):
        raise ValueError(f"every value must lie in [1e-3, 1e9] (deg/s, deg/s^2, deg/s^3; m for a prismatic joint), got {v}")
    return v


class LoadedLimitsFile(_Strict):
    """Joint limits carrying the rated payload (`payload`), deg/s, deg/s^2, deg/s^3."""

    velocity: list[Finite]
    acceleration: list[Finite]
    jerk: list[Finite]

    @field_validator("velocity", "acceleration", "jerk")
    @classmethod
    def _positive(cls, v: list[float]) -> list[float]:
        return _all_positive(v)


class LimitsFile(_Strict):
    acceleration: list[Finite] | None = None  # deg/s^2 (m/s^2 for a prismatic joint)
    jerk: list[Finite] | None = None          # deg/s^3
    loaded: LoadedLimitsFile | None = None    # extension: with the rated payload at the flange

    @field_validator("acceleration", "jerk")
    @classmethod
    def _positive(cls, v: list[float] | None) -> list[float] | None:
        return None if v is None else _all_positive(v)


class ControllerFile(_Strict):
    """docs/cell-files.md, "Controller programs": the controller's brand (its configuration data and native dialect) and base frame.

    `base` is the controller's base frame in the URDF root frame. Absent, it is the pose of the
    URDF's ROS-Industrial `base` link when fixed joints alone attach that link to the root
    (`urdf_base_link`), else the identity; given (an identity too), it is used as written.
    """

    brand: Literal["kuka", "abb", "fanuc", "ur", "yaskawa", "kawasaki", "staubli", "comau", "nachi"] = "kuka"
    j23_coupling: bool = False                # FANUC: J3 counted from the horizontal
    # Yaskawa: encoder pulses per degree of each axis (the controller's pulse/degree parameters),
    # which INFORM joint positions are counted in; None: joint moves go to Cartesian positions.
    pulses_per_degree: list[float] | None = None

    @field_validator("pulses_per_degree")
    @classmethod
    def _pulses(cls, v: list[float] | None) -> list[float] | None:
        if v is not None and (len(v) != 6 or any(not math.isfinite(x) or x == 0 for x in v)):
            raise ValueError("expected 6 non-zero numbers (negative where the axis counts the other way)")
        return v
    base: PoseFile | None = None              # None: the URDF's `base` link, else identity
    # Each joint's direction and zero as the controller counts it: controller value (deg) =
    # joint_signs[i] * URDF value (deg) + joint_zeros_deg[i]. None: the URDF's own (signs +1, zeros 0).
    joint_signs: list[int] | None = None
    joint_zeros_deg: list[float] | None = None

    @field_validator("joint_signs")
    @classmethod
    def _signs(cls, v: list[int] | None) -> list[int] | None:
        if v is not None and (not v or any(isinstance(x, bool) or x not in (1, -1) for x in v)):
            raise ValueError("expected one +1 or -1 per joint")
        return v

    @field_validator("joint_zeros_deg")
    @classmethod
    def _zeros(cls, v: list[float] | None) -> list[float] | None:
        if v is not None and (not v or any(not math.isfinite(x) for x in v)):
            raise ValueError("expected one finite number (deg) per joint")
        return v


class CollisionFile(_Strict):
    disable: list[Annotated[list[LinkName], Field(min_length=2, max_length=2)]] = []


class RobotFile(_Strict):
    name: str
    urdf: str
    flange: str
    ik: IkFile
    limits: LimitsFile = LimitsFile()
    # Extensions of docs/cell-files.md, "The robot folder", all optional.
    controller: ControllerFile = ControllerFile()
    collision: CollisionFile = CollisionFile()
    srdf: str | None = None                   # MoveIt SRDF whose disable_collisions are honoured
    payload: Annotated[float, Field(gt=0, allow_inf_nan=False)] | None = None   # kg, for listings
    description: str = ""


class ToolFile(_Strict):
    name: str
    body: str
    tips: str
    tcp: PoseFile = PoseFile()


# ------------------------------------------------------------------------------ the library path


def shipped_robots_dir() -> Path:
    """The robot library shipped inside the package (package data)."""
    return Path(__file__).resolve().parent.parent / "robots"


def robot_library() -> tuple[Path, ...]:
    """Folders searched for robots/tools by name, first match wins: ROBOMAX_ROBOTS entries, then shipped.

    The CLI's `--robots DIR` options are put in front of ROBOMAX_ROBOTS, so batch workers inherit them.
    """
    extra = [Path(p).expanduser() for p in os.environ.get(ROBOTS_ENV, "").split(os.pathsep) if p.strip()]
    out: list[Path] = []
    for d in [*extra, shipped_robots_dir()]:
        if d not in out:
            out.append(d)
    return tuple(out)


def resolve_robot_file(ref: str, relative_to: Path) -> Path:
    """A cell's `robot.model`: a folder name in the library path, or a path to a robot.yaml."""
    return _resolve(ref, relative_to, (), "robot.yaml")


def resolve_tool_file(ref: str, relative_to: Path) -> Path:
    """A cell's `tool`: a folder name in the library path's `tools/`, or a path to a tool.yaml."""
    return _resolve(ref, relative_to, ("tools",), "tool.yaml")




def _resolve(ref: str, relative_to: Path, sub: tuple[str, ...], filename: str) -> Path:
    looks_like_path = "/" in ref or "\\" in ref or ref.endswith((".yaml", ".yml"))
    if not looks_like_path:
        candidates = [Path(d, *sub, ref, filename) for d in robot_library()]
        return next((c for c in candidates if _is(c, Path.is_file)), candidates[-1])
    path = relative_to.parent / ref
    return path / filename if _is(path, Path.is_dir) else path


def _is(path: Path, test: Any) -> bool:
    """`path.is_file()` / `is_dir()` that says False for paths the OS refuses (too long, a loop);
    the guard then names the problem when the file is opened."""
    try:
        return bool(test(path))
    except (OSError, ValueError, RuntimeError):
        return False


# ------------------------------------------------------------------------------ package:// meshes


def package_share_dirs() -> list[Path]:
    """`share` folders of installed packages, for URDFs naming meshes as package://<pkg>/...

    example-robot-data installs under <site-packages>/cmeel.prefix/share; we locate it through the
    installed distribution's file list rather than guessing a path.
    """
    from importlib import metadata

    dirs: list[Path] = []
    try:
        files = metadata.files("example-robot-data") or []
    except metadata.PackageNotFoundError:
        files = []
    for f in files:
        parts = Path(str(f)).parts
        if "share" in parts and "example-robot-data" in parts:
            idx = parts.index("share")
            located = Path(str(f.locate())).resolve()
            share = located.parents[len(parts) - idx - 2]
            dirs.append(share)
            break
    return dirs


def package_dirs_for(name: str, near: Path) -> list[Path]:
    """Folders P such that P/name is the ROS package `name`, best first.

    Searched: the folder `near` and its parents (one of them named `name`, or holding a folder of
    that name), folders named `name` up to PACKAGE_SEARCH_DEPTH levels below `near`'s first
    PACKAGE_SEARCH_PARENTS parents, then each ROS_PACKAGE_PATH entry (and below it), then the
    installed packages' share folders.
    """
    found: list[Path] = []

    def add(p: Path) -> None:
        if (p / name).is_dir() and p not in found:
            found.append(p)

    near = near.resolve()
    ancestors = [near, *near.parents]
    for a in ancestors:
        if a.name == name:
            add(a.parent)
        add(a)
    for a in ancestors[:PACKAGE_SEARCH_PARENTS + 1]:
        for hit in _folders_named(a, name, PACKAGE_SEARCH_DEPTH):
            add(hit.parent)
    for entry in os.environ.get(ROS_PACKAGE_PATH_ENV, "").split(os.pathsep):
        if not entry.strip():
            continue
        root = Path(entry).expanduser()
        if root.name == name:
            add(root.parent)
        add(root)
        for hit in _folders_named(root, name, PACKAGE_SEARCH_DEPTH):
            add(hit.parent)
    for share in package_share_dirs():
        add(share)
    return found


def _folders_named(root: Path, name: str, depth: int) -> list[Path]:
    """Folders called `name` at most `depth` levels below root (sorted, hidden folders skipped)."""
    out: list[Path] = []
    level = [root]
    for _ in range(depth):
        nxt: list[Path] = []
        for d in level:
            try:
                children = sorted(c for c in d.iterdir() if c.is_dir() and not c.name.startswith("."))
            except OSError:
                continue
            for c in children:
                (out if c.name == name else nxt).append(c)
        level = nxt
    return out


def resolve_package_uri(uri: str, file: Path, key: str, near: Path | None = None) -> Path:
    """package://<pkg>/<rest> -> an existing file, searched as `package_dirs_for` says."""
    rest = uri[len("package://"):]
    name, _, tail = rest.partition("/")
    for d in package_dirs_for(name, near if near is not None else file.parent):
        candidate = d / name / tail
        if candidate.exists():
            return candidate
    raise RobotModelError(file, key, f"{uri} not found (searched near {file.parent}, ROS_PACKAGE_PATH and installed packages)")


_PACKAGE_URI = re.compile(r"package://([^/\"']+)/")


def urdf_package_names(urdf_text: str) -> list[str]:
    """The ROS package names a URDF's mesh filenames use, in first-use order."""
    names: list[str] = []
    for m in _PACKAGE_URI.finditer(urdf_text):
        if m.group(1) not in names:
            names.append(m.group(1))
    return names


def urdf_package_dirs(urdf: Path, file: Path, text: str | None = None) -> tuple[Path, ...]:
    """Package folders for the `package://NAME/...` meshes a URDF names (searched near the URDF).

    Every mesh file the URDF names that exists is checked by the guard here (a regular file within
    the mesh size limit), so Pinocchio never opens a device, a pipe or a symlink loop. `text` is the
    URDF's text when the caller has read it already."""
    if text is None:
        text = read_text(urdf, LIMITS.urdf, named_by(RobotModelError, file, "urdf"), f"URDF {urdf}")
    dirs: list[Path] = []
    for name in urdf_package_names(text):
        for d in package_dirs_for(name, urdf.parent):
            if d not in dirs:
                dirs.append(d)
    for uri in _MESH_FILENAME.findall(text):
        for candidate in mesh_candidates(uri, urdf, dirs):
            if os.path.lexists(candidate):
                checked_file(candidate, LIMITS.mesh, named_by(RobotModelError, urdf, f"mesh {uri}"), f"mesh {candidate}")
                break
    return tuple(dirs)


_MESH_FILENAME = re.compile(r"<mesh[^>]*\sfilename\s*=\s*[\"']([^\"']*)[\"']")


def mesh_candidates(uri: str, urdf: Path, dirs: Sequence[Path]) -> list[Path]:
    """Where a URDF's mesh `filename` may be: package:// under each package folder, file://, or
    relative to the URDF."""
    if "\x00" in uri:
        return [Path(uri)]
    if uri.startswith("package://"):
        name, _, rest = uri[len("package://"):].partition("/")
        return [d / name / rest for d in dirs]
    if uri.startswith("file://"):
        return [Path(uri[len("file://"):])]
    return [urdf.parent / uri]


# ------------------------------------------------------------------------------ the `base` link

# The link ROS-Industrial support packages put at the vendor's own base frame, the origin of the
# controller's robot Cartesian coordinates: REP-199 (draft, "Coordinate Frames for Serial Industrial
# Manipulators", frame `base`), attached to `base_link` by the fixed joint `base_link-base`. At J2
# height on FANUC arms (fanuc_m20ia_support/urdf/m20ia_macro.xacro: "base_link to Fanuc World
# Coordinates transform", xyz 0 0 0.525), at `base_link` on ABB and KUKA arms, `base_link` turned
# 180 deg about z on UR arms (Universal Robots' ur_description, doc/robot_frames.rst).
ROS_INDUSTRIAL_BASE_LINK = "base"


def parse_urdf(text: str, urdf: Path) -> ET.Element:
    """The root element of a URDF's text; RobotModelError naming the file when it is not XML."""
    try:
        return ET.fromstring(text)
    except ET.ParseError as exc:
        raise RobotModelError(urdf, None, f"cannot parse URDF: {exc}") from None


def urdf_base_link(root: ET.Element, urdf: Path) -> FloatArray | None:
    """The pose of the URDF's link named `base` in its root link's frame, when only fixed joints
    lie between the two (ROS-Industrial's `base` link, the vendor's base frame).

    Parameters
    ----------
    root : Element
        The URDF's `<robot>` element.
    urdf : Path
        The URDF file, named in errors.

    Returns
    -------
    (4, 4) float or None
        The link's pose, metres, composed from the joints' `<origin>` (R = Rz(yaw) Ry(pitch) Rx(roll),
        the URDF convention); exactly the identity when every origin on the way is zero. None when
        the URDF has no link `base`, when a movable joint lies between it and the root (such a link
        moves with that joint, so it is no fixed frame of the controller), or when the link is not
        below the URDF's single root link (Pinocchio refuses such a URDF).

    Raises
    ------
    RobotModelError
        An `<origin>` on the way from the root is not three finite numbers for `xyz` or `rpy`.
    """
    links = {name for el in root.findall("link") if (name := el.get("name"))}
    if ROS_INDUSTRIAL_BASE_LINK not in links:
        return None
    parent_joint: dict[str, ET.Element] = {}
    for joint in root.findall("joint"):
        child = joint.find("child")
        name = None if child is None else child.get("link")
        if name:
            parent_joint.setdefault(name, joint)
    chain: list[ET.Element] = []
    link: str | None = ROS_INDUSTRIAL_BASE_LINK
    while link in parent_joint:
        joint = parent_joint[link]
        parent = joint.find("parent")
        if joint.get("type") != "fixed" or parent is None or len(chain) >= len(parent_joint):
            return None          # movable, malformed, or a loop
        chain.append(joint)
        link = parent.get("link")
    if links - set(parent_joint) != {link}:
        return None              # not below the single root link
    T: FloatArray = np.eye(4)
    for joint in reversed(chain):
        T = T @ _joint_origin(joint, urdf)
    return T


def _joint_origin(joint: ET.Element, urdf: Path) -> FloatArray:
    """A URDF joint's `<origin>`: the child link's frame in the parent link's, (4, 4), metres."""
    origin = joint.find("origin")
    values = []
    for key in ("xyz", "rpy"):
        text = "0 0 0" if origin is None else origin.get(key, "0 0 0")
        try:
            v = [float(x) for x in text.split()]
        except ValueError:
            v = []
        if len(v) != 3 or not all(math.isfinite(x) for x in v):
            raise RobotModelError(urdf, f"joint {joint.get('name')}: origin {key}", f"expected 3 finite numbers, got {text!r}")
        values.append(v)
    return pose_matrix(values[0], values[1])


# ------------------------------------------------------------------------------ URDF checks

# Joint limits outside these are refused at load as typos or unit mistakes (a velocity of 1e-300 in
# a URDF passed `check` and ended planning in an overflow): no industrial axis is slower than
# 0.06 deg/s or faster than 100 rad/s at full speed, no linear axis slower than 0.1 mm/s or faster
# than 10 m/s; a revolute joint's range stays within 8 turns either way, a prismatic one within 100 m.
JOINT_VELOCITY_RANGE = {"revolute": (1e-3, 100.0), "continuous": (1e-3, 100.0), "prismatic": (1e-4, 10.0)}
JOINT_POSITION_BOUND = {"revolute": 16 * math.pi, "prismatic": 100.0}
_VELOCITY_UNIT = {"revolute": "rad/s", "continuous": "rad/s", "prismatic": "m/s"}
_SHAPES = ("mesh", "box", "cylinder", "sphere", "capsule")


def check_urdf(root: ET.Element, urdf: Path) -> tuple[str, ...]:
    """The checks every robot's URDF passes at load (`load_robot_spec`, and `import-urdf` before it
    writes anything): at most LIMITS.urdf_links links and joints; each revolute or prismatic joint
    (but the passive `<mimic>` ones, whose limits are never used) with finite limits lower < upper within JOINT_POSITION_BOUND and a velocity within
    JOINT_VELOCITY_RANGE; collision geometry where the robot moves.

    Collision geometry: a URDF with `<visual>` but no `<collision>` geometry anywhere is refused
    (nothing could be checked for collisions); one without any geometry (a kinematic model) gets a
    warning. A moving body (the child link of a movable joint with the links fixed to it) without
    `<collision>` is refused when it has `<visual>` geometry (a shape that would pass through
    everything unseen); with no geometry at all it carries nothing (a frame between two joints) and
    gets a warning.

    Returns
    -------
    tuple of str
        Warnings, each naming the file and the link.

    Raises
    ------
    RobotModelError
        Naming the joint or link and the problem.
    """
    links = root.findall("link")
    joints = root.findall("joint")
    if max(len(links), len(joints)) > LIMITS.urdf_links:
        raise RobotModelError(urdf, None, f"{len(links)} links and {len(joints)} joints: more than the "
                              f"{LIMITS.urdf_links} allowed")
    for joint in joints:
        _check_joint_limits(joint, urdf)
    return _check_collision_geometry(links, joints, urdf)


def _urdf_number(element: ET.Element, attr: str, default: float | None, urdf: Path, key: str) -> float:
    text = element.get(attr)
    if text is None:
        if default is None:
            raise RobotModelError(urdf, key, f"<{element.tag}> needs the attribute {attr}")
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise RobotModelError(urdf, key, f"<{element.tag}> {attr}: expected a finite number, got {text!r}")
    return value


def _check_joint_limits(joint: ET.Element, urdf: Path) -> None:
    kind = joint.get("type", "")
    if kind not in JOINT_VELOCITY_RANGE:
        return
    if joint.find("mimic") is not None:
        # A passive joint follows the joint it mimics: its own limits are never used (packages
        # leave placeholders, abb_irb6700_support/urdf/irb6700_200_260_macro.xacro `piston_joint`
        # velocity="100" m/s), so they are not checked.
        return
    key = f"joint {joint.get('name')}"
    limit = joint.find("limit")
    if limit is None:
        if kind == "continuous":
            return
        raise RobotModelError(urdf, key, f"a {kind} joint needs <limit lower=.. upper=.. velocity=..>")
    velocity = _urdf_number(limit, "velocity", None, urdf, key)
    slowest, fastest = JOINT_VELOCITY_RANGE[kind]
    unit = _VELOCITY_UNIT[kind]
    if velocity <= 0:
        raise RobotModelError(urdf, key, f"limit velocity {velocity:g} {unit}: must be > 0")
    if not slowest <= velocity <= fastest:
        raise RobotModelError(urdf, key, f"limit velocity {velocity:g} {unit} is outside [{slowest:g}, {fastest:g}] "
                              f"{unit} (a typo or another unit?)")
    if kind == "continuous":
        return
    lower = _urdf_number(limit, "lower", 0.0, urdf, key)      # the URDF default for both is 0
    upper = _urdf_number(limit, "upper", 0.0, urdf, key)
    if lower > upper:
        raise RobotModelError(urdf, key, f"limit lower {lower:g} > upper {upper:g}")
    if lower == upper:
        raise RobotModelError(urdf, key, f"limit lower = upper = {lower:g}: the joint cannot move (make it fixed)")
    bound = JOINT_POSITION_BOUND[kind]
    if max(abs(lower), abs(upper)) > bound:
        raise RobotModelError(urdf, key, f"limits [{lower:g}, {upper:g}] go beyond ±{bound:g} "
                              f"{'rad' if kind == 'revolute' else 'm'} (a typo or another unit?)")


def _has_shape(link: ET.Element, tag: str) -> bool:
    return any(geometry.find(shape) is not None
               for el in link.findall(tag) for geometry in el.findall("geometry") for shape in _SHAPES)


def _check_collision_geometry(links: list[ET.Element], joints: list[ET.Element], urdf: Path) -> tuple[str, ...]:
    if not any(_has_shape(link, "collision") for link in links):
        if any(_has_shape(link, "visual") for link in links):
            raise RobotModelError(urdf, None, "no <collision> geometry at all, only <visual>: robomax could not check "
                                  "the robot for collisions (add <collision> elements; the visual meshes will do)")
        return (f"{urdf}: no geometry at all (a kinematic model): collisions of the arm are not checked",)
    parent_joint: dict[str, ET.Element] = {}
    child_of: dict[str, str] = {}
    for joint in joints:
        child = joint.find("child")
        if child is not None and child.get("link"):
            parent_joint.setdefault(str(child.get("link")), joint)
            child_of[str(joint.get("name"))] = str(child.get("link"))

    def moved_by(link: str) -> ET.Element | None:
        """The movable joint nearest above `link` (through fixed joints); None on the root body."""
        for _ in range(len(joints) + 1):
            joint = parent_joint.get(link)
            if joint is None:
                return None
            if joint.get("type") != "fixed":
                return joint
            parent = joint.find("parent")
            link = "" if parent is None else str(parent.get("link", ""))
        return None      # a loop: Pinocchio names it

    bodies: dict[str, list[ET.Element]] = {}
    for link in links:
        mover = moved_by(str(link.get("name", "")))
        if mover is not None:
            bodies.setdefault(str(mover.get("name")), []).append(link)
    warnings = []
    for joint_name, body in bodies.items():
        if any(_has_shape(link, "collision") for link in body):
            continue
        moving = child_of.get(joint_name, str(body[0].get("name")))
        if any(_has_shape(link, "visual") for link in body):
            raise RobotModelError(urdf, f"link {moving}", f"moves with joint {joint_name} and has <visual> but no "
                                  "<collision> geometry: it would pass through everything unseen (add a <collision>)")
        warnings.append(f"{urdf}: link {moving} moves with joint {joint_name} but has no geometry at all; "
                        "robomax takes it to carry nothing")
    return tuple(warnings)


# ------------------------------------------------------------------------------ SRDF


def srdf_disabled_pairs(path: Path, file: Path) -> list[tuple[str, str]]:
    """The `disable_collisions link1/link2` pairs of a MoveIt SRDF."""
    text = read_text(path, LIMITS.description, named_by(RobotModelError, file, "srdf"), f"SRDF {path}")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise RobotModelError(file, "srdf", f"cannot read SRDF {path}: {exc}") from None
    pairs = []
    for el in root.iter("disable_collisions"):
        a, b = el.get("link1"), el.get("link2")
        if not a or not b:
            raise RobotModelError(file, "srdf", f"{path.name}: disable_collisions needs link1 and link2")
        pairs.append((a, b))
    return pairs




# ------------------------------------------------------------------------------ loading


def load_robot_spec(path: Path) -> RobotSpec:
    """Read and check a robot.yaml. What needs the URDF (limits' length, link names, fitted IK
    parameters and their agreement with the URDF) is checked by `robot.load_robot`.

    Without `controller.base` the controller's base frame is the URDF's ROS-Industrial `base` link
    (`urdf_base_link`), or the URDF root frame when there is none; a given `controller.base` wins.
    """
    from robomax_py.io.ik_params import params_from_mapping

    data = read_yaml_mapping(path, RobotModelError, "robot description", LIMITS.description)
    try:
        parsed = RobotFile.model_validate(data)
    except ValidationError as exc:
        raise validation_error(exc, RobotFile, path, RobotModelError) from None
    if path.parent.name != parsed.name and path.name == "robot.yaml":
        raise RobotModelError(path, "name", f"must equal the folder name '{path.parent.name}', got '{parsed.name}'")
    if parsed.urdf.startswith("package://"):
        urdf = resolve_package_uri(parsed.urdf, path, "urdf")
    else:
        urdf = (path.parent / parsed.urdf).resolve()
    urdf = checked_file(urdf, LIMITS.urdf, named_by(RobotModelError, path, "urdf"), f"URDF {urdf}")
    ik_params = None
    if parsed.ik.params is not None or parsed.ik.solver not in ("opw", "ur"):
        try:
            ik_params = params_from_mapping(parsed.ik.solver, parsed.ik.params or {})
        except RobotModelError as exc:
            key = exc.key if exc.key != "ik.params.solver" else "ik.solver"
            raise RobotModelError(path, key, exc.problem) from None
    disabled = tuple((a, b) for a, b in parsed.collision.disable)
    srdf = () if parsed.srdf is None else tuple(srdf_disabled_pairs((path.parent / parsed.srdf).resolve(), path))
    ctrl = parsed.controller
    limits = parsed.limits
    if limits.loaded is not None and parsed.payload is None:
        raise RobotModelError(path, "limits.loaded", "needs `payload` (kg): the loaded limits hold for the rated payload")
    urdf_text = read_text(urdf, LIMITS.urdf, named_by(RobotModelError, path, "urdf"), f"URDF {urdf}")
    package_dirs = urdf_package_dirs(urdf, path, urdf_text)
    urdf_root = parse_urdf(urdf_text, urdf)
    warnings = check_urdf(urdf_root, urdf)
    if ctrl.base is not None:
        T_root_base = pose_matrix(ctrl.base.xyz, [math.radians(a) for a in ctrl.base.rpy])
    else:
        from_urdf = urdf_base_link(urdf_root, urdf)
        T_root_base = np.eye(4) if from_urdf is None else from_urdf
    return RobotSpec(
        name=parsed.name,
        source=path.resolve(),
        urdf=urdf,
        flange=parsed.flange,
        ik_solver=parsed.ik.solver,
        ik_params=ik_params,
        acceleration=None if limits.acceleration is None else frozen_array(degs_to_rads(limits.acceleration)),
        jerk=None if limits.jerk is None else frozen_array(degs_to_rads(limits.jerk)),
        payload_kg=parsed.payload,
        description=parsed.description,
        controller=ControllerSpec(
            brand=ctrl.brand, j23_coupling=ctrl.j23_coupling,
            pulses_per_degree=tuple(ctrl.pulses_per_degree or ()),
            joint_signs=tuple(float(s) for s in ctrl.joint_signs or ()),
            joint_zeros=tuple(math.radians(z) for z in ctrl.joint_zeros_deg or ()),
            T_root_base=frozen_array(T_root_base),
        ),
        disabled_links=disabled,
        srdf_disabled_links=srdf,
        package_dirs=package_dirs,
        loaded=None if limits.loaded is None else JointLoadLimits(
            velocity=frozen_array(degs_to_rads(limits.loaded.velocity)),
            acceleration=frozen_array(degs_to_rads(limits.loaded.acceleration)),
            jerk=frozen_array(degs_to_rads(limits.loaded.jerk)),
        ),
        warnings=warnings,
    )


def load_tool_spec(path: Path) -> ToolSpec:
    """Read and check a tool.yaml; its meshes must exist (they are read when the scene is built)."""
    data = read_yaml_mapping(path, RobotModelError, "tool description", LIMITS.description)
    try:
        parsed = ToolFile.model_validate(data)
    except ValidationError as exc:
        raise validation_error(exc, ToolFile, path, RobotModelError) from None
    meshes = {}
    for key in ("body", "tips"):
        named = path.parent / getattr(parsed, key)
        meshes[key] = checked_file(named, LIMITS.mesh, named_by(RobotModelError, path, key), f"mesh {named}")
    rpy = [math.radians(a) for a in parsed.tcp.rpy]
    return ToolSpec(
        name=parsed.name,
        source=path.resolve(),
        body=meshes["body"],
        tips=meshes["tips"],
        T_flange_tcp=frozen_array(pose_matrix(parsed.tcp.xyz, rpy)),
    )
