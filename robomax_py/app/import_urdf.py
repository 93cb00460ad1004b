"""`robomax import-urdf`: a URDF or xacro from a ROS package -> a self-contained robot folder.

The folder holds the expanded URDF with relative mesh paths, the meshes it names (copied), an SRDF
when one is given, and a robot.yaml with IK parameters fitted from the URDF and checked against its
forward kinematics; when the URDF has a ROS-Industrial `base` link (the vendor's base frame), the
robot.yaml states its pose as `controller.base`, so the folder says which frame Cartesian targets are
in.

A robot package is untrusted data (downloaded, sent by others):

- files are read only below the `--packages` folders and the source's own folder (real paths,
  symlinks resolved): xacro includes, `xacro.load_yaml`, `$(find pkg)` and mesh files alike;
- xacro is expanded by `xacro_sandbox` in a process of its own, bounded in CPU time and memory
  (`FileLimits.xacro_cpu_s`, `xacro_memory`), with a restricted evaluator instead of Python's eval;
- each mesh is checked (inside the folders, a mesh file type, within `FileLimits.mesh`) before it
  is read, and goes to `meshes/collision/...` or `meshes/visual/...`, so a visual mesh never
  replaces a collision mesh of the same name; every written path is confined to the output folder;
- the URDF passes `io.robot.check_urdf` (joint limits, collision geometry) before anything is
  written, and the staged folder is loaded back as any robot folder is (`robot.load_robot`: a
  non-finite mesh vertex is refused there).

The folder is built in a staging folder beside the target (`_staging`: a name pattern and a marker
file, so the next import removes one a killed import left, and nothing else) and moved into place
with one rename (an atomic exchange when it replaces a folder): a failed or killed import leaves the
old folder or the new one, never a mix, and no other file.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from robomax_py._typing import FloatArray
from robomax_py.app import xacro_sandbox
from robomax_py.app.xacro_sandbox import _package_candidates
from robomax_py.errors import RobotModelError
from robomax_py.io.robot import check_urdf, srdf_disabled_pairs, urdf_base_link
from robomax_py.safe_files import (
    LIMITS,
    MB,
    FileLimits,
    checked_file,
    named_by,
    printable,
    read_text,
)
from robomax_py.spec import RobotSpec
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.transforms import rpy_from_matrix

# Mesh files a URDF may name: single-file formats trimesh reads (.gltf is left out: its buffers are
# further files the import would not copy).
MESH_SUFFIXES = (".stl", ".dae", ".obj", ".ply", ".off", ".glb")
_BRAND_PATTERNS = (
    ("kuka", re.compile(r"kuka|(^|[^a-z])kr\s*\d", re.IGNORECASE)),
    ("abb", re.compile(r"abb|irb\s*\d", re.IGNORECASE)),
    ("fanuc", re.compile(r"fanuc|lrmate|(^|[^a-z])(m|r|cr|crx|arc|lr)[-_]?\d+i[a-z]", re.IGNORECASE)),
    ("ur", re.compile(r"(^|[^a-z])ur\d+e?([^a-z0-9]|$)|universal", re.IGNORECASE)),
    # ROS-Industrial package names: motoman_*_support, staubli_*_support, kawasaki_* (Yaskawa's
    # arms are Motoman).
    ("yaskawa", re.compile(r"motoman|yaskawa", re.IGNORECASE)),
    ("staubli", re.compile(r"st(a|ä)ubli", re.IGNORECASE)),
    ("kawasaki", re.compile(r"kawasaki", re.IGNORECASE)),
)


@dataclass(frozen=True, slots=True)
class ImportResult:
    folder: Path
    name: str
    solver: str
    brand: str
    meshes: int
    disabled_pairs: int
    fk_error_m: float
    seconds: float
    unchanged: bool               # the folder existed with exactly this content: nothing written
    warnings: tuple[str, ...]


def guess_brand(*names: str) -> str:
    """A controller brand (kuka, abb, fanuc, ur, yaskawa, staubli, kawasaki) from a robot's name or
    file names; kuka when nothing matches."""
    for brand, pattern in _BRAND_PATTERNS:
        if any(pattern.search(n) for n in names):
            return brand
    return "kuka"


# ------------------------------------------------------------------------------ what may be read


def allowed_folders(source: Path, packages: Sequence[Path]) -> tuple[Path, ...]:
    """The folders an import may read from: each `--packages` folder and the source's own folder
    (real paths). Everything the source names (includes, YAML, `$(find pkg)`, meshes) must lie in one."""
    roots: list[Path] = []
    for p in packages:
        real = Path(os.path.realpath(p))
        if not real.is_dir():
            raise RobotModelError(None, "--packages", f"{printable(str(p))}: not a folder")
        roots.append(real)
    roots.append(Path(os.path.realpath(source)).parent)
    return tuple(dict.fromkeys(roots))


def _inside(path: Path, roots: Sequence[Path]) -> bool:
    real = os.path.realpath(path)
    return any(real == str(r) or real.startswith(str(r).rstrip(os.sep) + os.sep) for r in roots)


@dataclass(frozen=True, slots=True)
class Expanded:
    """A URDF's text and the notes its expansion gave (xacro arguments taken from a launch file)."""

    text: str
    notes: tuple[str, ...] = ()


