"""What the preview draws into meshcat, under `ROOT` in the cell frame: the cell's objects in their
roles' colours, the carried parts, the robot's links and its tool, the spots with their TCP
frames, the TCP path by phase and the free-space voxels; and the links' poses at joint values.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray
from robomax_py.app import palette
from robomax_py.app.preview_parts import CarriedPart
from robomax_py.app.preview_program import ShownProgram
from robomax_py.errors import RobotModelError
from robomax_py.plan.poses import nominal_rotation
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.robot.geometry import load_mesh, shape_trimesh
from robomax_py.spec import Box, Capsule, CellSpec, Cylinder, Shape, Sphere
from robomax_py.world.scene import build_scene
from robomax_py.world.voxels import VoxelMap

ROOT = "robomax"                       # the meshcat path everything is drawn under
SPOT_MARKER_RADIUS_M = 0.006
TRIAD_SCALE_M = 0.06


@dataclass(frozen=True, slots=True, eq=False)
class _LinkNode:
    """One visual geometry of the robot: its mesh in the geometry frame and where it is attached."""

    path: str
    geometry_index: int
    vertices: FloatArray
    faces: Any


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "_"


def _mesh_geometry(vertices: FloatArray, faces: Any) -> Any:
    import meshcat.geometry as g

    return g.TriangularMeshGeometry(np.asarray(vertices, dtype=np.float32), np.asarray(faces, dtype=np.uint32))


def _draw_objects(root: Any, cell: CellSpec, robot: RobotModel) -> list[tuple[str, str, int]]:
    import meshcat.geometry as g

    # Moving objects are drawn and animated by `preview_moving` (a scene holds them as many spans).
    standing = tuple(d for d in cell.dynamic if d.motion is None)
    scene = build_scene(replace(cell, dynamic=standing), robot)
    T_world_base = np.asarray(cell.T_world_base, dtype=float)
    drawn = []
    for specs, posed, dynamic in ((cell.objects, scene.obstacles, False), (standing, scene.dynamic, True)):
        for spec, obj in zip(specs, posed):
            role = palette.object_role(spec, dynamic=dynamic)
            colour = palette.ROLE_COLOURS[role]
            mesh = shape_trimesh(spec.shape)
            opacity = palette.DYNAMIC_OPACITY if dynamic else 1.0
            path = f"cell/{role}/{_safe(obj.name)}"
            root[path].set_object(_mesh_geometry(mesh.vertices, mesh.faces),
                                  g.MeshLambertMaterial(color=colour, opacity=opacity))
            root[path].set_transform(T_world_base @ np.asarray(obj.T_base_object, dtype=float))
            drawn.append((path, role, colour))
    return drawn


def _draw_parts(root: Any, carried: list[CarriedPart]) -> list[str]:
    """The transfers' parts (pick and place), in the workpiece colour."""
    import meshcat.geometry as g

    drawn = []
    for item in carried:
        mesh = shape_trimesh(item.part.shape)
        path = f"cell/carried/{_safe(item.name)}"
        root[path].set_object(_mesh_geometry(mesh.vertices, mesh.faces), g.MeshLambertMaterial(color=palette.ROLE_COLOURS["part"]))
        drawn.append(path)
    return drawn


def _pose_parts(at: Any, carried: list[CarriedPart], paths: list[str], t: float, T_world_tcp: FloatArray,
                animated: bool = False) -> None:
    """Each part where it is at program time t (an animation frame's properties are typed)."""
    for item, path in zip(carried, paths):
        T = item.pose(t, T_world_tcp)
        if animated:
            at[path].set_property("visible", "boolean", T is not None)
        else:
            at[path].set_property("visible", T is not None)
        if T is not None:
            at[path].set_transform(T)


def _draw_tool(root: Any, cell: CellSpec) -> list[str]:
    import meshcat.geometry as g

    drawn = []
    for part, shape, colour in (("body", cell.tool.body, palette.TOOL_BODY), ("tips", cell.tool.tips, palette.TOOL_TIPS)):
        try:
            mesh = shape_trimesh(shape)         # in its units and scale, as the collision world reads it
        except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for unreadable files
            raise RobotModelError(cell.tool.source, part, f"cannot read mesh {shape.path}: {exc}") from None
        path = f"robot/tool/{part}"
        root[path].set_object(_mesh_geometry(mesh.vertices, mesh.faces), g.MeshLambertMaterial(color=colour))
        drawn.append(path)
    return drawn


