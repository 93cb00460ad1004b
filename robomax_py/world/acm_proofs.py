"""What proves pairs of the allowed-collision matrix (`world.acm`) apart or always touching: the
reach spheres that leave far obstacles out, the seeded sampling of self pairs, the Lipschitz proof
that a pair is never close, and coal's per-pair requests they share with the collision world."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray
from robomax_py.robot import RobotModel
from robomax_py.world.acm_cache import SampledPairs
from robomax_py.world.acm_types import (
    OBSTACLE_KINDS,
    ROBOT_KINDS,
    CollisionOptions,
    Piece,
)
from robomax_py.world.bounds import KinematicBounds, joint_path, support_points

# Added to the reach bound before an obstacle is left out: rounding, and GJK's own tolerance.
OUT_OF_REACH_SLACK_M = 1e-3


def reach_spheres(model: pin.Model, gm: pin.GeometryModel, moving: list[bool]) -> list[tuple[FloatArray, float]]:
    """Spheres (centre in the base frame, m; radius, m) that hold every point of the moving pieces
    in every configuration within the limits: one per joint attached to the base (the first
    axis), centred on its origin, with radius the sum of the joint offsets down to each piece,
    the travel of prismatic joints and the piece's farthest point from its joint (triangle
    inequality). Empty when a moving piece hangs on no such joint."""
    bounds = KinematicBounds.of(model)
    spheres: dict[int, float] = {}
    for g, is_moving in zip(gm.geometryObjects, moving):
        j = int(g.parentJoint)
        if not is_moving or j == 0:
            continue
        path = joint_path(model, 0, j)
        if not path:
            return []
        root = path[0]
        pts = support_points(g.geometry, g.placement.homogeneous)
        radius = (float(np.max(np.linalg.norm(pts, axis=1))) + float(bounds.travel[root])
                  + sum(float(np.linalg.norm(model.jointPlacements[m].translation)) + float(bounds.travel[m])
                        for m in path[1:]))
        spheres[root] = max(spheres.get(root, 0.0), radius)
    return [(np.asarray(model.jointPlacements[r].translation, dtype=float), rad) for r, rad in sorted(spheres.items())]


def _out_of_reach(model: pin.Model, gm: pin.GeometryModel, pieces: list[Piece], margin: float) -> set[int]:
    """Obstacle pieces (indices) whose bounding box is farther than reach + margin from the centre
    of every reach sphere: no robot or tool point can come within the margin of them."""
    moving = [p.kind in ROBOT_KINDS for p in pieces]
    spheres = reach_spheres(model, gm, moving)
    if not spheres:
        return set()
    far = set()
    for k, piece in enumerate(pieces):
        if piece.kind not in OBSTACLE_KINDS:
            continue
        g = gm.geometryObjects[k]
        pts = support_points(g.geometry, g.placement.homogeneous)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        if all(float(np.linalg.norm(np.maximum(np.maximum(lo - c, c - hi), 0.0))) > r + margin + OUT_OF_REACH_SLACK_M
               for c, r in spheres):
            far.add(k)
    return far


def acm_samples(robot: RobotModel, count: int, seed: int) -> FloatArray:
    """(count, n) rad: the ACM's seeded samples, half uniform in the limits, half limit-biased."""
    rng = np.random.default_rng(seed)
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    qs = rng.uniform(lower, upper, size=(count, robot.dof))
    biased = np.arange(count) % 2 == 1
    at_limit = rng.random((count, robot.dof)) < 0.5
    pick_upper = rng.random((count, robot.dof)) < 0.5
    limits = np.where(pick_upper, upper, lower)
    qs = np.where(biased[:, None] & at_limit, limits, qs)
    return np.asarray(qs, dtype=float)


def _sample_self_pairs(
    robot: RobotModel,
    gm: pin.GeometryModel,
    candidates: list[tuple[int, int]],
    provable: set[tuple[int, int]],
    flange_candidates: set[tuple[int, int]],
    options: CollisionOptions,
) -> SampledPairs:
    """Run the seeded ACM samples over the candidate self pairs (decided pairs drop out early).

    Only `provable` pairs are tested against `acm_margin` (the others can never be disabled).
    """
    if not candidates:
        return SampledPairs(frozenset(), frozenset(), frozenset())
    tmp = pin.GeometryModel()
    for g in gm.geometryObjects:
        tmp.addGeometryObject(pin.GeometryObject(g))
    for a, b in candidates:
        tmp.addCollisionPair(pin.CollisionPair(a, b))
    n = len(candidates)
    model, data = robot.model, robot.model.createData()
    near_gd, flange_gd, touch_gd = tmp.createData(), tmp.createData(), tmp.createData()
    configure_requests(near_gd, np.full(n, options.acm_margin))
    configure_requests(flange_gd, np.full(n, options.flange_contact_m))
    configure_requests(touch_gd, np.zeros(n))
    for p in range(n):
        if candidates[p] not in flange_candidates:
            flange_gd.deactivateCollisionPair(p)
        if candidates[p] not in provable:
            near_gd.deactivateCollisionPair(p)
    undecided_near = {p for p in range(n) if candidates[p] in provable}   # not yet seen within the margin
    undecided_flange = {p for p in range(n) if candidates[p] in flange_candidates}   # always touching so far
    undecided_touch = set(range(n))                              # always touching so far
    for q in acm_samples(robot, options.acm_samples, options.acm_seed):
        for gd, undecided, keep_if in (
            (near_gd, undecided_near, False),
            (flange_gd, undecided_flange, True),
            (touch_gd, undecided_touch, True),
        ):
            if not undecided:
                continue
            pin.computeCollisions(model, data, tmp, gd, q, False)
            results = gd.collisionResults
            decided = [p for p in undecided if results[p].isCollision() != keep_if]
            for p in decided:
                undecided.discard(p)
                gd.deactivateCollisionPair(p)
    return SampledPairs(
        never_near=frozenset(candidates[p] for p in undecided_near),
        flange_touch=frozenset(candidates[p] for p in undecided_flange),
        always_touch=frozenset(candidates[p] for p in undecided_touch),
    )


