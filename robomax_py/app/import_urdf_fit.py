"""The robot.yaml that `import_urdf` writes, the IK solver fitted to the URDF, and what the import
can tell of the controller's conventions (KUKA's axis directions and zeros, ABB's coupled J2/J3,
the flange's z axis)."""

from __future__ import annotations

import json
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from robomax_py._typing import FloatArray
from robomax_py.app.import_urdf_staging import _inside
from robomax_py.safe_files import printable
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.transforms import rpy_from_matrix


def _number(v: float) -> str:
    text = f"{v:.9f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _base_yaml(T_root_base: FloatArray) -> str:
    """robot.yaml's `controller.base` for a pose (4, 4), metres: xyz in m, rpy in deg (a half turn
    written as 180, not -180)."""
    xyz = ", ".join(_number(v) for v in T_root_base[:3, 3])
    angles = [_number(math.degrees(a)) for a in rpy_from_matrix(T_root_base[:3, :3])]
    rpy = ", ".join("180" if a == "-180" else a for a in angles)
    return f"{{xyz: [{xyz}], rpy: [{rpy}]}}"


def _robot_yaml(name: str, urdf: str, flange: str, solver: str, params: object, brand: str, srdf: str | None,
                source: Path, T_root_base: FloatArray | None, convention: Convention | None = None,
                touching: AlwaysTouching | None = None) -> str:
    """The robot.yaml text. `T_root_base` (4, 4), metres: the URDF's ROS-Industrial `base` link in
    its root frame (`io.robot.urdf_base_link`), written as `controller.base`; None when the URDF has
    none (a UR arm then gets the UR controller's base, `base_link` turned 180 deg about z).
    `touching`: link pairs touching in every sampled posture, written as `collision.disable` with
    the reason beside them, for the user to review."""
    from robomax_py.robot.ik.opw import OpwParams
    from robomax_py.robot.ik.ur import UrParams

    lines = [
        f"# Imported by `robomax import-urdf` from {printable(source.name)}; IK parameters fitted from the URDF's",
        "# joint origins and axes and checked against its forward kinematics.",
        f"name: {name}",
        f"description: {_yaml_text(f'{name} (imported from {source.name})')}",
        f"urdf: {urdf}",
        f"flange: {_yaml_text(flange)}",
        "ik:",
        f"  solver: {solver}",
    ]
    if isinstance(params, OpwParams):
        lines.append("  params:")
        for key in ("a1", "a2", "b", "c1", "c2", "c3", "c4"):
            lines.append(f"    {key}: {_number(getattr(params, key))}")
        lines.append(f"    offsets: [{', '.join(_number(math.degrees(o)) for o in params.offsets)}]")
        lines.append(f"    sign_corrections: [{', '.join(str(s) for s in params.sign_corrections)}]")
        if params.base_xy != (0.0, 0.0):
            lines.append(f"    base_xy: [{', '.join(_number(v) for v in params.base_xy)}]  # axis 1 in the root frame")
        if params.flange_xy != (0.0, 0.0):
            lines.append(f"    flange_xy: [{', '.join(_number(v) for v in params.flange_xy)}]  # flange off axis 6")
        if params.flange_rpy != (0.0, 0.0, 0.0):
            lines.append(f"    flange_rpy: [{', '.join(_number(math.degrees(v)) for v in params.flange_rpy)}]"
                         "  # the URDF flange in the paper's (z along axis 6)")
    elif isinstance(params, UrParams):
        lines.append("  params:")
        for key in ("d1", "a2", "a3", "d4", "d5", "d6"):
            lines.append(f"    {key}: {_number(getattr(params, key))}")
        for key in ("base_xyz", "flange_xyz"):
            lines.append(f"    {key}: [{', '.join(_number(v) for v in getattr(params, key))}]")
        for key in ("base_rpy", "flange_rpy"):
            lines.append(f"    {key}: [{', '.join(_number(math.degrees(v)) for v in getattr(params, key))}]")
    lines.append("controller:")
    lines.append(f"  brand: {brand}")
    if brand == "fanuc":
        lines.append("  j23_coupling: true        # FANUC counts J3 from the horizontal")
    if T_root_base is not None:
        lines.append(f"  base: {_base_yaml(T_root_base)}  # ROS-Industrial's `base` link: the vendor's base frame")
    elif brand == "ur":
        lines.append("  base: {rpy: [0, 0, 180]}  # the UR controller's base: base_link turned 180 deg about z")
    if convention is not None and convention.signs:
        lines.append(f"  joint_signs: [{', '.join(str(v) for v in convention.signs)}]  # derived from the URDF's axes")
        lines.append(f"  joint_zeros_deg: [{', '.join(_number(v) for v in convention.zeros_deg)}]")
    if touching is not None and touching.pairs:
        lines.extend([
            "collision:",
            f"  # Touching in every one of the collision world's {touching.samples} seeded postures (random within the",
            "  # joint limits), so never checked, as MoveIt's Setup Assistant disables its \"Always\" pairs: parts",
            "  # that touch by design, or coarse meshes. Review them; remove a pair that must stay checked.",
            "  disable:",
            *(f"    - [{_yaml_text(a)}, {_yaml_text(b)}]  # in contact in {touching.samples} of {touching.samples} samples"
              for a, b in touching.pairs),
        ])
    if srdf is not None:
        lines.append(f"srdf: {srdf}")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True, slots=True)