def expand(source: Path, roots: Sequence[Path], limits: FileLimits = LIMITS,
           args: Mapping[str, str] | None = None) -> str:
    """The URDF text of a .urdf file, or of a .xacro expanded by `xacro_sandbox` (see `expanded`)."""
    return expanded(source, roots, limits, args).text


def expanded(source: Path, roots: Sequence[Path], limits: FileLimits = LIMITS,
             args: Mapping[str, str] | None = None) -> Expanded:
    """The URDF text of a .urdf file, or of a .xacro expanded by `xacro_sandbox` in a process of its
    own: only files below `roots` are read, no Python runs from the file, and the expansion ends
    after `limits.xacro_cpu_s` CPU seconds or `limits.xacro_memory` bytes with a message.

    `args` are xacro arguments (name -> value, as `name:=value` on xacro's command line); those not
    given take the values the package's `launch/load_<robot>.launch` passes where they resolve
    (`xacro_sandbox.Expansion.launch_defaults`; each noted), else the file's defaults."""
    if source.suffix != ".xacro":
        if args:
            raise RobotModelError(source, "--xacro-arg", "xacro arguments are given for a URDF, not a .xacro")
        return Expanded(read_text(source, limits.urdf, RobotModelError, "URDF"))
    checked_file(source, limits.urdf, RobotModelError, "xacro file")
    request = {
        "source": os.path.realpath(source), "roots": [str(r) for r in roots], "parent": os.getpid(),
        "args": dict(args or {}),
        "max_file_bytes": limits.urdf, "max_yaml_bytes": limits.description, "max_output_chars": limits.urdf,
        "cpu_s": limits.xacro_cpu_s, "memory_bytes": limits.xacro_memory,
    }
    seconds = f"xacro expansion exceeds {limits.xacro_cpu_s:g} s of CPU time"
    memory = f"xacro expansion exceeds {limits.xacro_memory / MB:.0f} MB of memory"
    # The CPU limit ends a busy child; the wall-clock limit one that waits (with slack for a busy
    # machine, where a process gets a fraction of a CPU).
    wall_s = 10 * limits.xacro_cpu_s + 30
    try:
        done = subprocess.run([sys.executable, "-I", "-X", "utf8", str(Path(xacro_sandbox.__file__))],
                              input=json.dumps(request).encode(), capture_output=True, timeout=wall_s,
                              env={}, check=False)
    except subprocess.TimeoutExpired:
        raise RobotModelError(source, None, f"xacro expansion exceeds {wall_s:g} s of waiting "
                              f"({limits.xacro_cpu_s:g} s of CPU time allowed)") from None
    if done.returncode in (-signal.SIGXCPU, -signal.SIGKILL):
        raise RobotModelError(source, None, seconds)
    try:
        answer = json.loads(done.stdout)
    except ValueError:
        answer = None
    if done.returncode != 0 or not isinstance(answer, dict):
        how = (f"signal {signal.Signals(-done.returncode).name}" if done.returncode < 0
               else f"exit code {done.returncode}")
        tail = printable(done.stderr.decode("utf-8", "replace").strip().splitlines()[-1]) if done.stderr.strip() else ""
        raise RobotModelError(source, None, f"xacro expansion ended abnormally ({how}; {memory}?)"
                              + (f": {tail}" if tail else ""))
    if "urdf" in answer:
        return Expanded(str(answer["urdf"]), tuple(str(n) for n in answer.get("notes") or ()))
    if answer.get("kind") == "memory":
        raise RobotModelError(answer.get("file") or source, None, memory)
    raise RobotModelError(answer.get("file") or source, answer.get("where"), str(answer.get("problem")))


