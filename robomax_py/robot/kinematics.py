"""A URDF's kinematic model in Pinocchio: `<mimic>` joints read as passive joints, the model checked
(single-axis active joints, finite limits, the flange frame), and which joints own a configuration
entry, which are prismatic and which follow another."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin

from robomax_py.errors import RobotModelError
from robomax_py.spec import RobotSpec

# A `<mimic>` joint (a parallelogram link, a balancer's cylinder and piston) is passive: its value
# follows the joint it mimics (multiplier * q + offset), it has no configuration entry of its own
# and takes no part in IK or programs; its link moves and collides like every other. Pinocchio
# models it so when the URDF is read with `mimic=True` (JointModelMimic, nq = nv = 0), but the
# installed Pinocchio refuses a `continuous` joint mimicking a revolute one (their configuration
# spaces differ: cos/sin against an angle), the form ROS-Industrial ABB packages use for their
# balancers (abb_irb6640_support/urdf/irb6640_185_280_macro.xacro `joint_piston`). Its value
# follows a bounded joint, so it is read as a revolute joint with limits of a full turn either way.
_MIMIC_CONTINUOUS_LIMIT_RAD = 2 * np.pi


# Pinocchio's URDF reader walks the link tree depth first, a link's child joints in the order of
# their names (urdfdom keeps joints in a sorted map), and refuses a mimic joint met before the joint
# it follows ("The parent joint of the mimic joint is not in the kinematic tree"): the IRB 6700's
# `cylinder_joint` hangs from link_1 beside `joint_2`, which it follows
# (abb_irb6700_support/urdf/irb6700_200_260_macro.xacro). Pinocchio therefore reads every mimic
# joint under a name sorting after all others (this prefix; `~` is the last printable ASCII
# character), so that it meets each after its active siblings, and `urdf_model` gives the names back.
_PASSIVE_PREFIX = "~"


def pinocchio_urdf_text(text: str) -> str:
    """A URDF's text as `urdf_model` hands it to Pinocchio: `continuous` mimic joints made revolute
    and mimic joints renamed (see above); the text unchanged when it has none."""
    import xml.etree.ElementTree as ET

    if "mimic" not in text:
        return text
    root = ET.fromstring(text)
    joints = [joint for joint in root.findall("joint") if joint.find("mimic") is not None]
    if not joints:
        return text
    passive = {str(joint.get("name")) for joint in joints}
    for joint in joints:
        joint.set("name", _PASSIVE_PREFIX + str(joint.get("name")))
        mimic = joint.find("mimic")
        if mimic is not None and mimic.get("joint") in passive:
            mimic.set("joint", _PASSIVE_PREFIX + str(mimic.get("joint")))
        if joint.get("type") != "continuous":
            continue
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = ET.SubElement(joint, "limit", {"effort": "0", "velocity": "1"})
        limit.set("lower", repr(-_MIMIC_CONTINUOUS_LIMIT_RAD))
        limit.set("upper", repr(_MIMIC_CONTINUOUS_LIMIT_RAD))
    return ET.tostring(root, encoding="unicode")


def urdf_model(text: str) -> pin.Model:
    """Pinocchio's model of a URDF's text, `<mimic>` joints as passive joints (JointModelMimic)."""
    model = pin.buildModelFromXML(pinocchio_urdf_text(text), mimic=True)
    for j in range(1, model.njoints):
        if model.names[j].startswith(_PASSIVE_PREFIX) and is_passive(model, j):
            model.names[j] = model.names[j][len(_PASSIVE_PREFIX):]
    for frame in model.frames:
        if frame.type == pin.FrameType.JOINT and frame.name.startswith(_PASSIVE_PREFIX) and is_passive(model, frame.parentJoint):
            frame.name = frame.name[len(_PASSIVE_PREFIX):]
    return model


def is_passive(model: pin.Model, j: int) -> bool:
    """Joint j follows another joint (`<mimic>`): no configuration entry of its own."""
    return bool(model.joints[j].shortname() == "JointModelMimic")


def active_joints(model: pin.Model) -> list[int]:
    """The joint ids that own a configuration entry, in configuration order (passive ones left out)."""
    return sorted((j for j in range(1, model.njoints) if not is_passive(model, j)), key=lambda j: int(model.joints[j].idx_q))


def passive_joints(model: pin.Model) -> list[int]:
    """The ids of the `<mimic>` joints."""
    return [j for j in range(1, model.njoints) if is_passive(model, j)]


def mimic_relation(model: pin.Model, j: int) -> tuple[int, float, float]:
    """A passive joint's relation: (configuration index it follows, multiplier, offset)."""
    mimic = model.joints[j].extract()
    return int(mimic.idx_q), float(mimic.scaling), float(mimic.offset)


def _urdf_text(urdf: Path, error_file: Path) -> str:
    from robomax_py.safe_files import LIMITS, named_by, read_text

    return read_text(urdf, LIMITS.urdf, named_by(RobotModelError, error_file, "urdf"), f"URDF {urdf}")


def kinematic_model(spec: RobotSpec) -> pin.Model:
    """The URDF's Pinocchio model, checked: single-axis active joints, finite limits, the flange
    frame exists. `<mimic>` joints are passive (see `urdf_model`)."""
    try:
        model = urdf_model(_urdf_text(spec.urdf, spec.source))
    except RobotModelError:
        raise
    except Exception as exc:  # noqa: BLE001 - Pinocchio raises plain RuntimeError/ValueError for bad URDFs
        raise RobotModelError(spec.urdf, None, f"cannot parse URDF: {exc}") from None
    if not model.existFrame(spec.flange):
        raise RobotModelError(spec.source, "flange", f"URDF {spec.urdf.name} has no frame '{spec.flange}'")
    for j in range(1, model.njoints):
        if is_passive(model, j):
            continue
        if model.joints[j].nq != 1 or model.joints[j].nv != 1:
            # A `continuous` joint: JointModelRUBX/Y/Z, or JointModelRevoluteUnboundedUnaligned.
            name = model.joints[j].shortname()
            unbounded = name.startswith("JointModelRUB") or "Unbounded" in name
            raise RobotModelError(spec.urdf, f"joint {model.names[j]}", "is continuous: give it the controller's "
                                  "software limits as a revolute joint, or import the URDF with `robomax import-urdf`, "
                                  "which bounds it at ±360 deg" if unbounded else
                                  "only revolute and prismatic joints are supported")
        i = model.joints[j].idx_q
        lo, hi, v = model.lowerPositionLimit[i], model.upperPositionLimit[i], model.velocityLimit[i]
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise RobotModelError(spec.urdf, f"joint {model.names[j]}", "needs finite position limits lower < upper")
        if not (np.isfinite(v) and v > 0):
            raise RobotModelError(spec.urdf, f"joint {model.names[j]}", "needs a velocity limit > 0")
    return model


def prismatic_mask(model: pin.Model) -> np.ndarray:
    """(n,) bool: which joints are prismatic (their values are metres, not radians)."""
    return np.array([model.joints[j].shortname().startswith("JointModelP") for j in active_joints(model)])
