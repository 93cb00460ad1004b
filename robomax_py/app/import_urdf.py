"""`robomax import-urdf`: a URDF or xacro from a ROS package -> a self-contained robot folder.

The folder holds the expanded URDF with relative mesh paths, the meshes it names (copied), an SRDF
when one is given, and a robot.yaml with IK parameters fitted from the URDF and checked against its
forward kinematics; when the URDF has a ROS-Industrial `base` link (the vendor's base frame), the
robot.yaml states its pose as `controller.base`, so the folder says which frame Cartesian targets are
in. It is built in a temporary folder beside the target, loaded back as any robot folder is
(`robot.load_robot`), and only then moved into place: a failure leaves nothing behind.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import shutil
import sys
import tempfile
import time
import types
import xml.etree.ElementTree as ET
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from robomax_py._typing import FloatArray
from robomax_py.errors import RobotModelError
from robomax_py.io.robot import mesh_candidates, package_dirs_for, urdf_base_link
from robomax_py.transforms import rpy_from_matrix

MESH_SUFFIXES = (".stl", ".dae", ".obj", ".ply", ".off", ".glb", ".gltf")
_BRAND_PATTERNS = (
    ("kuka", re.compile(r"kuka|(^|[^a-z])kr\s*\d", re.I)),
    ("abb", re.compile(r"abb|irb\s*\d", re.I)),
    ("fanuc", re.compile(r"fanuc|lrmate|(^|[^a-z])(m|r|cr|crx|arc|lr)[-_]?\d+i[a-z]", re.I)),
    ("ur", re.compile(r"(^|[^a-z])ur\d+e?([^a-z0-9]|$)|universal", re.I)),
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
    """kuka | abb | fanuc | ur from a robot's name or file names; kuka when nothing matches."""
    for brand, pattern in _BRAND_PATTERNS:
        if any(pattern.search(n) for n in names):
            return brand
    return "kuka"


@contextmanager
def _ament_stand_in(roots: Sequence[Path], near: Path) -> Iterator[None]:
    """xacro's `$(find pkg)` asks ament_index_python; answer from our package search instead."""

    def share(name: str) -> str:
        for root in roots:
            if root.name == name and root.is_dir():
                return str(root)
            if (root / name).is_dir():
                return str(root / name)
        found = package_dirs_for(name, near)
        if not found:
            raise LookupError(f"package '{name}' not found (give its folder or a parent with --packages)")
        return str(found[0] / name)

    packages = types.ModuleType("ament_index_python.packages")
    packages.get_package_share_directory = share  # type: ignore[attr-defined]
    top = types.ModuleType("ament_index_python")
    top.packages = packages  # type: ignore[attr-defined]
    saved = {k: sys.modules.get(k) for k in ("ament_index_python", "ament_index_python.packages")}
    sys.modules["ament_index_python"], sys.modules["ament_index_python.packages"] = top, packages
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                sys.modules.pop(k, None)
            else:
                sys.modules[k] = v


def expand(source: Path, packages: Sequence[Path]) -> str:
    """The URDF text of a .urdf file, or of a .xacro expanded with the xacro package (without ROS)."""
    if not source.is_file():
        raise RobotModelError(source, None, "file not found")
    if source.suffix != ".xacro":
        try:
            return source.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise RobotModelError(source, None, f"cannot read URDF: {exc}") from None
    import xacro

    with _ament_stand_in(packages, source.parent):
        try:
            doc = xacro.process_file(str(source))
            return str(doc.toprettyxml(indent="  "))
        except Exception as exc:  # xacro raises its own and plain errors (XacroException, KeyError, ...)
            raise RobotModelError(source, None, f"xacro does not expand: {type(exc).__name__}: {exc}") from None


def _resolve_mesh(uri: str, source: Path, packages: Sequence[Path]) -> Path | None:
    """The file a mesh `filename` names: under the --packages folders first, then as any URDF's."""
    dirs: list[Path] = []
    if uri.startswith("package://"):
        name = uri[len("package://"):].partition("/")[0]
        dirs = [r.parent if r.name == name else r for r in packages] + package_dirs_for(name, source.parent)
    return next((c for c in mesh_candidates(uri, source, dirs) if c.is_file()), None)


