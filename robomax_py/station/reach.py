"""What each robot of a station can weld, and what it costs: the collision-free candidates of every
spot it may weld (the single-robot planner's own, `plan.candidates`), reduced to what the assignment
needs: a few representative approach configurations per spot for the tour estimate, and every
candidate's weld and approach configuration (and their box) for the lower bound."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.candidates import SpotCandidates, seam_candidates
from robomax_py.plan.pipeline import spot_failure
from robomax_py.plan.reach import reach_report
from robomax_py.robot import RobotModel
from robomax_py.spec_station import SpotKey, StationSpec, robot_view
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

# Representative configurations per spot for the tour estimate: the candidate nearest home and the
# ones farthest from those chosen (farthest-point sampling), so that distinct IK branches are seen.
REPRESENTATIVES = 4


@dataclass(frozen=True, slots=True, eq=False)
class RobotReach:
    """One robot's view of the spots it may weld.

    keys : the spots with at least one collision-free candidate, in file order.
    unreachable : the spots it may weld but has no candidate for.
    reps : (len(keys), REPRESENTATIVES, n) float, rad: approach configurations (repeated when fewer).
    lo, hi : (len(keys), n) float, rad: the box of every candidate's weld configuration.
    weld_q, app_q : per spot (c, n) float, rad: every candidate's weld and approach configuration
        (row k of both one candidate), for the lower bound.
    home : (n,) rad. velocity, acceleration : (n,) joint limits.
    dwell : (len(keys),) s, the weld time of each spot.
    line_s : s per approach or retract line (at the planner's TCP speed), for the estimate only.
    candidates : each key's candidates, as the single-robot planner finds them (`plan_cell(known=)`).
    why : each unreachable spot's reason, as the single-robot planner states it ("collision
        (tool_body vs frame x12, ...)", "0.412 m out of reach at the best orientation").
    """

    robot: str
    keys: tuple[SpotKey, ...]
    unreachable: tuple[SpotKey, ...]
    reps: FloatArray
    lo: FloatArray
    hi: FloatArray
    home: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    dwell: FloatArray
    line_s: float
    candidates: Mapping[SpotKey, SpotCandidates]
    weld_q: tuple[FloatArray, ...] = ()
    app_q: tuple[FloatArray, ...] = ()
    why: Mapping[SpotKey, str] = field(default_factory=dict)

    def index(self) -> dict[SpotKey, int]:
        return {k: i for i, k in enumerate(self.keys)}


def robot_reach(station: StationSpec, name: str, model: RobotModel) -> RobotReach:
    """The candidates of every spot robot `name` may weld, found as the single-robot planner finds them."""
    allowed = station.allowed(name)
    # Spots beyond the arm's reach at every orientation (plan.reach, a few ms) need no candidates.
    far = {(r.seam, r.name): r for r in reach_report(robot_view(station, name, allowed), model) if not r.reachable}
    why = {k: f"{r.out_by_m:.3f} m out of reach at the best orientation" for k, r in far.items()}
    cell = robot_view(station, name, [k for k in allowed if k not in far])
    world = CollisionWorld(model, build_scene(cell, model), cell.process.clearance)
    home = np.asarray(cell.home, dtype=float)
    keys: list[SpotKey] = []
    unreachable: list[SpotKey] = [k for k in allowed if k in far]
    reps, lo, hi, dwell, weld_q, app_q = [], [], [], [], [], []
    candidates: dict[SpotKey, SpotCandidates] = {}
    for s, seam in enumerate(cell.seams):
        found, _ = seam_candidates(cell, model, world, s)
        for c in found:
            key = (seam.name, c.name)
            if len(c) == 0:
                unreachable.append(key)
                failure = spot_failure(cell, c)
                why[key] = f"{failure.reason} ({failure.detail})"
                continue
            keys.append(key)
            candidates[key] = c
            reps.append(_representatives(c.q_app, home))
            lo.append(c.q_spot.min(axis=0))
            hi.append(c.q_spot.max(axis=0))
            weld_q.append(np.ascontiguousarray(c.q_spot, dtype=float))
            app_q.append(np.ascontiguousarray(c.q_app, dtype=float))
            dwell.append(cell.process.weld_time_of(seam.spots[c.spot_index]))
    n = model.dof
    line_s = cell.process.approach / max(cell.planner.tcp_speed * cell.planner.speed, 1e-6)
    return RobotReach(name, tuple(keys), tuple(unreachable),
                      np.asarray(reps).reshape(len(keys), REPRESENTATIVES, n),
                      np.asarray(lo).reshape(len(keys), n), np.asarray(hi).reshape(len(keys), n), home,
                      np.asarray(model.limits.velocity, dtype=float), np.asarray(model.limits.acceleration, dtype=float),
                      np.asarray(dwell, dtype=float), float(line_s), candidates, tuple(weld_q), tuple(app_q), why)


def _representatives(q: FloatArray, home: FloatArray) -> FloatArray:
    """(REPRESENTATIVES, n): the candidate nearest home, then farthest-point picks."""
    chosen = [int(np.argmin(np.abs(q - home).max(axis=1)))]
    while len(chosen) < min(REPRESENTATIVES, len(q)):
        d = np.min([np.abs(q - q[c]).max(axis=1) for c in chosen], axis=0)
        chosen.append(int(np.argmax(d)))
    while len(chosen) < REPRESENTATIVES:
        chosen.append(chosen[-1])
    return q[chosen]


def move_time(qa: FloatArray, qb: FloatArray, velocity: FloatArray, acceleration: FloatArray) -> FloatArray:
    """Estimated time of a joint move, rest to rest, each joint bang-coast-bang at its limits and the
    slowest joint deciding: (..., n) x (..., n) -> (...) s. An estimate, not a bound (fly-by legs are
    faster)."""
    d = np.abs(np.asarray(qa) - np.asarray(qb))
    v, a = velocity, acceleration
    t = np.where(d > v * v / a, d / v + v / a, 2.0 * np.sqrt(d / a))
    out: FloatArray = t.max(axis=-1)
    return out


def cost_matrix(reach: RobotReach) -> FloatArray:
    """(m + 1, m + 1) estimated leg times between home (index 0) and every reachable spot: the
    quickest move between any of their representative configurations."""
    m = len(reach.keys)
    pts = np.concatenate([np.repeat(reach.home[None, None, :], REPRESENTATIVES, axis=1), reach.reps], axis=0)
    out = np.zeros((m + 1, m + 1))
    for i in range(m + 1):
        t = move_time(pts[i][None, :, None, :], pts[:, None, :, :], reach.velocity, reach.acceleration)
        out[i] = t.reshape(m + 1, -1).min(axis=1)
    np.fill_diagonal(out, 0.0)
    return out


def tour_legs(reach: RobotReach, cost: FloatArray, order: Sequence[SpotKey]) -> float:
    """The estimated time of the moves of the tour home -> `order` -> home, s (`cost`: the robot's
    `cost_matrix`)."""
    index = reach.index()
    nodes = np.array([0, *(index[k] + 1 for k in order), 0])
    return float(cost[nodes[:-1], nodes[1:]].sum())


def tour_estimate(reach: RobotReach, cost: FloatArray, order: Sequence[SpotKey],
                  penalty: Mapping[tuple[str, SpotKey], float]) -> float:
    """The estimated time of the tour home -> `order` -> home as the assignment counts it, s: the
    moves (`tour_legs`), each spot's weld and approach and retract lines, and `penalty` (extra
    seconds a spot costs the robot: the side prior)."""
    index = reach.index()
    work = sum(float(reach.dwell[index[k]]) + 2 * reach.line_s + penalty.get((reach.robot, k), 0.0) for k in order)
    return tour_legs(reach, cost, order) + work
