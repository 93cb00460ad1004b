"""A path's free shape parameters chosen for the least travel time of its two-step jerk-limited
profile (`frenet_profile`): the objective Benko Loknar, Klančar and Blažič optimise ("in each
iteration of the optimisation ... we compute the travel time on the given path"), not a proxy.

Nelder-Mead (the objective is a black box, not smooth where the profile's repairs move from one
node to the next or the grid gains a node), restarted from its own result so that a collapsed
simplex opens again. A shape the caller rejects (`build` returns a violation > 0) costs
PENALTY_S plus PENALTY_S per metre of violation, so the search is pushed back rather than stopped.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from robomax_py._typing import FloatArray
from robomax_py.spec import TcpLimits
from robomax_py.timing._common import TimingError
from robomax_py.timing.frenet_profile import time_of
from robomax_py.timing.quintic_chain import QuinticChain

PENALTY_S = 100.0
GRID_STEP_M = 0.02
Shape = Callable[[FloatArray], tuple[QuinticChain | None, float]]


@dataclass(frozen=True, slots=True)
class ShapeResult:
    """The best parameters found, their travel time on the search's grid (s), and the number of
    profiles computed."""

    x: FloatArray
    time: float
    evaluations: int


def optimise_shape(build: Shape, x0: FloatArray, scales: FloatArray, limits: TcpLimits, max_evaluations: int,
                   restarts: int = 2, step: float = GRID_STEP_M) -> ShapeResult:
    """Minimise the two-step profile's travel time over the parameters x of `build`, which maps x to
    (the chain, how far in metres it leaves the allowed region; None for no chain). Starts at x0
    with a simplex `scales` wide; profiles on a grid `step` m apart."""
    chain0, outside0 = build(np.asarray(x0, dtype=float))
    if chain0 is None or outside0 > 0.0:
        raise TimingError("the starting shape is not allowed")
    evaluations = 0

    def cost(x: FloatArray) -> float:
        nonlocal evaluations
        evaluations += 1
        chain, outside = build(np.asarray(x, dtype=float))
        if chain is None:
            return 2.0 * PENALTY_S
        if outside > 0.0:
            return PENALTY_S * (1.0 + outside)
        t = time_of(chain, limits, step)
        return t if math.isfinite(t) else 2.0 * PENALTY_S

    x = np.asarray(x0, dtype=float)
    best = cost(x)
    per_run = max(1, max_evaluations // (restarts + 1))
    for _ in range(restarts + 1):
        simplex = np.vstack([x, x + np.diag(np.asarray(scales, dtype=float))])
        res = minimize(cost, x, method="Nelder-Mead",
                       options={"maxfev": per_run, "xatol": 1e-5, "fatol": 1e-6, "adaptive": True,
                                "initial_simplex": simplex})
        if float(res.fun) < best:
            x, best = np.asarray(res.x, dtype=float), float(res.fun)
    return ShapeResult(x, best, evaluations)
