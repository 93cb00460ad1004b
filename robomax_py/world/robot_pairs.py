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
from robomax_py.world.bounds import KinematicBounds
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
    lever : (nq,) m/rad (m/m prismatic): how far any of its points moves per unit of each joint at
        most (`world.bounds`), for checks between two poses.
    """

    name: str
    model: pin.Model
    geometries: tuple[coal.CollisionGeometry, ...]
    joints: tuple[int, ...]
    placements: FloatArray
    labels: tuple[str, ...]
    local_boxes: FloatArray
    T_world_base: FloatArray
    lever: FloatArray


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
    gm = pin.GeometryModel()
    for k, (geom, joint, T) in enumerate(zip(geoms, joints, placements)):
        gm.addGeometryObject(pin.GeometryObject(labels[k], joint, 0, pin.SE3(T), geom))
    lever = KinematicBounds.of(robot.model).lever_arms(gm, [True] * len(geoms))
    boxes = []
    for geom in geoms:
        geom.computeLocalAABB()
        box = geom.aabb_local
        boxes.append([np.asarray(box.min_, dtype=float), np.asarray(box.max_, dtype=float)])
    return RobotBody(name, robot.model, tuple(geoms), tuple(joints), np.asarray(placements),
                     tuple(labels), np.asarray(boxes), np.asarray(scene.T_world_base, dtype=float), lever)


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


def swept_contact(a: RobotBody, qa: tuple[FloatArray, FloatArray], b: RobotBody, qb: tuple[FloatArray, FloatArray],
                  margin: float, step: float) -> tuple[float, RobotContact] | None:
    """A contact while both robots move linearly in joint space from their first to their second
    joint values (the two ends apart), as the fraction of the way (0..1) where it is found; None
    when they stay apart except perhaps for contacts shallower than `step` m. Halves the move
    while the midpoint's poses, grown by how far any point of either robot can be from them over
    the half-moves (`lever` times the joint change, halved), touch."""
    stack = [(0.0, 1.0)]
    while stack:
        s0, s1 = stack.pop()
        qa0, qa1 = (qa[0] + s0 * (qa[1] - qa[0]), qa[0] + s1 * (qa[1] - qa[0]))
        qb0, qb1 = (qb[0] + s0 * (qb[1] - qb[0]), qb[0] + s1 * (qb[1] - qb[0]))
        reach = 0.5 * (float(a.lever @ np.abs(qa1 - qa0)) + float(b.lever @ np.abs(qb1 - qb0)))
        if reach <= step:
            continue
        sm = 0.5 * (s0 + s1)
        qam, qbm = 0.5 * (qa0 + qa1), 0.5 * (qb0 + qb1)
        if robots_contact(a, qam, b, qbm, margin + reach) is None:
            continue
        contact = robots_contact(a, qam, b, qbm, margin)
        if contact is not None:
            return sm, contact
        stack += [(sm, s1), (s0, sm)]          # the earlier half first
    return None