class AlwaysTouching:
    """Link pairs in contact in every one of `samples` seeded postures (`world.acm.always_touching_links`)."""

    pairs: tuple[tuple[str, str], ...]
    samples: int


def _yaml_text(text: str) -> str:
    """A YAML scalar for `text`: as it is when plain, else quoted (a file name may hold ': ', '#' or
    a line break)."""
    return text if re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.() -]*", text) and not text.endswith(" ") else json.dumps(text)


# What the numeric solver costs, for the warning when the fit falls back to it. Measured once on
# ROS-Industrial's KR 210 L150 planning a four-spot flange cell (tests/app/test_import_urdf.py's
# `_flange_cell`), one thread, warm: 6.6 s CPU with numeric IK against 1.4 to 2.1 s with the fitted
# OPW solver.
NUMERIC_COST = ("planning several times slower (about 3x CPU on a KR 210 L150 cell), and the IK branches of each "
                "pose found by sampling from random starts, not enumerated, so a branch can be missed")


CONVENTION_UNKNOWN = ("joint directions and zeros taken from the URDF; check them against the controller's axis "
                      "display (robot.yaml controller.joint_signs, controller.joint_zeros_deg)")
# KUKA's own axis directions in its base frame at A1..A6 = 0 (KSS: A1 turns about -z, A4 and A6
# about -x; A2 = 0 with the upper arm horizontal, forward; A3 = 0 with the forearm in line with
# it, so that the mastering position A2 = -90, A3 = 90 deg has the upper arm upright and the
# forearm horizontal), which the ROS-Industrial KUKA URDFs follow so that their joint values are
# the controller's: kuka_rsi_hw_interface passes the controller's axis values through unchanged
# (ros-industrial/kuka_experimental@e78bbd15
# kuka_rsi_hw_interface/src/kuka_hardware_interface.cpp:109, `joint_position_[i] = DEG2RAD *
# rsi_state_.positions[i]`; kuka_kr120_support/urdf/kr120r2500pro_macro.xacro:156-196). Not all do:
# kuka_kr210_support's kr210l150 (A1 about +z, A2 = 0 upright) is kuka_experimental issue 98,
# "kr210: update xacro to comply with actual kinematic chain".
_KUKA_AXES = ((0, 0, -1), (0, 1, 0), (0, 1, 0), (-1, 0, 0), (0, 1, 0), (-1, 0, 0))
# ROS-Industrial's tool0 (z out of the flange, REP 199) at KUKA's zero: x pointing down
# (kr120r2500pro_macro.xacro, flange-tool0 rpy 0 90 0 on a flange whose frame is the base's at zero).
_KUKA_TOOL0_X = (0.0, 0.0, -1.0)
# How far (deg) the URDF's upper arm, forearm or front may lie from a quarter turn at its zero: the
# ROS-Industrial meshes' origins are a few degrees off (the KR 210 L150's A2 origin is 6 deg off x).
_QUARTER_TOL_DEG = 15.0
# abb_driver exchanges joint values with the controller in degrees <-> radians only
# (ros-industrial/abb_driver@f3068b92d9f5550992143f775d110b946ef04551 rapid/ROS_messages.sys:131-145,
# `message.joints := rad2deg_robjoint(message.joints)`, and :155-175; rapid/ROS_stateServer.mod:64-70,
# `joints := CJointT(); message.joints := joints.robax`; rapid/ROS_motion.mod:56-66, `target.robax :=
# trajectory{current_index}.joint_pos; MoveAbsJ target`), except on arms whose support package sets
# `J23_coupled` (src/abb_utils.cpp:52, `points_out->at(2) += J23_factor * points_out->at(1)`: the
# controller's J3 = J3 + J2 of the URDF; ros-industrial/abb@77db19bd: IRB 2400, 4400, 5400), which
# robot.yaml cannot state for ABB.
_J23 = re.compile(r'<arg\s+name="J23_coupled"\s+default="(true|false)"')
_LAUNCH_BYTES = 65536


