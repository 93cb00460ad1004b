"""The compiled iterations of the numeric IK (`robot.ik.numeric_kernel`) against the array code
they replaced, kept here as the second implementation: every seed of a batch iterated at once
with numpy (forward kinematics and Jacobian from `_chain`, LU solves), on a seven-joint arm, an
arm on a track (a prismatic joint) and an arm with a passive (`<mimic>`) joint on its flange
chain. One step agrees to round-off; whole runs agree where the iteration converges, and every
solution the kernel returns is one by Pinocchio's forward kinematics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from urdf_case import iiwa14_urdf, track_arm_urdf

from robomax_py.robot.ik._chain import (
    chain_to_frame,
    frame_pose_and_jacobian,
    revolute_mask,
)
from robomax_py.robot.ik.numeric import (
    _MAX_STEP,
    _STOP_POS_M,
    _STOP_ROT_RAD,
    numeric_ik,
)
from robomax_py.robot.ik.numeric_kernel import iterate_seeds
from robomax_py.robot.model import urdf_model
from tests.robot.test_passive_joints import _OFFSET_WRIST

TWO_PI = 2.0 * np.pi
# One step from the same start: the two differ in the order of a few sums and in the 6 x 6 solve
# (Cholesky against LU), each a few ulp of values of order 1; allowed to grow tenfold a step (the
# steps amplify a difference by their Jacobians' conditioning; measured growth is far less).
ONE_STEP = 1e-12
# Converged runs: both stop within 1e-12 of the pose, from starts that agree after each step to
# round-off: they end at the same solution (all 604 converged runs of the three arms here, the
# seven-joint arm's self-motion included).
CONVERGED = 1e-9
SOLVED_M = SOLVED_RAD = 1e-6         # numeric_ik's own acceptance


def _into_limits(q: np.ndarray, revolute: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """A revolute joint that stepped past a limit re-enters 2 pi further round if that is inside; then clip.

    Without the wrap, seeds of joints with +-2 pi (or +-pi) limits pile up on the limit and stall.
    """
    q = np.where(revolute & (q > upper) & (q - TWO_PI >= lower), q - TWO_PI, q)
    q = np.where(revolute & (q < lower) & (q + TWO_PI <= upper), q + TWO_PI, q)
    return np.clip(q, lower, upper)


def _rotation_log(M: np.ndarray) -> np.ndarray:
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


def _array_iterations(chain, q, pose_of, T, lower, upper, rev, max_iterations):  # type: ignore[no-untyped-def]
    """The array version: every seed at once, until each converges or max_iterations pass."""
    q = q.copy()
    R_des = T[:, :3, :3].transpose(1, 2, 0)
    p_des = T[:, :3, 3].T
    active = np.arange(q.shape[0])
    for _ in range(max_iterations):
        if active.size == 0:
            break
        qa = q[active]
        R, p, J = frame_pose_and_jacobian(chain, qa)
        target = pose_of[active]
        e_pos = p_des[:, target] - p
        e_rot = _rotation_log(np.einsum("ikm,jkm->ijm", R_des[:, :, target], R))
        err_p = np.sqrt(np.einsum("im,im->m", e_pos, e_pos))
        err_r = np.sqrt(np.einsum("im,im->m", e_rot, e_rot))
        go = ~((err_p < _STOP_POS_M) & (err_r < _STOP_ROT_RAD))
        if not go.any():
            break
        e = np.concatenate([e_pos, e_rot], axis=0).T[go]
        Jg = J[go]
        lam = np.clip(1e-2 * (err_p[go] ** 2 + err_r[go] ** 2), 1e-10, 1e-1)
        A = Jg @ Jg.transpose(0, 2, 1)
        A[:, range(6), range(6)] += lam[:, None]
        x = np.linalg.solve(A, e[..., None])
        dq = (Jg.transpose(0, 2, 1) @ x)[..., 0]
        step = np.max(np.abs(dq), axis=-1, keepdims=True)
        dq *= np.minimum(1.0, _MAX_STEP / np.maximum(step, 1e-300))
        idx = active[go]
        q[idx] = _into_limits(qa[go] + dq, rev, lower, upper)
        active = idx
    return q


def _compiled(chain, q, pose_of, T, lower, upper, rev, max_iterations):  # type: ignore[no-untyped-def]
    q = np.ascontiguousarray(q.copy())
    iterate_seeds(np.ascontiguousarray(chain.K), chain.scale, chain.offset, chain.active, chain.revolute,
                  np.asarray(chain.q_index, dtype=np.int64), q, pose_of, np.ascontiguousarray(T[:, :3, :3]),
                  np.ascontiguousarray(T[:, :3, 3]), lower, upper, rev, max_iterations, _STOP_POS_M, _STOP_ROT_RAD,
                  _MAX_STEP)
    return q


def _model(kind: str, tmp_path: Path) -> tuple[pin.Model, int]:
    if kind == "iiwa":
        model = urdf_model(iiwa14_urdf(tmp_path / "iiwa.urdf").read_text())
    elif kind == "track":
        model = urdf_model(track_arm_urdf(tmp_path / "track.urdf").read_text())
    else:
        model = urdf_model(_OFFSET_WRIST)
    return model, model.getFrameId("tool0")


def _batch(model: pin.Model, frame: int, seed: int, poses: int, seeds: int):  # type: ignore[no-untyped-def]
    """Target poses of random configurations inside 80 % of the limits, and random starts (one of
    them near a pose's own configuration, so that the runs also converge)."""
    rng = np.random.default_rng(seed)
    lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    data = model.createData()
    q_pose = rng.uniform(0.8 * lower + 0.2 * upper, 0.2 * lower + 0.8 * upper, (poses, model.nq))
    T = np.empty((poses, 4, 4))
    for i, qi in enumerate(q_pose):
        pin.framesForwardKinematics(model, data, qi)
        T[i] = data.oMf[frame].homogeneous
    start = rng.uniform(lower, upper, (poses, seeds, model.nq))
    start[:, 0] = np.clip(q_pose + rng.normal(0.0, 0.05, q_pose.shape), lower, upper)
    return T, start.reshape(-1, model.nq), np.repeat(np.arange(poses), seeds), lower, upper


def _case(kind: str, tmp_path: Path, seed: int, poses: int, seeds: int):  # type: ignore[no-untyped-def]
    """The arm, its chain and revolute entries, and a batch (`_batch`)."""
    model, frame = _model(kind, tmp_path)
    return model, frame, chain_to_frame(model, frame), revolute_mask(model), _batch(model, frame, seed, poses, seeds)


@pytest.mark.parametrize("kind", ["iiwa", "track", "mimic"])
def test_one_step_is_the_array_versions(kind: str, tmp_path: Path) -> None:
    _, _, chain, rev, (T, start, pose_of, lower, upper) = _case(kind, tmp_path, 1, 20, 16)
    for steps in (1, 2, 3):
        ref = _array_iterations(chain, start, pose_of, T, lower, upper, rev, steps)
        got = _compiled(chain, start, pose_of, T, lower, upper, rev, steps)
        assert np.abs(got - ref).max() < ONE_STEP * 10 ** (steps - 1), (kind, steps)
    assert np.abs(got - start).max() > 0.1              # the steps moved the seeds


@pytest.mark.parametrize("kind", ["iiwa", "track", "mimic"])
def test_converged_runs_end_where_the_array_versions_do(kind: str, tmp_path: Path) -> None:
    model, frame, chain, rev, (T, start, pose_of, lower, upper) = _case(kind, tmp_path, 2, 30, 8)
    ref = _array_iterations(chain, start, pose_of, T, lower, upper, rev, 50)
    got = _compiled(chain, start, pose_of, T, lower, upper, rev, 50)
    data = model.createData()

    def solved(q: np.ndarray, i: int) -> bool:
        pin.framesForwardKinematics(model, data, q)
        M = data.oMf[frame]
        return bool(np.linalg.norm(M.translation - T[pose_of[i], :3, 3]) < SOLVED_M
                    and np.linalg.norm(pin.log3(M.rotation.T @ T[pose_of[i], :3, :3])) < SOLVED_RAD)

    both = [i for i in range(len(start)) if solved(ref[i], i) and solved(got[i], i)]
    only_ref = [i for i in range(len(start)) if solved(ref[i], i) and not solved(got[i], i)]
    only_got = [i for i in range(len(start)) if solved(got[i], i) and not solved(ref[i], i)]
    assert len(both) >= 30                               # at least the starts near each pose's own
    assert not only_ref and not only_got, (only_ref, only_got)
    same = [i for i in both if np.abs(got[i] - ref[i]).max() < CONVERGED]
    assert same == both, (kind, len(same), len(both))


def test_numeric_ik_finds_several_solutions_of_each_pose(tmp_path: Path) -> None:
    """numeric_ik through the kernel on the arm with a passive joint: several distinct solutions of
    each reachable pose, each one by Pinocchio's forward kinematics."""
    model, frame = _model("mimic", tmp_path)
    T, _, _, lower, upper = _batch(model, frame, 3, 5, 1)
    q, valid = numeric_ik(model, frame, T, lower, upper, np.random.default_rng(0), 64, max_solutions=16)
    data = model.createData()
    for i in range(5):
        assert valid[i].sum() >= 2
        for qk in q[i][valid[i]]:
            pin.framesForwardKinematics(model, data, qk)
            assert np.linalg.norm(data.oMf[frame].translation - T[i, :3, 3]) < SOLVED_M
