"""Moving dynamic objects as obstacles that stand still in short time windows.

A moving object (a part carried along timed poses, `spec.PathMotion`; another robot replaying a
trajectory, `spec.RobotMotion`) is made of rigid bodies whose poses follow the clock. Each body's
motion is cut into spans; in each span the body is one ordinary dynamic obstacle (`SceneObject`)
posed where the body is at one time c of the span, present during the span, and counted larger by
the span's sweep margin (`SceneObject.margin`: coal's security margin grows by it, which is the
Minkowski sum with a ball of that radius). Every checker that knows dynamic objects' windows (the
timed search, the program's final timed check, `verify`) then checks the moving object without
change.

Conservative, exact in time: a point p of a body at distance <= r from the body's origin moves,
between times a and b, by at most |o(b) - o(a)| + r * angle(R(a)^T R(b)) when the body moves
along one straight line at one rate and turns about one axis at one rate (a path's poses are
linear in position and slerped in rotation between its knots, so this holds between consecutive
grid times, and is additive along the grid). The margin of a span is the largest sum from c to
either end, so at every time of the span the body lies inside its posed shape grown by the margin:
whenever the robot touches the moving body, it touches the grown shape of the span holding that
time. For another robot (linear in joint space between samples) the same sum is taken over a grid
of its own samples refined until each step moves a body by at most `sweep / 4`; between two grid
times a link's point leaves the chord of its two end positions by a second-order amount (< 0.1 mm
at the default sweep of 20 mm on the shipped arms), which the margin does not count: that is the
stated tolerance for robots. Spans are grown greedily until the margin would exceed `sweep`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
from scipy.spatial.transform import Rotation, Slerp

from robomax_py._typing import FloatArray
from robomax_py.errors import CellFileError
from robomax_py.robot import load_robot
from robomax_py.spec import MeshShape, ObjectSpec, PathMotion, RobotMotion, frozen_array
from robomax_py.world.bounds import support_points

# Grid steps move a body by at most this fraction of the sweep, so spans end close to it.
GRID_FRACTION = 0.25
# Spans a moving object may be cut into, over all its bodies: beyond, the cell is refused (a larger
# `sweep` or a slower motion is needed): every span is one obstacle of every collision world, and
# Pinocchio's geometry model grows worse than linearly in them (1000 pieces: ~1 s a world).
MAX_SPANS = 1500


@dataclass(frozen=True, slots=True, eq=False)
class Span:
    """One body standing still: its pose (world) at `t_pose`, in [t0, t1], grown by `margin` m."""

    t0: float
    t1: float
    t_pose: float
    T_world_body: FloatArray
    margin: float


@dataclass(frozen=True, slots=True, eq=False)
class Body:
    """A rigid body of a moving object: coal pieces in its frame, their radius about its origin,
    and its world pose at any times (vectorised: (m,) s -> (m, 4, 4))."""

    label: str
    pieces: tuple[coal.CollisionGeometry, ...]
    radius: float
    poses: Callable[[FloatArray], FloatArray]
    knots: FloatArray                # times where its motion may change rate (grid points)


def path_poses(motion: PathMotion, times: FloatArray) -> FloatArray:
    """(m, 4, 4) world poses of a path at `times` (s from the start of its first pass), held at its
    end poses outside it: position linear, rotation slerped between the knots."""
    t = np.asarray(motion.t, dtype=float)
    T = np.asarray(motion.T_world_object, dtype=float)
    tau = np.clip(np.asarray(times, dtype=float), t[0], t[-1])
    out = np.tile(np.eye(4), (len(tau), 1, 1))
    for i in range(3):
        out[:, i, 3] = np.interp(tau, t, T[:, i, 3])
    out[:, :3, :3] = Slerp(t, Rotation.from_matrix(T[:, :3, :3]))(tau).as_matrix()
    return out


def sweep_bound(poses: FloatArray, radius: float) -> FloatArray:
    """(m - 1,) m: how far any point within `radius` of the body's origin moves between consecutive
    poses (m, 4, 4), for a motion straight and at one rate in position and rotation between them."""
    P = np.asarray(poses, dtype=float)
    dp = np.linalg.norm(np.diff(P[:, :3, 3], axis=0), axis=1)
    rel = np.einsum("kji,kjl->kil", P[:-1, :3, :3], P[1:, :3, :3])
    cos = np.clip((np.trace(rel, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    return np.asarray(dp + radius * np.arccos(cos), dtype=float)


def spans(body: Body, window: tuple[float, float], sweep: float) -> list[Span]:
    """The body's motion over `window` (s; an infinite end holds the pose there) as spans whose
    margins are at most `sweep` (module docstring), in time order, sharing their end times."""
    w0, w1 = window
    k = np.asarray(body.knots, dtype=float)
    lo, hi = (max(w0, float(k[0])), min(w1, float(k[-1]))) if len(k) else (w0, w0)
    inner = k[(k > lo) & (k < hi)]
    grid = np.unique(np.concatenate([[lo], inner, [max(lo, hi)]]))
    poses = body.poses(grid)
    # Refine each step until it moves the body by at most GRID_FRACTION * sweep.
    d = sweep_bound(poses, body.radius)
    parts = [np.linspace(a, b, int(math.ceil(x / (GRID_FRACTION * sweep))) + 1)[:-1] if x > 0 else np.array([a])
             for a, b, x in zip(grid[:-1], grid[1:], d)]
    grid = np.concatenate([*parts, grid[-1:]]) if parts else grid
    poses = body.poses(grid)
    cum = np.concatenate([[0.0], np.cumsum(sweep_bound(poses, body.radius))])
    out: list[Span] = []
    a = 0
    n = len(grid) - 1
    while True:
        c = max(a, int(np.searchsorted(cum, cum[a] + sweep, side="right")) - 1)
        b = max(c, int(np.searchsorted(cum, cum[c] + sweep, side="right")) - 1)
        if b == a and a < n:
            b = a + 1                                  # a step longer than the sweep (never after refining)
        t0 = w0 if a == 0 else float(grid[a])
        t1 = w1 if b == n else float(grid[b])
        out.append(Span(t0, t1, float(grid[c]), frozen_array(poses[c]), float(max(cum[c] - cum[a], cum[b] - cum[c]))))
        if b >= n:
            return out
        a = b


def path_body(obj: ObjectSpec, pieces: tuple[coal.CollisionGeometry, ...]) -> Body:
    motion = obj.motion
    assert isinstance(motion, PathMotion)
    radius = max(float(np.max(np.linalg.norm(support_points(p), axis=1))) for p in pieces)
    return Body(obj.name, pieces, radius, lambda ts: path_poses(motion, ts), frozen_array(motion.t))


def path_windows(motion: PathMotion, span: Span) -> tuple[tuple[float, float], ...]:
    """A span of a path's first pass, in every pass (`repeat`)."""
    period = motion.repeat or 0.0
    return tuple((span.t0 + n * period, span.t1 + n * period) for n in range(motion.count))