@dataclass(frozen=True, slots=True)
class Convention:
    """What the import knows of how the controller counts the URDF's joints: the robot.yaml keys
    (`signs`, `zeros_deg`; empty for the URDF's own count) and the note it gives, if any."""

    signs: tuple[int, ...] = ()
    zeros_deg: tuple[float, ...] = ()
    note: str | None = None


def _quarter(angle: float) -> float | None:
    """The multiple of 90 deg an angle (deg) lies within _QUARTER_TOL_DEG of, in (-180, 180]."""
    q = 90.0 * round(angle / 90.0)
    if abs(angle - q) > _QUARTER_TOL_DEG:
        return None
    q = (q + 180.0) % 360.0 - 180.0
    return 180.0 if q == -180.0 else q + 0.0


def _kuka_counting(axes: object, R: FloatArray) -> tuple[tuple[int, ...], tuple[float, ...]] | None:
    """KUKA's joint_signs and joint_zeros_deg for a URDF (controller = sign * URDF + zero), derived
    from its joint axes and flange at q = 0 in the controller's base frame, or None when they are
    not quarter turns and axis flips of KUKA's (`_KUKA_AXES`).

    At the URDF's zero the controller's A1 is where the arm faces (A2's origin off A1), A2 the angle
    of the upper arm (A2 -> A3 origins) from the horizontal about +y, A2 + A3 that of the forearm
    (along axis 4, away from A3), A4 = A5 = 0 (the wrist straight: axis 6 in line with axis 4), A6
    the turn of ROS-Industrial's tool0 from its place at KUKA's zero (`_KUKA_TOOL0_X`). The signs
    are then those of the URDF's axes against KUKA's turned into that posture. A4 + 180, -A5,
    A6 + 180 give the same flange pose: the URDF's zero is taken to have A4 = 0, as ROS-Industrial
    models the arm at the mastering position."""
    import numpy as np

    from robomax_py.transforms import rot_y, rot_z

    u = np.asarray(axes.u) @ R                                    # type: ignore[attr-defined]
    p = np.asarray(axes.p) @ R                                    # type: ignore[attr-defined]
    x_tool = np.asarray(axes.T_flange)[:3, 0] @ R                 # type: ignore[attr-defined]
    if len(u) != 6 or abs(float(u[5] @ u[3])) < 1 - 1e-6:
        return None
    front = p[1] - p[0]
    a1 = _quarter(-math.degrees(math.atan2(front[1], front[0])))
    if a1 is None or math.hypot(front[0], front[1]) < 1e-3:
        return None
    Rz = rot_z(-math.radians(a1))                                  # KUKA's A1 turns about -z
    upper = Rz.T @ (p[2] - p[1])
    a2 = _quarter(math.degrees(math.atan2(-upper[2], upper[0])))
    w = Rz.T @ (u[3] * np.sign(float((p[4] - p[2]) @ u[3]) or 1.0))
    a23 = _quarter(math.degrees(math.atan2(-w[2], w[0])))
    if a2 is None or a23 is None:
        return None
    R_arm = Rz @ rot_y(math.radians(a23))                          # the forearm's turn at the URDF's zero
    want = [Rz @ np.asarray(e, dtype=float) for e in _KUKA_AXES[:3]] + \
        [R_arm @ np.asarray(e, dtype=float) for e in _KUKA_AXES[3:]]
    dots = [float(a @ e) for a, e in zip(u, want)]
    if any(abs(d) < 1 - 1e-6 for d in dots):
        return None
    e6 = want[5]                                                   # KUKA's A6 axis in that posture
    ref = R_arm @ np.asarray(_KUKA_TOOL0_X)
    if abs(float(x_tool @ e6)) > 1e-6:
        return None
    a6 = math.degrees(math.atan2(float(np.cross(ref, x_tool) @ e6), float(ref @ x_tool)))
    if abs(a6 - 90.0 * round(a6 / 90.0)) > 1e-4:
        return None
    a6_quarter = _quarter(a6)
    a3 = (a23 - a2 + 180.0) % 360.0 - 180.0
    if a6_quarter is None:
        return None
    signs = tuple(1 if d > 0 else -1 for d in dots)
    return signs, (a1, a2, 180.0 if a3 == -180.0 else a3 + 0.0, 0.0, 0.0, a6_quarter)