# ------------------------------------------------------------------------------ meshes


@dataclass(frozen=True, slots=True)
class _Mesh:
    real: Path          # the file read
    local: str          # where it goes in the robot folder: meshes/<kind>/...


def _mesh_file(uri: str, kind: str, where: str, source: Path, roots: Sequence[Path], limits: FileLimits) -> _Mesh | None:
    """The file a URDF mesh `filename` names, checked before it is read (inside `roots`, a regular
    file of a mesh type within `limits.mesh`), and its place in the folder; None when not found.

    `package://pkg/rest` is looked for below the allowed folders (the folder named pkg, a child or
    up to three levels down) and may not leave its package (`..`); file:// and relative paths must
    lie inside the allowed folders once resolved.
    """
    error = named_by(RobotModelError, source, where)
    if "\x00" in uri or not uri.strip():
        raise error(None, None, "not a file name")
    if PurePosixPath(uri).suffix.lower() not in MESH_SUFFIXES:
        raise error(None, None, f"not a mesh file ({', '.join(MESH_SUFFIXES)})")
    if uri.startswith("package://"):
        package, _, rest = uri[len("package://"):].partition("/")
        parts = PurePosixPath(rest).parts
        if not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.-]*", package) or package in (".", ".."):
            raise error(None, None, f"'{printable(package)}' is not a package name")
        if not parts or rest.startswith("/") or ".." in parts:
            raise error(None, None, "leaves its package ('..' or an absolute path)")
        candidates = [Path(folder) / rest for root in roots for folder in _package_candidates(str(root), package)
                      if os.path.isdir(folder)]
        local_parts: tuple[str, ...] = (package, *(p for p in parts if p != "."))
    elif uri.startswith("file://"):
        candidates, local_parts = [Path(uri[len("file://"):])], ()
    elif re.match(r"^[A-Za-z][A-Za-z0-9+.-]*://", uri):
        raise error(None, None, "only package://, file:// and relative paths name mesh files")
    else:
        candidates, local_parts = [Path(os.path.realpath(source)).parent / uri], ()
    for candidate in candidates:
        if not os.path.lexists(candidate):
            continue
        if not _inside(candidate, roots):
            raise error(None, None, f"{printable(os.path.realpath(candidate))} is outside the package folders given "
                        "(--packages) and the source's folder")
        real = checked_file(candidate, limits.mesh, error, f"{kind} mesh")
        if not local_parts:
            root = next(r for r in roots if _inside(real, (r,)))
            local_parts = (root.name, *real.relative_to(root).parts)
        return _Mesh(real, "/".join(("meshes", kind, *local_parts)))
    return None


def _confined(stage: Path, local: str) -> Path:
    """stage/local, refused unless it stays inside the staged folder (no '..', no absolute part)."""
    parts = PurePosixPath(local).parts
    if not parts or local.startswith("/") or any(p in ("", ".", "..") for p in parts) or "\x00" in local \
            or any(len(p.encode("utf-8", "surrogateescape")) > LIMITS.name_chars for p in parts):
        raise RobotModelError(None, None, f"output path {printable(local)} would leave the robot folder")
    path = stage.joinpath(*parts)
    if not _inside(path.parent, (stage,)):
        raise RobotModelError(None, None, f"output path {printable(local)} would leave the robot folder")
    return path


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
                source: Path, T_root_base: FloatArray | None, convention: Convention | None = None) -> str:
    """The robot.yaml text. `T_root_base` (4, 4), metres: the URDF's ROS-Industrial `base` link in
    its root frame (`io.robot.urdf_base_link`), written as `controller.base`; None when the URDF has
    none (a UR arm then gets the UR controller's base, `base_link` turned 180 deg about z)."""
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
    if srdf is not None:
        lines.append(f"srdf: {srdf}")
    return "\n".join(lines) + "\n"