def robot_bodies(obj: ObjectSpec, source: Path, tool_pieces: Callable[[MeshShape, str], tuple[coal.CollisionGeometry, ...]]) -> list[Body]:
    """The links (and tool) of another robot replaying a trajectory, each a body; CellFileError
    when the trajectory's joints are not the model's."""
    motion = obj.motion
    assert isinstance(motion, RobotMotion)
    robot = load_robot(motion.robot)
    if tuple(motion.joints) != tuple(robot.joint_names):
        raise CellFileError(source, motion.key + ".trajectory",
                            f"{motion.source.name}: joints {list(motion.joints)} are not those of {robot.name} "
                            f"{list(robot.joint_names)}")
    t = np.asarray(motion.t, dtype=float)
    q = np.asarray(motion.q, dtype=float)
    if not (robot.limits.contains(q, tol=1e-6).all()):
        raise CellFileError(source, motion.key + ".trajectory",
                            f"{motion.source.name}: joint values outside {robot.name}'s limits")
    T_wb = np.asarray(motion.T_world_base, dtype=float)
    model = robot.model
    data = model.createData()

    def frames(ts: FloatArray) -> FloatArray:
        """(m, nj + 1, 4, 4): every joint frame (then the flange) in the world at times ts."""
        tau = np.clip(np.asarray(ts, dtype=float), t[0], t[-1])
        qs = np.stack([np.interp(tau, t, q[:, j]) for j in range(q.shape[1])], axis=1)
        out = np.empty((len(tau), model.njoints + 1, 4, 4))
        for k, qk in enumerate(qs):
            pin.framesForwardKinematics(model, data, qk)
            for j in range(model.njoints):
                out[k, j] = T_wb @ data.oMi[j].homogeneous
            out[k, -1] = T_wb @ data.oMf[robot.flange_frame_id].homogeneous
        return out

    cache: dict[bytes, FloatArray] = {}

    def cached(ts: FloatArray) -> FloatArray:
        key = np.asarray(ts, dtype=float).tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = frames(ts)
        return cache[key]

    bodies: list[Body] = []
    for g in robot.collision_model.geometryObjects:
        P = g.placement.homogeneous
        j = int(g.parentJoint)
        pts = support_points(g.geometry, P)
        bodies.append(Body(f"{obj.name}/{g.name}", (g.geometry,), float(np.max(np.linalg.norm(pts, axis=1))),
                           _link(cached, j, P), frozen_array(t)))
    if motion.tool is not None:
        for part, mesh in (("tool_body", motion.tool.body), ("tool_tips", motion.tool.tips)):
            pieces = tool_pieces(mesh, part)
            radius = max(float(np.max(np.linalg.norm(support_points(p), axis=1))) for p in pieces)
            bodies.append(Body(f"{obj.name}/{part}", pieces, radius, _flange(cached), frozen_array(t)))
    return bodies


def _link(frames: Callable[[FloatArray], FloatArray], j: int, P: FloatArray) -> Callable[[FloatArray], FloatArray]:
    def poses(ts: FloatArray) -> FloatArray:
        out: FloatArray = frames(ts)[:, j] @ P
        return out
    return poses


def _flange(frames: Callable[[FloatArray], FloatArray]) -> Callable[[FloatArray], FloatArray]:
    def poses(ts: FloatArray) -> FloatArray:
        out: FloatArray = frames(ts)[:, -1]
        return out
    return poses


__all__ = ["MAX_SPANS", "Body", "Span", "path_body", "path_poses", "path_windows", "robot_bodies", "spans", "sweep_bound"]
