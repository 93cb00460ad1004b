"""Numeric IK for any serial arm: damped least squares from many seeds, batched.

For robots without a closed form (robot.yaml `ik.solver: numeric`). Every seed of every pose is
iterated at once with array operations; kinematics come from the Pinocchio model's constant data via
`_chain` (agreeing with `pin.framesForwardKinematics` to round-off), since calling Pinocchio once
per seed and iteration would cost milliseconds per pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.robot.ik._chain import (
    chain_to_frame,
    frame_pose,
    frame_pose_and_jacobian,
    revolute_mask,
)
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
    q = start.reshape(-1, nq)
    pose_of = np.repeat(np.arange(n_pose), n_start)
    R_des = T[:, :3, :3].transpose(1, 2, 0)                            # (3, 3, n_pose)
    p_des = T[:, :3, 3].T                                              # (3, n_pose)

    active = np.arange(q.shape[0])
    for _ in range(max_iterations):
        if active.size == 0:
            break
        qa = q[active]
        R, p, J = frame_pose_and_jacobian(chain, qa)
        target = pose_of[active]
        e_pos = p_des[:, target] - p                                   # (3, m)
        e_rot = _rotation_log(np.einsum("ikm,jkm->ijm", R_des[:, :, target], R))
        err_p = np.sqrt(np.einsum("im,im->m", e_pos, e_pos))
        err_r = np.sqrt(np.einsum("im,im->m", e_rot, e_rot))
        done = (err_p < _STOP_POS_M) & (err_r < _STOP_ROT_RAD)
        go = ~done
        if not go.any():
            break
        e = np.concatenate([e_pos, e_rot], axis=0).T[go]               # (m', 6)
        Jg = J[go]
        # Levenberg-Marquardt damping: large far from the target, vanishing near it.
        lam = np.clip(1e-2 * (err_p[go] ** 2 + err_r[go] ** 2), 1e-10, 1e-1)
        A = Jg @ Jg.transpose(0, 2, 1)
        A[:, range(6), range(6)] += lam[:, None]
        try:
            x = np.linalg.solve(A, e[..., None])
        except np.linalg.LinAlgError:                                  # a numerically singular A
            x = np.linalg.pinv(A) @ e[..., None]
        dq = (Jg.transpose(0, 2, 1) @ x)[..., 0]
        step = np.max(np.abs(dq), axis=-1, keepdims=True)
        dq *= np.minimum(1.0, _MAX_STEP / np.maximum(step, 1e-300))
        idx = active[go]
        q[idx] = _into_limits(qa[go] + dq, rev, lower, upper)
        active = idx

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


def _into_limits(q: FloatArray, revolute: BoolArray, lower: FloatArray, upper: FloatArray) -> FloatArray:
    """A revolute joint that stepped past a limit re-enters 2 pi further round if that is inside; then clip.

    Without the wrap, seeds of joints with +-2 pi (or +-pi) limits pile up on the limit and stall.
    """
    q = np.where(revolute & (q > upper) & (q - TWO_PI >= lower), q - TWO_PI, q)
    q = np.where(revolute & (q < lower) & (q + TWO_PI <= upper), q + TWO_PI, q)
    return np.clip(q, lower, upper)


def _canonical(q: FloatArray, revolute: BoolArray, lower: FloatArray, upper: FloatArray) -> FloatArray:
    """Revolute joints moved by 2 pi k to the in-limit value nearest (-pi, pi]; others unchanged."""
    wrapped = wrap_to_pi(q)
    out = np.where(revolute, np.nan, q)
    for k in (0, -1, 1, -2, 2):
        cand = wrapped + TWO_PI * k
        take = revolute & np.isnan(out) & (cand >= lower) & (cand <= upper)
        out = np.where(take, cand, out)
    return np.where(np.isnan(out), q, out)


def _rotation_log(M: FloatArray) -> FloatArray:
    """Rotation vectors (3, m), rad, of rotation matrices stored as (3, 3, m)."""
    v = 0.5 * np.stack([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]])   # sin(theta) * axis
    cos = np.clip(0.5 * (M[0, 0] + M[1, 1] + M[2, 2] - 1.0), -1.0, 1.0)
    sin = np.sqrt(np.einsum("im,im->m", v, v))
    theta = np.arctan2(sin, cos)
    factor = np.where(sin > 1e-12, theta / np.maximum(sin, 1e-300), 1.0)
    out = v * factor
    near_pi = (sin < 1e-6) & (cos < 0.0)
    if near_pi.any():
        # theta ~ pi: sin(theta) * axis carries no direction; read the axis off the symmetric part,
        # (M + M^T) / 2 = cos I + (1 - cos) a a^T.
        Mp = M[:, :, near_pi]
        c = cos[near_pi]
        diag = np.stack([Mp[0, 0], Mp[1, 1], Mp[2, 2]])
        aa = np.clip((diag - c) / (1.0 - c), 0.0, None)               # a_i^2
        j = np.argmax(aa, axis=0)
        cols = np.arange(Mp.shape[2])
        a_j = np.sqrt(aa[j, cols])
        sym = 0.5 * (Mp[:, j, cols] + Mp[j, :, cols].T)                # (3, k): (1 - cos) a_i a_j, i != j
        axis = sym / ((1.0 - c) * a_j)
        axis[j, cols] = a_j
        axis /= np.linalg.norm(axis, axis=0)
        out[:, near_pi] = axis * theta[near_pi]
    return out
