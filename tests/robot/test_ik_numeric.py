"""Numeric IK (batched damped least squares) on the UR10 URDF and on a KUKA-like OPW model."""

from __future__ import annotations

from importlib import metadata
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

from robomax_py.errors import RobotModelError
from robomax_py.io.ik_params import params_from_mapping
from robomax_py.robot import JointLimits, RobotModel
from robomax_py.robot.ik._chain import (
    chain_to_frame,
    frame_pose,
    frame_pose_and_jacobian,
    joint_frames,
)
from robomax_py.robot.ik.numeric import DEDUPE_RAD, NumericIkParams, numeric_ik
from robomax_py.robot.ik.opw import OpwParams, opw_fk, opw_ik, opw_pin_model
from robomax_py.robot.ik.ur import UR10_EXAMPLE_ROBOT_DATA as UR10
from robomax_py.robot.ik.ur import ur_fk, ur_ik
from robomax_py.robot.solve import solve_all
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.transforms import rotation_angle

DEG = np.pi / 180.0
KR16_LIKE = OpwParams(
    a1=0.26, a2=-0.035, b=0.0, c1=0.675, c2=0.68, c3=0.67, c4=0.158,
    offsets=(0.0, -np.pi / 2, 0.0, 0.0, 0.0, 0.0), sign_corrections=(-1, 1, 1, -1, 1, -1),
)
KR_LOWER = np.array([-185, -155, -130, -350, -130, -350]) * DEG
KR_UPPER = np.array([185, 35, 154, 350, 130, 350]) * DEG
N_POSES = 1000


def ur10_model() -> pin.Model:
    for f in metadata.files("example-robot-data") or []:
        if str(f).endswith("ur_description/urdf/ur10_robot.urdf"):
            return pin.buildModelFromUrdf(str(f.locate()))
    pytest.skip("example-robot-data's ur10_robot.urdf not installed")


def wrapped_diff(a: np.ndarray, b: np.ndarray | float) -> np.ndarray:
    d: np.ndarray = np.abs(np.angle(np.exp(1j * (a - b))))
    return d


def pose_errors(T_got: np.ndarray, T_want: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    pos = np.linalg.norm(T_got[..., :3, 3] - T_want[..., :3, 3], axis=-1)
    return pos, rotation_angle(T_got[..., :3, :3], T_want[..., :3, :3])


def check_solutions(model: pin.Model, fid: int, T: np.ndarray, q: np.ndarray, valid: np.ndarray) -> None:
    """Valid rows reproduce the pose (Pinocchio FK, a sample) within the numeric tolerance, stay
    within limits, and are pairwise distinct; invalid rows are NaN."""
    data = model.createData()
    lower, upper = model.lowerPositionLimit, model.upperPositionLimit
    assert np.all(np.isnan(q[~valid])) and np.all(np.isfinite(q[valid]))
    assert np.all((q[valid] >= lower) & (q[valid] <= upper))
    for i in range(0, len(T), 7):
        for k in np.flatnonzero(valid[i]):
            pin.framesForwardKinematics(model, data, q[i, k])
            pos, rot = pose_errors(data.oMf[fid].homogeneous, T[i])
            assert pos < TOL.ik_numeric_pos_m and rot < TOL.ik_numeric_rot_rad
    got = frame_pose(chain_to_frame(model, fid), np.where(valid[..., None], q, 0))
    pos, rot = pose_errors(got, T[:, None])
    assert pos[valid].max() < TOL.ik_numeric_pos_m and rot[valid].max() < TOL.ik_numeric_rot_rad
    d = np.max(wrapped_diff(q[:, :, None], q[:, None, :]), axis=-1)
    both = valid[:, :, None] & valid[:, None, :] & ~np.eye(q.shape[1], dtype=bool)
    assert np.all(d[both] >= DEDUPE_RAD)


def test_chain_kinematics_match_pinocchio(rng: np.random.Generator) -> None:
    for model, frame in ((ur10_model(), "tool0"), (opw_pin_model(KR16_LIKE), "flange")):
        fid = model.getFrameId(frame)
        chain = chain_to_frame(model, fid)
        data = model.createData()
        q = rng.uniform(-np.pi, np.pi, size=(40, model.nq))
        R, p, J = frame_pose_and_jacobian(chain, q)
        frames = joint_frames(chain, q)
        T = frame_pose(chain, q)
        for i, qi in enumerate(q):
            pin.computeJointJacobians(model, data, qi)
            pin.updateFramePlacements(model, data)
            assert_allclose(T[i], data.oMf[fid].homogeneous, atol=1e-14)
            assert_allclose(R[:, :, i], T[i, :3, :3], atol=0)
            assert_allclose(p[:, i], T[i, :3, 3], atol=0)
            assert_allclose(J[i], pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED), atol=1e-14)
            for j, jid in enumerate(chain.joints):
                assert_allclose(frames[i, j], data.oMi[jid].homogeneous, atol=1e-14)


