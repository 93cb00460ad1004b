"""The links' collision and visual geometry of a URDF (Pinocchio geometry models), collision meshes
as their convex hulls, built once per process and reused while the arm's files are unchanged."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py.errors import RobotModelError
from robomax_py.robot.geometry import (
    LINK_HULL_EXCESS_M,
    LINK_HULL_MAX_VERTICES,
    hull_shape,
    load_mesh,
    outer_hull,
)
from robomax_py.robot.kinematics import _urdf_text, pinocchio_urdf_text
from robomax_py.robot.mesh_cache import kept_arrays
from robomax_py.spec import RobotSpec

# Link geometry already built in this process, by (URDF, package folders, kind): with the state
# (size, modification time, inode) of the URDF and of every mesh file it read. Loading an arm
# builds its meshes and their convex hulls (0.3-0.6 s); a batch, a preview that reloads or a
# sweep of checks loads the same arm again and again. An entry is used only while none of those
# files has changed, and a copy is handed out (the geometry objects are shared, never modified).
_GEOMETRY: dict[tuple[str, tuple[str, ...], str], tuple[tuple[tuple[str, int, int, int], ...], pin.GeometryModel]] = {}
_GEOMETRY_ENTRIES = 8


def _file_states(urdf: Path, geom_model: pin.GeometryModel) -> tuple[tuple[str, int, int, int], ...] | None:
    """(path, size, mtime_ns, inode) of the URDF and of each mesh file the model was built from;
    None when one cannot be read (then nothing is kept)."""
    paths = [str(urdf), *sorted({o.meshPath for o in geom_model.geometryObjects if o.meshPath
                                 and o.meshPath not in ("BOX", "SPHERE", "CYLINDER", "CAPSULE", "CONE")})]
    try:
        return tuple((p, (st := Path(p).stat()).st_size, st.st_mtime_ns, st.st_ino) for p in paths)
    except OSError:
        return None


def _geometry(model: pin.Model, spec: RobotSpec, kind: Any, package_dirs: list[str]) -> pin.GeometryModel:
    """The links' geometry of `kind` (collision meshes as convex hulls), built or reused."""
    key = (str(Path(spec.urdf).resolve()), tuple(package_dirs), f"{kind}|{model.njoints}|{model.nframes}")
    hit = _GEOMETRY.get(key)
    if hit is not None and _file_states(spec.urdf, hit[1]) == hit[0]:
        return hit[1].copy()
    geom_model = _build_geometry(model, spec, kind, package_dirs)
    if kind == pin.GeometryType.COLLISION:
        _make_meshes_convex(geom_model, spec)
    states = _file_states(spec.urdf, geom_model)
    if states is not None:
        if len(_GEOMETRY) >= _GEOMETRY_ENTRIES:
            del _GEOMETRY[next(iter(_GEOMETRY))]
        _GEOMETRY[key] = (states, geom_model)
    return geom_model.copy()


def _build_geometry(model: pin.Model, spec: RobotSpec, kind: Any, package_dirs: list[str]) -> pin.GeometryModel:
    text = pinocchio_urdf_text(_urdf_text(spec.urdf, spec.source))
    try:
        return pin.buildGeomFromUrdfString(model, text, kind, package_dirs=package_dirs)
    except Exception as exc:  # noqa: BLE001 - a missing or unreadable mesh surfaces here, of any kind
        raise RobotModelError(spec.urdf, None, f"cannot load link geometry: {exc}") from None


def _make_meshes_convex(geom_model: pin.GeometryModel, spec: RobotSpec) -> None:
    """Replace link meshes by their convex hulls: fast GJK instead of BVH, and conservative. A hull
    of many vertices by an outer polytope of fewer, within LINK_HULL_EXCESS_M of it (`outer_hull`)."""
    for obj in geom_model.geometryObjects:
        if not obj.meshPath or obj.meshPath in ("BOX", "SPHERE", "CYLINDER", "CAPSULE", "CONE"):
            continue
        path, scale = Path(obj.meshPath), np.asarray(obj.meshScale, dtype=float)

        def hull(path: Path = path, scale: np.ndarray = scale) -> dict[str, np.ndarray]:
            return {"vertices": outer_hull(load_mesh(path, scale).vertices)}

        try:
            # The hull read back from the cache when an earlier run built it from the same file.
            params = ("link hull", tuple(scale.tolist()), "outer", LINK_HULL_EXCESS_M, LINK_HULL_MAX_VERTICES)
            vertices = kept_arrays("hull", path, params, hull)["vertices"]
        except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for unreadable files
            raise RobotModelError(spec.urdf, f"link {obj.name}", f"cannot read mesh {obj.meshPath}: {exc}") from None
        obj.geometry = hull_shape(vertices)