def _yaml_text(text: str) -> str:
    """A YAML scalar for `text`: as it is when plain, else quoted (a file name may hold ': ', '#' or
    a line break)."""
    return text if re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.() -]*", text) and not text.endswith(" ") else json.dumps(text)


# What the numeric solver costs, for the warning when the fit falls back to it. Measured once on
# ROS-Industrial's KR 210 L150 planning a four-spot flange cell (tests/app/test_import_urdf.py's
# `_flange_cell`), one thread, warm: 6.6 s CPU with numeric IK against 1.4 to 2.1 s with the fitted
# OPW solver.
NUMERIC_COST = ("planning several times slower (about 4x CPU on a KR 210 L150 cell), and the IK branches of each "
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
    ur_description's URDFs. KUKA: KUKA's axis directions and zero (`_KUKA_AXES`) against the
    URDF's; where they differ by axis flips and quarter turns the keys are derived
    (`_kuka_counting`). Other brands: not known here."""
    import numpy as np

    from robomax_py.robot.ik._chain import joint_axes_at_zero

    if brand in ("fanuc", "ur"):
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


def import_urdf(
    source: Path, out: Path, packages: Sequence[Path] = (), *, name: str | None = None, flange: str = "tool0",
    srdf: Path | None = None, solver: str | None = None, brand: str | None = None, force: bool = False,
    limits: FileLimits = LIMITS, xacro_args: Mapping[str, str] | None = None,
) -> ImportResult:
    """Write the robot folder `out` from `source` (.urdf or .xacro); see the module docstring.

    The source is untrusted data: files are read only below `packages` and the source's folder
    (`allowed_folders`), xacro runs in a bounded process without evaluating Python (`expand`),
    meshes are checked before they are read, every written path stays inside `out`, and nothing is
    written until everything named has been checked. `xacro_args` are the xacro arguments (name ->
    value) as on xacro's command line (see `expanded`).

    Raises
    ------
    RobotModelError
        The source does not expand or parse or names a file it may not read, a joint's limits or the
        collision geometry fail `io.robot.check_urdf`, a collision mesh is missing, unreadable or not
        finite, the flange frame is not in the URDF, the chain is not of the requested solver's
        class, or `out` exists with other content and `force` is not set.
    """
    t0 = time.perf_counter()
    source, out = Path(source), Path(out)
    name = name or out.name
    if name != out.name:
        raise RobotModelError(out, None, f"the folder must be named after the robot (docs/cell-files.md, 'The robot folder'): {name!r}")
    if not re.fullmatch(_NAME, name):
        raise RobotModelError(out, None, f"robot name {printable(name)!r} must be letters, digits, '_', '.', '-'")
    roots = allowed_folders(source, packages)
    parent = Path(os.path.abspath(out)).parent
    clean_stale_staging(parent)
    expansion = expanded(source, roots, limits, xacro_args)
    text = expansion.text
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise RobotModelError(source, None, f"not a valid URDF (XML): {exc}") from None
    if root.tag != "robot":
        raise RobotModelError(source, None, f"not a URDF: the root element is <{printable(root.tag)}>, not <robot>")
    warnings = [f"{source}: {note}" for note in expansion.notes]
    warnings.extend(check_urdf(root, source))
    T_root_base = urdf_base_link(root, source)
    meshes, mesh_warnings = _collect_meshes(root, source, roots, limits)
    warnings.extend(mesh_warnings)
    srdf_text = None
    if srdf is not None:
        srdf_disabled_pairs(Path(srdf), Path(srdf))   # readable, every pair has two links
        srdf_text = read_text(Path(srdf), limits.description, RobotModelError, "SRDF")
    urdf_name = f"{name}.urdf"
    urdf_bytes = ET.tostring(root, encoding="unicode").encode("utf-8") + b"\n"

    # Everything named is checked: build the folder aside, load it back, then move it into place.
    try:
        with _staging(parent, name) as stage:
            for local, real in meshes.items():
                _copy(real, _confined(stage, local), limits.mesh, source, local)
            _confined(stage, urdf_name).write_bytes(urdf_bytes)
            if srdf_text is not None:
                _confined(stage, f"{name}.srdf").write_text(srdf_text, encoding="utf-8")
            try:
                solver_name, fk_error, spec, robot_warnings = _build(
                    stage, name, urdf_name, flange, solver, brand, source, root, T_root_base,
                    None if srdf_text is None else f"{name}.srdf", roots)
            except RobotModelError as exc:
                raise _unstaged(exc, stage, source, urdf_name) from None
            warnings.extend(w for w in robot_warnings if w.startswith(
                ("IK falls back", "the flange frame", "joint directions", "the URDF's joint axes", "abb_driver")))
            warnings.extend(w.replace(str(stage), str(out)) for w in robot_warnings if "limits." in w)
            warnings.extend(_named_srdf(w, stage, source, urdf_name, srdf) for w in robot_warnings if ": srdf: " in w)
            unchanged = out.is_dir() and not out.is_symlink() and _digest(out) == _digest(stage)
            if not unchanged:
                if os.path.lexists(out) and not force:
                    raise RobotModelError(out, None, "exists with other content; use --force to replace it")
                _commit(stage, out)
    except OSError as exc:
        raise RobotModelError(out, None, f"cannot write the robot folder: {exc.strerror or exc}") from None
    return ImportResult(out, name, solver_name, spec.controller.brand, len(meshes), len(spec.srdf_disabled_links),
                        fk_error, time.perf_counter() - t0, unchanged, tuple(warnings))


def _collect_meshes(root: ET.Element, source: Path, roots: Sequence[Path],
                    limits: FileLimits) -> tuple[dict[str, Path], list[str]]:
    """The mesh files the links name, checked (`_mesh_file`), by their place in the folder; each
    `filename` rewritten to that place. Visual and collision meshes go to meshes/visual/ and
    meshes/collision/, so a visual mesh never stands in for a collision mesh of the same name. A
    missing visual mesh is shown as the link's collision mesh (a warning)."""
    meshes: dict[str, Path] = {}
    warnings: list[str] = []
    for link in root.findall("link"):
        link_name = printable(str(link.get("name")))
        collision_meshes: list[str] = []
        for kind in ("collision", "visual"):
            for el in list(link.findall(kind)):
                for mesh in el.iter("mesh"):
                    uri = mesh.get("filename") or ""
                    where = f"link {link_name}: {kind} mesh {printable(uri)}"
                    found = _mesh_file(uri, kind, where, source, roots, limits)
                    if found is None:
                        if kind == "collision":
                            raise RobotModelError(source, where, "not found in the package folders given "
                                                  "(--packages) or the source's folder")
                        warnings.append(f"link {link_name}: visual mesh {printable(uri)} not found; shown as its "
                                        "collision mesh")
                        if not collision_meshes:
                            link.remove(el)
                            break
                        mesh.set("filename", collision_meshes[0])
                        continue
                    if meshes.setdefault(found.local, found.real) != found.real:
                        raise RobotModelError(source, where, f"{printable(str(found.real))} and "
                                              f"{printable(str(meshes[found.local]))} would both be {found.local}")
                    mesh.set("filename", found.local)
                    if kind == "collision":
                        collision_meshes.append(found.local)
        for material in link.iter("material"):
            for texture in material.findall("texture"):
                material.remove(texture)
                warnings.append(f"link {link_name}: texture {printable(str(texture.get('filename')))} not imported")
    for material in root.findall("material"):
        for texture in material.findall("texture"):
            material.remove(texture)
            warnings.append(f"material {printable(str(material.get('name')))}: texture "
                            f"{printable(str(texture.get('filename')))} not imported")
    return meshes, warnings


def _build(stage: Path, name: str, urdf_name: str, flange: str, solver: str | None, brand: str | None, source: Path,
           root: ET.Element, T_root_base: FloatArray | None,
           srdf_name: str | None, roots: Sequence[Path] = ()) -> tuple[str, float, RobotSpec, tuple[str, ...]]:
    """Fit the IK, write robot.yaml, and load the staged folder back as any robot folder is."""
    import pinocchio as pin

    from robomax_py.io.robot import load_robot_spec
    from robomax_py.robot import load_robot, urdf_model
    from robomax_py.robot.ik.fit import FitError

    try:
        model = urdf_model((stage / urdf_name).read_text(encoding="utf-8"))
    except Exception as exc:  # noqa: BLE001 - Pinocchio raises plain errors for bad URDFs
        raise RobotModelError(source, None, f"cannot parse URDF: {exc}") from None
    if not model.existFrame(flange):
        frames = ", ".join(f.name for f in model.frames if f.type == pin.FrameType.BODY)
        raise RobotModelError(source, "flange", f"the URDF has no frame '{flange}' (links: {frames})")
    try:
        solver_name, params, fk_error, fallback = _fit(model, int(model.getFrameId(flange)), solver)
    except FitError as exc:
        raise RobotModelError(source, "ik.solver", f"not a {solver}-class arm: {exc.problem}") from None
    # The file's folders too: ROS-Industrial packages name the maker (motoman_gp180_support/urdf/...).
    brand = brand or guess_brand(name, *source.parts[-4:], str(root.get("name", "")))
    convention = _convention(model, int(model.getFrameId(flange)), brand, T_root_base, source, roots)
    _confined(stage, "robot.yaml").write_text(
        _robot_yaml(name, urdf_name, flange, solver_name, params, brand, srdf_name, source, T_root_base, convention),
        encoding="utf-8")
    spec = load_robot_spec(stage / "robot.yaml")
    robot = load_robot(spec)       # the whole folder loads: meshes, pairs, IK checked against the URDF
    flange_z = _flange_z_warning(model, int(model.getFrameId(flange)), flange)
    notes = tuple(n for n in (fallback, flange_z, convention.note) if n is not None)
    return solver_name, fk_error, spec, (*notes, *robot.warnings)


def _unstaged(exc: RobotModelError, stage: Path, source: Path, urdf_name: str) -> RobotModelError:
    """An error met loading the staged folder, naming the source (for the URDF written there) and
    the mesh paths as the URDF names them in the folder rather than the staging folder that is
    about to vanish."""
    file = source if exc.file is None or exc.file.startswith(str(stage)) else exc.file
    problem = exc.problem.replace(str(stage) + os.sep, "").replace(f"URDF {urdf_name}", f"URDF {source.name}")
    return RobotModelError(file, exc.key, problem)


def _named_srdf(warning: str, stage: Path, source: Path, urdf_name: str, srdf: Path | None) -> str:
    """A warning about the staged folder's SRDF, naming the user's SRDF and source instead."""
    text = warning.replace(f"{stage / 'robot.yaml'}: srdf:", f"{srdf}:" if srdf is not None else "srdf:")
    return text.replace(f"URDF {urdf_name}", f"URDF {source.name}").replace(str(stage) + os.sep, "")


def _copy(real: Path, dst: Path, limit: int, source: Path, local: str) -> None:
    """Copy a checked file, never more than `limit` bytes (it may have grown since the check), to a
    new file (an existing file or link at `dst` is an error, never written through)."""
    dst.parent.mkdir(parents=True, exist_ok=True)
    copied = 0
    with open(real, "rb") as src, open(dst, "xb") as target:
        while chunk := src.read(1 << 20):
            copied += len(chunk)
            if copied > limit:
                raise RobotModelError(source, local, f"{printable(str(real))} grew beyond {limit / MB:.0f} MB "
                                      "while it was copied")
            target.write(chunk)


# ------------------------------------------------------------------------------ staging

# A staging folder: `.<robot>.robomax-import-<pid>-<8 random characters>` beside the output folder,
# holding STAGING_MARKER (its first line MARKER_TEXT, then `out <folder name>`) and the robot folder
# being built. The next import in that folder removes one whose process has ended (a killed
# import); nothing else is ever removed.
STAGING_MARKER = ".robomax-import"
MARKER_TEXT = "robomax import-urdf staging folder; removed by the next import once its process has ended\n"
_NAME = r"[A-Za-z0-9_][A-Za-z0-9_.-]*"
_STAGING = re.compile(rf"\.(?P<name>{_NAME})\.robomax-import-(?P<pid>[0-9]+)-[a-z0-9_]{{8}}")


@contextmanager
def _staging(parent: Path, name: str) -> Iterator[Path]:
    """A fresh staging folder in `parent` (created if missing); yields the robot folder to build in
    it. Removed afterwards, and on failure also the parent folders this made."""
    made = _make_folders(parent)
    holder: Path | None = None
    try:
        holder = Path(tempfile.mkdtemp(prefix=f".{name}.robomax-import-{os.getpid()}-", dir=parent))
        with open(holder / STAGING_MARKER, "x", encoding="utf-8") as f:
            f.write(f"{MARKER_TEXT}out {name}\n")
        stage = Path(os.path.realpath(holder / name))
        stage.mkdir()
        yield stage
    except BaseException:
        if holder is not None:
            shutil.rmtree(holder, ignore_errors=True)
            holder = None
        for folder in reversed(made):
            try:
                folder.rmdir()
            except OSError:
                break
        raise
    finally:
        if holder is not None:
            shutil.rmtree(holder, ignore_errors=True)


def _make_folders(folder: Path) -> list[Path]:
    """mkdir -p `folder`; the folders created, outermost first."""
    missing = []
    while not os.path.lexists(folder):
        missing.append(folder)
        if folder.parent == folder:
            break
        folder = folder.parent
    made = []
    for f in reversed(missing):
        f.mkdir()
        made.append(f)
    return made


def clean_stale_staging(parent: Path) -> list[Path]:
    """Remove the staging folders in `parent` left by imports that were killed (their process has
    ended): recognised by their name (`_STAGING`) and their marker file, or empty (killed before the
    marker was written). A folder a killed replacement had moved aside (`old`) is put back first
    when its place is still empty. Returns the folders removed."""
    removed: list[Path] = []
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return removed
    for entry in entries:
        m = _STAGING.fullmatch(entry.name)
        if m is None or not entry.is_dir(follow_symlinks=False) or _alive(int(m["pid"])):
            continue
        folder = Path(entry.path)
        out_name = _marked(folder / STAGING_MARKER)
        if out_name is None:
            try:
                folder.rmdir()           # only ever an empty folder
                removed.append(folder)
            except OSError:
                pass
            continue
        old, target = folder / "old", parent / out_name
        if old.is_dir() and not old.is_symlink() and not os.path.lexists(target):
            try:
                os.rename(old, target)
            except OSError:
                continue             # kept, with the folder it holds, for the user to look at
        shutil.rmtree(folder, ignore_errors=True)
        removed.append(folder)
    return removed


def _marked(marker: Path) -> str | None:
    """The output folder name a staging marker states; None when `marker` is not one."""
    try:
        if marker.is_symlink() or not marker.is_file() or marker.stat().st_size > 4096:
            return None
        text = marker.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    if not text.startswith(MARKER_TEXT):
        return None
    m = re.fullmatch(rf"out ({_NAME})\n", text[len(MARKER_TEXT):])
    return None if m is None else m.group(1)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def _commit(stage: Path, out: Path) -> None:
    """Put the staged folder at `out` in one step: a rename, or (replacing a folder) an atomic
    exchange, so that `out` is the old folder or the new one at every instant. Where the system
    cannot exchange, the old folder is moved into the staging folder first (a kill between the two
    renames leaves it there, and the next import puts it back)."""
    if not os.path.lexists(out):
        os.rename(stage, out)
        return
    if out.is_symlink() or not out.is_dir():
        raise RobotModelError(out, None, "exists and is not a folder")
    if _exchange(stage, out):
        return                       # the old folder is now at `stage`, removed with the staging folder
    os.rename(out, stage.parent / "old")
    os.rename(stage, out)


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux renameat2 RENAME_EXCHANGE); False where unsupported."""
    import ctypes
    import errno

    try:
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    at_fdcwd, rename_exchange = -100, 2
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), str(b))


def _digest(folder: Path) -> str:
    h = hashlib.sha256()
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        h.update(str(path.relative_to(folder)).encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()
