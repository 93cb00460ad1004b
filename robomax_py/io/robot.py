"""robot.yaml and tool.yaml (docs/cell-files.md, "The robot folder" and "The tool folder") -> checked RobotSpec / ToolSpec.

Owns the keys of those two files. A robot or tool is named either by folder name (looked up in the
robot library path: `--robots` folders, then `ROBOMAX_ROBOTS`, then the shipped library) or by a
path, relative to the file that names it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from robomax_py.errors import RobotModelError
from robomax_py.io.cell_file_values import Place
from robomax_py.io.mesh_keys import MeshScale, MeshTolerance, MeshUnits, mesh_shape
from robomax_py.io.robot_paths import (
    PACKAGE_SEARCH_DEPTH,
    PACKAGE_SEARCH_PARENTS,
    ROBOTS_ENV,
    ROS_PACKAGE_PATH_ENV,
    mesh_candidates,
    package_dirs_for,
    package_share_dirs,
    resolve_package_uri,
    resolve_robot_file,
    resolve_tool_file,
    robot_library,
    shipped_robots_dir,
    urdf_package_dirs,
    urdf_package_names,
)
from robomax_py.io.urdf import (
    JOINT_POSITION_BOUND,
    JOINT_VELOCITY_RANGE,
    ROS_INDUSTRIAL_BASE_LINK,
    bound_continuous_joints,
    check_urdf,
    parse_urdf,
    srdf_disabled_pairs,
    urdf_base_link,
)
from robomax_py.io.yaml_files import read_yaml_mapping, validation_error
from robomax_py.program import ToolLoad
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

# What this module offered before its parts moved out stays importable from here.
__all__ = [
    "JOINT_POSITION_BOUND", "JOINT_VELOCITY_RANGE", "PACKAGE_SEARCH_DEPTH", "PACKAGE_SEARCH_PARENTS",
    "ROBOTS_ENV", "ROS_INDUSTRIAL_BASE_LINK", "ROS_PACKAGE_PATH_ENV", "CollisionFile", "ControllerFile",
    "Finite", "IkFile", "LimitsFile", "LinkName", "LoadedLimitsFile", "PoseFile", "RobotFile", "ToolFile",
    "ToolLoadFile", "ToolMeshFile",
    "Vec3", "bound_continuous_joints", "check_urdf", "load_robot_spec", "load_tool_spec", "mesh_candidates", "package_dirs_for",
    "package_share_dirs", "parse_urdf", "resolve_package_uri", "resolve_robot_file", "resolve_tool_file",
    "robot_library", "shipped_robots_dir", "srdf_disabled_pairs", "urdf_base_link", "urdf_package_dirs",
    "urdf_package_names",
]

Finite = Annotated[float, Field(allow_inf_nan=False)]
Vec3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
LinkName = Annotated[str, Field(min_length=1)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class PoseFile(_Strict):
    xyz: Place = [0.0, 0.0, 0.0]              # m
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


class ToolMeshFile(_Strict):
    """A tool mesh with its own keys, as a cell object gives them beside `mesh` (docs/cad.md)."""

    mesh: str
    units: MeshUnits | None = None
    scale: MeshScale | None = None
    tolerance: MeshTolerance | None = None


class ToolLoadFile(_Strict):
    """The tool's load (docs/cell-files.md, "The tool folder"): mass, kg; centre of gravity in the
    flange frame, m. Programs declare it where the controller takes it (RAPID tooldata, URScript
    set_payload), and a cell checks it against the robot's rated `payload`."""

    mass: Annotated[float, Field(gt=0, allow_inf_nan=False)]
    cog: Vec3


class ToolFile(_Strict):
    name: str
    body: str | ToolMeshFile                  # a path, or {mesh, units, scale, tolerance}
    tips: str | ToolMeshFile
    tcp: PoseFile = PoseFile()
    # Extensions (docs/cad.md, "Tool meshes"): the unit and factor of both meshes' numbers, and a
    # STEP's meshing tolerance; a mesh given as a mapping overrides each key it gives.
    units: MeshUnits | None = None
    scale: MeshScale | None = None
    tolerance: MeshTolerance | None = None
    load: ToolLoadFile | None = None          # extension: mass and centre of gravity; None: not stated


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


# No tool's TCP stands farther from the flange than this, m (the longest spot guns and grippers
# reach about 1.5 m): a farther one is a file in millimetres, where tcp.xyz is metres.
MAX_TCP_OFFSET_M = 5.0


def load_tool_spec(path: Path) -> ToolSpec:
    """Read and check a tool.yaml; its meshes must exist (they are read when the scene is built).

    Each mesh's `units`, `scale` and `tolerance` are its own when it is given as a mapping, else
    the tool's top-level ones; they mean what they mean beside a cell object's mesh (docs/cad.md).
    """
    data = read_yaml_mapping(path, RobotModelError, "tool description", LIMITS.description)
    try:
        parsed = ToolFile.model_validate(data)
    except ValidationError as exc:
        raise validation_error(exc, ToolFile, path, RobotModelError) from None
    meshes = {}
    for key in ("body", "tips"):
        given = getattr(parsed, key)
        own = given if isinstance(given, ToolMeshFile) else ToolMeshFile(mesh=given)
        mesh_key = f"{key}.mesh" if isinstance(given, ToolMeshFile) else key
        named = path.parent / own.mesh
        found = checked_file(named, LIMITS.mesh, named_by(RobotModelError, path, mesh_key), f"mesh {named}")
        # A key the mesh leaves out comes from the top level, and a problem with it is named there.
        keys = {name: name for name in ("units", "scale", "tolerance") if getattr(own, name) is None}
        meshes[key] = mesh_shape(found, own.units or parsed.units,
                                 own.scale if own.scale is not None else parsed.scale,
                                 own.tolerance if own.tolerance is not None else parsed.tolerance,
                                 path, key, RobotModelError, keys)
    offset = math.dist(parsed.tcp.xyz, (0.0, 0.0, 0.0))
    if offset > MAX_TCP_OFFSET_M:
        raise RobotModelError(path, "tcp.xyz", f"{parsed.tcp.xyz} puts the TCP {offset:g} m from the flange, farther "
                              f"than any tool reaches ({MAX_TCP_OFFSET_M:g} m): tcp.xyz is in metres (in mm? "
                              f"{[round(v / 1000, 6) for v in parsed.tcp.xyz]})")
    rpy = [math.radians(a) for a in parsed.tcp.rpy]
    return ToolSpec(
        name=parsed.name,
        source=path.resolve(),
        body=meshes["body"],
        tips=meshes["tips"],
        T_flange_tcp=frozen_array(pose_matrix(parsed.tcp.xyz, rpy)),
        load=None if parsed.load is None else ToolLoad(parsed.load.mass, (parsed.load.cog[0], parsed.load.cog[1],
                                                                         parsed.load.cog[2])),
    )
