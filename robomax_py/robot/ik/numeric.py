"""Numeric IK for any serial arm: damped least squares from many seeds, batched.

For robots without a closed form (robot.yaml `ik.solver: numeric`). Every seed of every pose is
iterated by Levenberg-Marquardt (damping large far from the target, vanishing near it) in one
compiled loop (`numeric_kernel`), its kinematics from the Pinocchio model's constant data via
`_chain` (agreeing with `pin.framesForwardKinematics` to round-off), since calling Pinocchio once
per seed and iteration would cost milliseconds per pose; the solutions are then accepted,
canonicalised and told apart here with array operations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.robot.ik._chain import chain_to_frame, frame_pose, revolute_mask
from robomax_py.robot.ik.numeric_kernel import iterate_seeds
from robomax_py.robot.ik.turns import wrap_to_pi

TWO_PI = 2.0 * np.pi
# Iteration stops once both errors are below these (far tighter than the acceptance tolerance, and
# reached in one or two Gauss-Newton steps after it): the returned solutions are exact to round-off.
_STOP_POS_M = 1e-12
_STOP_ROT_RAD = 1e-12
# Largest joint step per iteration, rad (or m): keeps far-away seeds from jumping across the workspace.
_MAX_STEP = 0.5
# Two solutions closer than this in every joint (rad, wrapped; m for prismatic) are the same.
DEDUPE_RAD = 1e-4


@dataclass(frozen=True, slots=True)
class NumericIkParams:
    """robot.yaml `ik.params` for `solver: numeric`.

    seeds : random starting configurations per pose (plus the hint, when one is given).
    solutions : K, the fixed number of solution slots returned per pose.
    max_iterations : damped-least-squares iterations per seed.
    """

    seeds: int = 32
    solutions: int = 8
    max_iterations: int = 50


def numeric_ik(
    model: pin.Model,
    frame_id: int,
    T_root_frame: FloatArray,
    lower: FloatArray,
    upper: FloatArray,
    rng: np.random.Generator,
    n_seeds: int = 32,
    q_hint: FloatArray | None = None,
    *,
    max_solutions: int = 8,
    max_iterations: int = 50,
    pos_tol_m: float = 1e-6,
    rot_tol_rad: float = 1e-6,
    seeds: FloatArray | None = None,
) -> tuple[FloatArray, BoolArray]:
    """The distinct solutions found from `n_seeds` random starts per pose.

    Parameters
    ----------
    model : pin.Model
        Serial arm with single-axis (revolute or prismatic) joints; not modified.
    frame_id : int
        The frame to place (usually the flange).
    T_root_frame : (..., 4, 4) float
        Target poses of that frame in the model's root frame, metres.
    lower, upper : (n,) float
        Joint limits, rad (m for prismatic joints); every solution lies within them.
    rng : np.random.Generator
        Source of the random seeds (uniform within the limits, [-pi, pi] where a limit is infinite).
    n_seeds : int
        Random seeds per pose.
    q_hint : (..., n) or (n,) float, optional
        An extra first seed per pose (clipped into the limits): its solution, if any, comes first.
    max_solutions : int
        K, the number of solution slots per pose.
    pos_tol_m, rot_tol_rad : float
        A converged seed is accepted when its flange position and rotation errors are within these.
    seeds : (P, S, n) float, optional
        Starting configurations per pose (P poses flattened) used after the hint and before
        `n_seeds` random ones (the table solver's nearest stored rows).

    Returns
    -------
    q : (..., K, n) float
        Distinct solutions (no two within DEDUPE_RAD in every joint, revolute joints compared modulo
        2 pi), first found first; revolute joints at the in-limit value nearest to (-pi, pi]. NaN rows
        pad the slots not filled.
    valid : (..., K) bool
    """
    T = np.asarray(T_root_frame, dtype=float)
    batch = T.shape[:-2]
    T = T.reshape(-1, 4, 4)
    n_pose = T.shape[0]
    nq = int(model.nq)
    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    chain = chain_to_frame(model, frame_id)
    rev = revolute_mask(model)

    lo = np.where(np.isfinite(lower), lower, -np.pi)
    hi = np.where(np.isfinite(upper), upper, np.pi)
    given = np.zeros((n_pose, 0, nq)) if seeds is None else np.asarray(seeds, dtype=float).reshape(n_pose, -1, nq)
    n_start = n_seeds + (q_hint is not None) + given.shape[1]
    start = rng.uniform(lo, hi, size=(n_pose, n_start, nq))
    first = int(q_hint is not None)
    start[:, first:first + given.shape[1]] = given
    if q_hint is not None:
        hint = np.broadcast_to(np.asarray(q_hint, dtype=float), batch + (nq,)).reshape(-1, nq)
        start[:, 0] = np.clip(hint, lower, upper)
    q = np.ascontiguousarray(start.reshape(-1, nq))
    pose_of = np.repeat(np.arange(n_pose), n_start)
    iterate_seeds(np.ascontiguousarray(chain.K), np.asarray(chain.scale, dtype=float),
                  np.asarray(chain.offset, dtype=float), np.asarray(chain.active, dtype=bool),
                  np.asarray(chain.revolute, dtype=bool), np.asarray(chain.q_index, dtype=np.int64), q, pose_of,
                  np.ascontiguousarray(T[:, :3, :3]), np.ascontiguousarray(T[:, :3, 3]), lower, upper,
                  np.asarray(rev, dtype=bool), int(max_iterations), _STOP_POS_M, _STOP_ROT_RAD, _MAX_STEP)

    # Accept, canonicalise, dedupe.
    T_got = frame_pose(chain, q)
    pos_err = np.linalg.norm(T_got[:, :3, 3] - T[pose_of, :3, 3], axis=-1)
    R_rel = np.einsum("mki,mkj->mij", T_got[:, :3, :3], T[pose_of, :3, :3])
    rot_err = np.arccos(np.clip((np.trace(R_rel, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0))
    ok = (pos_err <= pos_tol_m) & (rot_err <= rot_tol_rad) & np.all(np.isfinite(q), axis=-1)
    q = _canonical(q, rev, lower, upper)
    ok &= np.all((q >= lower) & (q <= upper), axis=-1)

    q_seed = q.reshape(n_pose, n_start, nq)
    ok = ok.reshape(n_pose, n_start)
    kept = np.zeros_like(ok)
    for i in range(n_start):
        diff = np.abs(q_seed[:, :i] - q_seed[:, i : i + 1])            # (n_pose, i, nq)
        diff = np.where(rev, np.minimum(diff, TWO_PI - np.mod(diff, TWO_PI)), diff)
        dup = np.any(kept[:, :i] & np.all(diff < DEDUPE_RAD, axis=-1), axis=-1)
        kept[:, i] = ok[:, i] & ~dup
    order = np.argsort(~kept, axis=1, kind="stable")[:, :max_solutions]
    q_out = np.take_along_axis(q_seed, order[..., None], axis=1)
    valid = np.take_along_axis(kept, order, axis=1)
    if q_out.shape[1] < max_solutions:                                # fewer seeds than slots
        pad = max_solutions - q_out.shape[1]
        q_out = np.concatenate([q_out, np.full((n_pose, pad, nq), np.nan)], axis=1)
        valid = np.concatenate([valid, np.zeros((n_pose, pad), dtype=bool)], axis=1)
    q_out[~valid] = np.nan
    return q_out.reshape(batch + (max_solutions, nq)), valid.reshape(batch + (max_solutions,))


def _canonical(q: FloatArray, revolute: BoolArray, lower: FloatArray, upper: FloatArray) -> FloatArray:
    """Revolute joints moved by 2 pi k to the in-limit value nearest (-pi, pi]; others unchanged."""
    wrapped = wrap_to_pi(q)
    out = np.where(revolute, np.nan, q)
    for k in (0, -1, 1, -2, 2):
        cand = wrapped + TWO_PI * k
        take = revolute & np.isnan(out) & (cand >= lower) & (cand <= upper)
        out = np.where(take, cand, out)
    return np.where(np.isnan(out), q, out)
