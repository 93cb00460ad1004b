"""Where the preview's viewer looks from: the camera between the robot base and the spots, far
enough to see both, a floor plate under the cell and a light background.

Poses under `robomax/` are in the cell frame; `robomax/` itself is shifted so that the point the
camera looks at is the viewer's origin, which meshcat's orbit controls always look at.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robomax_py.app import palette
from robomax_py.app.preview_drawing import ROOT
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec

# Camera: looks at the centre of the cell objects from this direction (world frame, unit-free).
CAMERA_DIRECTION = (-0.75, -1.0, 0.8)
CAMERA_DISTANCE_FACTOR = 1.05
CAMERA_MIN_DISTANCE_M = 2.5
FLOOR_MARGIN_M = 1.0
FLOOR_THICKNESS_M = 0.01
# A light background (meshcat's default is a dark blue gradient), RGB in [0, 1].
BACKGROUND_TOP = [0.98, 0.98, 0.99]
BACKGROUND_BOTTOM = [0.78, 0.81, 0.86]


def _place_camera(vis: Any, cell: CellSpec, robot: RobotModel) -> None:
    """Look between the robot base and the spots from CAMERA_DIRECTION, far enough to see both; a floor
    plate under the cell; light background."""
    import meshcat.geometry as g

    base = np.asarray(cell.T_world_base, dtype=float)[:3, 3]
    spots = [np.asarray(s.xyz, dtype=float) for seam in cell.seams for s in seam.spots]
    pts = np.array([base, *spots, *(np.asarray(o.T_world_object, dtype=float)[:3, 3] for o in cell.objects)])
    work = np.mean(spots, axis=0) if spots else (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    target = (base + work) / 2.0
    target[2] = float(work[2])
    size = float(np.max(pts.max(axis=0) - pts.min(axis=0)))
    direction = np.array(CAMERA_DIRECTION, dtype=float)
    offset = direction / np.linalg.norm(direction) * max(CAMERA_MIN_DISTANCE_M, CAMERA_DISTANCE_FACTOR * size + 1.0)
    # meshcat's orbit controls always look at the viewer's origin: shift the cell so the target is
    # there. Paths under robomax/ keep their cell-frame poses relative to that shift. meshcat's grid
    # stays at the viewer's z = 0, so it is hidden and a floor plate is drawn at the cell's z = 0.
    shift = np.eye(4)
    shift[:3, 3] = -target
    vis[ROOT].set_transform(shift)
    vis["/Grid"].set_property("visible", False)
    lo = pts.min(axis=0) - FLOOR_MARGIN_M
    hi = pts.max(axis=0) + FLOOR_MARGIN_M
    floor = np.eye(4)
    floor[:3, 3] = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, -FLOOR_THICKNESS_M / 2.0]
    vis[f"{ROOT}/floor"].set_object(g.Box([float(hi[0] - lo[0]), float(hi[1] - lo[1]), FLOOR_THICKNESS_M]),
                                    g.MeshLambertMaterial(color=palette.FLOOR))
    vis[f"{ROOT}/floor"].set_transform(floor)
    # The camera sits in a frame rotated +90 deg about x (three.js is y-up): world (x, y, z) = local (x, -z, y).
    vis["/Cameras/default/rotated/<object>"].set_property("position", [float(offset[0]), float(offset[2]), float(-offset[1])])
    vis["/Background"].set_property("top_color", BACKGROUND_TOP)
    vis["/Background"].set_property("bottom_color", BACKGROUND_BOTTOM)
