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
- "held part on its support, checked lifted": a part in the gripper may rest on the objects it
  lies on where it is gripped and released (its supports), sinking in by at most
  `HELD_SUPPORT_PENETRATION_M`. Where both are convex or primitive, that is coal's negative
  security margin on the pair. coal has none for a triangle mesh (its BVH collider refuses a
  negative margin), so where the part or the support is one the part is checked against the support
  lifted by that much, at margin 0: lifted along the world's up as it lies where it is gripped and
  released (`HeldPart.up`, the way a part comes off what it rests on, whichever way the gripper
  holds it). It may rest on the support and sink in up to 1 mm, as the margin allows; a part
  pressed flat against a support's side wall counts as touching it.
"""

from __future__ import annotations

from typing import Any

import coal
import numpy as np
import pinocchio as pin

from robomax_py.robot import RobotModel
from robomax_py.world.acm_cache import SampledPairs, cached_self_analysis
from robomax_py.world.acm_proofs import (
    OUT_OF_REACH_SLACK_M,
    _is_passive_piece,
    _out_of_reach,
    _passive_on,
    _prove_never_close,
    _sample_self_pairs,
    acm_samples,
    configure_requests,
    reach_spheres,
)
from robomax_py.world.acm_types import (
    HELD_SUPPORT_PENETRATION_M,
    KIND_DYNAMIC,
    KIND_HELD,
    KIND_HELD_LIFTED,
    KIND_LINK,
    KIND_OBJECT,
    KIND_TOOL_BODY,
    KIND_TOOL_TIPS,
    OBSTACLE_KINDS,
    ROBOT_KINDS,
    AllowedCollisions,
    CollisionOptions,
    DisabledPair,
    Piece,
    SharedGeometry,
    _PairRules,
)
from robomax_py.world.bounds import KinematicBounds, joint_path
from robomax_py.world.prefilter import Prefilter
from robomax_py.world.scene import Scene, ToolGeometry

# What this module offered before its parts moved out stays importable from here.
__all__ = [
    "HELD_SUPPORT_PENETRATION_M", "KIND_DYNAMIC", "KIND_HELD", "KIND_LINK", "KIND_OBJECT", "KIND_TOOL_BODY",
    "KIND_TOOL_TIPS", "OBSTACLE_KINDS", "OUT_OF_REACH_SLACK_M", "ROBOT_KINDS", "AllowedCollisions",
    "CollisionOptions", "DisabledPair", "Piece", "SharedGeometry", "acm_samples", "always_touching_links",
    "build_shared", "configure_requests", "reach_spheres",
]


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
        T_flange_part = np.asarray(scene.held.T_flange_part, dtype=float)
        placement = flange.placement * pin.SE3(T_flange_part)
        for i, geom in enumerate(scene.held.pieces):
            name = f"{KIND_HELD}:{scene.held.name}[{i}]"
            gm.addGeometryObject(pin.GeometryObject(name, int(flange.parentJoint), int(scene.flange_frame_id), placement, geom))
            pieces.append(Piece(name, scene.held.name, KIND_HELD, int(flange.parentJoint), -1))
        if _held_meets_mesh(scene):
            # The stand-ins against the supports (module docstring): each piece lifted along the
            # world's up as the part lies (a direction in the part's own frame).
            lift = np.eye(4)
            lift[:3, 3] = HELD_SUPPORT_PENETRATION_M * np.asarray(scene.held.up, dtype=float)
            lifted = flange.placement * pin.SE3(T_flange_part @ lift)
            for i, geom in enumerate(scene.held.pieces):
                name = f"{KIND_HELD_LIFTED}:{scene.held.name}[{i}]"
                gm.addGeometryObject(pin.GeometryObject(name, int(flange.parentJoint), int(scene.flange_frame_id), lifted, geom))
                pieces.append(Piece(name, scene.held.name, KIND_HELD_LIFTED, int(flange.parentJoint), -1))

    obstacles = (*scene.obstacles, *scene.dynamic)
    for o, obj in enumerate(obstacles):
        kind = KIND_DYNAMIC if obj.dynamic else KIND_OBJECT
        placement = pin.SE3(np.asarray(obj.T_base_object, dtype=float))
        for i, geom in enumerate(obj.pieces):
            name = f"{kind}:{obj.name}[{i}]"
            gm.addGeometryObject(pin.GeometryObject(name, 0, 0, placement, geom))
            pieces.append(Piece(name, obj.name, kind, 0, o))

    return gm, pieces, obstacles


def _is_mesh(geom: coal.CollisionGeometry) -> bool:
    return isinstance(geom, coal.BVHModelBase)


def _held_meets_mesh(scene: Scene) -> bool:
    """A held part that is a triangle mesh, or rests on a support that is one."""
    held = scene.held
    if held is None:
        return False
    supports = set(held.supports)
    return any(_is_mesh(g) for g in held.pieces) or any(
        _is_mesh(g) for obj in scene.obstacles if obj.name in supports for g in obj.pieces)


def _classify_pairs(robot: RobotModel, scene: Scene, gm: pin.GeometryModel, pieces: list[Piece],
                    obstacles: tuple[Any, ...], far: set[int]) -> _PairRules:
    model = robot.model
    supports = set(scene.held.supports) if scene.held is not None else set()
    flange = model.frames[scene.flange_frame_id]
    rules = _PairRules()
    disabled, obstacle_pairs, self_candidates = rules.disabled, rules.obstacle_pairs, rules.self_candidates
    flange_candidates, base_obstacle = rules.flange_candidates, rules.base_obstacle
    mount_joint = int(flange.parentJoint)
    mount_parent = int(model.parents[mount_joint])
    n_geom = len(pieces)
    for a in range(n_geom):
        pa = pieces[a]
        if pa.kind in OBSTACLE_KINDS:
            continue  # obstacles come last (`_pieces`) and are never paired with each other
        for b in range(a + 1, n_geom):
            pb = pieces[b]
            if pa.kind in OBSTACLE_KINDS and pb.kind in OBSTACLE_KINDS:
                continue  # obstacles never move relative to each other: not a pair at all
            if pb.kind in OBSTACLE_KINDS or pa.kind in OBSTACLE_KINDS:
                rob, obs = (pa, pb) if pb.kind in OBSTACLE_KINDS else (pb, pa)
                if rob.kind in (KIND_HELD, KIND_HELD_LIFTED):
                    r, o = (a, b) if rob is pa else (b, a)
                    lifted = obstacles[obs.obstacle].name in supports and (
                        _is_mesh(gm.geometryObjects[r].geometry) or _is_mesh(gm.geometryObjects[o].geometry))
                    if rob.kind == KIND_HELD_LIFTED and not lifted:
                        continue  # the stand-in meets its supports only: not a pair at all
                    if rob.kind == KIND_HELD and lifted:
                        disabled.append(DisabledPair(pa.name, pb.name, "held part on its support, checked lifted"))
                        continue
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
            if KIND_HELD_LIFTED in (pa.kind, pb.kind):
                continue  # the stand-in meets its supports only: not a pair at all
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
    rules = _classify_pairs(robot, scene, gm, pieces, obstacles, _out_of_reach(model, gm, pieces, max(clearance, 0.0) + max((o.margin for o in obstacles), default=0.0)))
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
        elif pair in sampled.always_touch and _passive_pair(model, pieces, pair):
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
        held, obstacle = (pa, pb) if pa.kind in (KIND_HELD, KIND_HELD_LIFTED) else (pb, pa)
        if held.kind == KIND_HELD_LIFTED:
            return 0.0                          # lifted by the depth it may sink in (module docstring)
        if held.kind == KIND_HELD and obstacles[obstacle.obstacle].name in supports:
            return -HELD_SUPPORT_PENETRATION_M
        # A moving object's span counts larger by its sweep margin (`world.moving`).
        other = pb if pb.kind in OBSTACLE_KINDS else pa
        return clearance + float(obstacles[other.obstacle].margin)

    pair_margin = np.array([margin(a, b) for a, b in ordered], dtype=float)
    dynamic_ids = np.array([o for o, obj in enumerate(obstacles) if obj.dynamic], dtype=np.int64)
    pair_obstacle = np.array([max(pieces[a].obstacle, pieces[b].obstacle) for a, b in ordered], dtype=np.int64)
    # Grouped once (a moving object is hundreds of obstacles: `world.moving`).
    by_obstacle = np.argsort(pair_obstacle, kind="stable")
    first = np.searchsorted(pair_obstacle[by_obstacle], dynamic_ids, side="left")
    last = np.searchsorted(pair_obstacle[by_obstacle], dynamic_ids, side="right")
    dynamic_pairs = tuple(np.sort(by_obstacle[a:b]).astype(np.int64) for a, b in zip(first, last))
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
        pair_obstacle=pair_obstacle,
        lever=bounds.lever_arms(gm, moving),
        clearance=clearance,
        options=options,
        acm=acm,
        layout_contacts=_layout_contacts(gm, pieces, base_obstacle),
        prefilter=Prefilter.of(model, gm, [p.kind in OBSTACLE_KINDS for p in pieces], pair_a, pair_b, pair_margin),
    )


def _passive_pair(model: pin.Model, pieces: list[Piece], pair: tuple[int, int]) -> bool:
    return _is_passive_piece(model, pieces[pair[0]].joint) or _is_passive_piece(model, pieces[pair[1]].joint)


def always_touching_links(robot: RobotModel, options: CollisionOptions = CollisionOptions()) -> tuple[tuple[str, str], ...]:
    """The arm's link pairs that `build_shared` would keep checked though they touch in every one of
    its `options.acm_samples` seeded samples: its `AllowedCollisions.always_in_contact` for the arm
    alone (no tool, no objects), by link name, in geometry order.

    The same pair rules and the same samples (`_classify_pairs`, `_sample_self_pairs`), without the
    never-close proof: a pair touching in every sample cannot be proved apart. Pairs of a passive
    link are left out (the world disables those itself), as are adjacent pairs and those robot.yaml
    or its SRDF disable."""
    eye = np.eye(4)
    bare = Scene("", (), (), ToolGeometry("", (), (), "", "", eye), eye, int(robot.flange_frame_id))
    gm, pieces, obstacles = _pieces(robot, bare)
    rules = _classify_pairs(robot, bare, gm, pieces, obstacles, set())
    sampled = _sample_self_pairs(robot, gm, rules.self_candidates, set(), set(), options)
    links = (
        (pieces[a].body, pieces[b].body) for a, b in rules.self_candidates
        if (a, b) in sampled.always_touch and not _passive_pair(robot.model, pieces, (a, b)))
    return tuple(dict.fromkeys(links))


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