def test_ur10_round_trip_and_agreement_with_closed_form(rng: np.random.Generator) -> None:
    model = ur10_model()
    fid = model.getFrameId("tool0")
    q0 = rng.uniform(-np.pi, np.pi, size=(N_POSES, 6))
    T = ur_fk(UR10, q0)
    q, valid = numeric_ik(model, fid, T, model.lowerPositionLimit, model.upperPositionLimit, rng, n_seeds=32)
    assert q.shape == (N_POSES, 8, 6)
    check_solutions(model, fid, T, q, valid)
    # Every numeric solution is one of the eight closed-form ones (modulo 2 pi) ...
    exact, exact_valid = ur_ik(UR10, T)
    close = np.all(wrapped_diff(q[:, :, None], exact[:, None, :]) < 1e-5, axis=-1)   # (N, K, 8)
    assert close.any(axis=-1)[valid].mean() > 0.999
    # ... and 32 seeds find almost all of them.
    assert close.any(axis=1)[exact_valid].mean() > 0.95


def test_kr_like_round_trip_with_limits(rng: np.random.Generator) -> None:
    model = opw_pin_model(KR16_LIKE, KR_LOWER, KR_UPPER)
    fid = model.getFrameId("flange")
    q0 = rng.uniform(KR_LOWER, KR_UPPER, size=(N_POSES, 6))
    T = opw_fk(KR16_LIKE, q0)
    q, valid = numeric_ik(model, fid, T, KR_LOWER, KR_UPPER, rng, n_seeds=24, max_solutions=6)
    assert q.shape == (N_POSES, 6, 6)
    check_solutions(model, fid, T, q, valid)
    exact, _exact_valid = opw_ik(KR16_LIKE, T)
    close = np.all(wrapped_diff(q[:, :, None], exact[:, None, :]) < 1e-5, axis=-1)
    assert close.any(axis=-1)[valid].mean() > 0.999
    assert valid.any(axis=-1).mean() > 0.97


def test_hint_is_first_and_exact(rng: np.random.Generator) -> None:
    model = ur10_model()
    fid = model.getFrameId("tool0")
    q0 = rng.uniform(-np.pi, np.pi, size=(50, 6))
    T = ur_fk(UR10, q0)
    q, valid = numeric_ik(model, fid, T, model.lowerPositionLimit, model.upperPositionLimit, rng, 4, q_hint=q0)
    assert valid[:, 0].all()
    assert np.all(wrapped_diff(q[:, 0], q0) < 1e-6)


def test_deterministic_with_same_seed() -> None:
    model = ur10_model()
    fid = model.getFrameId("tool0")
    T = ur_fk(UR10, np.random.default_rng(1).uniform(-np.pi, np.pi, size=(20, 6)))
    a = numeric_ik(model, fid, T, model.lowerPositionLimit, model.upperPositionLimit, np.random.default_rng(7), 8)
    b = numeric_ik(model, fid, T, model.lowerPositionLimit, model.upperPositionLimit, np.random.default_rng(7), 8)
    assert np.array_equal(a[1], b[1]) and np.array_equal(a[0][a[1]], b[0][b[1]])


def test_unreachable_gives_nothing(rng: np.random.Generator) -> None:
    model = ur10_model()
    T = np.eye(4)
    T[:3, 3] = (3.0, 0.0, 0.0)
    q, valid = numeric_ik(model, model.getFrameId("tool0"), T, model.lowerPositionLimit, model.upperPositionLimit, rng, 8)
    assert q.shape == (8, 6) and not valid.any() and np.isnan(q).all()


