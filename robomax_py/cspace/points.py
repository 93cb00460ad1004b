"""Obstacles as points: the cell's object surfaces sampled for the learned C-space model.

Each object piece becomes a triangle surface (a mesh piece as it is; a box, convex piece or other
primitive as the convex hull of its support points, which contains it), subdivided until no edge is
longer than `spacing`; its vertices are the points. Every point of a surface is then within
`spacing / sqrt(3)` of a point (the circumradius bound of a triangle with edges <= spacing), which
the model adds to the radius of the sphere it was trained with. An arm that touches an object
crosses its surface (the arm is a chain from the fixed base, outside every object), so the points
cover every contact.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import coal
import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.world.bounds import support_points, triangles
from robomax_py.world.scene import Scene

if TYPE_CHECKING:       # imported where points are sampled: a plan that samples none never imports it
    import trimesh


def cover_radius(spacing: float) -> float:
    """m: how far a surface point can be from the nearest sample at this spacing."""
    return spacing / math.sqrt(3.0)


def surface_points(scene: Scene, spacing: float) -> FloatArray:
    """(P, 3) points on every obstacle surface (static and dynamic), robot base frame, metres."""
    import trimesh

    if not spacing > 0:
        raise ValueError(f"spacing must be > 0 m, got {spacing}")
    out = []
    for obj in (*scene.obstacles, *scene.dynamic):
        T = np.asarray(obj.T_base_object, dtype=float)
        for geom in obj.pieces:
            mesh = _piece_mesh(geom)
            if mesh is None:
                continue
            vertices, _ = trimesh.remesh.subdivide_to_size(  # type: ignore[no-untyped-call]
                mesh.vertices, mesh.faces, max_edge=spacing)
            out.append(np.asarray(vertices) @ T[:3, :3].T + T[:3, 3])
    if not out:
        return np.zeros((0, 3))
    points = np.unique(np.round(np.concatenate(out), 9), axis=0)   # shared vertices once; order fixed
    return points


def _piece_mesh(geom: coal.CollisionGeometry) -> trimesh.Trimesh | None:
    import trimesh

    if isinstance(geom, coal.BVHModelBase):
        return trimesh.Trimesh(support_points(geom), triangles(geom), process=False)
    pts = support_points(geom)
    if not np.isfinite(pts).all():
        return None                       # an unbounded shape (a plane) has no surface to sample
    hull: trimesh.Trimesh = trimesh.convex.convex_hull(pts)
    return hull