def _local_name(uri: str) -> str:
    """Where a mesh goes inside the folder: meshes/<package>/<path>, or meshes/<file name>."""
    if uri.startswith("package://"):
        return "meshes/" + uri[len("package://"):]
    return "meshes/" + Path(uri).name


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
                source: Path, T_root_base: FloatArray | None) -> str:
    """The robot.yaml text. `T_root_base` (4, 4), metres: the URDF's ROS-Industrial `base` link in
    its root frame (`io.robot.urdf_base_link`), written as `controller.base`; None when the URDF has
    none (a UR arm then gets the UR controller's base, `base_link` turned 180 deg about z)."""
    from robomax_py.robot.ik.opw import OpwParams
    from robomax_py.robot.ik.ur import UrParams

    lines = [
        f"# Imported by `robomax import-urdf` from {source.name}; IK parameters fitted from the URDF's",
        "# joint origins and axes and checked against its forward kinematics.",
        f"name: {name}",
        f"description: {name} (imported from {source.name})",
        f"urdf: {urdf}",
        f"flange: {flange}",
        "ik:",
        f"  solver: {solver}",
    ]
    if isinstance(params, OpwParams):
        lines.append("  params:")
        for key in ("a1", "a2", "b", "c1", "c2", "c3", "c4"):
            lines.append(f"    {key}: {_number(getattr(params, key))}")
        lines.append(f"    offsets: [{', '.join(_number(math.degrees(o)) for o in params.offsets)}]")
        lines.append(f"    sign_corrections: [{', '.join(str(s) for s in params.sign_corrections)}]")
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
    if srdf is not None:
        lines.append(f"srdf: {srdf}")
    return "\n".join(lines) + "\n"


def _fit(model: object, frame_id: int, solver: str | None) -> tuple[str, object, float]:
    from robomax_py.robot.ik.fit import FitError, fit_opw, fit_ur, fk_agreement

    tried: list[str] = []
    for name, fit in (("opw", fit_opw), ("ur", fit_ur)):
        if solver not in (None, name):
            continue
        try:
            params = fit(model, frame_id)  # type: ignore[arg-type]
        except FitError as exc:
            tried.append(f"{name}: {exc.problem}")
            continue
        agreement = fk_agreement(model, frame_id, params)  # type: ignore[arg-type]
        if agreement.ok:
            return name, params, agreement.position_m
        tried.append(f"{name}: fitted parameters disagree with the URDF by {agreement.position_m * 1000:.3f} mm")
    if solver in (None, "numeric"):
        return "numeric", None, 0.0
    raise FitError("; ".join(tried))