def _abb_coupling(source: Path, roots: Sequence[Path]) -> tuple[bool, Path] | None:
    """Whether the URDF's ROS-Industrial support package has abb_driver couple J3 with J2 (a
    launch file's `J23_coupled` default, the package's folder above `urdf/`), with that file;
    None when no readable launch file of the package says."""
    package = source.resolve().parent.parent
    launch = package / "launch"
    if not launch.is_dir() or not _inside(launch, roots):
        return None
    found = None
    for path in sorted(launch.glob("*.launch")):
        if not path.is_file() or not _inside(path, roots):
            continue
        with open(path, "rb") as f:
            match = _J23.search(f.read(_LAUNCH_BYTES).decode("utf-8", "replace"))
        if match:
            if match[1] == "true":
                return True, path
            found = (False, path)
    return found


def _convention(model: object, frame_id: int, brand: str, T_root_base: FloatArray | None,
                source: Path | None = None, roots: Sequence[Path] = ()) -> Convention:
    """How the controller counts the URDF's joints, as far as it is known (`Convention`).

    FANUC: ROS-Industrial's fanuc_driver exchanges the URDF's joint values with the controller
    unchanged but for the J2/J3 linkage (ros-industrial/fanuc@8fee5e30
    fanuc_driver/include/fanuc_driver/fanuc_utils.h:55-71, `J3_out = J3_in + j23_factor * J2_in`),
    which `controller.j23_coupling` states. ABB: abb_driver passes the values unchanged but on arms
    whose support package couples J2 and J3 (`_J23`). UR: Universal_Robots_ROS_Driver takes the
    controller's `actual_q` (rad) as the joint positions and sends its commands as they are
    (UniversalRobots/Universal_Robots_ROS_Driver@66510fde40df294631bd22899677375d0b190d4e
    ur_robot_driver/src/hardware_interface.cpp:526, `readData(data_pkg, "actual_q",
    joint_positions_)`, and :714, `writeJointCommand(joint_position_command_, ...MODE_SERVOJ`) for
    ur_description's URDFs. Kawasaki: Kawasaki's own driver compares and commands the controller's
    joint angles (rad) as the URDF's joint values, converting only a prismatic axis to mm
    (Kawasaki-Robotics/khi_robot@57200db576c6feb7cea442ff06f27334a520eb7a
    khi_robot_control/src/khi_robot_krnx_driver.cpp:366-371, `diff = home[jt]*conv -
    motion_data.ang[jt]`, and :680-689, `comp = cmd - home`, times 1000 only for PRISMATIC), for
    khi_robot's URDFs. KUKA: KUKA's axis directions and zero (`_KUKA_AXES`) against the
    URDF's; where they differ by axis flips and quarter turns the keys are derived
    (`_kuka_counting`). Other brands: not known here."""
    import numpy as np

    from robomax_py.robot.ik._chain import joint_axes_at_zero

    if brand in ("fanuc", "ur", "kawasaki"):
        return Convention()
    if brand == "abb":
        coupled = _abb_coupling(source, roots) if source is not None else None
        if coupled is None:
            return Convention(note="abb_driver passes joint values unchanged except on arms whose J3 it couples with "
                                   "J2 (its J23_coupled: IRB 2400, 4400, 5400), and no launch file of the URDF's support "
                                   f"package says which: {CONVENTION_UNKNOWN}")
        if coupled[0]:
            return Convention(note=f"abb_driver couples J3 with J2 for this arm (J23_coupled in {coupled[1].name}): the "
                                   "controller's J3 is the URDF's J3 + J2, which robot.yaml does not state for ABB; "
                                   f"{CONVENTION_UNKNOWN}")
        return Convention()
    if brand != "kuka" or model.nq != 6:  # type: ignore[attr-defined]
        return Convention(note=CONVENTION_UNKNOWN)
    try:
        axes = joint_axes_at_zero(model, frame_id)
    except Exception:  # noqa: BLE001 - a chain the check cannot read is simply not known to match
        return Convention(note=CONVENTION_UNKNOWN)
    R = np.eye(3) if T_root_base is None else np.asarray(T_root_base)[:3, :3]
    derived = _kuka_counting(axes, R)
    if derived is None:
        return Convention(note=f"the URDF's joint axes or zero differ from KUKA's (A1 about -z, A4 and A6 about -x, "
                               f"A2 = 0 with the upper arm horizontal): {CONVENTION_UNKNOWN}")
    signs, zeros = derived
    if all(s == 1 for s in signs) and not any(zeros):
        return Convention()
    return Convention(signs, zeros, (
        f"the URDF's joint axes differ from KUKA's (A1 about -z, A4 and A6 about -x, A2 = 0 with the upper arm "
        f"horizontal; cf. kuka_experimental issue 98): controller.joint_signs [{', '.join(map(str, signs))}] and "
        f"joint_zeros_deg [{', '.join(_number(z) for z in zeros)}] derived from the axes at the URDF's zero, taken to be KUKA's mastering "
        "position with A4 = 0 (A4 + 180, -A5, A6 + 180 reach the same flange pose): check them against the axis "
        "display"))


