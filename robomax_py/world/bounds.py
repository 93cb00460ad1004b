"""Kinematic bounds: how far any point of a robot piece can move for a change of the joints, the
Lipschitz constants behind swept checks and the never-close proof, and support points of coal shapes."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray


def support_points(geom: coal.CollisionGeometry, pose: FloatArray | None = None) -> FloatArray:
    """(m, 3) points whose convex hull contains the piece, metres: in the piece's own frame, or in
    the frame where the piece sits at `pose` (4, 4).

    Convex polytope: its vertices; BVH: its vertices; anything else: its local AABB corners.
    """
    if isinstance(geom, coal.ConvexBase):
        pts = np.asarray(geom.points(), dtype=float).reshape(-1, 3)
    elif isinstance(geom, coal.BVHModelBase):
        pts = np.asarray(geom.vertices(), dtype=float).reshape(-1, 3)
    else:
        geom.computeLocalAABB()
        lo, hi = np.asarray(geom.aabb_local.min_, dtype=float), np.asarray(geom.aabb_local.max_, dtype=float)
        pts = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    if pose is None:
        return pts
    T = np.asarray(pose, dtype=float)
    placed: FloatArray = pts @ T[:3, :3].T + T[:3, 3]
    return placed


def triangles(geom: coal.BVHModelBase) -> np.ndarray:
    """(t, 3) vertex indices of a mesh piece's triangles (into `support_points`' rows)."""
    return np.array([[t[0], t[1], t[2]] for t in (geom.tri_indices(i) for i in range(geom.num_tris))],
                    dtype=np.int64).reshape(-1, 3)


@dataclass(frozen=True, slots=True, eq=False)
class KinematicBounds:
    """Joint axes and prismatic travel, for bounds on how far points move per unit joint motion."""

    model: pin.Model
    axis: FloatArray          # (njoints, 3) unit axis of each joint in its own frame
    prismatic: BoolArray      # (njoints,)
    travel: FloatArray        # (njoints,) m, largest |q| of prismatic joints (0 for revolute)
    scale: FloatArray         # (njoints,) |multiplier| of a passive (`<mimic>`) joint, else 1

    @staticmethod
    def of(model: pin.Model) -> KinematicBounds:
        njoints = model.njoints
        prismatic = np.array([model.joints[j].shortname().startswith("JointModelP") for j in range(njoints)])
        # Axes in their own frames, from the LOCAL joint Jacobian at the neutral configuration.
        data = model.createData()
        pin.computeJointJacobians(model, data, pin.neutral(model))
        axis = np.zeros((njoints, 3))
        travel = np.zeros(njoints)
        scale = np.ones(njoints)
        for j in range(1, njoints):
            if model.joints[j].nq == 0:
                axis[j], prismatic[j], scale[j] = _mimic_axis(model, j)
                if prismatic[j]:
                    mimic = model.joints[j].extract()
                    i = int(mimic.idx_q)
                    travel[j] = scale[j] * max(abs(model.lowerPositionLimit[i]), abs(model.upperPositionLimit[i])) \
                        + abs(float(mimic.offset))
                continue
            J = pin.getJointJacobian(model, data, j, pin.ReferenceFrame.LOCAL)
            col = np.asarray(J[:, model.joints[j].idx_v], dtype=float)
            vec = col[:3] if prismatic[j] else col[3:]
            axis[j] = vec / np.linalg.norm(vec)
            if prismatic[j]:
                i = model.joints[j].idx_q
                travel[j] = max(abs(model.lowerPositionLimit[i]), abs(model.upperPositionLimit[i]))
        return KinematicBounds(model=model, axis=axis, prismatic=prismatic, travel=travel, scale=scale)

    def piece_lever(self, k: int, geometry_object: Any) -> float:
        """Bound (m per rad; 1 for a prismatic k) of dist(p, axis_k) over the piece's points p and all q.

        Piece on joint k: exact largest distance of its support points from the axis. Piece on a
        descendant j: dist(o_c, axis_k) + |offsets| from c down to j (+ prismatic travel) + largest
        distance of its points from o_j, c being k's child towards j (triangle inequality). 0 when the
        piece is not beyond joint k.
        """
        if self.prismatic[k]:
            return 1.0
        j = int(geometry_object.parentJoint)
        pts = support_points(geometry_object.geometry, geometry_object.placement.homogeneous)
        if j == k:
            radial = pts - np.outer(pts @ self.axis[k], self.axis[k])
            return float(np.max(np.linalg.norm(radial, axis=1)))
        path = _path_below(self.model, k, j)
        if path is None:
            return 0.0
        c = path[0]
        oc = np.asarray(self.model.jointPlacements[c].translation, dtype=float)
        d_c = float(np.linalg.norm(oc - np.dot(oc, self.axis[k]) * self.axis[k])) + float(self.travel[c])
        chain = sum(float(np.linalg.norm(self.model.jointPlacements[m].translation)) + float(self.travel[m]) for m in path[1:])
        return d_c + chain + float(np.max(np.linalg.norm(pts, axis=1)))

    def lever_arms(self, gm: pin.GeometryModel, moving: list[bool]) -> FloatArray:
        """(n,) per joint: the largest `piece_lever` over every moving piece (robot and tool). A
        passive (`<mimic>`) joint turns with the joint it follows, |multiplier| times as fast: its
        lever, so scaled, adds to that joint's (a bound: the sum of the two largest levers)."""
        lever = np.zeros(self.model.nq)
        for k in range(1, self.model.njoints):
            idx = self.model.joints[k].idx_q
            best = 1.0 if self.prismatic[k] else 0.0
            for g, is_moving in zip(gm.geometryObjects, moving):
                if is_moving and g.parentJoint != 0:
                    best = max(best, self.piece_lever(k, g))
            lever[idx] += self.scale[k] * best
        return lever


def _mimic_axis(model: pin.Model, j: int) -> tuple[FloatArray, bool, float]:
    """A passive joint's unit axis in its own frame, whether it slides, and |multiplier|: from its
    motion when the joint it follows moves by 1 / multiplier (Pinocchio's JointModelMimic)."""
    mimic = model.joints[j].extract()
    scale = float(mimic.scaling)
    if scale == 0.0:
        return np.array([0.0, 0.0, 1.0]), False, 0.0
    data = mimic.createData()
    q = np.zeros(model.nq)
    mimic.calc(data, q)
    M0 = data.M.copy()
    q[int(mimic.idx_q)] = 1.0 / scale
    mimic.calc(data, q)
    step = M0.inverse() * data.M
    turn = np.asarray(pin.log3(step.rotation), dtype=float)
    if np.linalg.norm(turn) > 1e-9:
        return turn / np.linalg.norm(turn), False, abs(scale)
    slide = np.asarray(step.translation, dtype=float)
    return slide / np.linalg.norm(slide), True, abs(scale)


def joint_path(model: pin.Model, i: int, j: int) -> list[int] | None:
    """The joints whose motion changes the relative pose of bodies on joints i and j (either order):
    the path from the ancestor's child down to the descendant; None if neither is an ancestor."""
    lo, hi = (i, j) if i < j else (j, i)
    return _path_below(model, lo, hi)


def _path_below(model: pin.Model, i: int, j: int) -> list[int] | None:
    """Joints from the child of i down to j (inclusive) when j is a descendant of i, else None."""
    path = []
    k = j
    while k > i:
        path.append(k)
        k = int(model.parents[k])
    if k != i:
        return None
    return path[::-1]


