"""Shapes and meshes -> coal collision geometry.

Convex hulls are built with `coal.Convex.convexHull` from trimesh's hull vertices: coal 3.0.3's
`BVHModel.buildConvexRepresentation` has reported clearance between meshes that overlap. A mesh is
replaced by convex pieces only when each piece *is* convex (hull volume equals piece volume);
otherwise it stays an exact BVH, so a shortcut never changes a collision answer.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import TYPE_CHECKING

import coal
import numpy as np

from robomax_py.robot.cad import is_step, load_step
from robomax_py.spec import Box, Capsule, Cylinder, MeshShape, Shape, Sphere
from robomax_py.tolerances import DEFAULT as TOL

# trimesh is imported where a mesh is read or built: a run that finds what it needs of its meshes
# in the cache (`mesh_cache`) never imports it.
if TYPE_CHECKING:
    import trimesh

# Relative volume difference below which a closed piece counts as convex (mesh tessellation noise).
CONVEX_VOLUME_RTOL = TOL.convex_volume_rtol


def load_mesh(path: Path, scale: np.ndarray | None = None, tolerance: float | None = None) -> trimesh.Trimesh:
    """Any format trimesh reads, flattened into one triangle mesh (scene graphs concatenated), times
    `scale`; a STEP file (`cad.load_step`, in metres from the unit it states) meshed at `tolerance`
    (m; None: `cad.DEFAULT_TOLERANCE_MM`).

    A vertex that is not finite is an error: trimesh's processing would drop it and the faces using
    it without a word, and the collision geometry would have holes.

    Each call returns a mesh of its own (a caller may move or change it), but a file read before in
    this process, unchanged since, is not parsed again: a run whose cache folder has nothing of a
    mesh asks for it four or five times (its triangle count, the lint's checks, its collision
    pieces, its extents), and a tessellated CAD part of 800,000 triangles takes about 2 s to parse.
    """
    try:
        info = Path(path).stat()
    except OSError:
        return _load_mesh(Path(path), scale, tolerance)         # raises as it would have
    scale_key = None if scale is None else (np.shape(scale), tuple(float(v) for v in np.ravel(scale)))
    return _parsed_mesh(str(Path(path).resolve()), info.st_size, info.st_mtime_ns, info.st_ino,
                        scale_key, tolerance).copy()


# Meshes kept parsed: a cell's part, fixtures and tool (a batch worker plans cell after cell, and a
# tessellated part of 790,528 triangles holds 77 MB, by tracemalloc).
@functools.lru_cache(maxsize=4)
def _parsed_mesh(path: str, size: int, mtime_ns: int, inode: int,
                 scale: tuple[tuple[int, ...], tuple[float, ...]] | None, tolerance: float | None) -> trimesh.Trimesh:
    """`_load_mesh`, once per process while the file's size, modification time and inode are the
    same (a failure is not kept: it raises again at the next call)."""
    factor = None if scale is None else np.asarray(scale[1], dtype=float).reshape(scale[0])
    return _load_mesh(Path(path), factor, tolerance)


def _load_mesh(path: Path, scale: np.ndarray | None, tolerance: float | None) -> trimesh.Trimesh:
    import trimesh

    loaded = (load_step(path, None if tolerance is None else tolerance * 1000.0) if is_step(path)
              else trimesh.load(str(path), force="mesh", process=False))
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise ValueError("no triangles in file")
    bad = ~np.isfinite(np.asarray(loaded.vertices)).all(axis=1)
    if bad.any():
        raise ValueError(f"{int(bad.sum())} of {len(bad)} vertices are not finite (NaN or infinity), "
                         f"the first at index {int(np.flatnonzero(bad)[0])}")
    loaded.process()
    if scale is not None and not np.allclose(scale, 1.0):
        loaded.apply_scale(np.asarray(scale, dtype=float))  # type: ignore[no-untyped-call]
    return loaded


def hull_vertices(vertices: np.ndarray) -> np.ndarray:
    """(k, 3) float, m: the vertices of the convex hull of a point set (trimesh's, in its order)."""
    import trimesh

    hull = trimesh.convex.convex_hull(np.asarray(vertices, dtype=float))
    return np.asarray(hull.vertices, dtype=float)


# A link hull of more vertices than this is replaced by an outer polytope of fewer (`outer_hull`).
# ROS-Industrial's collision meshes are often the visual ones: an LR Mate's forearm hull has 2,927
# vertices, and coal's test of it against a meshed obstacle took 67 us where the outer polytope's
# (232 vertices) takes 11 us. The shipped arms' hulls have at most 245 and stay as they are.
LINK_HULL_MAX_VERTICES = 256
# How far the outer polytope may reach beyond the hull, m: a link's collision mesh is itself an
# outer stand-in for the casting, and 1 mm is below every clearance a cell states.
LINK_HULL_EXCESS_M = 0.001
# Supporting planes the outer polytope starts from: an icosphere's 42 vertex directions.
_START_DIRECTIONS = 1
# Hull planes added per round: those most violated by the polytope's farthest vertices.
_ADDED_PER_ROUND = 16


def outer_hull(vertices: np.ndarray, excess: float = LINK_HULL_EXCESS_M,
               above: int = LINK_HULL_MAX_VERTICES) -> np.ndarray:
    """(k, 3) float, m: the vertices of a convex polytope that contains the convex hull of
    `vertices` and reaches at most `excess` beyond it, k < the hull's vertex count; the hull's
    own vertices when it has no more than `above` of them, or is flat.

    The polytope is an intersection of the hull's supporting planes: first in 42 directions, then,
    round by round, the hull's own face planes that its farthest vertices violate most, until no
    vertex lies more than `excess` from the hull. Its farthest point from the hull is one of its
    vertices (the distance to a convex set is convex), so that bound holds for all of it, and it
    contains the hull because every plane supports it."""
    import trimesh
    from scipy.spatial import ConvexHull, HalfspaceIntersection

    surface = trimesh.convex.convex_hull(np.asarray(vertices, dtype=float))    # as `hull_vertices` builds it
    points = np.asarray(surface.vertices, dtype=float)
    if len(points) <= above:
        return points
    normals = np.asarray(surface.face_normals, dtype=float)
    # (m, 4): n . x + d <= 0 inside, n the outward unit normal of each hull face.
    faces = np.column_stack([normals, -np.einsum("ij,ij->i", normals, np.asarray(surface.triangles)[:, 0])])
    inside = points.mean(axis=0)
    if not np.all(faces[:, :3] @ inside + faces[:, 3] < -1e-6):   # flat or degenerate: kept as it is
        return points
    dirs = np.asarray(trimesh.creation.icosphere(subdivisions=_START_DIRECTIONS).vertices, dtype=float)
    planes = np.column_stack([dirs, -(points @ dirs.T).max(axis=0)])
    for _ in range(len(faces)):
        corners = HalfspaceIntersection(planes, inside).intersections
        corners = corners[ConvexHull(corners).vertices]
        _, distance, _ = trimesh.proximity.closest_point(surface, corners)  # type: ignore[no-untyped-call]
        out = np.flatnonzero(np.asarray(distance) > excess)
        if not out.size:
            return corners if len(corners) < len(points) else points
        worst = out[np.argsort(-np.asarray(distance)[out])[:_ADDED_PER_ROUND]]
        violated = np.unique(np.argmax(corners[worst] @ faces[:, :3].T + faces[:, 3], axis=1))
        planes = np.vstack([planes, faces[violated]])
    return points


def hull_shape(hull: np.ndarray) -> coal.ConvexBase:
    """coal convex polytope of the hull vertices `hull_vertices` gave (m)."""
    points = coal.StdVec_Vec3s()
    for p in np.asarray(hull, dtype=float):
        points.append(p)
    return coal.Convex.convexHull(points, False, None)


def bvh_of(vertices: np.ndarray, faces: np.ndarray) -> coal.BVHModelOBBRSS:
    """Exact triangle-soup collision model of vertices (n, 3) m and faces (k, 3) int."""
    bvh = coal.BVHModelOBBRSS()
    bvh.beginModel(len(faces), len(vertices))
    bvh.addVertices(np.ascontiguousarray(vertices, dtype=float))
    bvh.addTriangles(np.ascontiguousarray(faces, dtype=np.int64))
    bvh.endModel()
    return bvh


def is_convex_piece(piece: trimesh.Trimesh) -> bool:
    if not piece.is_watertight or piece.volume <= 0:
        return False
    hull_volume = piece.convex_hull.volume
    return bool(abs(hull_volume - piece.volume) <= CONVEX_VOLUME_RTOL * hull_volume + 1e-12)


def mesh_collision_shapes(mesh: trimesh.Trimesh) -> list[coal.CollisionGeometry]:
    """Convex pieces when the mesh is a set of closed convex shells, else one exact BVH."""
    return collision_shapes_of(collision_piece_arrays(mesh))


def collision_piece_arrays(mesh: trimesh.Trimesh) -> dict[str, np.ndarray]:
    """`mesh_collision_shapes`' choice as arrays, to keep: the hull vertices of each convex piece
    (hull_0, hull_1, ...) when the mesh is a set of closed convex shells, else the mesh's vertices
    and faces for one exact BVH."""
    import trimesh

    # trimesh's `split` (its pieces' holes of a triangle or a quad filled), one piece at a time,
    # stopping at the first that is no closed convex shell: splitting all of a tessellated CAD part
    # (often a soup of tens of thousands of open patches) first cost seconds.
    components = trimesh.graph.connected_components(edges=mesh.face_adjacency, nodes=np.arange(len(mesh.faces)),
                                                    min_len=1)
    pieces: list[trimesh.Trimesh] = []
    for faces in components:
        made = mesh.submesh([faces], only_watertight=False, repair=True)
        piece = made[0] if isinstance(made, list) else made        # a list of one, for a list of one
        if not is_convex_piece(piece):
            return _whole(mesh)
        pieces.append(piece)
    if pieces:
        return {f"hull_{i}": hull_vertices(p.vertices) for i, p in enumerate(pieces)}
    return _whole(mesh)


def _whole(mesh: trimesh.Trimesh) -> dict[str, np.ndarray]:
    return {"vertices": np.asarray(mesh.vertices, dtype=float), "faces": np.asarray(mesh.faces, dtype=np.int64)}


def collision_shapes_of(arrays: dict[str, np.ndarray]) -> list[coal.CollisionGeometry]:
    """The coal shapes of `collision_piece_arrays`' arrays."""
    if "faces" in arrays:
        return [bvh_of(arrays["vertices"], arrays["faces"])]
    return [hull_shape(arrays[f"hull_{i}"]) for i in range(len(arrays))]


def primitive_shape(shape: Shape) -> coal.CollisionGeometry:
    """coal geometry of a cell-file primitive (docs/cell-files.md), centred on its local frame, axis z."""
    if isinstance(shape, Box):
        return coal.Box(*shape.extents)
    if isinstance(shape, Cylinder):
        return coal.Cylinder(shape.radius, shape.length)
    if isinstance(shape, Sphere):
        return coal.Sphere(shape.radius)
    if isinstance(shape, Capsule):
        return coal.Capsule(shape.radius, shape.length)
    raise TypeError(f"not a primitive: {shape!r}")


def mesh_shape_trimesh(shape: MeshShape) -> trimesh.Trimesh:
    """A cell object's mesh as its cell file states it: scaled by its units and scale, a STEP meshed
    at its tolerance."""
    return load_mesh(shape.path, np.asarray(shape.scale, dtype=float), shape.tolerance)


def shape_trimesh(shape: Shape) -> trimesh.Trimesh:
    """A triangle mesh of any shape in its local frame (for previews and exact-answer tests)."""
    import trimesh

    if isinstance(shape, Box):
        made: trimesh.Trimesh = trimesh.creation.box(extents=shape.extents)
        return made
    if isinstance(shape, Cylinder):
        cylinder: trimesh.Trimesh = trimesh.creation.cylinder(radius=shape.radius, height=shape.length, sections=48)
        return cylinder
    if isinstance(shape, Sphere):
        sphere: trimesh.Trimesh = trimesh.creation.icosphere(subdivisions=3, radius=shape.radius)
        return sphere
    if isinstance(shape, Capsule):
        return trimesh.creation.capsule(height=shape.length, radius=shape.radius, count=[48, 24])
    if isinstance(shape, MeshShape):
        return mesh_shape_trimesh(shape)
    raise TypeError(f"unknown shape: {shape!r}")
