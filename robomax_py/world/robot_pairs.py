"""Robot against robot: the links and tool of two robots of a station, each posed at its own joint
values at the same moment, tested for contact in the station's world.

A `RobotBody` is one robot's moving and fixed pieces (its link pieces from the URDF, its tool's
body and tips on the flange) with its placement in the world (`T_world_base`). `robots_contact`
poses both, keeps the piece pairs whose world-space boxes (each piece's local box carried by its
pose, then the axis-aligned box around that, grown by the margin) overlap, and asks coal for the
exact answer of each of those, stopping at the first contact. The boxes contain their pieces, so a
pair they keep apart is apart: every verdict is coal's. The tool's tips count as hard here: a
robot's electrodes may touch its workpiece, never another robot.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray
from robomax_py.robot import RobotModel
from robomax_py.world.scene import Scene


@dataclass(frozen=True, slots=True, eq=False)
class RobotBody:
    """One robot's pieces for robot–robot checks.

    name : the robot's name in the station.
    model : its Pinocchio model (read-only; scratch is made per call).
    geometries : coal pieces, each in its parent joint's frame at `placements`.
    joints : (n,) int, the parent joint of each piece.
    placements : pieces' placements in their joint frames, (n, 4, 4).
    labels : a name per piece ("link_3_1", "tool_body[2]").
    local_boxes : (n, 2, 3) the pieces' local axis-aligned boxes (min, max), m.
    T_world_base : (4, 4) the robot base in the station's world.
    """

    name: str
    model: pin.Model
    geometries: tuple[coal.CollisionGeometry, ...]
    joints: tuple[int, ...]
    placements: FloatArray
    labels: tuple[str, ...]
    local_boxes: FloatArray
    T_world_base: FloatArray


@dataclass(frozen=True, slots=True)
class RobotContact:
    """Two robots touching: the piece of each that touches the other."""

    piece_a: str
    piece_b: str


def robot_body(name: str, robot: RobotModel, scene: Scene) -> RobotBody:
    """The robot's link pieces and the tool of `scene` (built for this robot) on its flange."""
    geoms: list[coal.CollisionGeometry] = []
    joints: list[int] = []
    placements: list[FloatArray] = []
    labels: list[str] = []
    for g in robot.collision_model.geometryObjects:
        geoms.append(g.geometry)
        joints.append(int(g.parentJoint))
        placements.append(np.asarray(g.placement.homogeneous, dtype=float))
        labels.append(str(g.name))
    flange = robot.model.frames[scene.flange_frame_id]
    for kind, parts in (("tool_body", scene.tool.body), ("tool_tips", scene.tool.tips)):
        for i, geom in enumerate(parts):
            geoms.append(geom)
            joints.append(int(flange.parentJoint))
            placements.append(np.asarray(flange.placement.homogeneous, dtype=float))
            labels.append(f"{kind}[{i}]")
    boxes = []
    for geom in geoms:
        geom.computeLocalAABB()
        box = geom.aabb_local
        boxes.append([np.asarray(box.min_, dtype=float), np.asarray(box.max_, dtype=float)])
    return RobotBody(name, robot.model, tuple(geoms), tuple(joints), np.asarray(placements),
                     tuple(labels), np.asarray(boxes), np.asarray(scene.T_world_base, dtype=float))


def piece_poses(body: RobotBody, q: FloatArray) -> FloatArray:
    """Every piece's pose in the world at joint values q (rad): (n, 4, 4)."""
    data = body.model.createData()
    pin.forwardKinematics(body.model, data, np.asarray(q, dtype=float))
    joint_T = [np.asarray(data.oMi[j].homogeneous) for j in range(body.model.njoints)]
    return np.array([body.T_world_base @ joint_T[j] @ P for j, P in zip(body.joints, body.placements)])


def _world_boxes(body: RobotBody, poses: FloatArray) -> FloatArray:
    """(n, 2, 3) axis-aligned world boxes around each piece's local box carried by its pose."""
    lo, hi = body.local_boxes[:, 0], body.local_boxes[:, 1]
    centre, half = (lo + hi) / 2.0, (hi - lo) / 2.0
    R, p = poses[:, :3, :3], poses[:, :3, 3]
    c = np.einsum("nij,nj->ni", R, centre) + p
    h = np.einsum("nij,nj->ni", np.abs(R), half)
    return np.stack([c - h, c + h], axis=1)


def robots_contact(a: RobotBody, qa: FloatArray, b: RobotBody, qb: FloatArray,
                   margin: float = 0.0) -> RobotContact | None:
    """The first contact of robot a at qa with robot b at qb (closer than `margin` m counts); None
    when they are apart."""
    pa, pb = piece_poses(a, qa), piece_poses(b, qb)
    ba, bb = _world_boxes(a, pa), _world_boxes(b, pb)
    grow = margin / 2.0
    overlap = np.all((ba[:, None, 0] - grow <= bb[None, :, 1] + grow)
                     & (bb[None, :, 0] - grow <= ba[:, None, 1] + grow), axis=2)
    request = coal.CollisionRequest()
    request.enable_contact = True          # coal 3.0.3 misses some convex overlaps without it (world.collision)
    request.security_margin = float(margin)
    for i, j in zip(*np.nonzero(overlap)):
        result = coal.CollisionResult()
        ta = coal.Transform3s(pa[i, :3, :3], pa[i, :3, 3])
        tb = coal.Transform3s(pb[j, :3, :3], pb[j, :3, 3])
        if coal.collide(a.geometries[i], ta, b.geometries[j], tb, request, result):
            return RobotContact(a.labels[i], b.labels[j])
    return None
