"""Quick checks of a cell's robot that `robomax check` runs before any planning.

- Reach: whether each spot can be reached at all, by a bound that needs no IK. A point fixed in the
  link that axis 4 turns (the wrist centre of a spherical wrist) stays within the upper arm plus
  forearm length of the axis-2 origin, which itself turns on a circle about axis 1; a spot all of
  whose grid orientations put that point farther from the circle is unreachable, and by how much
  is a figure the user can act on. Arms without a spherical wrist use the whole chain's length to
  the TCP instead (a weaker bound, still never wrong). An arm on a track or a gantry (prismatic
  joints before its first revolute one) has its circle moved along their travel: the distance is
  the least over a grid of the travel, less the most the grid can miss by (a distance moves by at
  most what the arm moves); a chain with a prismatic joint after a revolute one is not checked.
- Self contact: link pairs (neither adjacent nor disabled) that touch at home, or in every one of the
  collision world's seeded samples: candidates for robot.yaml `collision.disable`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray
from robomax_py.plan.poses import orientation_grid, spot_poses
from robomax_py.robot import RobotModel
from robomax_py.robot.ik._chain import joint_axes_at_zero
from robomax_py.spec import CellSpec
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.transforms import closest_on_line, invert
from robomax_py.world.acm import CollisionOptions, always_touching_links

WRIST_MEET_TOL_M = TOL.wrist_meet_tol_m


@dataclass(frozen=True, slots=True)
class SpotReach:
    """How far a spot's best grid orientation puts the arm's reference point from the shoulder circle."""

    seam: str
    name: str
    key: str                 # seams[i].spots[j], or where the cell file states the spot
    distance_m: float        # from the shoulder circle to the reference point, best orientation
    reach_m: float           # the longest that distance can be

    @property
    def out_by_m(self) -> float:
        return self.distance_m - self.reach_m

    @property
    def reachable(self) -> bool:
        return self.out_by_m <= 0.0


# A track's (or a gantry's) travel is sampled at most this many times in all, for the bound below:
# 8 mm apart on a 4 m track, the bound weaker by 4 mm; each sample costs a pass over the spots.
TRAVEL_SAMPLES = 512


@dataclass(frozen=True, slots=True)
class _ReachModel:
    axis_point: FloatArray   # (3,) on axis 1
    axis: FloatArray         # (3,) unit
    shoulder: FloatArray     # (3,) the axis-2 origin at q = 0
    p_tcp_ref: FloatArray    # (3,) the reference point in the TCP frame
    reach: float
    # Prismatic joints before the arm (a track, a gantry): the arm's offsets from where it stands at
    # q = 0, sampled over their travel (m, 3), and how far the nearest sample may be from any
    # offset of the travel (the bound subtracts it: distances change by at most the offset's move).
    offsets: FloatArray
    offset_slack_m: float


def _reach_model(robot: RobotModel) -> _ReachModel | None:
    """The bound's model of the arm; None for a chain it does not cover (a prismatic joint after
    a revolute one), whose spots are then not checked."""
    axes = joint_axes_at_zero(robot.model, robot.flange_frame_id)
    revolute = [bool(r) for r in axes.revolute]
    slides = next((k for k, r in enumerate(revolute) if r), len(revolute))
    if not all(revolute[slides:]) or len(revolute) - slides < 2:
        return None
    offsets, slack = _travel(robot, axes.u[:slides], list(axes.q_index[:slides]))
    u, p = list(axes.u[slides:]), list(axes.p[slides:])
    T_tcp = axes.T_flange @ np.asarray(robot.T_flange_tcp)
    wrist = _wrist_centre(p, u) if len(p) >= 6 else None
    if wrist is not None:
        ref = wrist
        reach = float(np.linalg.norm(p[2] - p[1]) + np.linalg.norm(wrist - p[2]))
    else:
        ref = T_tcp[:3, 3]
        reach = float(sum(np.linalg.norm(p[i + 1] - p[i]) for i in range(1, len(p) - 1)) + np.linalg.norm(ref - p[-1]))
    p_ref = (invert(T_tcp) @ np.append(ref, 1.0))[:3]
    return _ReachModel(p[0], u[0], p[1], p_ref, reach, offsets, slack)


def _travel(robot: RobotModel, slides: FloatArray, index: list[int]) -> tuple[FloatArray, float]:
    """Offsets (m, 3) of the arm over the leading prismatic joints' travel, on a grid of at most
    TRAVEL_SAMPLES points, and the most any offset of the travel lies from its nearest sample
    (half a grid step along each slide, summed)."""
    if not index:
        return np.zeros((1, 3)), 0.0
    per_axis = max(2, int(TRAVEL_SAMPLES ** (1.0 / len(index))))
    grids, slack = [], 0.0
    for q in index:
        lo, hi = float(robot.limits.lower[q]), float(robot.limits.upper[q])
        grids.append(np.linspace(lo, hi, per_axis))
        slack += 0.5 * (hi - lo) / (per_axis - 1)
    values = np.stack(np.meshgrid(*grids, indexing="ij"), axis=-1).reshape(-1, len(index))
    offsets: FloatArray = values @ np.asarray(slides, dtype=float)
    return offsets, slack


def _wrist_centre(p: list[FloatArray], u: list[FloatArray]) -> FloatArray | None:
    """Where axes 4, 5 and 6 meet at q = 0, or None when they do not meet in one point."""
    c = closest_on_line(p[3], u[3], p[4], u[4])            # u: unit axes
    for k in (3, 4, 5):
        if np.linalg.norm(np.cross(c - p[k], u[k])) > WRIST_MEET_TOL_M:
            return None
    return c


def reach_report(cell: CellSpec, robot: RobotModel) -> list[SpotReach]:
    """Every spot's reach figure, in cell order (see the module docstring); none for a chain the
    bound does not cover."""
    rm = _reach_model(robot)
    if rm is None:
        return []
    T_base_world = invert(np.asarray(cell.T_world_base))
    out: list[SpotReach] = []
    for i, seam in enumerate(cell.seams):
        grid = orientation_grid(seam)
        poses = spot_poses(seam.spots, grid)                      # (s, o, 4, 4) world
        ref = np.einsum("...ij,j->...i", T_base_world @ poses, np.append(rm.p_tcp_ref, 1.0))[..., :3]
        best = np.full(len(seam.spots), np.inf)
        for offset in rm.offsets:                                  # the arm where a track puts it
            best = np.minimum(best, _distance_to_circle(ref - offset, rm).min(axis=1))   # (s, o) -> (s,)
        best = np.maximum(best - rm.offset_slack_m, 0.0)
        for j, spot in enumerate(seam.spots):
            out.append(SpotReach(seam.name, spot.name, spot.key or f"seams[{i}].spots[{j}]", float(best[j]), rm.reach))
    return out


def _distance_to_circle(points: FloatArray, rm: _ReachModel) -> FloatArray:
    """Distance of points (..., 3) from the circle the shoulder point sweeps about axis 1."""
    rel_s = rm.shoulder - rm.axis_point
    h_s = float(rel_s @ rm.axis)
    r_s = float(np.linalg.norm(rel_s - h_s * rm.axis))
    rel = points - rm.axis_point
    h = rel @ rm.axis
    rho = np.linalg.norm(rel - h[..., None] * rm.axis, axis=-1)
    dist: FloatArray = np.hypot(h - h_s, rho - r_s)
    return dist


def self_contacts(robot: RobotModel, home: FloatArray) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """(link pairs touching at home, link pairs touching in every one of the collision world's seeded
    samples, `world.acm.always_touching_links`); neither adjacent nor disabled in robot.yaml. Link
    geometry only (the tool is checked by the planner)."""
    model = robot.model
    gm = robot.collision_model.copy()
    objs = list(gm.geometryObjects)
    pairs: list[tuple[int, int]] = []
    for a in range(len(objs)):
        for b in range(a + 1, len(objs)):
            ja, jb = int(objs[a].parentJoint), int(objs[b].parentJoint)
            if ja == jb or int(model.parents[ja]) == jb or int(model.parents[jb]) == ja:
                continue
            la, lb = model.frames[objs[a].parentFrame].name, model.frames[objs[b].parentFrame].name
            if frozenset((la, lb)) in robot.disabled_links:
                continue
            gm.addCollisionPair(pin.CollisionPair(a, b))
            pairs.append((a, b))
    if not pairs:
        return [], []
    gdata = gm.createData()
    for req in gdata.collisionRequests:
        req.enable_contact = True      # coal reports overlapping convex hulls only with contacts on
    pin.computeCollisions(model, model.createData(), gm, gdata, np.asarray(home, dtype=float), False)
    at_home: list[tuple[str, str]] = []
    for k, result in enumerate(gdata.collisionResults):
        a, b = pairs[k]
        pair = (model.frames[objs[a].parentFrame].name, model.frames[objs[b].parentFrame].name)
        if result.isCollision() and pair not in at_home:
            at_home.append(pair)
    return at_home, list(always_touching_links(robot))


def always_touching_text(robot: RobotModel, link_a: str, link_b: str,
                         samples: int = CollisionOptions().acm_samples) -> str:
    """What a link pair touching in every one of the collision world's `samples` samples means, and
    how to exempt it: every posture of the arm is a collision until it is."""
    return (f"links {link_a} and {link_b} touch in every one of the {samples} sampled "
            f"postures (parts that touch by design, or coarse collision meshes), so every posture collides; if "
            f"they touch by design, add [{link_a}, {link_b}] to collision.disable in {robot.source}")
