"""The value types the cell file's keys take, shared by its sections: bounded names and file
references, finite and positive numbers, poses, time windows, an object and its shape; the checks
they run, and the limits on a cell's size (docs/limits.md). The models of the sections
(`cell_file`, `cell_file_dynamic`, `cell_file_jobs`) are built from these, so this module imports
none of them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, TypeVar

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    model_validator,
)

from robomax_py.errors import CellFileError
from robomax_py.io.mesh_keys import (
    MESH_ONLY_KEYS,
    MeshScale,
    MeshTolerance,
    MeshUnits,
    misplaced_mesh_keys,
)

# The type variable of the generic helpers of `cell_problems`.
T = TypeVar("T")
SUPPORTED_VERSIONS = (1,)
# A direction this close to parallel with the normal (sine of the angle) leaves no seam direction.
MIN_DIRECTION_SINE = 1e-3

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Vec3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]
# A place in a cell or station, m: beyond 1000 km it is no place at all (a hostile or broken file),
# and the geometry code squares such coordinates past the floats' range (1e308 m made the collision
# world's eigen-solver fail). A cell written in millimetres (thousands of "metres") is read, and
# `cell_lint` names it.
MAX_COORDINATE_M = 1e6
Coordinate = Annotated[float, Field(ge=-MAX_COORDINATE_M, le=MAX_COORDINATE_M, allow_inf_nan=False)]
Place = Annotated[list[Coordinate], Field(min_length=3, max_length=3)]
# Names end up in messages, program identifiers and (the cell's) file names: printable text of a
# bounded length; a cell name is also a file stem, so no path separators and at most 100 characters.
MAX_NAME_CHARS = 200
MAX_CELL_NAME_CHARS = 100
# Dynamic windows beyond a day of program time are a typo, and would overflow the time grid.
MAX_WINDOW_S = 86_400.0


@dataclass(frozen=True, slots=True)
class CellLimits:
    """The most one cell may ask for (docs/limits.md), checked at load
    before anything is planned: planning time and memory grow with each. A spot costs its seam's
    orientations x approach samples x IK columns of IK table and its candidates' approach lines;
    every object adds pairs to every collision check; triangles are held in memory as BVHs."""

    spots: int = 2_000                  # spots of all seams together (a robot welds tens per cycle)
    objects: int = 1_000                # objects and dynamic objects together
    orientations: int = 1_000           # per seam: its grid's orientations and its spots' pinned ones
    mesh_triangles: int = 2_000_000     # one mesh
    cell_triangles: int = 5_000_000     # every mesh of the cell and its tool together


CELL_LIMITS = CellLimits()
# A tolerance range this narrow is one orientation sample (as `plan.poses.axis_samples` takes it).
SAME_ORIENTATION_RAD = 1e-9


def _printable_name(v: str) -> str:
    if not v.strip():
        raise ValueError("must not be blank")
    bad = next((ch for ch in v if not ch.isprintable()), None)
    if bad is not None:
        raise ValueError(f"must be printable text, got the control character {bad!a}")
    return v


# Names Windows keeps for devices, whatever extension follows ("con.srcl" opens the console), and
# characters it refuses in a file name (Microsoft, "Naming Files, Paths, and Namespaces").
_WINDOWS_DEVICES = frozenset({"con", "prn", "aux", "nul", *(f"com{i}" for i in range(1, 10)),
                              *(f"lpt{i}" for i in range(1, 10))})
_WINDOWS_REFUSED = '<>:"|?*'


def file_stem(v: str) -> str:
    """A name the programs' files are named after: one file name on every system a cell may be
    planned on (a cell folder is shared between Linux and the integrator's Windows laptop)."""
    _printable_name(v)
    if any(sep in v for sep in "/\\") or v in (".", ".."):
        raise ValueError(f"is the program's file name: no '/', '\\', '.' or '..', got {v!r}")
    if v.startswith("."):
        raise ValueError(f"is the program's file name: it must not start with '.' (a hidden file), got {v!r}")
    refused = next((ch for ch in v if ch in _WINDOWS_REFUSED), None)
    if refused is not None:
        raise ValueError(f"is the program's file name: no {refused!r} (Windows refuses {_WINDOWS_REFUSED} in file "
                         f"names), got {v!r}")
    if v.endswith((".", " ")):
        raise ValueError(f"is the program's file name: it must not end with '.' or ' ' (Windows drops them), "
                         f"got {v!r}")
    if v.split(".")[0].rstrip(" ").lower() in _WINDOWS_DEVICES:
        raise ValueError(f"is the program's file name: {v!r} is a name Windows keeps for a device "
                         "(CON, PRN, AUX, NUL, COM1-9, LPT1-9)")
    return v


def stem_name(path: Path) -> str:
    """The name of a cell or station whose file gives none: its file stem, under the rules of
    `name` (CellFileError naming `name` otherwise)."""
    stem = path.stem
    if len(stem) > MAX_CELL_NAME_CHARS:
        raise CellFileError(path, "name", f"not given, and the file name is longer than {MAX_CELL_NAME_CHARS} "
                            "characters (the programs are named after the cell); give a shorter name:")
    try:
        return file_stem(stem)
    except ValueError as exc:
        raise CellFileError(path, "name", f"not given, and the file's stem {exc}: give a name") from None


def _reference(v: str) -> str:
    """A robot or tool: a library name or a path; printable, and short enough for the file system."""
    _printable_name(v)
    if len(v) > 4096 or any(len(part.encode()) > 255 for part in v.replace("\\", "/").split("/")):
        raise ValueError("is longer than a file name or path can be")
    return v


Name = Annotated[str, Field(min_length=1, max_length=MAX_NAME_CHARS), AfterValidator(_printable_name)]
CellName = Annotated[str, Field(min_length=1, max_length=MAX_CELL_NAME_CHARS), AfterValidator(file_stem)]
Reference = Annotated[str, Field(min_length=1), AfterValidator(_reference)]
WindowTime = Annotated[float, Field(ge=0, le=MAX_WINDOW_S, allow_inf_nan=False)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class PoseFile(_Strict):
    xyz: Place = [0.0, 0.0, 0.0]     # m
    rpy: Vec3 = [0.0, 0.0, 0.0]      # deg


class CylinderFile(_Strict):
    radius: Positive
    length: Positive


class SphereFile(_Strict):
    radius: Positive


_SHAPE_KEYS = ("box", "cylinder", "sphere", "capsule", "mesh")


class ObjectFile(_Strict):
    name: Name
    box: Annotated[list[Positive], Field(min_length=3, max_length=3)] | None = None
    cylinder: CylinderFile | None = None
    sphere: SphereFile | None = None
    capsule: CylinderFile | None = None
    mesh: Reference | None = None
    units: MeshUnits | None = None      # of the mesh file's numbers (docs/cad.md)
    scale: MeshScale | None = None
    tolerance: MeshTolerance | None = None
    pose: PoseFile = PoseFile()
    frame: Name | None = None           # pose given in this frame (docs/frames.md); default: the world
    workpiece: bool = False
    signal: Name | None = None          # extension: clamp interlock input (docs/cell-extensions.md)

    @model_validator(mode="after")
    def _one_shape(self) -> ObjectFile:
        _check_one_shape(self)
        return self


def _check_one_shape(obj: ObjectFile) -> None:
    given = [k for k in _SHAPE_KEYS if getattr(obj, k) is not None]
    if len(given) != 1:
        got = ", ".join(given) if given else "none"
        raise ValueError(f"exactly one of {', '.join(_SHAPE_KEYS)} is required, got {got}")
    if (stray := misplaced_mesh_keys({k: getattr(obj, k) for k in ("mesh", *MESH_ONLY_KEYS)})) is not None:
        raise ValueError(stray)


Window = Annotated[list[WindowTime], Field(min_length=2, max_length=2)]


def _windows_in_order(windows: list[list[float]] | None) -> list[list[float]] | None:
    for i, (t0, t1) in enumerate(windows or ()):
        assert windows is not None
        if not t0 < t1:
            raise ValueError(f"window {i} [{t0}, {t1}]: start must be before end")
        if i and t0 < windows[i - 1][1]:
            raise ValueError(f"window {i} starts at {t0}, before window {i - 1} ends at {windows[i - 1][1]}")
    return windows
