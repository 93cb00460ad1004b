"""robot.yaml and tool.yaml (SPEC §1, §2) -> checked RobotSpec / ToolSpec.

Owns the keys of those two files. A robot or tool is named either by folder name (looked up in the
package's `robots/` and `robots/tools/`) or by a path, relative to the file that names it.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from robomax_py._files import read_yaml_mapping, validation_error
from robomax_py.errors import RobotModelError
from robomax_py.spec import RobotSpec, ToolSpec, frozen_array
from robomax_py.transforms import pose_matrix
from robomax_py.units import degs_to_rads

Finite = Annotated[float, Field(allow_inf_nan=False)]
Vec3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class PoseFile(_Strict):
    xyz: Vec3 = [0.0, 0.0, 0.0]
    rpy: Vec3 = [0.0, 0.0, 0.0]               # deg


class IkFile(_Strict):
    solver: str
    params: dict[str, Any] = {}


class LimitsFile(_Strict):
    acceleration: list[Finite] | None = None  # deg/s^2 (m/s^2 for a prismatic joint)
    jerk: list[Finite] | None = None          # deg/s^3

    @field_validator("acceleration", "jerk")
    @classmethod
    def _positive(cls, v: list[float] | None) -> list[float] | None:
        if v is not None and any(x <= 0 for x in v):
            raise ValueError(f"every value must be > 0, got {v}")
        return v


class RobotFile(_Strict):
    name: str
    urdf: str
    flange: str
    ik: IkFile
    limits: LimitsFile = LimitsFile()
    # Extensions to SPEC §1, both optional and informational.
    payload: Annotated[float, Field(gt=0, allow_inf_nan=False)] | None = None   # kg
    description: str = ""


class ToolFile(_Strict):
    name: str
    body: str
    tips: str
    tcp: PoseFile = PoseFile()


def package_robots_dir() -> Path:
    """The shipped robot library; ROBOMAX_ROBOTS overrides it (tests, site-specific libraries)."""
    override = os.environ.get("ROBOMAX_ROBOTS")
    return Path(override) if override else Path(__file__).resolve().parent.parent / "robots"


def resolve_robot_file(ref: str, relative_to: Path) -> Path:
    """A cell's `robot.model`: a folder name in robots/, or a path to a robot.yaml."""
    return _resolve(ref, relative_to, package_robots_dir(), "robot.yaml")


def resolve_tool_file(ref: str, relative_to: Path) -> Path:
    """A cell's `tool`: a folder name in robots/tools/, or a path to a tool.yaml."""
    return _resolve(ref, relative_to, package_robots_dir() / "tools", "tool.yaml")


def _resolve(ref: str, relative_to: Path, library: Path, filename: str) -> Path:
    looks_like_path = "/" in ref or "\\" in ref or ref.endswith((".yaml", ".yml"))
    if not looks_like_path:
        return library / ref / filename
    path = (relative_to.parent / ref).resolve()
    return path / filename if path.is_dir() else path


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


def resolve_package_uri(uri: str, file: Path, key: str) -> Path:
    """package://<pkg>/<rest> -> a file inside an installed package's share folder."""
    rest = uri[len("package://"):]
    for share in package_share_dirs():
        candidate = share / rest
        if candidate.exists():
            return candidate
    raise RobotModelError(file, key, f"{uri} not found in any installed package")


def load_robot_spec(path: Path) -> RobotSpec:
    """Read and check a robot.yaml. Limits whose length needs the URDF are checked by `robot.load_robot`."""
    from robomax_py.ik import params_from_mapping

    data = read_yaml_mapping(path, RobotModelError, "robot description")
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
    if not urdf.is_file():
        raise RobotModelError(path, "urdf", f"file not found: {urdf}")
    try:
        ik_params = params_from_mapping(parsed.ik.solver, parsed.ik.params)
    except RobotModelError as exc:
        key = exc.key if exc.key != "ik.params.solver" else "ik.solver"
        raise RobotModelError(path, key, exc.problem) from None
    return RobotSpec(
        name=parsed.name,
        source=path.resolve(),
        urdf=urdf,
        flange=parsed.flange,
        ik_solver=parsed.ik.solver,
        ik_params=ik_params,
        acceleration=None if parsed.limits.acceleration is None else frozen_array(degs_to_rads(parsed.limits.acceleration)),
        jerk=None if parsed.limits.jerk is None else frozen_array(degs_to_rads(parsed.limits.jerk)),
        payload_kg=parsed.payload,
        description=parsed.description,
    )


def load_tool_spec(path: Path) -> ToolSpec:
    """Read and check a tool.yaml; its meshes must exist (they are read when the scene is built)."""
    data = read_yaml_mapping(path, RobotModelError, "tool description")
    try:
        parsed = ToolFile.model_validate(data)
    except ValidationError as exc:
        raise validation_error(exc, ToolFile, path, RobotModelError) from None
    meshes = {}
    for key in ("body", "tips"):
        mesh = (path.parent / getattr(parsed, key)).resolve()
        if not mesh.is_file():
            raise RobotModelError(path, key, f"mesh file not found: {mesh}")
        meshes[key] = mesh
    rpy = [math.radians(a) for a in parsed.tcp.rpy]
    return ToolSpec(
        name=parsed.name,
        source=path.resolve(),
        body=meshes["body"],
        tips=meshes["tips"],
        T_flange_tcp=frozen_array(pose_matrix(parsed.tcp.xyz, rpy)),
    )
