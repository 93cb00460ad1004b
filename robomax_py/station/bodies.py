"""Robot-robot collision on a shared clock: every link piece and the tool (body and tips) of one
robot against every one of another, each posed by its own joint values, in the station's world.

The pieces are the collision pieces the single-robot checks use (`RobotModel.collision_model`, the
tool's pieces of `world.scene`), so "collide" means the same here as there. A shortcut culls most
pairs before coal is asked: spheres around each link (a gun: each few of its pieces) over a block of
consecutive samples, then around each link and each piece at a sample (coal's local AABB radius about its centre, which holds
the whole piece), then each piece's box (that AABB, placed with the piece) - volumes that keep apart
cannot hold pieces that touch, so the answer is the exact one (tests compare with every pair asked
of coal).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.robot import RobotModel
from robomax_py.station.clash_kernels import near_pieces
from robomax_py.world.scene import Scene

# Consecutive samples bounded together (`clash_map`): larger blocks cull fewer pairs per test,
# smaller ones need more tests; 16 samples are 0.64 s of motion at the diagrams' 40 ms.
BLOCK = 16
# Added to every sphere and box test's reach, m: the volumes' own arithmetic rounds, and coal's
# convex distance has a tolerance; a culled pair is then farther apart than either could hide.
ALLOWANCE_M = 1e-4
# Pieces per sphere above the pieces' own (`_clusters`): a link's pieces, a gun's split into a few.
CLUSTER = 3


@dataclass(frozen=True, slots=True, eq=False)
class RobotBody:
    """A robot's and its tool's collision pieces, each on its parent joint (-1: the flange)."""

    name: str
    robot: RobotModel
    pieces: tuple[coal.CollisionGeometry, ...]
    parent: tuple[int, ...]
    T_parent_piece: FloatArray      # (p, 4, 4)
    centre: FloatArray              # (p, 3) sphere and box centres in each piece's frame, m
    radius: FloatArray              # (p,) m
    half: FloatArray                # (p, 3) box half extents along the piece's axes, m
    T_world_base: FloatArray        # (4, 4)


def robot_body(name: str, robot: RobotModel, scene: Scene) -> RobotBody:
    pieces: list[coal.CollisionGeometry] = []
    parent: list[int] = []
    placement: list[FloatArray] = []
    for g in robot.collision_model.geometryObjects:
        pieces.append(g.geometry)
        parent.append(int(g.parentJoint))
        placement.append(g.placement.homogeneous)
    for piece in (*scene.tool.body, *scene.tool.tips):
        pieces.append(piece)
        parent.append(-1)
        placement.append(np.eye(4))
    centre, radius, half = [], [], []
    for piece in pieces:
        piece.computeLocalAABB()
        centre.append(np.asarray(piece.aabb_center, dtype=float))
        radius.append(float(piece.aabb_radius))
        box = piece.aabb_local
        half.append((np.asarray(box.max_, dtype=float) - np.asarray(box.min_, dtype=float)) / 2)
    return RobotBody(name, robot, tuple(pieces), tuple(parent), np.asarray(placement), np.asarray(centre),
                     np.asarray(radius), np.asarray(half), np.asarray(scene.T_world_base, dtype=float))


def body_poses(body: RobotBody, qs: FloatArray) -> FloatArray:
    """(k, n) joint values -> (k, p, 4, 4) world poses of every piece."""
    model = body.robot.model
    data = model.createData()
    flange = body.robot.flange_frame_id
    out = np.empty((len(qs), len(body.pieces), 4, 4))
    for i, q in enumerate(np.asarray(qs, dtype=float)):
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacement(model, data, flange)
        frames = [data.oMf[flange].homogeneous if p < 0 else data.oMi[p].homogeneous for p in body.parent]
        out[i] = body.T_world_base @ np.asarray(frames) @ body.T_parent_piece
    return out


def _spheres(body: RobotBody, poses: FloatArray) -> FloatArray:
    """(k, p, 3) world sphere centres."""
    out: FloatArray = np.einsum("kpij,pj->kpi", poses[:, :, :3, :3], body.centre) + poses[:, :, :3, 3]
    return out


def clash_map(a: RobotBody, poses_a: FloatArray, b: RobotBody, poses_b: FloatArray, margin: float,
              prefilter: bool = True, slack_a: FloatArray | None = None, slack_b: FloatArray | None = None,
              block: int = BLOCK) -> BoolArray:
    """(ka, kb) bool: True where robot a at sample i and robot b at sample j come closer than
    `margin + slack_a[i] + slack_b[j]` (m; slacks default 0) - any piece of one within that of any
    piece of the other. `prefilter=False` asks coal of every pair (the slow reference the tests
    hold the shortcut to); `block`: samples bounded together by the shortcut."""
    ka, kb = len(poses_a), len(poses_b)
    sa = np.zeros(ka) if slack_a is None else np.asarray(slack_a, dtype=float)
    sb = np.zeros(kb) if slack_b is None else np.asarray(slack_b, dtype=float)
    out = np.zeros((ka, kb), dtype=bool)
    ca, cb = _spheres(a, poses_a), _spheres(b, poses_b)
    request = coal.CollisionRequest()
    request.security_margin = margin
    if not prefilter:
        for i, j in np.argwhere(np.ones((ka, kb), dtype=bool)):
            request.security_margin = margin + sa[i] + sb[j]
            out[i, j] = any(_touch(a.pieces[u], poses_a[i, u], b.pieces[v], poses_b[j, v], request)
                            for u in range(len(a.pieces)) for v in range(len(b.pieces)))
        return out
    # Per block of `block` consecutive samples and per cluster of pieces (a link's; the gun's split
    # in a few), one sphere around that cluster's spheres over the block (each grown by its
    # sample's slack); block pairs whose cluster spheres keep apart are done, the rest descend to
    # each sample pair's cluster spheres, then its pieces' spheres and boxes (compiled:
    # `clash_kernels.near_pieces`), and coal decides what is left.
    ga, gb = _clusters(a), _clusters(b)
    La, RLa = _groups(ca, a.radius, ga)
    Lb, RLb = _groups(cb, b.radius, gb)
    rows, gaps = near_pieces(block, *_blocks(La, RLa, sa, block), *_blocks(Lb, RLb, sb, block), La, RLa, Lb, RLb,
                             ca, a.radius, *_members(ga), poses_a, a.half, cb, b.radius, *_members(gb), poses_b,
                             b.half, sa, sb, margin + ALLOWANCE_M)
    if not len(rows):
        return out
    # Per sample pair, the nearest piece pair first: a pair that touches mostly touches there.
    order = np.lexsort((gaps, rows[:, 1], rows[:, 0]))
    rows = rows[order]
    bounds = np.flatnonzero(np.any(np.diff(rows[:, :2], axis=0) != 0, axis=1)) + 1
    tf_a, tf_b = _transforms(poses_a), _transforms(poses_b)
    for first, stop in zip(np.r_[0, bounds].tolist(), np.r_[bounds, len(rows)].tolist(), strict=True):
        i, j = rows[first, :2].tolist()
        request.security_margin = margin + sa[i] + sb[j]
        for u, v in rows[first:stop, 2:].tolist():
            result = coal.CollisionResult()
            if coal.collide(a.pieces[u], tf_a(i, u), b.pieces[v], tf_b(j, v), request, result):
                out[i, j] = True
                break
    return out


def _blocks(centres: FloatArray, radius: FloatArray, slack: FloatArray, block: int
            ) -> tuple[FloatArray, FloatArray]:
    """Per block of `block` samples, a sphere around each group's spheres over the block, each grown
    by its sample's slack (and the rounding allowance): centres (nb, g, 3), radii (nb, g)."""
    k = len(centres)
    pad = -k % block
    C = np.concatenate([centres, np.repeat(centres[-1:], pad, axis=0)]).reshape(-1, block, *centres.shape[1:])
    R = np.concatenate([radius + slack[:, None], np.repeat(radius[-1:] + slack[-1], pad, axis=0)])
    R = R.reshape(-1, block, radius.shape[1])
    mid = (C.min(axis=1) + C.max(axis=1)) / 2
    out = (np.linalg.norm(C - mid[:, None], axis=3) + R).max(axis=1) + ALLOWANCE_M
    return mid, out


