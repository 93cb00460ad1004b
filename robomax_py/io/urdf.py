"""What robot.yaml's URDF and SRDF are read for: the ROS-Industrial `base` link, the checks a URDF
passes at load (joint limits, collision geometry), and the SRDF's disabled collision pairs."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import RobotModelError
from robomax_py.safe_files import LIMITS, named_by, read_text
from robomax_py.transforms import pose_matrix

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


# The bounds `bound_continuous_joints` gives a `continuous` joint: a full turn either way, the
# software limits a controller puts on its endless axes when nobody set others (UR's ±360 deg of
# every joint; KUKA's A6 of ±350 deg is inside them).
CONTINUOUS_BOUND_RAD = 2.0 * math.pi


def bound_continuous_joints(root: ET.Element) -> tuple[str, ...]:
    """Every active `continuous` joint of a URDF made `revolute` within ±CONTINUOUS_BOUND_RAD
    (its `<limit>` velocity and effort kept), in place; the names of those changed.

    robomax_py plans joints with bounds (a configuration is one angle per joint, and a controller
    limits every axis in software); a `continuous` joint mimicking another is left to
    `robot.kinematics`, which bounds it alike."""
    changed = []
    for joint in root.findall("joint"):
        if joint.get("type") != "continuous" or joint.find("mimic") is not None:
            continue
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = ET.SubElement(joint, "limit")
        limit.set("lower", repr(-CONTINUOUS_BOUND_RAD))
        limit.set("upper", repr(CONTINUOUS_BOUND_RAD))
        changed.append(str(joint.get("name")))
    return tuple(changed)


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