# The vendors' mounting flange (ISO 9409-1) has z out of the flange along the last axis, and so does
# ROS-Industrial's `tool0` (REP 199, "Coordinate Frames for Serial Industrial Manipulators", as the
# support packages cite it: ros-industrial/kuka_experimental@e78bbd15
# kuka_kr120_support/urdf/kr120r2500pro_macro.xacro:146 "Following REP199, this frame shall be use to
# attach EEF", :217-220 tool0 = flange turned 90 deg about y, z along axis 6;
# ros-industrial/abb@77db19bd abb_irb2400_support/urdf/irb2400_macro.xacro:164-167 likewise, after
# its CHANGELOG's "corrects tool0 to match robot controller"). Not every package does:
# abb_irb4400_support's irb4400l_30_243 publishes tool0 = link_6's frame, x along axis 6.
FLANGE_Z_WARNING = ("the flange frame '{flange}' has its z axis {angle:.1f} deg off the last joint's axis: not the "
                    "vendor's mounting flange convention (z out of the flange along the last axis, as "
                    "ROS-Industrial's tool0 has it, REP 199). Tools mount on this frame as published, so a "
                    "tool's z (its working direction) points along this frame's z; choose another frame with "
                    "--flange or fix the URDF's flange joint")


def _flange_z_warning(model: object, frame_id: int, flange: str) -> str | None:
    """The warning when the flange frame's z axis is not along the last joint's axis (either way), else None."""
    import numpy as np

    from robomax_py.robot.ik._chain import joint_axes_at_zero

    try:
        axes = joint_axes_at_zero(model, frame_id)
    except Exception:  # noqa: BLE001 - a chain the check cannot read: nothing to say about its flange
        return None
    if len(axes.u) == 0:
        return None
    cos = abs(float(axes.u[-1] @ axes.T_flange[:3, 2]))
    angle = float(np.degrees(np.arccos(min(cos, 1.0))))
    return None if cos >= math.cos(TOL.structure_tol) else FLANGE_Z_WARNING.format(flange=flange, angle=angle)


def _fit(model: object, frame_id: int, solver: str | None) -> tuple[str, object, float, str | None]:
    """(solver, parameters, FK error in m, warning): the warning says why the closed forms were not
    taken and what that costs, whenever the fit fell back to numeric IK (None otherwise)."""
    from robomax_py.robot.ik.fit import FitError, fit_opw, fit_ur, fk_agreement

    tried: list[str] = []
    for name, fit in (("opw", fit_opw), ("ur", fit_ur)):
        if solver not in (None, name):
            continue
        if model.nq != 6:  # type: ignore[attr-defined]
            tried.append(f"{name}: the URDF has {model.nq} joints, not six")  # type: ignore[attr-defined]
            continue
        try:
            params = fit(model, frame_id)
        except FitError as exc:
            tried.append(f"{name}: {exc.problem}")
            continue
        agreement = fk_agreement(model, frame_id, params)
        if agreement.ok:
            return name, params, agreement.position_m, None
        tried.append(f"{name}: fitted parameters disagree with the URDF by {agreement.position_m * 1000:.3f} mm")
    if solver == "numeric":
        return "numeric", None, 0.0, None
    if solver is None:
        return "numeric", None, 0.0, (f"IK falls back to the numeric solver: no closed form fits ({'; '.join(tried)}); "
                                      f"this costs {NUMERIC_COST}")
    raise FitError("; ".join(tried))
