"""The cell's moving objects in the preview (docs/cell-extensions.md, "Moving objects"), animated on
the program's clock: a part carried along its path (one node per pass of a repeated path, so
passes that overlap are all shown), another robot's links and tool as the collision checks see them
(the convex hull of each body's collision pieces), each where it is at program time t and shown
only while present.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import trimesh

from robomax_py._typing import FloatArray
from robomax_py.app import palette
from robomax_py.robot import RobotModel
from robomax_py.robot.geometry import shape_trimesh
from robomax_py.spec import CellSpec, ObjectSpec, PathMotion, RobotMotion
from robomax_py.world.bounds import support_points
from robomax_py.world.moving import path_poses, robot_bodies
from robomax_py.world.scene import shape_pieces


@dataclass(frozen=True, slots=True, eq=False)
class MovingNode:
    """One drawn body: its meshcat path and its world pose at program time t (None: absent)."""

    path: str
    pose: Callable[[float], FloatArray | None]


def draw_moving(root: Any, cell: CellSpec, robot: RobotModel, safe: Callable[[str], str]) -> list[MovingNode]:
    """Draw every moving object of the cell (under `cell/dynamic/`) and say how each body moves."""
    import meshcat.geometry as g

    colour = palette.ROLE_COLOURS["dynamic"]
    nodes: list[MovingNode] = []
    for obj in cell.dynamic:
        for suffix, vertices, faces, pose in _bodies(obj, cell):
            path = f"cell/dynamic/{safe(obj.name)}{suffix}"
            root[path].set_object(g.TriangularMeshGeometry(np.asarray(vertices, dtype=np.float32),
                                                           np.asarray(faces, dtype=np.uint32)),
                                  g.MeshLambertMaterial(color=colour, opacity=palette.DYNAMIC_OPACITY))
            nodes.append(MovingNode(path, pose))
    return nodes


_Drawn = tuple[str, FloatArray, Any, Callable[[float], FloatArray | None]]


def _bodies(obj: ObjectSpec, cell: CellSpec) -> list[_Drawn]:
    motion = obj.motion
    out: list[_Drawn] = []
    if isinstance(motion, PathMotion):
        mesh = shape_trimesh(obj.shape)
        for n in range(motion.count):
            shift = n * (motion.repeat or 0.0)
            windows = ((float(motion.t[0]) + shift, float(motion.t[-1]) + shift),) if motion.repeat is not None \
                else obj.present or ()
            out.append((f"/pass_{n}" if motion.repeat is not None else "", mesh.vertices, mesh.faces,
                        _path_pose(motion, shift, windows)))
        return out
    if isinstance(motion, RobotMotion):
        bodies = robot_bodies(obj, cell.source, lambda mesh, part: shape_pieces(mesh)[0])
        for k, body in enumerate(bodies):
            hull = trimesh.convex.convex_hull(np.vstack([support_points(p) for p in body.pieces]))
            out.append((f"/body_{k}", hull.vertices, hull.faces, _body_pose(body.poses, obj.present)))
    return out


def _present(windows: tuple[tuple[float, float], ...] | None, t: float) -> bool:
    return windows is None or any(a <= t <= b for a, b in windows)


def _path_pose(motion: PathMotion, shift: float,
               windows: tuple[tuple[float, float], ...]) -> Callable[[float], FloatArray | None]:
    def pose(t: float) -> FloatArray | None:
        return path_poses(motion, np.array([t - shift]))[0] if _present(windows, t) else None
    return pose


def _body_pose(poses: Callable[[FloatArray], FloatArray],
               windows: tuple[tuple[float, float], ...] | None) -> Callable[[float], FloatArray | None]:
    def pose(t: float) -> FloatArray | None:
        return poses(np.array([t]))[0] if _present(windows, t) else None
    return pose


def pose_moving(at: Any, nodes: list[MovingNode], t: float, animated: bool) -> None:
    """Each body where it is at program time t (an animation frame's properties are typed)."""
    for node in nodes:
        T = node.pose(t)
        if animated:
            at[node.path].set_property("visible", "boolean", T is not None)
        else:
            at[node.path].set_property("visible", T is not None)
        if T is not None:
            at[node.path].set_transform(T)


__all__ = ["MovingNode", "draw_moving", "pose_moving"]