def import_urdf(
    source: Path, out: Path, packages: Sequence[Path] = (), *, name: str | None = None, flange: str = "tool0",
    srdf: Path | None = None, solver: str | None = None, brand: str | None = None, force: bool = False,
) -> ImportResult:
    """Write the robot folder `out` from `source` (.urdf or .xacro); see the module docstring.

    Raises
    ------
    RobotModelError
        The source does not expand or parse, a collision mesh is missing, the flange frame is not
        in the URDF, the chain is not of the requested solver's class, or `out` exists with other
        content and `force` is not set.
    """
    import pinocchio as pin

    from robomax_py.io.robot import load_robot_spec, srdf_disabled_pairs
    from robomax_py.robot import load_robot
    from robomax_py.robot.ik.fit import FitError

    t0 = time.perf_counter()
    source = Path(source)
    packages = tuple(Path(p).resolve() for p in packages)
    name = name or out.name
    if name != out.name:
        raise RobotModelError(out, None, f"the folder must be named after the robot (SPEC §1): {name!r}")
    if not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.-]*", name):
        raise RobotModelError(out, None, f"robot name {name!r} must be letters, digits, '_', '.', '-'")
    text = expand(source, packages)
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise RobotModelError(source, None, f"not a valid URDF (XML): {exc}") from None
    if root.tag != "robot":
        raise RobotModelError(source, None, f"not a URDF: the root element is <{root.tag}>, not <robot>")
    T_root_base = urdf_base_link(root, source)

    warnings: list[str] = []
    files: dict[str, bytes] = {}
    for link in root.iter("link"):
        collisions = {m.get("filename") for el in link.iter("collision") for m in el.iter("mesh")}
        for kind in ("collision", "visual"):
            for el in list(link.iter(kind)):
                for mesh in el.iter("mesh"):
                    uri = mesh.get("filename") or ""
                    found = _resolve_mesh(uri, source, packages)
                    if found is None:
                        if kind == "collision":
                            raise RobotModelError(source, f"link {link.get('name')}: collision mesh", f"{uri} not found")
                        warnings.append(f"link {link.get('name')}: visual mesh {uri} not found; shown as its collision mesh")
                        fallback = next(iter(collisions - {None}), None)
                        if fallback is None:
                            link.remove(el)
                            break
                        mesh.set("filename", _local_name(fallback))
                        continue
                    local = _local_name(uri)
                    files[local] = found.read_bytes()
                    mesh.set("filename", local)
    urdf_name = f"{name}.urdf"
    files[urdf_name] = ET.tostring(root, encoding="unicode").encode("utf-8") + b"\n"

    with tempfile.TemporaryDirectory(prefix=f".{name}.", dir=_existing_parent(out)) as tmp:
        stage = Path(tmp) / name
        for rel, data in files.items():
            (stage / rel).parent.mkdir(parents=True, exist_ok=True)
            (stage / rel).write_bytes(data)
        try:
            model = pin.buildModelFromUrdf(str(stage / urdf_name))
        except Exception as exc:  # Pinocchio raises plain errors for bad URDFs
            raise RobotModelError(source, None, f"cannot parse URDF: {exc}") from None
        if not model.existFrame(flange):
            frames = ", ".join(f.name for f in model.frames if f.type == pin.FrameType.BODY)
            raise RobotModelError(source, "flange", f"the URDF has no frame '{flange}' (links: {frames})")
        try:
            solver_name, params, fk_error = _fit(model, int(model.getFrameId(flange)), solver)
        except FitError as exc:
            raise RobotModelError(source, "ik.solver", f"not a {solver}-class arm: {exc.problem}") from None
        srdf_name = None
        if srdf is not None:
            srdf_disabled_pairs(Path(srdf), Path(srdf))   # readable, every pair has two links
            srdf_name = f"{name}.srdf"
            (stage / srdf_name).write_bytes(Path(srdf).read_bytes())
        brand = brand or guess_brand(name, source.name, str(root.get("name", "")))
        (stage / "robot.yaml").write_text(
            _robot_yaml(name, urdf_name, flange, solver_name, params, brand, srdf_name, source, T_root_base),
            encoding="utf-8")
        spec = load_robot_spec(stage / "robot.yaml")
        robot = load_robot(spec)       # the whole folder loads: meshes, pairs, IK checked against the URDF
        warnings.extend(w.replace(str(stage), str(out)) for w in robot.warnings if "limits." in w)
        unchanged = out.is_dir() and _digest(out) == _digest(stage)
        if not unchanged:
            if out.exists() and not force:
                raise RobotModelError(out, None, "exists with other content; use --force to replace it")
            _replace(stage, out)
    return ImportResult(out, name, solver_name, brand, sum(1 for f in files if f.startswith("meshes/")),
                        len(spec.srdf_disabled_links), fk_error, time.perf_counter() - t0, unchanged, tuple(warnings))


def _existing_parent(out: Path) -> Path:
    parent = out.resolve().parent
    parent.mkdir(parents=True, exist_ok=True)
    return parent


def _digest(folder: Path) -> str:
    h = hashlib.sha256()
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        h.update(str(path.relative_to(folder)).encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def _replace(stage: Path, out: Path) -> None:
    """Move the staged folder to `out`, the old one (if any) out of the way first, so a reader
    sees the old folder or the new one, never a mix."""
    old = None
    if out.exists():
        old = out.with_name(f".{out.name}.old-{os.getpid()}")
        os.replace(out, old)
    os.replace(stage, out)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
