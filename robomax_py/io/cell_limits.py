"""A cell within `CELL_LIMITS`: its spots, objects, orientations per seam and mesh triangles, each
counted before the work it would cost (a list composed, a seam solved, a mesh read) is done."""

from __future__ import annotations

import re
import stat
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.io.cell_file import CellFile
from robomax_py.io.cell_file_values import CELL_LIMITS, SAME_ORIENTATION_RAD
from robomax_py.robot.geometry import load_mesh, mesh_shape_trimesh
from robomax_py.robot.mesh_cache import kept_arrays
from robomax_py.safe_files import LIMITS
from robomax_py.spec import MeshShape
from robomax_py.units import deg_to_rad


def _check_mesh_readable(shape: Path | MeshShape, error: CellFileError | RobotModelError, triangles: list[int]) -> int:
    """The mesh's triangles, when it reads, has at most `CELL_LIMITS.mesh_triangles` and keeps the
    cell's meshes read so far (`triangles`) within `CELL_LIMITS.cell_triangles`. What the file
    states of its size is judged before it is read (reading a mesh of millions of triangles takes
    seconds)."""
    mesh = shape.path if isinstance(shape, MeshShape) else shape
    limit, total = CELL_LIMITS.mesh_triangles, sum(triangles)
    declared, exact = _declared_triangles(mesh)
    more = "" if exact else " or more"
    if declared > limit:
        raise type(error)(error.file, error.key, f"mesh {mesh} has {declared:,} triangles{more}, more than the "
                                                 f"{limit:,} a mesh may have (mesh_triangles)")
    if total + declared > CELL_LIMITS.cell_triangles:
        raise type(error)(error.file, error.key, f"mesh {mesh} brings the cell's meshes and its tool's to "
                                                 f"{total + declared:,} triangles{more}, more than the "
                                                 f"{CELL_LIMITS.cell_triangles:,} a cell may have (cell_triangles)")

    def count() -> dict[str, np.ndarray]:
        loaded = mesh_shape_trimesh(shape) if isinstance(shape, MeshShape) else load_mesh(mesh)
        return {"triangles": np.array([len(loaded.faces)], dtype=np.int64)}

    params = ("triangles", shape.scale, shape.tolerance) if isinstance(shape, MeshShape) else ("triangles",)
    try:
        # The count read back from the cache when an earlier run read the same file.
        n = int(kept_arrays("triangles", mesh, params, count)["triangles"][0])
    except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for unreadable files
        raise type(error)(error.file, error.key, f"{error.problem}: {exc}") from None
    if n > limit:
        raise type(error)(error.file, error.key, f"mesh {mesh} has {n:,} triangles, more than the {limit:,} a mesh "
                                                 "may have (mesh_triangles)")
    return n


def _declared_triangles(mesh: Path) -> tuple[int, bool]:
    """As many triangles as the file states before it is read, at least, and whether exactly: a
    binary STL's count (exact: its size is 84 bytes plus 50 per triangle), a PLY header's faces, an
    OBJ's face lines (a face is one triangle or more); 0 for other formats or a file that cannot
    be read, is not a regular file or is larger than LIMITS.mesh (refused when it is checked)."""
    suffix = mesh.suffix.lower()
    try:
        info = mesh.stat()
        size = info.st_size
        if not stat.S_ISREG(info.st_mode) or size > LIMITS.mesh:
            return 0, False
        if suffix == ".stl":
            with open(mesh, "rb") as fh:
                head = fh.read(84)
            n = int.from_bytes(head[80:84], "little") if len(head) == 84 else 0
            return (n, True) if size == 84 + 50 * n else (0, False)
        if suffix == ".ply":
            with open(mesh, "rb") as fh:
                header = fh.read(4096).split(b"end_header", 1)[0]
            found = re.search(rb"^element\s+face\s+(\d{1,12})\s*$", header, re.MULTILINE)
            return (int(found.group(1)) if found else 0), False
        if suffix == ".obj":
            faces, tail = 0, b"\n"             # a face line starts the file or follows a line end
            with open(mesh, "rb") as fh:
                while chunk := fh.read(1 << 24):
                    data = tail + chunk
                    faces += data.count(b"\nf ") + data.count(b"\nf\t")
                    tail = data[-2:]
            return faces, False
    except OSError:
        pass
    return 0, False


