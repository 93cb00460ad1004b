"""The keys beside a mesh: `units`, `scale` and `tolerance` (docs/cad.md), for a cell object's
`mesh` and a tool.yaml's `body` and `tips` alike.

    - name: door
      mesh: parts/door.step       # or .stl, .obj, .ply, .glb ...
      units: mm                   # the unit of the numbers in the mesh file: m (default) or mm
      scale: 1                    # a further factor, one number or one per axis (default 1)
      tolerance: 0.1              # STEP only: largest mesh-to-surface distance, in `units`

A STEP file states its own length unit and is read in metres from it, so for a STEP `units` only
says what `tolerance` is written in; it defaults to the unit the file states (mm in nearly every
file from a CAD system) and, when given, must be that unit.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field

from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.robot.cad import (
    DEFAULT_TOLERANCE_MM,
    MIN_TOLERANCE_MM,
    is_step,
    step_length_unit,
)
from robomax_py.spec import MeshShape

MeshUnits = Literal["m", "mm"]
_Factor = Annotated[float, Field(gt=0, allow_inf_nan=False)]
MeshScale = _Factor | Annotated[list[_Factor], Field(min_length=3, max_length=3)]
MeshTolerance = Annotated[float, Field(gt=0, allow_inf_nan=False)]

METRES_PER_UNIT = {"m": 1.0, "mm": 0.001}
MESH_ONLY_KEYS = ("units", "scale", "tolerance")


def misplaced_mesh_keys(given: dict[str, object]) -> str | None:
    """The problem when `units`, `scale` or `tolerance` are given to an object that has no mesh."""
    if given.get("mesh") is not None:
        return None
    stray = [k for k in MESH_ONLY_KEYS if given.get(k) is not None]
    if not stray:
        return None
    return f"{', '.join(stray)} belong{'s' if len(stray) == 1 else ''} to a mesh; this object has none"


def mesh_shape(mesh: Path, units: MeshUnits | None, scale: float | list[float] | None, tolerance: float | None,
               file: Path, key: str, error: type[CellFileError | RobotModelError] = CellFileError,
               keys: Mapping[str, str] | None = None) -> MeshShape:
    """The MeshShape of a mesh file (checked to exist and be readable) and the keys beside it.

    `key` is the item the keys sit in (a cell's `objects[i]`): a problem with `units` is reported
    at `{key}.units`, unless `keys` names another place for it (a tool.yaml's top-level `units`,
    given for both its meshes). `error` (CellFileError, or RobotModelError for a tool.yaml) is
    raised, naming `file`, on keys that do not fit the mesh file.
    """
    def at(name: str) -> str:
        return (keys or {}).get(name, f"{key}.{name}")

    factors = (1.0, 1.0, 1.0)
    if isinstance(scale, list):
        factors = (float(scale[0]), float(scale[1]), float(scale[2]))
    elif scale is not None:
        factors = (float(scale),) * 3
    if not is_step(mesh):
        if tolerance is not None:
            raise error(file, at("tolerance"), f"{mesh.name} is already triangles; a tolerance is "
                                               "for meshing a STEP file (.step, .stp)")
        unit = METRES_PER_UNIT[units or "m"]
        return MeshShape(path=mesh, scale=(factors[0] * unit, factors[1] * unit, factors[2] * unit))
    try:
        stated = step_length_unit(mesh)
    except OSError:
        stated = None                           # unreadable: refused, naming the mesh key, when it is read
    if units is not None and stated in METRES_PER_UNIT and units != stated:
        raise error(file, at("units"), f"{mesh.name} states its lengths in {stated} and is read in "
                                       f"them; units: {units} contradicts it (leave units out, or "
                                       f"write units: {stated})")
    unit_name = units or (stated if stated in METRES_PER_UNIT else "mm")
    metres = (DEFAULT_TOLERANCE_MM / 1000.0 if tolerance is None
              else float(tolerance) * METRES_PER_UNIT[unit_name])
    if metres < MIN_TOLERANCE_MM / 1000.0:
        raise error(file, at("tolerance"), f"{tolerance:g} {unit_name} is finer than the "
                                           f"{MIN_TOLERANCE_MM:g} mm a STEP is meshed at, at the finest")
    return MeshShape(path=mesh, scale=factors, tolerance=metres)
