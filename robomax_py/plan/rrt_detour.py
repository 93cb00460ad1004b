"""A detour by bidirectional rapidly-exploring random trees (RRT-Connect) in joint space.

The last resort between two configurations that the lift, the roadmap, the local A1-A3 map and
sliding the gun off a flange all failed to join: a narrow way out of a flange or bracket, where
the gun must turn about its electrode axis, lies in a corridor the shared roadmap samples too
thinly and the local map (the wrist interpolated along A1-A3) cannot express. Two trees grow from
the ends, within the joint limits, each extension a swept-checked straight move of at most `step`
(time-scaled joint distance); the search stops after `budget` swept checks (a count, not a clock).
The path found is shortened greedily.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.roadmap import Detour
from robomax_py.plan.shortcut import greedy_shortcut
from robomax_py.robot import JointLimits
from robomax_py.timing import ptp_time_estimate
from robomax_py.world.collision import CollisionWorld

# Swept checks (tree extensions and connections) per search, and per pair of trees: the trees are
# grown afresh after TRY_BUDGET checks (trees that missed a narrow way out early mostly keep
# missing it, their nodes crowding the open space).
BUDGET = 2400
TRY_BUDGET = 100
# Longest tree edge, as a share of the joint-limit box's diagonal (time-scaled). OMPL's default
# (0.2) leaves a gun wrapped round a flange almost no free first step: on a generated flange cell
# one seed in four met within 2,400 checks, against every seed at this step.
STEP_FRACTION = 0.05


def rrt_detour(world: CollisionWorld, limits: JointLimits, qa: FloatArray, qb: FloatArray,
               rng: np.random.Generator, budget: int = BUDGET) -> tuple[Detour | None, int]:
    """A swept-checked detour from qa to qb (None when the trees have not met within `budget`
    swept checks), and the collision checks spent."""
    qa, qb = np.asarray(qa, dtype=float), np.asarray(qb, dtype=float)
    lo, hi = np.asarray(limits.lower, dtype=float), np.asarray(limits.upper, dtype=float)
    scale = 1.0 / np.asarray(limits.velocity, dtype=float)          # distance ~ joint time
    step = STEP_FRACTION * float(np.linalg.norm((hi - lo) * scale))
    checks = 0
    segments = 0

    def free(p: FloatArray, r: FloatArray) -> bool:
        nonlocal checks, segments
        res = world.check_segment(p, r)
        checks += res.checks
        segments += 1
        return bool(res.free)

    def toward(p: FloatArray, target: FloatArray) -> FloatArray:
        d = float(np.linalg.norm((target - p) * scale))
        return target if d <= step else p + (target - p) * (step / d)

    path = None
    while path is None and segments < budget:
        path = _try(qa, qb, lo, hi, scale, rng, free, toward, min(budget, segments + TRY_BUDGET), lambda: segments)
    if path is None:
        return None, checks
    found = path
    keep = greedy_shortcut(len(found), lambda i, j: free(found[i], found[j]))
    assert keep is not None                              # neighbours were checked as tree edges
    wp = found[keep]
    return Detour(wp, float(np.sum(ptp_time_estimate(wp[:-1], wp[1:], limits))), checks), checks


def _try(qa: FloatArray, qb: FloatArray, lo: FloatArray, hi: FloatArray, scale: FloatArray,
         rng: np.random.Generator, free: Callable[[FloatArray, FloatArray], bool],
         toward: Callable[[FloatArray, FloatArray], FloatArray], stop: int,
         spent: Callable[[], int]) -> FloatArray | None:
    """One pair of trees grown from qa and qb until they meet (the path, (m, n)) or `spent()`
    reaches `stop` (None)."""
    # Each tree: nodes (list of arrays) and parent indices.
    trees: list[tuple[list[FloatArray], list[int]]] = [([qa], [-1]), ([qb], [-1])]
    grow = 0
    while spent() < stop:
        nodes, parents = trees[grow]
        other_nodes, other_parents = trees[1 - grow]
        target = rng.uniform(lo, hi)
        near = int(np.argmin(np.linalg.norm((np.array(nodes) - target) * scale, axis=1)))
        new = toward(nodes[near], target)
        if free(nodes[near], new):
            nodes.append(new)
            parents.append(near)
            # Connect: the other tree grows straight towards the new node until blocked or there.
            k = int(np.argmin(np.linalg.norm((np.array(other_nodes) - new) * scale, axis=1)))
            while spent() < stop:
                nxt = toward(other_nodes[k], new)
                if not free(other_nodes[k], nxt):
                    break
                other_nodes.append(nxt)
                other_parents.append(k)
                k = len(other_nodes) - 1
                if nxt is new:
                    return _joined(trees, grow, len(nodes) - 1, k)
        grow = 1 - grow
    return None


def _branch(nodes: list[FloatArray], parents: list[int], k: int) -> list[FloatArray]:
    out = []
    while k >= 0:
        out.append(nodes[k])
        k = parents[k]
    return out                                     # from node k back to the tree's root


def _joined(trees: list[tuple[list[FloatArray], list[int]]], grow: int, k_grow: int, k_other: int) -> FloatArray:
    """The path from qa (tree 0's root) to qb (tree 1's root) through the two meeting nodes."""
    a = _branch(*trees[grow], k_grow)
    b = _branch(*trees[1 - grow], k_other)
    start_side, goal_side = (a, b) if grow == 0 else (b, a)
    # The meeting node is the last of both branches' heads: keep it once.
    return np.array([*start_side[::-1], *goal_side[1:]])