def _check_declared_triangles(parsed: CellFile, path: Path) -> None:
    """The cell's meshes within `CELL_LIMITS.cell_triangles` by what their files state
    (`_declared_triangles`), before any is read: three meshes of 1.9 million triangles each were
    read, 20 s of CPU, before the third was refused. The tool's meshes and what the files do not
    state are counted as they are read."""
    named = [(f"objects[{i}]", o) for i, o in enumerate(parsed.objects)]
    named += [(f"dynamic[{i}]", o) for i, o in enumerate(parsed.dynamic)]
    if parsed.tending is not None:
        named += [(f"tending.machines[{i}].door", m.door) for i, m in enumerate(parsed.tending.machines)]
    if parsed.pick_place is not None:
        named += [(f"pick_place.parts[{i}]", p) for i, p in enumerate(parsed.pick_place.parts)]
    total, exact = 0, True
    for key, obj in named:
        if obj.mesh is None:
            continue
        n, known = _declared_triangles(path.parent / obj.mesh)
        total, exact = total + n, exact and known
        if total > CELL_LIMITS.cell_triangles:
            raise CellFileError(path, f"{key}.mesh", f"the cell's meshes up to this one have {total:,} triangles"
                                f"{'' if exact else ' or more'}, more than the {CELL_LIMITS.cell_triangles:,} a "
                                "cell may have (cell_triangles)")


def _check_counts(data: dict[str, Any], path: Path) -> None:
    """Spots and objects within `CELL_LIMITS`, counted in the file's data before it is validated."""
    seams = data.get("seams")
    spots = sum(len(s["spots"]) for s in seams if isinstance(s, dict) and isinstance(s.get("spots"), list)) \
        if isinstance(seams, list) else 0
    objects = sum(len(v) for v in (data.get("objects"), data.get("dynamic")) if isinstance(v, list))
    _refuse_counts(spots, objects, path)


def _refuse_counts(spots: int, objects: int, path: Path) -> None:
    if spots > CELL_LIMITS.spots:
        raise CellFileError(path, "seams", f"{spots:,} spots, more than the {CELL_LIMITS.spots:,} a cell may have "
                                           "(spots); split the job into cells")
    if objects > CELL_LIMITS.objects:
        raise CellFileError(path, "objects", f"{objects:,} objects and dynamic objects, more than the "
                                             f"{CELL_LIMITS.objects:,} a cell may have (objects)")


def _check_orientations(parsed: CellFile, path: Path) -> None:
    """Each seam's orientations (its grid's samples, as `plan.poses.orientation_grid` takes them,
    and its spots' pinned orientations) within `CELL_LIMITS.orientations`: every spot of the seam
    is solved at every one of them."""
    for i, seam in enumerate(parsed.seams):
        tol = seam.tolerance
        ranges = (2 * deg_to_rad(tol.alpha), 2 * deg_to_rad(tol.beta), deg_to_rad(tol.gamma[1] - tol.gamma[0]))
        grid = 1
        for r in ranges:
            grid *= 1 if seam.grid == 1 or r <= SAME_ORIENTATION_RAD else seam.grid
        pinned = sum(1 for s in seam.spots if s.alpha is not None and not s.skip)
        if grid + pinned > CELL_LIMITS.orientations:
            raise CellFileError(path, f"seams[{i}].grid", f"{grid:,} grid orientations and {pinned:,} pinned ones, "
                                f"more than the {CELL_LIMITS.orientations:,} a seam may have (orientations): "
                                "every spot is solved at each")
