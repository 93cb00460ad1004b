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

import json
import os
import re
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from robomax_py._typing import FloatArray
from robomax_py.app import xacro_sandbox
from robomax_py.app.import_urdf_fit import (
    CONVENTION_UNKNOWN,
    FLANGE_Z_WARNING,
    NUMERIC_COST,
    AlwaysTouching,
    Convention,
    _convention,
    _fit,
    _flange_z_warning,
    _robot_yaml,
)
from robomax_py.app.import_urdf_staging import (
    _NAME,
    MARKER_TEXT,
    STAGING_MARKER,
    _commit,
    _copy,
    _digest,
    _inside,
    _staging,
    clean_stale_staging,
)
from robomax_py.app.xacro_sandbox.expansion import _package_candidates
from robomax_py.errors import RobotModelError
from robomax_py.io.robot import (
    bound_continuous_joints,
    check_urdf,
    srdf_disabled_pairs,
    urdf_base_link,
)
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

# What the robot.yaml / IK fit and staging modules hold stays importable from here.
__all__ = [
    "CONVENTION_UNKNOWN", "FLANGE_Z_WARNING", "MARKER_TEXT", "MESH_SUFFIXES", "NUMERIC_COST", "STAGING_MARKER",
    "Convention", "Expanded", "ImportResult", "allowed_folders", "clean_stale_staging", "expand", "expanded",
    "guess_brand", "import_urdf",
]

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
    # Kawasaki's own ROS packages say `khi` (Kawasaki-Robotics/khi_robot@57200db5:
    # khi_rs_description/urdf/rs080n.urdf.xacro, `<robot name="khi_rs080n">`); its RS arms are
    # RS<payload><N|L|X>, its dual arm duAro.
    ("kawasaki", re.compile(r"kawasaki|(^|[^a-z])khi([^a-z]|$)|(^|[^a-z])rs\d{3}[nlx]([^a-z]|$)|duaro",
                            re.IGNORECASE)),
    ("comau", re.compile(r"comau", re.IGNORECASE)),
    ("nachi", re.compile(r"nachi", re.IGNORECASE)),
)
# What robot.yaml says when no name tells the maker (the brand decides how the programs count the
# joints and state the frames, so the import says it guessed).
DEFAULT_BRAND = "kuka"
BRAND_UNKNOWN = ("the controller brand is not told by the robot's name or its files' names ({names}): robot.yaml "
                 f"says {DEFAULT_BRAND}; pass --brand (kuka, abb, fanuc, ur, yaskawa, kawasaki, staubli, comau, "
                 "nachi) or edit controller.brand before writing programs for another controller")


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
    # Link pairs touching in every sampled posture, written to robot.yaml's `collision.disable`.
    always_touching: AlwaysTouching


def guess_brand(*names: str) -> str | None:
    """A controller brand (kuka, abb, fanuc, ur, yaskawa, staubli, kawasaki, comau, nachi) from a
    robot's name or file names; None when no name tells."""
    for brand, pattern in _BRAND_PATTERNS:
        if any(pattern.search(n) for n in names):
            return brand
    return None


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
        done = subprocess.run([sys.executable, "-I", "-X", "utf8", str(Path(xacro_sandbox.__file__).with_name("__main__.py"))],
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
    endless = bound_continuous_joints(root)
    if endless:
        warnings.append(f"{source}: joint(s) {', '.join(endless)} continuous: imported as revolute within ±360 deg; "
                        f"set the controller's software limits in {out / (name + '.urdf')}")
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
                solver_name, fk_error, spec, robot_warnings, touching = _build(
                    stage, name, urdf_name, flange, solver, brand, source, root, T_root_base,
                    None if srdf_text is None else f"{name}.srdf", roots)
            except RobotModelError as exc:
                raise _unstaged(exc, stage, source, urdf_name) from None
            warnings.extend(w for w in robot_warnings if w.startswith(
                ("the controller brand", "IK falls back", "the flange frame", "joint directions", "the URDF's joint axes", "abb_driver")))
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
                        fk_error, time.perf_counter() - t0, unchanged, tuple(warnings), touching)


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
           srdf_name: str | None, roots: Sequence[Path] = (),
           ) -> tuple[str, float, RobotSpec, tuple[str, ...], AlwaysTouching]:
    """Fit the IK, write robot.yaml, and load the staged folder back as any robot folder is.

    Link pairs the collision world would keep checked though they touch in every one of its seeded
    samples (`world.acm.always_touching_links`: the arm alone, pairs its SRDF disables left out)
    would make every posture a collision. Like MoveIt's Setup Assistant, which disables the pairs
    in collision in (nearly) all of its random samples ("Always"; moveit_setup_srdf_plugins
    `computeDefaultCollisions(..., trials, min_collision_fraction, ...)`,
    https://docs.ros.org/en/iron/p/moveit_setup_srdf_plugins/generated/function_compute__default__collisions_8hpp_1a2812f73b447d838cd7dba1b0ee1a0c95.html),
    the import writes them into `collision.disable`, with the reason, and names them in its summary
    for the user to review. Only pairs touching in *every* sample are taken: one that separates
    anywhere may be a real collision."""
    import pinocchio as pin

    from robomax_py.io.robot import load_robot_spec
    from robomax_py.robot import load_robot, urdf_model
    from robomax_py.robot.ik.fit import FitError
    from robomax_py.world.acm import CollisionOptions, always_touching_links

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
    names = (name, *source.parts[-4:], str(root.get("name", "")))
    brand_note = None
    if brand is None:
        brand = guess_brand(*names)
        if brand is None:
            brand = DEFAULT_BRAND
            shown = (name, source.name, str(root.get("name", "")), source.parent.parent.name)
            brand_note = BRAND_UNKNOWN.format(names=", ".join(dict.fromkeys(n for n in shown if n)))
    convention = _convention(model, int(model.getFrameId(flange)), brand, T_root_base, source, roots)

    def written(touching: AlwaysTouching | None) -> RobotSpec:
        _confined(stage, "robot.yaml").write_text(
            _robot_yaml(name, urdf_name, flange, solver_name, params, brand, srdf_name, source, T_root_base,
                        convention, touching), encoding="utf-8")
        return load_robot_spec(stage / "robot.yaml")

    spec = written(None)
    robot = load_robot(spec)       # the whole folder loads: meshes, pairs, IK checked against the URDF
    options = CollisionOptions()   # the plan's own: the same seeded samples
    touching = AlwaysTouching(always_touching_links(robot, options), options.acm_samples)
    if touching.pairs:
        spec = written(touching)
        robot = load_robot(spec)   # and loads again with the pairs written
    flange_z = _flange_z_warning(model, int(model.getFrameId(flange)), flange)
    notes = tuple(n for n in (brand_note, fallback, flange_z, convention.note) if n is not None)
    return solver_name, fk_error, spec, (*notes, *robot.warnings), touching


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
