"""The allowed-collision proof: which piece pairs a CollisionWorld checks, and why the others never
need to be.

Allowed-collision matrix (pairs never checked), deterministic for a given `CollisionOptions`
-----------------------------------------------------------------------------------------------
- "rigid": two pieces on the same joint (a link's own pieces, the tool on the flange link, body vs
  tips): they never move relative to each other.
- "adjacent": robot link pieces on a joint and on its parent joint (they meet at the joint).
- "disabled in robot.yaml": link pairs named in robot.yaml `collision.disable` or its SRDF's
  `disable_collisions` (parts that touch by design, such as an ABB arm's link_4 and link_6).
- "tips on workpiece": tool tips vs objects marked `workpiece: true`. The tool *body* vs a workpiece
  stays checked.
- "fixed base": robot pieces on the fixed base (joint 0) vs obstacles: they never move, so their
  contact is a property of the layout, not of q (a base standing on a riser touches it). Such
  contacts are listed in `layout_contacts`, never reported by queries.
- "tool touches flange link": a tool piece vs a piece of the link before the flange link, when they
  are within `flange_contact_m` of each other in *every* sampled configuration (the gun's mounting
  plate sits on the wrist at the flange). A tool piece that only sometimes touches that link stays
  checked: that contact is the gun swinging into the wrist.
- "out of reach": robot/tool pieces vs an obstacle piece farther from the arm's first joint than
  any robot or tool point can ever be, plus the pair's margin (`reach_spheres`, a bound from the
  joint offsets and the pieces' extents): no configuration can come within the margin of it, so
  its pairs would only cost every check and every clearance measurement.
- "never close": self pairs (robot/tool vs robot/tool) that can never touch, *proved*, not guessed.
  First `acm_samples` seeded random configurations (half uniform within the joint limits, half with
  each joint at a limit with probability 1/2): a pair within `acm_margin` (2 cm), or colliding, in
  any sample stays checked. Sampling alone is not safe: on kr125 + spot_gun_c, 3000 samples left 9
  pairs "never within 2 cm" that 60000 samples showed colliding by up to 10 cm (base vs gun body).
  So each remaining pair must also be proved apart by branch and bound over the joints between its
  two pieces (`_prove_never_close`, a Lipschitz bound on the distance); pairs moved by more than
  `acm_proof_joints` (3) joints, or not proved within the budget, stay checked.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray, IntArray
from robomax_py.robot import RobotModel
from robomax_py.world.acm_cache import SampledPairs, cached_self_analysis
from robomax_py.world.bounds import KinematicBounds, joint_path, support_points
from robomax_py.world.prefilter import Prefilter
from robomax_py.world.scene import Scene, SceneObject

KIND_LINK = "link"
KIND_TOOL_BODY = "tool_body"
KIND_TOOL_TIPS = "tool_tips"
KIND_OBJECT = "object"
KIND_DYNAMIC = "dynamic"
KIND_HELD = "held"            # a part in the gripper: moves with the tool, collides like its body
ROBOT_KINDS = (KIND_LINK, KIND_TOOL_BODY, KIND_TOOL_TIPS, KIND_HELD)
# A held part may touch its supports (the objects it rests on where it is gripped or released)
# but not sink into them by more than this (m): resting is a contact at distance 0.
HELD_SUPPORT_PENETRATION_M = 1e-3
OBSTACLE_KINDS = (KIND_OBJECT, KIND_DYNAMIC)


@dataclass(frozen=True, slots=True)
class CollisionOptions:
    """How a CollisionWorld is built (defaults are the production settings)."""

    broad_phase: bool = True
    prefilter: bool = True            # bounding-volume pre-filter before coal (with the broad phase only)
    acm_samples: int = 2000           # seeded random configurations for the ACM rules
    acm_margin: float = 0.02          # m: a self pair closer than this in any sample stays checked
    acm_seed: int = 0
    acm_proof_margin: float = 0.002   # m: "never close" must be proved with at least this separation
    acm_proof_joints: int = 3         # pairs moved by more joints than this are never disabled
    acm_proof_budget: int = 20000     # box evaluations per joint group for the proof
    flange_contact_m: float = 1e-4    # m: "touching at the flange" = closer than this in every sample


@dataclass(frozen=True, slots=True)
class DisabledPair:
    piece_a: str
    piece_b: str
    reason: str      # "rigid" | "adjacent" | "disabled in robot.yaml" | "tips on workpiece" | "fixed base" | "tool touches flange link" | "never close" | "passive linkage: ..."


@dataclass(frozen=True, slots=True)
class AllowedCollisions:
    """The allowed-collision matrix as built: what is not checked, and why.

    enabled : (piece_a, piece_b) pairs that are checked.
    always_in_contact : enabled self pairs that touched in every ACM sample (likely bad link geometry:
        every configuration will be reported colliding with these bodies).
    """

    disabled: tuple[DisabledPair, ...]
    enabled: tuple[tuple[str, str], ...]
    always_in_contact: tuple[tuple[str, str], ...]
    samples: int


@dataclass(frozen=True, slots=True, eq=False)
class Piece:
    name: str
    body: str
    kind: str
    joint: int
    obstacle: int        # index into the world's obstacle list, -1 for robot/tool pieces


@dataclass(frozen=True, slots=True, eq=False)
class SharedGeometry:
    """Read-only state every copy of a world shares."""

    model: pin.Model
    geom_model: pin.GeometryModel
    pieces: tuple[Piece, ...]
    pair_a: IntArray                         # (p,) geometry index of each enabled pair
    pair_b: IntArray
    pair_margin: FloatArray                  # (p,) m
    obstacles: tuple[SceneObject, ...]       # static then dynamic
    dynamic_ids: IntArray                    # (d,) obstacle indices of dynamic obstacles
    dynamic_pairs: tuple[IntArray, ...]      # per dynamic obstacle: its pair indices
    lever: FloatArray                        # (n,) m per rad (m per m for prismatic joints)
    clearance: float
    options: CollisionOptions
    acm: AllowedCollisions
    layout_contacts: tuple[tuple[str, str], ...]
    prefilter: Prefilter | None              # bounding-sphere broad phase (None: coal's for every query)


@dataclass(slots=True)
class _PairRules:
    """Every piece pair sorted by the rules that need no sampling (see the module docstring)."""

    disabled: list[DisabledPair] = field(default_factory=list)
    obstacle_pairs: list[tuple[int, int]] = field(default_factory=list)   # robot/tool vs obstacle, checked
    self_candidates: list[tuple[int, int]] = field(default_factory=list)  # left to the sampling and the proof
    flange_candidates: set[tuple[int, int]] = field(default_factory=set)  # tool vs the link before the flange link
    base_obstacle: list[tuple[int, int]] = field(default_factory=list)    # fixed base vs obstacle: layout


def _pieces(robot: RobotModel, scene: Scene) -> tuple[pin.GeometryModel, list[Piece], tuple[Any, ...]]:
    """One geometry model of link pieces, tool pieces and obstacle pieces, with their descriptions."""
    model = robot.model
    gm = pin.GeometryModel()
    pieces: list[Piece] = []

    for g in robot.collision_model.geometryObjects:
        g.geometry.computeLocalAABB()
        gm.addGeometryObject(pin.GeometryObject(g))
        pieces.append(Piece(g.name, model.frames[g.parentFrame].name, KIND_LINK, int(g.parentJoint), -1))

    flange = model.frames[scene.flange_frame_id]
    for kind, parts in ((KIND_TOOL_BODY, scene.tool.body), (KIND_TOOL_TIPS, scene.tool.tips)):
        for i, geom in enumerate(parts):
            name = f"{kind}[{i}]"
            gm.addGeometryObject(
                pin.GeometryObject(name, int(flange.parentJoint), int(scene.flange_frame_id), flange.placement, geom)
            )
            pieces.append(Piece(name, kind, kind, int(flange.parentJoint), -1))
    if scene.held is not None:
        placement = flange.placement * pin.SE3(np.asarray(scene.held.T_flange_part, dtype=float))
        for i, geom in enumerate(scene.held.pieces):
            name = f"{KIND_HELD}:{scene.held.name}[{i}]"
            gm.addGeometryObject(pin.GeometryObject(name, int(flange.parentJoint), int(scene.flange_frame_id), placement, geom))
            pieces.append(Piece(name, scene.held.name, KIND_HELD, int(flange.parentJoint), -1))

    obstacles = (*scene.obstacles, *scene.dynamic)
    for o, obj in enumerate(obstacles):
        kind = KIND_DYNAMIC if obj.dynamic else KIND_OBJECT
        placement = pin.SE3(np.asarray(obj.T_base_object, dtype=float))
        for i, geom in enumerate(obj.pieces):
            name = f"{kind}:{obj.name}[{i}]"
            gm.addGeometryObject(pin.GeometryObject(name, 0, 0, placement, geom))
            pieces.append(Piece(name, obj.name, kind, 0, o))

    return gm, pieces, obstacles


def _classify_pairs(robot: RobotModel, scene: Scene, pieces: list[Piece], obstacles: tuple[Any, ...],
                    far: set[int]) -> _PairRules:
    model = robot.model
    flange = model.frames[scene.flange_frame_id]
    rules = _PairRules()
    disabled, obstacle_pairs, self_candidates = rules.disabled, rules.obstacle_pairs, rules.self_candidates
    flange_candidates, base_obstacle = rules.flange_candidates, rules.base_obstacle
    mount_joint = int(flange.parentJoint)
    mount_parent = int(model.parents[mount_joint])
    n_geom = len(pieces)
    for a in range(n_geom):
        pa = pieces[a]
        for b in range(a + 1, n_geom):
            pb = pieces[b]
            if pa.kind in OBSTACLE_KINDS and pb.kind in OBSTACLE_KINDS:
                continue  # obstacles never move relative to each other: not a pair at all
            if pb.kind in OBSTACLE_KINDS or pa.kind in OBSTACLE_KINDS:
                rob, obs = (pa, pb) if pb.kind in OBSTACLE_KINDS else (pb, pa)
                if rob.kind == KIND_TOOL_TIPS and obstacles[obs.obstacle].workpiece:
                    disabled.append(DisabledPair(pa.name, pb.name, "tips on workpiece"))
                elif rob.joint == 0:
                    disabled.append(DisabledPair(pa.name, pb.name, "fixed base"))
                    base_obstacle.append((a, b))
                elif (b if pb.kind in OBSTACLE_KINDS else a) in far:
                    disabled.append(DisabledPair(pa.name, pb.name, "out of reach"))
                else:
                    obstacle_pairs.append((a, b))
                continue
            if pa.joint == pb.joint:
                disabled.append(DisabledPair(pa.name, pb.name, "rigid"))
                continue
            tool_a, tool_b = pa.kind != KIND_LINK, pb.kind != KIND_LINK
            if not tool_a and not tool_b and (
                int(model.parents[pa.joint]) == pb.joint or int(model.parents[pb.joint]) == pa.joint
            ):
                disabled.append(DisabledPair(pa.name, pb.name, "adjacent"))
                continue
            if not tool_a and not tool_b and frozenset((pa.body, pb.body)) in robot.disabled_links:
                disabled.append(DisabledPair(pa.name, pb.name, "disabled in robot.yaml"))
                continue
            if (tool_a and pb.joint == mount_parent) or (tool_b and pa.joint == mount_parent):
                flange_candidates.add((a, b))
            self_candidates.append((a, b))

    return rules


def build_shared(robot: RobotModel, scene: Scene, clearance: float, options: CollisionOptions) -> SharedGeometry:
    """The geometry, checked pairs (in exhaustive-mode order), margins and ACM of a world."""
    model = robot.model
    gm, pieces, obstacles = _pieces(robot, scene)
    n_geom = len(pieces)
    rules = _classify_pairs(robot, scene, pieces, obstacles, _out_of_reach(model, gm, pieces, max(clearance, 0.0)))
    disabled, obstacle_pairs, self_candidates = rules.disabled, rules.obstacle_pairs, rules.self_candidates
    flange_candidates, base_obstacle = rules.flange_candidates, rules.base_obstacle

    provable = {
        (a, b) for a, b in self_candidates
        if 0 < len(path := joint_path(model, pieces[a].joint, pieces[b].joint) or []) <= options.acm_proof_joints
        and not _passive_on(model, path)
    }
    n_self = sum(1 for p in pieces if p.kind in ROBOT_KINDS)
    bounds = KinematicBounds.of(model)

    def analyse() -> tuple[SampledPairs, set[tuple[int, int]]]:
        sampled = _sample_self_pairs(robot, gm, self_candidates, provable, flange_candidates, options)
        return sampled, _prove_never_close(robot, gm, bounds, sorted(sampled.never_near), options)

    sampled, proved_far = cached_self_analysis(
        robot, gm, n_self, (self_candidates, sorted(provable), sorted(flange_candidates)), options, analyse)
    self_pairs: list[tuple[int, int]] = []
    for pair in self_candidates:
        a, b = pair
        if pair in sampled.flange_touch:
            disabled.append(DisabledPair(pieces[a].name, pieces[b].name, "tool touches flange link"))
        elif pair in sampled.always_touch and (_is_passive_piece(model, pieces[a].joint)
                                               or _is_passive_piece(model, pieces[b].joint)):
            # A passive link (a balancer's cylinder or piston, a parallelogram bar) closes a
            # linkage: it meets the links it is pinned to by design, in every posture. MoveIt's
            # Setup Assistant disables such pairs too ("Always" / "Default"); a pair that separates
            # in some sample stays checked.
            disabled.append(DisabledPair(pieces[a].name, pieces[b].name, "passive linkage: touching in every sample"))
        elif pair in proved_far:
            disabled.append(DisabledPair(pieces[a].name, pieces[b].name, "never close"))
        else:
            self_pairs.append(pair)

    # Exhaustive-mode order: obstacle pairs first (tips, body, then distal links), then self pairs.
    def _distal_key(pair: tuple[int, int]) -> tuple[int, int, int]:
        a, b = pair
        rob = pieces[a] if pieces[a].kind in ROBOT_KINDS else pieces[b]
        tool_rank = 0 if rob.kind == KIND_TOOL_TIPS else (1 if rob.kind == KIND_TOOL_BODY else 2)
        return (tool_rank, -rob.joint, a * n_geom + b)

    obstacle_pairs.sort(key=_distal_key)
    self_pairs.sort(key=lambda p: (-max(pieces[p[0]].joint, pieces[p[1]].joint), p[0], p[1]))
    ordered = obstacle_pairs + self_pairs
    for a, b in ordered:
        gm.addCollisionPair(pin.CollisionPair(a, b))
    pair_a = np.array([a for a, _ in ordered], dtype=np.int64)
    pair_b = np.array([b for _, b in ordered], dtype=np.int64)
    supports = set(scene.held.supports) if scene.held is not None else set()

    def margin(a: int, b: int) -> float:
        pa, pb = pieces[a], pieces[b]
        if pa.kind not in OBSTACLE_KINDS and pb.kind not in OBSTACLE_KINDS:
            return 0.0
        held, obstacle = (pa, pb) if pa.kind == KIND_HELD else (pb, pa)
        if held.kind == KIND_HELD and obstacles[obstacle.obstacle].name in supports:
            return -HELD_SUPPORT_PENETRATION_M
        return clearance

    pair_margin = np.array([margin(a, b) for a, b in ordered], dtype=float)
    dynamic_ids = np.array([o for o, obj in enumerate(obstacles) if obj.dynamic], dtype=np.int64)
    dynamic_pairs = tuple(
        np.array(
            [p for p, (a, b) in enumerate(ordered) if pieces[a].obstacle == o or pieces[b].obstacle == o], dtype=np.int64
        )
        for o in dynamic_ids
    )
    acm = AllowedCollisions(
        disabled=tuple(disabled),
        enabled=tuple((pieces[a].name, pieces[b].name) for a, b in ordered),
        always_in_contact=tuple((pieces[a].name, pieces[b].name) for a, b in self_pairs if (a, b) in sampled.always_touch),
        samples=options.acm_samples,
    )
    moving = [p.kind in ROBOT_KINDS for p in pieces]
    return SharedGeometry(
        model=model,
        geom_model=gm,
        pieces=tuple(pieces),
        pair_a=pair_a,
        pair_b=pair_b,
        pair_margin=pair_margin,
        obstacles=obstacles,
        dynamic_ids=dynamic_ids,
        dynamic_pairs=dynamic_pairs,
        lever=bounds.lever_arms(gm, moving),
        clearance=clearance,
        options=options,
        acm=acm,
        layout_contacts=_layout_contacts(gm, pieces, base_obstacle),
        prefilter=Prefilter.of(model, gm, [p.kind in OBSTACLE_KINDS for p in pieces], pair_a, pair_b, pair_margin),
    )


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


def _layout_contacts(gm: pin.GeometryModel, pieces: list[Piece], pairs: list[tuple[int, int]]) -> tuple[tuple[str, str], ...]:
    out = []
    for a, b in pairs:
        ga, gb = gm.geometryObjects[a], gm.geometryObjects[b]
        req, res = coal.CollisionRequest(), coal.CollisionResult()
        Ta = coal.Transform3s(ga.placement.rotation, ga.placement.translation)
        Tb = coal.Transform3s(gb.placement.rotation, gb.placement.translation)
        if coal.collide(ga.geometry, Ta, gb.geometry, Tb, req, res):
            out.append((pieces[a].name, pieces[b].name))
    return tuple(out)


def _passive_on(model: pin.Model, path: list[int]) -> bool:
    """A passive (`<mimic>`) joint lies on the path: the proof's box over the path's joint values
    takes each joint as free, which a joint following another is not; such pairs stay checked."""
    return any(model.joints[k].nq == 0 for k in path)


def _is_passive_piece(model: pin.Model, joint: int) -> bool:
    return joint > 0 and model.joints[joint].nq == 0
