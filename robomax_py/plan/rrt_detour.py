"""A detour by bidirectional rapidly-exploring random trees (OMPL's RRT-Connect) in joint space.

The last resort between two configurations that the lift, the roadmap, the local A1-A3 map and
sliding the gun off a flange all failed to join: a narrow way out of a flange or bracket, where
the gun must turn about its electrode axis, lies in a corridor the shared roadmap samples too
thinly and the local map (the wrist interpolated along A1-A3) cannot express. OMPL's RRT-Connect
grows two trees from the ends, within the joint limits, each extension a swept-checked straight
move of at most `STEP_FRACTION` of the joint box's diagonal in time-scaled joint distance; the
search stops after `budget` swept checks or `CHECK_BUDGET` configurations checked, whichever
comes first (counts, not a clock). The path found is shortened greedily.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.roadmap import Detour
from robomax_py.plan.shortcut import greedy_shortcut
from robomax_py.robot import JointLimits
from robomax_py.timing import polyline_time_estimate
from robomax_py.world.collision import CollisionWorld

# Swept checks (tree extensions and connections) per search, and per pair of trees: the trees are
# grown afresh after TRY_BUDGET checks (trees that missed a narrow way out early mostly keep
# missing it, their nodes crowding the open space). OMPL tests its termination condition between
# iterations, not within a connect run, so a try may overrun its share by one connect run.
BUDGET = 2400
TRY_BUDGET = 100
# Configurations checked per search, whatever the swept checks' lengths: a swept check samples
# the move every few millimetres of the arm's travel, so a tree edge of a fast small arm (an LR
# Mate's 0.08 s of joint time sweeps the TCP 0.6 m) checks some 300 configurations. 2,400 such
# edges were 770,000 checks, 20 s of CPU per search on a cell with meshed obstacles and a meshed
# part in the gripper, three searches per dead end, where "a few CPU seconds" was meant.
CHECK_BUDGET = 150_000
# Longest tree edge, as a share of the joint-limit box's diagonal (time-scaled). OMPL's default
# (0.2) leaves a gun wrapped round a flange almost no free first step: on a generated flange cell
# one seed in four met within 2,400 checks, against every seed at this step.
STEP_FRACTION = 0.05


def rrt_detour(world: CollisionWorld, limits: JointLimits, qa: FloatArray, qb: FloatArray,
               rng: np.random.Generator, budget: int = BUDGET) -> tuple[Detour | None, int]:
    """A swept-checked detour from qa to qb (None when the trees have not met within `budget`
    swept checks or `CHECK_BUDGET` configurations checked), and the collision checks spent.

    OMPL's random numbers come from a process-wide seed, set here from `rng` before the search,
    so the same planner state gives the same detour.
    """
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)
    qa, qb = np.asarray(qa, dtype=float), np.asarray(qb, dtype=float)
    dof = len(qa)
    # OMPL's real vector space measures plain Euclidean distance: the trees live in joint
    # coordinates divided by each joint's velocity limit, so distance there is joint time, as in
    # the roadmap and the move-time estimates.
    scale = 1.0 / np.asarray(limits.velocity, dtype=float)
    lo, hi = np.asarray(limits.lower, dtype=float), np.asarray(limits.upper, dtype=float)
    step = STEP_FRACTION * float(np.linalg.norm((hi - lo) * scale))
    # Ends within the joint tolerance but just outside the limits would be refused as start or goal.
    lo, hi = np.minimum(lo, np.minimum(qa, qb)), np.maximum(hi, np.maximum(qa, qb))
    checks = 0
    segments = 0

    def free(p: FloatArray, r: FloatArray) -> bool:
        nonlocal checks, segments
        res = world.check_segment(p, r)
        checks += res.checks
        segments += 1
        return bool(res.free)

    def joints(state: Any) -> FloatArray:
        return np.array([state[k] for k in range(dof)]) / scale

    def state_free(state: Any) -> bool:
        nonlocal checks
        checks += 1
        return bool(world.is_free(joints(state)))

    space = ob.RealVectorStateSpace(dof)
    bounds = ob.RealVectorBounds(dof)
    for k in range(dof):
        bounds.setLow(k, float(lo[k] * scale[k]))
        bounds.setHigh(k, float(hi[k] * scale[k]))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(state_free)
    validator = _swept_validator(ob, si, lambda s1, s2: free(joints(s1), joints(s2)))
    si.setMotionValidator(validator)
    si.setup()
    start, goal = space.allocState(), space.allocState()
    for k in range(dof):
        start[k], goal[k] = float(qa[k] * scale[k]), float(qb[k] * scale[k])

    path = None
    while path is None and segments < budget and checks < CHECK_BUDGET:
        # A fresh pair of trees per try, its random numbers drawn from `rng`: OMPL seeds each new
        # generator (the planner's, the sampler's) from one process-wide sequence, which setSeed
        # restarts even after the first seeds were handed out (OMPL logs a complaint, silenced
        # above). The plan runs in one thread, so no other search draws from that sequence meanwhile.
        ou.RNG.setSeed(int(rng.integers(1, 2**31)))
        setup = og.SimpleSetup(si)
        setup.setStartAndGoalStates(start, goal)
        planner = og.RRTConnect(si)
        planner.setRange(step)
        setup.setPlanner(planner)
        stop = min(budget, segments + TRY_BUDGET)
        solved = setup.solve(ob.PlannerTerminationCondition(
            lambda stop=stop: segments >= stop or checks >= CHECK_BUDGET))
        if solved and setup.haveExactSolutionPath():
            found = setup.getSolutionPath()
            path = np.array([joints(found.getState(i)) for i in range(found.getStateCount())])
    if path is None:
        return None, checks
    # The ends exactly as given, not as scaled and scaled back (a rounding apart).
    path[0], path[-1] = qa, qb
    joined = path
    keep = greedy_shortcut(len(joined), lambda i, j: free(joined[i], joined[j]))
    assert keep is not None                              # neighbours were checked as tree edges
    wp = joined[keep]
    return Detour(wp, polyline_time_estimate(wp, limits), checks), checks


def _swept_validator(ob: Any, si: Any, motion_free: Any) -> Any:
    """An OMPL motion validator whose every motion is the collision world's swept check."""

    class Swept(ob.MotionValidator):  # type: ignore[misc]
        def checkMotion(self, s1: Any, s2: Any) -> bool:          # OMPL's name
            return bool(motion_free(s1, s2))

    return Swept(si)
