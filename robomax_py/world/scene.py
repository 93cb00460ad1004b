"""Cell objects and tool -> coal collision geometry, posed in the robot base frame.

A `Scene` is what `collision.CollisionWorld` checks the robot against: static obstacles, dynamic
obstacles with their presence windows, and the tool's body and tips pieces in the flange frame.
Built once per cell; read-only afterwards (the coal geometries are shared, never modified).

How each shape becomes collision geometry
-----------------------------------------
- Box, cylinder, sphere, capsule: the exact coal primitive (docs/cell-files.md, "A cell file": centred, axis z).
- Mesh (obstacle, workpiece or tool): `geometry.collision_piece_arrays`: when *every* connected piece
  of the mesh is a closed convex shell, one coal convex polytope per piece (exact, and fast GJK);
  otherwise the whole mesh stays one exact triangle BVH (OBBRSS). Sheet-metal parts such as the
  reference `cabin_panel.stl` are open, bent surfaces, so they stay BVH: a convex hull would fill the
  space between the flange and the panel and forbid exactly the places the gun must reach.
- A BVH is a triangle *surface*: a robot piece entirely inside a closed non-convex mesh without
  touching its triangles is not reported. Swept motions (`CollisionWorld.segment_free`) cannot get
  inside without crossing the surface, which is reported.
- A perfectly flat mesh (zero thickness along a local axis) gets one extra triangle of
  `FLAT_MESH_PAD_M` size standing off the plane, so its bounding box has non-zero volume: Pinocchio's
  broad phase silently ignores geometry whose local bounding box has zero volume.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import coal
import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.robot import RobotModel
from robomax_py.robot.geometry import (
    CONVEX_VOLUME_RTOL,
    collision_piece_arrays,
    collision_shapes_of,
    mesh_shape_trimesh,
    primitive_shape,
)
from robomax_py.robot.mesh_cache import kept_arrays
from robomax_py.spec import (
    Box,
    Capsule,
    CellSpec,
    Cylinder,
    MeshShape,
    ObjectSpec,
    PartSpec,
    PathMotion,
    RobotMotion,
    Shape,
    Sphere,
    frozen_array,
)
from robomax_py.transforms import invert

# Size (m) of the stand-off triangle added to a perfectly flat mesh (see module docstring).
FLAT_MESH_PAD_M = 1e-7

REPRESENTATION_PRIMITIVE = "primitive"
REPRESENTATION_CONVEX = "convex pieces"
REPRESENTATION_BVH = "exact mesh (BVH)"


@dataclass(frozen=True, slots=True, eq=False)
class SceneObject:
    """One obstacle: coal pieces sharing one pose in the robot base frame.

    Attributes
    ----------
    name : str
        The cell's object name.
    pieces : tuple of coal.CollisionGeometry
        In the object's own frame, metres; never modified after the scene is built.
    T_base_object : (4, 4) float
        Object pose in the robot base frame, metres: inv(T_world_base) @ T_world_object.
    workpiece : bool
        The tool tips may touch it.
    representation : str
        "primitive", "convex pieces" or "exact mesh (BVH)" (module docstring says when each is used).
    present : tuple of (start, end) windows in s, or None
        None: a static obstacle, always present. Otherwise present at t iff start <= t <= end for one
        window; `present_at(None)` is True (unknown time: conservatively present).
    """

    name: str
    pieces: tuple[coal.CollisionGeometry, ...]
    T_base_object: FloatArray
    workpiece: bool
    representation: str
    present: tuple[tuple[float, float], ...] | None = None
    # m: a moving object's span counts this much larger (`world.moving`): every check grows by it.
    margin: float = 0.0

    @property
    def dynamic(self) -> bool:
        return self.present is not None

    def present_at(self, t: float | None) -> bool:
        """Whether the obstacle exists at time t (s from program start); t=None counts as present."""
        if self.present is None or t is None:
            return True
        return any(t0 <= t <= t1 for t0, t1 in self.present)


@dataclass(frozen=True, slots=True, eq=False)
class ToolGeometry:
    """The mounted tool: body and electrode-tip pieces in the flange frame, metres.

    The body collides with everything; the tips may touch workpieces (docs/cell-files.md, "The tool folder").
    """

    name: str
    body: tuple[coal.CollisionGeometry, ...]
    tips: tuple[coal.CollisionGeometry, ...]
    body_representation: str
    tips_representation: str
    T_flange_tcp: FloatArray          # (4, 4)


@dataclass(frozen=True, slots=True, eq=False)
class HeldPart:
    """A part in the gripper: pieces in the part's frame, that frame in the flange frame. It may
    touch (never enter) its supports, the objects it rests on where it is gripped and released;
    `up` is the world's up (+z) in the part's frame where it lies, the way it comes off them."""

    name: str
    pieces: tuple[coal.CollisionGeometry, ...]
    T_flange_part: FloatArray         # (4, 4)
    supports: tuple[str, ...]
    up: FloatArray                    # (3,) unit


@dataclass(frozen=True, slots=True, eq=False)
class Scene:
    """Everything the robot can hit, in the robot base frame.

    Attributes
    ----------
    obstacles : tuple of SceneObject
        Static obstacles (`present` is None), in cell order.
    dynamic : tuple of SceneObject
        Obstacles present only in time windows, in cell order.
    tool : ToolGeometry
        Mounted at `flange_frame_id` of the robot the scene was built for.
    T_world_base : (4, 4) float
        Robot base pose in the world (cell) frame, metres.
    """

    cell_name: str
    obstacles: tuple[SceneObject, ...]
    dynamic: tuple[SceneObject, ...]
    tool: ToolGeometry
    T_world_base: FloatArray
    flange_frame_id: int
    held: HeldPart | None = None

    def object(self, name: str) -> SceneObject:
        """The static or dynamic obstacle called `name`; KeyError if there is none."""
        for obj in (*self.obstacles, *self.dynamic):
            if obj.name == name:
                return obj
        raise KeyError(name)


def build_scene(cell: CellSpec, robot: RobotModel, held: PartSpec | None = None) -> Scene:
    """Collision geometry of a cell's objects and tool, posed for `robot`.

    Parameters
    ----------
    cell : CellSpec
        Objects in the world frame; the robot base at `cell.T_world_base`.
    robot : RobotModel
        The robot the tool is mounted on (its flange frame carries the tool pieces).
    held : PartSpec, optional
        A part of the cell in the gripper (carried with the tool).

    Returns
    -------
    Scene
        Obstacles posed in the robot base frame; tool pieces in the flange frame.

    Raises
    ------
    CellFileError
        An object's mesh is missing or unreadable: key `objects[i].mesh` / `dynamic[i].mesh`.
    RobotModelError
        The tool's body or tips mesh is missing or unreadable: tool.yaml key `body` / `tips`.
    """
    T_base_world = invert(np.asarray(cell.T_world_base, dtype=float))
    obstacles = tuple(
        _scene_object(obj, T_base_world, cell.source, f"objects[{i}]") for i, obj in enumerate(cell.objects)
    )
    dynamic = tuple(
        posed for i, obj in enumerate(cell.dynamic)
        for posed in ((_scene_object(obj, T_base_world, cell.source, f"dynamic[{i}]", dynamic=True),)
                      if obj.motion is None else _moving_objects(obj, T_base_world, cell.source, f"dynamic[{i}]"))
    )
    body, body_repr = _mesh_pieces(cell.tool.body, RobotModelError, cell.tool.source, "body")
    tips, tips_repr = _mesh_pieces(cell.tool.tips, RobotModelError, cell.tool.source, "tips")
    tool = ToolGeometry(
        name=cell.tool.name,
        body=body,
        tips=tips,
        body_representation=body_repr,
        tips_representation=tips_repr,
        T_flange_tcp=frozen_array(cell.tool.T_flange_tcp),
    )
    carried = None
    if held is not None:
        pieces, _ = shape_pieces(held.shape, cell.source, f"pick_place.parts[{cell.parts.index(held)}].mesh")
        carried = HeldPart(held.name, pieces, frozen_array(np.asarray(cell.tool.T_flange_tcp) @ held.T_tcp_part),
                           held.supports, held.up)
    return Scene(
        cell_name=cell.name,
        obstacles=obstacles,
        dynamic=dynamic,
        tool=tool,
        T_world_base=frozen_array(cell.T_world_base),
        flange_frame_id=int(robot.flange_frame_id),
        held=carried,
    )


def shape_pieces(shape: Shape, file: Path | None = None, key: str | None = None) -> tuple[tuple[coal.CollisionGeometry, ...], str]:
    """coal pieces of one cell-file shape (docs/cell-files.md) in its own frame, and how it is represented.

    Raises CellFileError(file, key, problem) when a mesh cannot be read.
    """
    if isinstance(shape, (Box, Cylinder, Sphere, Capsule)):
        geom = primitive_shape(shape)
        geom.computeLocalAABB()
        return (geom,), REPRESENTATION_PRIMITIVE
    if isinstance(shape, MeshShape):
        return _mesh_pieces(shape, CellFileError, file, key)
    raise TypeError(f"unknown shape: {shape!r}")


def _scene_object(obj: ObjectSpec, T_base_world: FloatArray, source: Path, key: str, dynamic: bool = False) -> SceneObject:
    pieces, representation = shape_pieces(obj.shape, source, f"{key}.mesh")
    present = obj.present if dynamic else None
    if dynamic and present is None:
        present = ((-np.inf, np.inf),)
    return SceneObject(
        name=obj.name,
        pieces=pieces,
        T_base_object=frozen_array(T_base_world @ np.asarray(obj.T_world_object, dtype=float)),
        workpiece=bool(obj.workpiece),
        representation=representation,
        present=None if present is None else tuple((float(a), float(b)) for a, b in present),
    )


def _moving_objects(obj: ObjectSpec, T_base_world: FloatArray, source: Path, key: str) -> tuple[SceneObject, ...]:
    """A moving object as obstacles standing still in short windows (`world.moving`), all named as
    the object, so contacts and waits name it."""
    from robomax_py.world import moving

    motion = obj.motion
    if isinstance(motion, PathMotion):
        pieces, representation = shape_pieces(obj.shape, source, f"{key}.mesh")
        body = moving.path_body(obj, pieces)
        runs = [(body, s, moving.path_windows(motion, s))
                for w in (((float(motion.t[0]), float(motion.t[-1])),) if motion.repeat is not None else obj.present or ())
                for s in moving.spans(body, w, motion.sweep)]
    else:
        assert isinstance(motion, RobotMotion)
        representation = REPRESENTATION_CONVEX
        bodies = moving.robot_bodies(obj, source, lambda mesh, part: _mesh_pieces(mesh, CellFileError, source,
                                                                                  f"{key}.robot.tool")[0])
        runs = [(b, s, ((s.t0, s.t1),)) for b in bodies for w in obj.present or ((0.0, np.inf),)
                for s in moving.spans(b, w, motion.sweep)]
    if len(runs) > moving.MAX_SPANS:
        raise CellFileError(source, f"{key}.sweep", f"the motion of '{obj.name}' needs {len(runs)} spans of at most "
                            f"{motion.sweep * 1000:g} mm of sweep, more than {moving.MAX_SPANS}: a larger sweep, please")
    return tuple(SceneObject(name=obj.name, pieces=body.pieces,
                             T_base_object=frozen_array(T_base_world @ np.asarray(span.T_world_body)),
                             workpiece=False, representation=representation, present=windows, margin=span.margin)
                 for body, span, windows in runs)


def _mesh_pieces(
    mesh: Path | MeshShape, error: type[CellFileError | RobotModelError], file: Path | None, key: str | None
) -> tuple[tuple[coal.CollisionGeometry, ...], str]:
    """Convex pieces if the mesh is a set of closed convex shells, else one exact BVH (see module doc)."""
    shape = mesh if isinstance(mesh, MeshShape) else MeshShape(path=Path(mesh))
    path = shape.path
    if not Path(path).is_file():
        raise error(file, key, f"mesh file not found: {path}")
    try:
        st = Path(path).stat()
        state: _MeshState | None = (str(Path(path).resolve()), st.st_size, st.st_mtime_ns, st.st_ino,
                                    shape.scale, shape.tolerance)
    except OSError:
        state = None
    if state is not None and state in _MESH_PIECES:
        return _MESH_PIECES[state]
    built = _build_mesh_pieces(shape, error, file, key)
    if state is not None:
        if len(_MESH_PIECES) >= _MESH_ENTRIES:
            del _MESH_PIECES[next(iter(_MESH_PIECES))]
        _MESH_PIECES[state] = built
    return built


# A cell's meshes split into pieces, by (path, size, modification time, inode, scale, tolerance): a
# plan, its proof and `verify` build the scene several times, and splitting a part mesh takes up to
# a second. The pieces are shared between scenes and never modified.
_MeshState = tuple[str, int, int, int, tuple[float, float, float], float | None]
_MESH_PIECES: dict[_MeshState, tuple[tuple[coal.CollisionGeometry, ...], str]] = {}
_MESH_ENTRIES = 32


def _build_mesh_pieces(
    shape: MeshShape, error: type[CellFileError | RobotModelError], file: Path | None, key: str | None
) -> tuple[tuple[coal.CollisionGeometry, ...], str]:
    # The pieces' arrays read back from the cache when an earlier run split the same file.
    params = ("collision pieces", shape.scale, shape.tolerance, CONVEX_VOLUME_RTOL, FLAT_MESH_PAD_M)
    arrays = kept_arrays("pieces", shape.path, params, lambda: _piece_arrays(shape, error, file, key))
    convex = "faces" not in arrays
    pieces = collision_shapes_of(arrays)
    for p in pieces:
        p.computeLocalAABB()
    return tuple(pieces), (REPRESENTATION_CONVEX if convex else REPRESENTATION_BVH)


def _piece_arrays(
    shape: MeshShape, error: type[CellFileError | RobotModelError], file: Path | None, key: str | None
) -> dict[str, np.ndarray]:
    """`geometry.collision_piece_arrays` of the mesh, a flat one's BVH with its stand-off triangle."""
    path = shape.path
    try:
        mesh = mesh_shape_trimesh(shape)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for unreadable files
        raise error(file, key, f"cannot read mesh {path}: {exc}") from None
    arrays = collision_piece_arrays(mesh)
    if "faces" in arrays and np.any(np.ptp(arrays["vertices"], axis=0) <= 0.0):
        arrays["vertices"], arrays["faces"] = _flat_padded(arrays["vertices"], arrays["faces"])
    return arrays


