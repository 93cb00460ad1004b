"""A continuation's first move: from where the robot stopped to the first stop of the rest.

The sequencer plans every tour from home to home (`plan.sequence.HOME`, one configuration at both
ends). A continuation (`CellSpec.start`, `robomax replan`) starts elsewhere: its tour is sequenced
as usual and its first transition, home to the first approach point, is then made again from the
start: the straight joint move where it is free of the static obstacles, else a path through the
plan's roadmap (whose anchors include the start), else the start joined straight to the tour's own
first move where it sees one of its waypoints, else the random trees of `plan.rrt_detour`, else back
to home (by the same ways) and the tour's first move from there. The order and the candidates were
chosen for a start at home; on the ordered jobs that replanning serves (a tending cycle's station visits) only
the candidate of the first stop could differ, and it is still a valid one.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from robomax_py.errors import RobomaxError
from robomax_py.plan.results import Transition, TransitionKind
from robomax_py.plan.roadmap import Roadmap
from robomax_py.plan.rrt_detour import rrt_detour
from robomax_py.program import as_written_joints
from robomax_py.robot import JointLimits, RobotModel
from robomax_py.world.collision import CollisionWorld

# The first move of a continuation is labelled `stop -> <first stop>` (a whole program's: `home -> ...`).
START_LABEL = "stop"


class LeadInError(RobomaxError):
    """No collision-free way from the start of a continuation to its first stop."""


def lead_in(world: CollisionWorld, roadmap: Roadmap | None, start: np.ndarray,
            transitions: list[Transition], robot: RobotModel, rng: np.random.Generator) -> list[Transition]:
    """The transitions with the first one starting at `start` (n,) rad instead of home.

    world : the static obstacles (the plan's world); roadmap : the plan's detour roadmap.
    robot, rng : the robot (its joint limits, and its joint kinds for the values as written) and the
    plan's random generator, for the last resort, the
    random trees of `plan.rrt_detour` (as between two spots no other detour joins).
    LeadInError when neither the straight move, a roadmap path, a join to the first move nor the
    random trees within their budget of checks is free."""
    if not transitions:
        return transitions
    first = transitions[0]
    q0 = as_written_joints(np.asarray(start, dtype=float), robot.prismatic)
    goal = np.asarray(first.waypoints[-1], dtype=float)
    label = f"{START_LABEL} ->" + first.label.partition("->")[2] if "->" in first.label else first.label
    first = replace(first, label=label)

    def led(kind: TransitionKind, waypoints: np.ndarray, checks: int) -> list[Transition]:
        # Joint moves from the start: a TCP line detour's lines were for a start at home.
        moved = replace(first, kind=kind, waypoints=waypoints, checks=checks, lin_targets=None, lin_configs=(),
                        lin_speed=0.0)
        return [moved, *transitions[1:]]

    if world.check_segment(q0, goal).free:
        return led("move", np.vstack([q0, goal]), 0)
    detour = roadmap.query(q0, goal) if roadmap is not None else None
    if detour is not None:
        return led("detour", as_written_joints(detour.waypoints, robot.prismatic), detour.checks)
    waypoints = np.asarray(first.waypoints, dtype=float)
    joined = _joined(world, q0, waypoints)
    if joined is None:
        searched, _ = rrt_detour(world, robot.limits, q0, goal, rng)
        joined = None if searched is None else searched.waypoints
    if joined is None:
        joined = _via_home(world, roadmap, q0, waypoints, robot.limits, rng)
    if joined is None:
        raise LeadInError(f"no collision-free move from the stop configuration to the first stop of the rest "
                          f"({first.label}), nor back to home")
    return led("detour", as_written_joints(joined, robot.prismatic), 0)


def _via_home(world: CollisionWorld, roadmap: Roadmap | None, q0: np.ndarray, waypoints: np.ndarray,
              limits: JointLimits, rng: np.random.Generator) -> np.ndarray | None:
    """The start taken back to home (straight, through the roadmap, else by the random trees) and
    the tour's own first move followed from there, as an operator restarts a cell: the first stop
    was chosen for a start at home, and the move from home to it was checked free when the tour was
    sequenced (its first waypoint is home). Where the stop sees no way to the first stop (a robot
    stopped beyond clamps from it, an object appeared between them), the way home, which the robot
    often came along, may still be open. None when no way home is found either."""
    home = waypoints[0]
    if world.check_segment(q0, home).free:
        back = np.vstack([q0, home])
    else:
        detour = roadmap.query(q0, home) if roadmap is not None else None
        if detour is None:
            searched, _ = rrt_detour(world, limits, q0, home, rng)
            if searched is None:
                return None
            back = np.asarray(searched.waypoints, dtype=float)
        else:
            back = np.asarray(detour.waypoints, dtype=float)
    return np.vstack([back, waypoints[1:]])


def _joined(world: CollisionWorld, q0: np.ndarray, waypoints: np.ndarray) -> np.ndarray | None:
    """The start joined straight to the latest waypoint of the tour's own first move it reaches free,
    that move followed from there: a robot stopped beside a clamp (a move cut short on its detour)
    often sees the detour's later waypoints, where the approach point itself is behind the clamp and
    the roadmap, sampled for moves between spots, has no node it sees. The first move's waypoints
    were checked free when the tour was sequenced; from home, the first is home itself."""
    for k in range(len(waypoints) - 2, 0, -1):
        if world.check_segment(q0, waypoints[k]).free:
            return np.vstack([q0[None, :], waypoints[k:]])
    return None