def _link_nodes(robot: RobotModel) -> list[_LinkNode]:
    nodes = []
    for k, obj in enumerate(robot.visual_model.geometryObjects):
        mesh_path = str(obj.meshPath or "")
        if mesh_path and Path(mesh_path).is_file():
            try:
                mesh = load_mesh(Path(mesh_path), np.asarray(obj.meshScale, dtype=float))
            except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for unreadable files
                raise RobotModelError(robot.source, f"link {obj.name}", f"cannot read mesh {mesh_path}: {exc}") from None
        else:
            shape = _coal_shape(obj.geometry)
            if shape is None:
                continue                       # a geometry type meshcat cannot show (e.g. a plane)
            mesh = shape_trimesh(shape)
        nodes.append(_LinkNode(f"robot/links/{k}_{_safe(obj.name)}", k, np.asarray(mesh.vertices, dtype=float), mesh.faces))
    return nodes


def _coal_shape(geom: Any) -> Shape | None:
    """The cell-file shape of a coal primitive, or None for other geometry."""
    import coal

    if isinstance(geom, coal.Box):
        h = np.asarray(geom.halfSide, dtype=float)
        return Box((2 * float(h[0]), 2 * float(h[1]), 2 * float(h[2])))
    if isinstance(geom, coal.Capsule):
        return Capsule(float(geom.radius), 2 * float(geom.halfLength))
    if isinstance(geom, coal.Cylinder):
        return Cylinder(float(geom.radius), 2 * float(geom.halfLength))
    if isinstance(geom, coal.Sphere):
        return Sphere(float(geom.radius))
    return None


def _node_poses(robot: RobotModel, links: list[_LinkNode], T_world_base: FloatArray, q: FloatArray) -> dict[str, FloatArray]:
    """World poses (4, 4) of every link node and of the tool (flange frame) at joint values q."""
    data = robot.model.createData()
    gdata = pin.GeometryData(robot.visual_model)
    q = np.asarray(q, dtype=float)
    pin.framesForwardKinematics(robot.model, data, q)
    pin.updateGeometryPlacements(robot.model, data, robot.visual_model, gdata)
    poses = {n.path: T_world_base @ gdata.oMg[n.geometry_index].homogeneous for n in links}
    poses["robot/tool"] = T_world_base @ data.oMf[robot.flange_frame_id].homogeneous
    return poses


def _draw_spots(root: Any, cell: CellSpec, robot: RobotModel, program: ShownProgram) -> list[str]:
    import meshcat.geometry as g

    T_world_base = np.asarray(cell.T_world_base, dtype=float)
    welded = {(s.seam, s.name): s for s in program.spots}
    drawn = []
    for seam in cell.seams:
        for spot in seam.spots:
            path = f"spots/{_safe(seam.name)}/{_safe(spot.name)}"
            shown = welded.get((seam.name, spot.name))
            if shown is not None:
                q = program.q_at(np.array([shown.t_arrive]))[0]
                T = T_world_base @ fk_tcp(robot, q)
            else:
                T = np.eye(4)
                T[:3, :3] = nominal_rotation(spot)
                T[:3, 3] = spot.xyz
            root[path].set_transform(T)
            root[f"{path}/marker"].set_object(g.Sphere(SPOT_MARKER_RADIUS_M), g.MeshLambertMaterial(color=palette.SPOT))
            root[f"{path}/frame"].set_object(g.triad(TRIAD_SCALE_M))
            drawn.append(path)
    return drawn


def _draw_path(root: Any, robot: RobotModel, program: ShownProgram, T_world_base: FloatArray) -> list[tuple[str, str, int]]:
    import meshcat.geometry as g

    if len(program.t) < 2:
        return []
    p_base = fk_tcp(robot, program.q)[:, :3, 3]
    p = p_base @ T_world_base[:3, :3].T + T_world_base[:3, 3]
    drawn = []
    for k, phase in enumerate(program.phases):
        if phase.kind == "weld" or phase.i_end <= phase.i_start:
            continue                          # at rest: the spot marker shows where
        colour = palette.phase_colour(phase.kind)
        path = f"path/{k:04d}_{phase.kind}"
        points = np.asarray(p[phase.i_start:phase.i_end + 1], dtype=np.float32).T
        root[path].set_object(g.Line(g.PointsGeometry(points), g.LineBasicMaterial(color=colour)))
        drawn.append((path, phase.kind, colour))
    return drawn


def _draw_voxels(root: Any, voxels: VoxelMap, T_world_base: FloatArray) -> int:
    """The blocked leaves' centres as one point cloud (world frame); how many."""
    import meshcat.geometry as g

    blocked = ~voxels.free
    centres = voxels.corner[blocked] + voxels.edge[blocked, None] / 2
    points = centres @ T_world_base[:3, :3].T + T_world_base[:3, 3]
    colour = np.tile(np.array([(palette.VOXEL >> s & 0xFF) / 255.0 for s in (16, 8, 0)], dtype=np.float32)[:, None],
                     (1, len(points)))
    root["voxels"].set_object(g.PointCloud(np.asarray(points.T, dtype=np.float32), colour, size=float(voxels.precision)))
    return len(points)
