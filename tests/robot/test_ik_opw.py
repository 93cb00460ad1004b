"""OPW closed-form IK: round trips against opw_fk and against Pinocchio, branches, singularities."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from robomax_py.errors import RobotModelError
from robomax_py.io.ik_params import params_from_mapping
from robomax_py.robot.ik.config import status_opw
from robomax_py.robot.ik.opw import (
    OpwParams,
    from_paper_angles,
    opw_fk,
    opw_ik,
    opw_pin_model,
    to_paper_angles,
)
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.transforms import rotation_angle

REPO = Path(__file__).resolve().parents[2]
DEG = np.pi / 180.0

KR6_R700 = OpwParams(
    a1=0.025, a2=-0.035, b=0.0, c1=0.400, c2=0.315, c3=0.365, c4=0.080,
    offsets=(0.0, -np.pi / 2, 0.0, 0.0, 0.0, 0.0), sign_corrections=(-1, 1, 1, -1, 1, -1),
)
IRB2400 = OpwParams(
    a1=0.100, a2=-0.135, b=0.0, c1=0.615, c2=0.705, c3=0.755, c4=0.085,
    offsets=(0.0, 0.0, -np.pi / 2, 0.0, 0.0, 0.0),
)
# Lateral offset b != 0, positive a2, offsets on every joint except A5, all signs +1.
LATERAL = OpwParams(
    a1=0.150, a2=0.080, b=0.070, c1=0.500, c2=0.600, c3=0.700, c4=0.100,
    offsets=(0.1, 0.2, -0.3, 0.4, 0.0, 0.6),
)
# A flange frame off axis 6 and turned against it (a URDF whose flange z is not along axis 6).
TURNED_FLANGE = OpwParams(
    a1=0.200, a2=-0.150, b=0.0, c1=0.680, c2=0.890, c3=1.380, c4=0.140,
    offsets=(0.0, 0.0, -np.pi / 2, 0.0, 0.0, -np.pi / 2), flange_xy=(0.004, -0.003), flange_rpy=(0.3, -1.2, 2.0),
)
PARAM_SETS = {"kr6_r700": KR6_R700, "irb2400": IRB2400, "lateral_b": LATERAL, "turned_flange": TURNED_FLANGE}
N_RANDOM = 2000


def wrapped_diff(a: np.ndarray, b: np.ndarray | float) -> np.ndarray:
    d: np.ndarray = np.abs(np.angle(np.exp(1j * (a - b))))
    return d


def pose_errors(T_got: np.ndarray, T_want: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    pos = np.linalg.norm(T_got[..., :3, 3] - T_want[..., :3, 3], axis=-1)
    rot = rotation_angle(T_got[..., :3, :3], T_want[..., :3, :3])
    return pos, rot


def regular(params: OpwParams, q: np.ndarray) -> np.ndarray:
    """(..., 6) -> (...) bool: away from the wrist, elbow and shoulder singularities, where the joint
    values of a pose are well conditioned (at a singularity they move ~sqrt(round-off) ~ 1e-7)."""
    th = to_paper_angles(params, q)
    beta = th[..., 2] + np.arctan2(params.a2, params.c3)
    k = np.hypot(params.a2, params.c3)
    x_wrist = params.c2 * np.sin(th[..., 1]) + k * np.sin(th[..., 1] + beta) + params.a1
    ok: np.ndarray = (np.abs(np.sin(th[..., 4])) > 1e-3) & (np.abs(np.sin(beta)) > 1e-3) & (np.abs(x_wrist) > 1e-3)
    return ok


def check_round_trip(params: OpwParams, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """IK of FK(q): every valid row reproduces the pose; q itself is found away from singularities."""
    T = opw_fk(params, q)
    sols, valid = opw_ik(params, T)
    assert sols.shape == q.shape[:-1] + (8, 6) and valid.shape == q.shape[:-1] + (8,)
    assert np.all(np.isfinite(sols[valid])) and np.all(np.isnan(sols[~valid]))
    assert np.all((sols[valid] > -np.pi) & (sols[valid] <= np.pi))
    T_back = opw_fk(params, np.where(valid[..., None], sols, 0.0))
    pos, rot = pose_errors(T_back, np.broadcast_to(T[..., None, :, :], T_back.shape))
    assert pos[valid].max() < TOL.ik_pos_m
    assert rot[valid].max() < TOL.ik_rot_rad
    found = np.any(valid & np.all(wrapped_diff(sols, q[..., None, :]) < 1e-7, axis=-1), axis=-1)
    assert found[regular(params, q)].all()
    return sols, valid


@pytest.mark.parametrize("name", sorted(PARAM_SETS))
def test_round_trip_random_batch(name: str, rng: np.random.Generator) -> None:
    params = PARAM_SETS[name]
    q = rng.uniform(-np.pi, np.pi, size=(N_RANDOM, 6))
    sols, valid = check_round_trip(params, q)
    assert valid.any(axis=-1).all()
    # Poses with all eight branches: the status bits tell the branches apart.
    th = to_paper_angles(params, sols)
    regular = np.all(valid, axis=-1) & np.all(np.abs(np.sin(th[..., 4])) > 1e-3, axis=-1)
    assert regular.sum() > N_RANDOM // 10
    status = status_opw(params, sols[regular])
    assert np.all(np.sort(status, axis=-1) == np.arange(8))


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(-np.pi, np.pi, allow_nan=False), min_size=6, max_size=6), st.sampled_from(sorted(PARAM_SETS)))
def test_round_trip_hypothesis(q: list[float], name: str) -> None:
    check_round_trip(PARAM_SETS[name], np.array(q))


def test_branch_order_is_as_documented(rng: np.random.Generator) -> None:
    """k = 4 * wrist + 2 * shoulder + elbow in paper angles."""
    for params in PARAM_SETS.values():
        q = rng.uniform(-np.pi, np.pi, size=(500, 6))
        sols, valid = opw_ik(params, opw_fk(params, q))
        th = to_paper_angles(params, sols)
        psi3 = np.arctan2(params.a2, params.c3)
        k_arm = np.hypot(params.a2, params.c3)
        x_wrist = params.c2 * np.sin(th[..., 1]) + k_arm * np.sin(th[..., 1] + th[..., 2] + psi3) + params.a1
        beta = np.angle(np.exp(1j * (th[..., 2] + psi3)))
        t5 = np.angle(np.exp(1j * th[..., 4]))
        for k in range(8):
            v = valid[:, k]
            wrist, shoulder, elbow = k >> 2, (k >> 1) & 1, k & 1
            assert np.all((x_wrist[v, k] < 1e-9) if shoulder else (x_wrist[v, k] > -1e-9))
            assert np.all((beta[v, k] <= 1e-9) if elbow else (beta[v, k] >= -1e-9))
            assert np.all((t5[v, k] <= 1e-9) if wrist else (t5[v, k] >= -1e-9))


@pytest.mark.parametrize("name", sorted(PARAM_SETS))
def test_against_pinocchio_model(name: str, rng: np.random.Generator) -> None:
    """Pinocchio FK of a model built joint by joint (independent of opw_fk's closed form)."""
    params = PARAM_SETS[name]
    model = opw_pin_model(params)
    data = model.createData()
    fid = model.getFrameId("flange")
    q = rng.uniform(-np.pi, np.pi, size=(150, 6))
    T = np.empty((len(q), 4, 4))
    for i, qi in enumerate(q):
        pin.framesForwardKinematics(model, data, qi)
        T[i] = data.oMf[fid].homogeneous
    assert_allclose(opw_fk(params, q), T, atol=1e-12)
    sols, valid = opw_ik(params, T)
    for i in range(len(q)):
        for k in np.flatnonzero(valid[i]):
            pin.framesForwardKinematics(model, data, sols[i, k])
            pos, rot = pose_errors(data.oMf[fid].homogeneous, T[i])
            assert pos < TOL.ik_pos_m and rot < TOL.ik_rot_rad


def test_unreachable_pose_has_no_valid_branch() -> None:
    T = np.eye(4)
    T[:3, 3] = (5.0, 0.0, 0.5)
    sols, valid = opw_ik(KR6_R700, T)
    assert not valid.any() and np.isnan(sols).all()
    T_nan = np.full((4, 4), np.nan)
    assert not opw_ik(KR6_R700, T_nan)[1].any()


def test_batch_shape_and_hint_broadcast(rng: np.random.Generator) -> None:
    q = rng.uniform(-1, 1, size=(3, 4, 6))
    sols, valid = opw_ik(IRB2400, opw_fk(IRB2400, q), q_hint=np.zeros(6))
    assert sols.shape == (3, 4, 8, 6) and valid.shape == (3, 4, 8)
    single, single_valid = opw_ik(IRB2400, opw_fk(IRB2400, q[1, 2]))
    assert_allclose(single[single_valid], sols[1, 2][valid[1, 2]], atol=1e-12)


@pytest.mark.parametrize("name", sorted(PARAM_SETS))
def test_wrist_singularity_is_solved_with_hint(name: str, rng: np.random.Generator) -> None:
    """theta5 = 0 exactly: theta4 + theta6 is fixed, theta4 comes from the hint, never NaN."""
    params = PARAM_SETS[name]
    th = rng.uniform(-np.pi, np.pi, size=(200, 6))
    th[:, 4] = 0.0
    th[:100, 4] = np.pi                                                 # the folded-back singularity too
    q = from_paper_angles(params, th)
    T = opw_fk(params, q)
    hint = q + rng.uniform(-0.3, 0.3, size=q.shape)
    for q_hint in (None, hint):
        sols, valid = opw_ik(params, T, q_hint=q_hint)
        assert np.all(np.isfinite(sols[valid]))
        pos, rot = pose_errors(opw_fk(params, np.where(valid[..., None], sols, 0)), T[:, None])
        assert pos[valid].max() < TOL.ik_pos_m and rot[valid].max() < TOL.ik_rot_rad
        assert valid[:, [0, 4]].any()
        th_sol = to_paper_angles(params, sols)
        want4 = 0.0 if q_hint is None else to_paper_angles(params, hint)[:, None, 3]
        ok = valid & (np.abs(np.sin(th_sol[..., 4])) < 1e-9)
        assert ok.sum() > 100
        assert np.all(wrapped_diff(th_sol[..., 3], want4)[ok] < 1e-12)
    # With the original q as hint, the original configuration is returned exactly.
    sols, valid = opw_ik(params, T, q_hint=q)
    found = np.any(valid & np.all(wrapped_diff(sols, q[:, None, :]) < 1e-9, axis=-1), axis=-1)
    assert found.all()


@pytest.mark.parametrize("name", ["kr6_r700", "irb2400"])
def test_shoulder_singularity_wrist_centre_on_axis_1(name: str, rng: np.random.Generator) -> None:
    """Wrist centre on axis 1 (b = 0): theta1 is free; taken from the hint, or 0."""
    params = PARAM_SETS[name]
    for _ in range(50):
        R = pin.exp3(rng.normal(size=3))
        T = np.eye(4)
        T[:3, :3] = R
        centre = np.array([0.0, 0.0, params.c1 + rng.uniform(0.3, 0.6) * (params.c2 + params.c3)])
        T[:3, 3] = centre + params.c4 * R[:, 2]
        hint = rng.uniform(-np.pi, np.pi, size=6)
        for q_hint in (None, hint):
            sols, valid = opw_ik(params, T, q_hint=q_hint)
            assert valid.sum() >= 4
            assert np.all(np.isfinite(sols[valid]))
            pos, rot = pose_errors(opw_fk(params, np.where(valid[:, None], sols, 0)), T)
            assert pos[valid].max() < TOL.ik_pos_m and rot[valid].max() < TOL.ik_rot_rad
            want1 = 0.0 if q_hint is None else to_paper_angles(params, hint)[0]
            th1 = to_paper_angles(params, sols)[:, 0]
            assert np.all(wrapped_diff(th1[[0, 1, 4, 5]][valid[[0, 1, 4, 5]]], want1) < 1e-12)


def test_full_stretch_round_off_is_reachable() -> None:
    """The arm fully stretched (beta = 0) sits on the workspace boundary: still solved."""
    for params in PARAM_SETS.values():
        th = np.array([0.3, 0.4, -np.arctan2(params.a2, params.c3), 0.2, 0.7, -0.1])
        q = from_paper_angles(params, th)
        check_round_trip(params, q[None, :])


# --- robot URDFs written from OPW parameters (appear with robots/kr16, robots/kr125) ------------------


@pytest.mark.parametrize("robot", ["kr16", "kr125"])
def test_against_robot_urdf(robot: str, rng: np.random.Generator) -> None:
    yaml = pytest.importorskip("yaml")
    folder = REPO / "robomax_py" / "robots" / robot
    urdf, robot_yaml = folder / f"{robot}.urdf", folder / "robot.yaml"
    assert urdf.is_file() and robot_yaml.is_file(), f"robots/{robot} is shipped with the repository"
    spec = yaml.safe_load(robot_yaml.read_text())
    assert spec["ik"]["solver"] == "opw", f"{robot}'s robot.yaml names the OPW solver"
    params = params_from_mapping("opw", spec["ik"]["params"])
    assert isinstance(params, OpwParams)
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    fid = model.getFrameId(spec.get("flange", "tool0"))
    lower, upper = model.lowerPositionLimit, model.upperPositionLimit
    q = rng.uniform(lower, upper, size=(1000, 6))
    T = np.empty((len(q), 4, 4))
    for i, qi in enumerate(q):
        pin.framesForwardKinematics(model, data, qi)
        T[i] = data.oMf[fid].homogeneous
    assert_allclose(opw_fk(params, q), T, atol=1e-9)
    sols, valid = check_round_trip(params, q)
    for i in range(0, len(q), 10):
        for k in np.flatnonzero(valid[i]):
            pin.framesForwardKinematics(model, data, sols[i, k])
            pos, rot = pose_errors(data.oMf[fid].homogeneous, T[i])
            assert pos < TOL.ik_pos_m and rot < TOL.ik_rot_rad


# --- robot.yaml parameters --------------------------------------------------------------------------


KR6_YAML = {
    "a1": 0.025, "a2": -0.035, "b": 0, "c1": 0.4, "c2": 0.315, "c3": 0.365, "c4": 0.08,
    "offsets": [0, -90, 0, 0, 0, 0], "sign_corrections": [-1, 1, 1, -1, 1, -1],
}


def test_params_from_mapping_converts_degrees() -> None:
    params = params_from_mapping("opw", KR6_YAML)
    assert isinstance(params, OpwParams)
    assert_allclose(params.offsets, KR6_R700.offsets, atol=1e-15)
    assert params.sign_corrections == KR6_R700.sign_corrections
    assert params.c3 == 0.365 and isinstance(params.b, float)
    defaults = params_from_mapping("opw", {k: v for k, v in KR6_YAML.items() if k in ["a1", "a2", "b", "c1", "c2", "c3", "c4"]})
    assert isinstance(defaults, OpwParams)
    assert defaults.offsets == (0.0,) * 6 and defaults.sign_corrections == (1,) * 6
    assert defaults.flange_rpy == (0.0, 0.0, 0.0)
    turned = params_from_mapping("opw", {**KR6_YAML, "flange_rpy": [0, -90, 45]})
    assert isinstance(turned, OpwParams)
    assert_allclose(turned.flange_rpy, (0.0, -np.pi / 2, np.pi / 4), atol=1e-15)


@pytest.mark.parametrize(
    ("change", "key", "words"),
    [
        ({"a3": 0.1}, "ik.params.a3", "unknown key"),
        ({"c1": None}, "ik.params.c1", "finite number"),
        ({"c2": "0.3"}, "ik.params.c2", "finite number"),
        ({"c2": -0.3}, "ik.params.c2", "> 0"),
        ({"offsets": [0, 90]}, "ik.params.offsets", "expected 6 values"),
        ({"offsets": 5}, "ik.params.offsets", "list of 6"),
        ({"sign_corrections": [1, 1, 1, 1, 1, 2]}, "ik.params.sign_corrections", "+1 or -1"),
        ({"b": True}, "ik.params.b", "finite number"),
        ({"flange_rpy": [0, 90]}, "ik.params.flange_rpy", "expected 3 values"),
    ],
)
def test_params_from_mapping_rejects(change: dict[str, object], key: str, words: str) -> None:
    bad = {**KR6_YAML, **change}
    bad = {k: v for k, v in bad.items() if v is not None}
    if change.get("c1", 0) is None:
        bad["c1"] = float("nan")
    with pytest.raises(RobotModelError) as info:
        params_from_mapping("opw", bad)
    assert info.value.key == key and words in info.value.problem and info.value.file is None


def test_params_from_mapping_missing_key_and_unknown_solver() -> None:
    partial = {k: v for k, v in KR6_YAML.items() if k != "c4"}
    with pytest.raises(RobotModelError) as info:
        params_from_mapping("opw", partial)
    assert info.value.key == "ik.params.c4" and "missing" in info.value.problem
    with pytest.raises(RobotModelError) as info:
        params_from_mapping("ikfast", {})
    assert info.value.key == "ik.params.solver"


def test_regression_wrap_boundary() -> None:
    """Found by hypothesis: a joint landing a hair above pi wrapped to exactly -pi, outside (-pi, pi]."""
    sols, valid = opw_ik(IRB2400, opw_fk(IRB2400, np.array([0.0, 0.0, 0.5, np.pi, 1.5, 0.0])))
    assert np.all((sols[valid] > -np.pi) & (sols[valid] <= np.pi))


def test_flange_rpy_turns_the_flange_about_its_origin(rng: np.random.Generator) -> None:
    """flange_rpy only turns the frame: same origin, T = T_paper * R(flange_rpy)."""
    from dataclasses import replace

    from robomax_py.transforms import rpy_matrix

    q = rng.uniform(-np.pi, np.pi, (50, 6))
    paper = opw_fk(replace(TURNED_FLANGE, flange_rpy=(0.0, 0.0, 0.0)), q)
    turned = opw_fk(TURNED_FLANGE, q)
    assert_allclose(turned[:, :3, 3], paper[:, :3, 3], atol=1e-15)
    assert_allclose(turned[:, :3, :3], paper[:, :3, :3] @ rpy_matrix(*TURNED_FLANGE.flange_rpy), atol=1e-14)