def _flat_padded(vertices: FloatArray, faces: np.ndarray) -> tuple[FloatArray, np.ndarray]:
    """A perfectly flat mesh plus a stand-off triangle, so its bounding box has volume."""
    extents = np.ptp(vertices, axis=0)
    flat = np.flatnonzero(extents <= 0.0)
    v0 = np.asarray(vertices[0], dtype=float)
    pad = np.zeros(3)
    pad[flat] = FLAT_MESH_PAD_M
    other = np.zeros(3)
    other[int(np.argmax(extents))] = FLAT_MESH_PAD_M
    n = len(vertices)
    return np.vstack([vertices, v0 + pad, v0 + other]), np.vstack([faces, [[0, n, n + 1]]])


__all__ = [
    "FLAT_MESH_PAD_M",
    "Scene",
    "SceneObject",
    "ToolGeometry",
    "build_scene",
    "shape_pieces",
]


def distance_to_object(obj: ObjectSpec, point: FloatArray) -> float:
    """Distance (m) from a world point to an object's geometry (0 inside or touching)."""
    probe = coal.Sphere(1e-6)
    T_probe = coal.Transform3s(np.eye(3), np.asarray(point, dtype=float))
    T = np.asarray(obj.T_world_object, dtype=float)
    T_obj = coal.Transform3s(T[:3, :3], T[:3, 3])
    pieces, _ = shape_pieces(obj.shape)
    best = np.inf
    for piece in pieces:
        result = coal.DistanceResult()
        coal.distance(piece, T_obj, probe, T_probe, coal.DistanceRequest(), result)
        best = min(best, max(0.0, float(result.min_distance) + 1e-6))
    return float(best)


def clamps_near(cell: CellSpec, point: FloatArray) -> list[ObjectSpec]:
    """The clamps (objects with an interlock `signal`) within `process.interlock_distance` of a
    world point: a weld there waits for their inputs first."""
    return [o for o in cell.objects
            if o.signal and distance_to_object(o, point) <= cell.process.interlock_distance]