def _members(group: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pieces of each group: group g's are members[start[g]:start[g + 1]]."""
    members = np.argsort(group, kind="stable")
    start = np.r_[0, np.cumsum(np.bincount(group))]
    return start.astype(np.int64), members.astype(np.int64)


def _transforms(poses: FloatArray) -> Callable[[int, int], coal.Transform3s]:
    """coal's transform of piece p at sample i, made once when first asked for."""
    made: dict[tuple[int, int], coal.Transform3s] = {}

    def get(i: int, p: int) -> coal.Transform3s:
        tf = made.get((i, p))
        if tf is None:
            T = poses[i, p]
            tf = made[(i, p)] = coal.Transform3s(T[:3, :3], T[:3, 3])
        return tf

    return get


def _sq(d: FloatArray) -> FloatArray:
    out: FloatArray = np.einsum("...i,...i->...", d, d)
    return out


def _clusters(body: RobotBody, most: int = CLUSTER) -> np.ndarray:
    """Each piece's cluster, numbered 0..: the pieces of one link (the tool's: the flange's), split
    where there are more than `most` at the median of their centres along the axis they spread most
    on (in the link's frame, where they do not move), until none has more; a gun of many pieces is
    then several spheres, not one around all of it."""
    centre = np.einsum("pij,pj->pi", body.T_parent_piece[:, :3, :3], body.centre) + body.T_parent_piece[:, :3, 3]
    out = np.zeros(len(body.pieces), dtype=np.int64)
    todo = [np.flatnonzero(np.asarray(body.parent) == p) for p in sorted(set(body.parent))]
    n = 0
    while todo:
        members = todo.pop()
        if len(members) <= most:
            out[members] = n
            n += 1
            continue
        pts = centre[members]
        axis = int(np.argmax(pts.max(axis=0) - pts.min(axis=0)))
        order = members[np.argsort(pts[:, axis], kind="stable")]
        todo += [order[:len(order) // 2], order[len(order) // 2:]]
    return out


def _groups(centres: FloatArray, radius: FloatArray, group: np.ndarray) -> tuple[FloatArray, FloatArray]:
    """Per sample, a sphere around each group's piece spheres: centres (k, g, 3), radii (k, g)."""
    n = int(group.max()) + 1
    C = np.stack([centres[:, group == g].mean(axis=1) for g in range(n)], axis=1)
    R = np.stack([(np.linalg.norm(centres[:, group == g] - C[:, g, None], axis=2) + radius[group == g]).max(axis=1)
                  for g in range(n)], axis=1)
    return C, R


def sample_steps(body: RobotBody, poses: FloatArray) -> FloatArray:
    """(k,) the farthest any point of any piece moves between sample i and its neighbours (i - 1,
    i + 1), bounded as `sample_step` bounds it, m: between samples a piece is within half of this
    of the nearest sample."""
    if len(poses) < 2:
        return np.zeros(len(poses))
    c = _spheres(body, poses)
    shift = np.linalg.norm(np.diff(c, axis=0), axis=2)
    R0, R1 = poses[:-1, :, :3, :3], poses[1:, :, :3, :3]
    angle = np.arccos(np.clip((np.einsum("kpij,kpij->kp", R0, R1) - 1.0) / 2.0, -1.0, 1.0))
    step = (shift + angle * body.radius).max(axis=1)
    out: FloatArray = np.maximum(np.r_[step, 0.0], np.r_[0.0, step])
    return out


def sample_step(body: RobotBody, poses: FloatArray) -> float:
    """The farthest any point of any piece moves between two consecutive samples, bounded by its
    sphere: the centre's displacement plus the radius times the rotation angle, m. Between samples
    a piece is then within half this of where a sample has it."""
    if len(poses) < 2:
        return 0.0
    c = _spheres(body, poses)
    shift = np.linalg.norm(np.diff(c, axis=0), axis=2)
    R0, R1 = poses[:-1, :, :3, :3], poses[1:, :, :3, :3]
    cos = (np.einsum("kpij,kpij->kp", R0, R1) - 1.0) / 2.0
    angle = np.arccos(np.clip(cos, -1.0, 1.0))
    return float((shift + angle * body.radius).max())


def _touch(ga: coal.CollisionGeometry, Ta: FloatArray, gb: coal.CollisionGeometry, Tb: FloatArray,
           request: coal.CollisionRequest) -> bool:
    result = coal.CollisionResult()
    return bool(coal.collide(ga, coal.Transform3s(Ta[:3, :3], Ta[:3, 3]), gb, coal.Transform3s(Tb[:3, :3], Tb[:3, 3]),
                             request, result))