def _prove_never_close(
    robot: RobotModel,
    gm: pin.GeometryModel,
    bounds: KinematicBounds,
    pairs: list[tuple[int, int]],
    options: CollisionOptions,
) -> set[tuple[int, int]]:
    """The pairs proved to stay more than `acm_proof_margin` apart over the whole joint-limit box.

    For pieces a (joint i) and b (joint j, a descendant of i), their distance depends only on the
    joints K on the path i -> j. Branch and bound over the box of K's limits: at a box centre c with
    half-widths h, every q in the box has d(q) >= d(c) - sum_k L_k h_k, where L_k bounds the distance
    of b's points from axis k (same bound as `sweep_length`, for piece b alone). A box is proved when
    that bound exceeds the margin, split in two along its worst joint otherwise; a pair fails when
    d(c) <= margin at any centre, and is left checked when its joint group exceeds
    `acm_proof_joints` joints or `acm_proof_budget` box evaluations.
    """
    model = robot.model
    groups: dict[tuple[int, ...], list[tuple[int, int, int]]] = {}
    for a, b in pairs:
        ja, jb = int(gm.geometryObjects[a].parentJoint), int(gm.geometryObjects[b].parentJoint)
        distal = b if ja < jb else a
        path = joint_path(model, ja, jb)
        if path is None or not 0 < len(path) <= options.acm_proof_joints or _passive_on(model, path):
            continue
        groups.setdefault(tuple(path), []).append((a, b, distal))
    proved: set[tuple[int, int]] = set()
    data = model.createData()
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    margin = options.acm_proof_margin
    for chain, members in groups.items():
        idx = [int(model.joints[k].idx_q) for k in chain]
        m = len(idx)
        # L[p][k]: m per rad (plain floats: this loop is Python-bound, numpy per box costs more).
        L = [[bounds.piece_lever(k, gm.geometryObjects[hi]) for k in chain] for _, _, hi in members]
        tmp = pin.GeometryModel()
        for g in gm.geometryObjects:
            tmp.addGeometryObject(pin.GeometryObject(g))
        for a, b, _ in members:
            tmp.addCollisionPair(pin.CollisionPair(a, b))
        gd = tmp.createData()
        q = np.clip(pin.neutral(model), lower, upper)
        failed: set[int] = set()
        centre0 = [float(lower[i] + upper[i]) / 2 for i in idx]
        # A revolute joint repeats its poses every 2 pi: one period covers a wider range.
        half0 = [
            float(upper[i] - lower[i]) / 2 if bounds.prismatic[k] else min(float(upper[i] - lower[i]) / 2, math.pi)
            for i, k in zip(idx, chain)
        ]
        stack = [(centre0, half0, list(range(len(members))))]
        evaluations = 0
        while stack and evaluations < options.acm_proof_budget:
            centre, half, todo = stack.pop()
            todo = [p for p in todo if p not in failed]
            if not todo:
                continue
            q[idx] = centre
            pin.updateGeometryPlacements(model, data, tmp, gd, q)
            evaluations += 1
            unproved = []
            for p in todo:
                d = pin.computeDistance(tmp, gd, p).min_distance
                if d <= margin:
                    failed.add(p)
                elif d - sum(l * h for l, h in zip(L[p], half)) <= margin:
                    unproved.append(p)
            if unproved:
                # Halve the joint contributing most to the worst unproved pair's bound.
                split = max(range(m), key=lambda k: max(L[p][k] for p in unproved) * half[k])
                h2 = list(half)
                h2[split] /= 2
                for sign in (-1.0, 1.0):
                    c2 = list(centre)
                    c2[split] += sign * h2[split]
                    stack.append((c2, h2, unproved))
        open_pairs = {p for _, _, todo in stack for p in todo}
        proved.update((a, b) for p, (a, b, _) in enumerate(members) if p not in failed and p not in open_pairs)
    return proved


def configure_requests(gdata: Any, margins: FloatArray) -> None:
    """Per-pair coal requests: the pair's security margin, and `enable_contact` on.

    `enable_contact` must stay on (Pinocchio's GeometryData turns it off): in coal 3.0.3, when GJK
    ends with status Collision at a residual distance in (1e-12, gjk_tolerance] and EPA does not run,
    the shape-shape collider compares that positive distance with a 1e-12 threshold and reports *no*
    collision. We measured misses of convex-hull pairs overlapping by up to 19 mm. With contacts
    enabled, EPA runs on those cases and returns the (negative) penetration; measured cost: none.
    """
    for p, margin in enumerate(margins):
        request = gdata.collisionRequests[p]
        request.security_margin = float(margin)
        request.enable_contact = True


def _passive_on(model: pin.Model, path: list[int]) -> bool:
    """A passive (`<mimic>`) joint lies on the path: the proof's box over the path's joint values
    takes each joint as free, which a joint following another is not; such pairs stay checked."""
    return any(model.joints[k].nq == 0 for k in path)


def _is_passive_piece(model: pin.Model, joint: int) -> bool:
    return joint > 0 and model.joints[joint].nq == 0