def test_solve_all_numeric_slots_by_status(rng: np.random.Generator) -> None:
    """For a six-revolute arm, numeric column k holds the solution with status k."""
    model = opw_pin_model(KR16_LIKE, KR_LOWER, KR_UPPER)
    n = model.nq
    limits = JointLimits(KR_LOWER, KR_UPPER, np.ones(n), np.ones(n), np.ones(n))
    robot = RobotModel(
        "kr", Path("kr"), model, pin.GeometryModel(), pin.GeometryModel(), tuple(model.names[1:]),
        model.getFrameId("flange"), limits, "numeric", NumericIkParams(seeds=24), np.eye(4),
    )
    T = opw_fk(KR16_LIKE, rng.uniform(KR_LOWER, KR_UPPER, size=(100, 6)))
    table = solve_all(robot, T, rng=rng, expand_turns=False)
    assert table.q.shape == (100, 8, 6)
    ok = table.valid
    assert np.all(table.status[ok] == np.broadcast_to(np.arange(8), ok.shape)[ok])
    # Same columns as the closed form's in-limit solutions, by status.
    opw_robot = RobotModel(
        "kr", Path("kr"), model, pin.GeometryModel(), pin.GeometryModel(), tuple(model.names[1:]),
        model.getFrameId("flange"), limits, "opw", KR16_LIKE, np.eye(4),
    )
    exact = solve_all(opw_robot, T, expand_turns=False)
    found = []
    for b in range(8):
        col = exact.status[:, b]
        has = exact.valid[:, b]
        match = table.valid[has, col[has]]
        assert_allclose(table.q[has, col[has]][match], exact.q[has, b][match], atol=1e-6)
        found.append(match)
    assert np.concatenate(found).mean() > 0.9
    assert table.valid.sum() <= exact.valid.sum()


def test_params_from_mapping_numeric() -> None:
    assert params_from_mapping("numeric", {}) == NumericIkParams()
    assert params_from_mapping("numeric", {"seeds": 64, "solutions": 4}) == NumericIkParams(seeds=64, solutions=4)
    for bad, key in (({"seeds": 0}, "ik.params.seeds"), ({"seeds": 2.5}, "ik.params.seeds"),
                     ({"tolerance": 1}, "ik.params.tolerance"), ({"solutions": True}, "ik.params.solutions")):
        with pytest.raises(RobotModelError) as info:
            params_from_mapping("numeric", bad)
        assert info.value.key == key


def test_a_line_from_a_configuration_the_seeds_miss_is_followed(rng: np.random.Generator) -> None:
    """A seeded solver's table holds the solutions its seeds reached. A motion that starts (or goes
    on) in a configuration missing from it is still followed: the solver is seeded at the
    configuration itself. With one random seed per pose, most configurations of an eight-branch arm
    are missing from the plain table; column_of and a short LIN line from each still work, and the
    line's samples solve their poses on the line."""
    from robomax_py.timing.chain import column_of
    from robomax_py.timing.lin import lin_path

    model = opw_pin_model(KR16_LIKE, KR_LOWER, KR_UPPER)
    n = model.nq
    limits = JointLimits(KR_LOWER, KR_UPPER, np.ones(n), np.ones(n), np.ones(n))
    robot = RobotModel(
        "kr", Path("kr"), model, pin.GeometryModel(), pin.GeometryModel(), tuple(model.names[1:]),
        model.getFrameId("flange"), limits, "numeric", NumericIkParams(seeds=1, solutions=8), np.eye(4),
    )
    missed = 0
    for q in rng.uniform(np.asarray(KR_LOWER) * 0.8, np.asarray(KR_UPPER) * 0.8, size=(12, 6)):
        T0 = opw_fk(KR16_LIKE, q[None])[0]
        plain = solve_all(robot, T0[None])
        found = plain.valid[0] & np.all(np.abs(wrapped_diff(plain.q[0], q)) < 1e-6, axis=-1)
        missed += not found.any()
        k = column_of(robot, q)
        T1 = T0.copy()
        T1[:3, 3] += [0.0, 0.0, 0.01]                        # 10 mm up
        lp = lin_path(robot, T0, T1, k, q_start=q)
        if not lp.ok:
            assert lp.reason in ("joint_limit", "unreachable", "discontinuous"), lp.detail
            continue
        assert np.max(np.abs(wrapped_diff(lp.q[0], q))) < 1e-6
        T_got = opw_fk(KR16_LIKE, np.asarray(lp.q))
        assert np.abs(T_got[:, :2, 3] - T0[:2, 3]).max() < 1e-5 and np.abs(T_got[:, :3, :3] - T0[:3, :3]).max() < 1e-5
    assert missed >= 3                                       # the case arose
