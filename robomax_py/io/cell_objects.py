"""A cell file's objects as specs: their poses (degrees in the file) and shapes, a mesh read and
checked within the cell's triangle limits (`io.cell_limits`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robomax_py.errors import CellFileError
from robomax_py.io.cell_file_dynamic import DynamicObjectFile
from robomax_py.io.cell_file_values import ObjectFile, PoseFile
from robomax_py.io.cell_limits import _check_mesh_readable
from robomax_py.io.mesh_keys import mesh_shape
from robomax_py.safe_files import LIMITS, checked_file, named_by
from robomax_py.spec import (
    Box,
    Capsule,
    Cylinder,
    ObjectSpec,
    Shape,
    Sphere,
    frozen_array,
)
from robomax_py.transforms import pose_matrix
from robomax_py.units import deg_to_rad


def _pose(pose: PoseFile) -> np.ndarray:
    return pose_matrix(pose.xyz, [deg_to_rad(a) for a in pose.rpy])


def _object(obj: ObjectFile, path: Path, key: str, triangles: list[int]) -> ObjectSpec:
    """The object's spec; a mesh is read (and refused when unreadable or too large) and its
    triangles are added to `triangles`."""
    shape: Shape
    if obj.box is not None:
        shape = Box(extents=(obj.box[0], obj.box[1], obj.box[2]))
    elif obj.cylinder is not None:
        shape = Cylinder(radius=obj.cylinder.radius, length=obj.cylinder.length)
    elif obj.sphere is not None:
        shape = Sphere(radius=obj.sphere.radius)
    elif obj.capsule is not None:
        shape = Capsule(radius=obj.capsule.radius, length=obj.capsule.length)
    else:
        assert obj.mesh is not None  # guaranteed by ObjectFile._one_shape
        named = path.parent / obj.mesh
        mesh = checked_file(named, LIMITS.mesh, named_by(CellFileError, path, f"{key}.mesh"), f"mesh {named}")
        shape = mesh_shape(mesh, obj.units, obj.scale, obj.tolerance, path, key)
        triangles.append(_check_mesh_readable(shape, CellFileError(path, f"{key}.mesh", f"cannot read mesh {mesh}"),
                                              triangles))
    present = None
    if isinstance(obj, DynamicObjectFile) and obj.present is not None:
        present = tuple((float(t0), float(t1)) for t0, t1 in obj.present)
    return ObjectSpec(
        name=obj.name, shape=shape, T_world_object=frozen_array(_pose(obj.pose)),
        workpiece=obj.workpiece, present=present, signal=obj.signal,
    )
