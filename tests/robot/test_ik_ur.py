"""UR closed-form IK against Pinocchio FK of example-robot-data's ur10_robot.urdf."""

from __future__ import annotations

from importlib import metadata
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from robomax_py.errors import RobotModelError
from robomax_py.io.ik_params import params_from_mapping
from robomax_py.robot import JointLimits, RobotModel
from robomax_py.robot.ik.config import status_generic
from robomax_py.robot.ik.ur import UR10_EXAMPLE_ROBOT_DATA as UR10
from robomax_py.robot.ik.ur import UrParams, ur_fk, ur_ik
from robomax_py.robot.solve import solve_all
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.transforms import pose_matrix, rotation_angle

# The URDF writes pi/2 as 1.57079632679, so its poses differ from the exact DH chain by ~1e-11.
URDF_ROUND_OFF = 1e-10


def ur10_urdf() -> Path:
    files = metadata.files("example-robot-data") or []
    for f in files:
        if str(f).endswith("ur_description/urdf/ur10_robot.urdf"):
            return Path(str(f.locate()))
    pytest.skip("example-robot-data's ur10_robot.urdf not installed")


@pytest.fixture(scope="module")
def ur10() -> pin.Model:
    return pin.buildModelFromUrdf(str(ur10_urdf()))


def pin_fk(model: pin.Model, fid: int, q: np.ndarray) -> np.ndarray:
    data = model.createData()
    out = np.empty(q.shape[:-1] + (4, 4))
    for idx in np.ndindex(q.shape[:-1]):
        pin.framesForwardKinematics(model, data, q[idx])
        out[idx] = data.oMf[fid].homogeneous
    return out


def wrapped_diff(a: np.ndarray, b: np.ndarray | float) -> np.ndarray:
    d: np.ndarray = np.abs(np.angle(np.exp(1j * (a - b))))
    return d


def pose_errors(T_got: np.ndarray, T_want: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    pos = np.linalg.norm(T_got[..., :3, 3] - T_want[..., :3, 3], axis=-1)
    return pos, rotation_angle(T_got[..., :3, :3], T_want[..., :3, :3])


def regular(q: np.ndarray) -> np.ndarray:
    """(..., 6) -> (...) bool: away from the wrist, elbow and shoulder singularities, where the joint
    values of a pose are well conditioned (at a singularity they move ~sqrt(round-off) ~ 1e-7)."""
    T_dh = np.linalg.inv(UR10.T_root_dhbase) @ ur_fk(UR10, q)
    p05 = T_dh[..., :3, 3] - UR10.d6 * T_dh[..., :3, 2]
    shoulder = np.hypot(p05[..., 0], p05[..., 1]) ** 2 - UR10.d4**2
    ok: np.ndarray = (np.abs(np.sin(q[..., 4])) > 1e-3) & (np.abs(np.sin(q[..., 2])) > 1e-3) & (shoulder > 1e-6)
    return ok


def test_fk_matches_urdf(ur10: pin.Model, rng: np.random.Generator) -> None:
    q = rng.uniform(-2 * np.pi, 2 * np.pi, size=(300, 6))
    assert_allclose(ur_fk(UR10, q), pin_fk(ur10, ur10.getFrameId("tool0"), q), atol=URDF_ROUND_OFF)


def test_round_trip_against_urdf(ur10: pin.Model, rng: np.random.Generator) -> None:
    """1500 random q: each valid branch reproduces Pinocchio's pose; q is among the branches."""
    fid = ur10.getFrameId("tool0")
    q = rng.uniform(ur10.lowerPositionLimit, ur10.upperPositionLimit, size=(1500, 6))
    T = pin_fk(ur10, fid, q)
    sols, valid = ur_ik(UR10, T)
    assert np.all(np.isfinite(sols[valid])) and np.all(np.isnan(sols[~valid]))
    assert np.all((sols[valid] > -np.pi) & (sols[valid] <= np.pi))
    # Exact against the DH chain ...
    pos, rot = pose_errors(ur_fk(UR10, np.where(valid[..., None], sols, 0)), T[:, None])
    assert pos[valid].max() < TOL.ik_pos_m + URDF_ROUND_OFF and rot[valid].max() < TOL.ik_rot_rad + URDF_ROUND_OFF
    # ... and against Pinocchio's FK of the URDF (a sample, Pinocchio is one pose per call).
    sample = valid[:300]
    T_pin = pin_fk(ur10, fid, np.where(sample[..., None], sols[:300], 0))
    pos, rot = pose_errors(T_pin, T[:300, None])
    assert pos[sample].max() < TOL.ik_pos_m and rot[sample].max() < TOL.ik_rot_rad
    found = np.any(valid & np.all(wrapped_diff(sols, q[:, None]) < 1e-7, axis=-1), axis=-1)
    assert found[regular(q)].all()


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(-np.pi, np.pi, allow_nan=False), min_size=6, max_size=6))
def test_round_trip_hypothesis(q: list[float]) -> None:
    qa = np.array(q)
    T = ur_fk(UR10, qa)
    sols, valid = ur_ik(UR10, T)
    pos, rot = pose_errors(ur_fk(UR10, np.where(valid[:, None], sols, 0)), T)
    assert pos[valid].max() < TOL.ik_pos_m and rot[valid].max() < TOL.ik_rot_rad
    if regular(qa):
        assert np.any(valid & np.all(wrapped_diff(sols, qa) < 1e-7, axis=-1))


def test_branch_order_and_distinct_status(ur10: pin.Model, rng: np.random.Generator) -> None:
    q = rng.uniform(-np.pi, np.pi, size=(1000, 6))
    sols, valid = ur_ik(UR10, ur_fk(UR10, q))
    for k in range(8):
        v = valid[:, k]
        wrist, elbow = k >> 2, k & 1
        assert np.all(sols[v, k, 4] <= 1e-12 if wrist else sols[v, k, 4] >= -1e-12)
        assert np.all(sols[v, k, 2] <= 1e-12 if elbow else sols[v, k, 2] >= -1e-12)
    full = valid.all(axis=-1) & np.all(np.abs(np.sin(sols[..., 4])) > 1e-3, axis=-1) & np.all(
        np.abs(np.sin(sols[..., 2])) > 1e-3, axis=-1
    )
    assert full.sum() > 100
    status = status_generic(ur10, ur10.getFrameId("tool0"), sols[full])
    assert np.all(np.sort(status, axis=-1) == np.arange(8))
    # The shoulder bit splits columns 0-1 / 2-3 the same way for every pose.
    assert np.all((status[:, [0, 1, 4, 5]] & 1) == (status[:, [0]] & 1))
    assert np.all((status[:, [2, 3, 6, 7]] & 1) != (status[:, [0]] & 1))


def test_wrist_singularity(rng: np.random.Generator) -> None:
    q = rng.uniform(-np.pi, np.pi, size=(300, 6))
    q[:, 4] = 0.0
    q[:150, 4] = np.pi
    q[:, 2] = rng.uniform(0.5, 2.5, size=300) * rng.choice([-1, 1], size=300)   # elbow well inside reach
    T = ur_fk(UR10, q)
    for hint in (None, q):
        sols, valid = ur_ik(UR10, T, q_hint=hint)
        assert np.all(np.isfinite(sols[valid]))
        pos, rot = pose_errors(ur_fk(UR10, np.where(valid[..., None], sols, 0)), T[:, None])
        assert pos[valid].max() < TOL.ik_pos_m and rot[valid].max() < TOL.ik_rot_rad
        singular = valid & (np.abs(np.sin(sols[..., 4])) < 1e-9)
        want6 = 0.0 if hint is None else hint[:, None, 5]
        kept = wrapped_diff(sols[..., 5], want6) < 1e-12
        # q6 keeps the hint unless that puts the wrist-1 point out of the elbow's reach; then it
        # moves just far enough: the elbow ends up stretched or folded.
        assert kept[singular].mean() > 0.5
        moved = singular & ~kept
        assert np.all(np.abs(np.sin(sols[..., 2][moved])) < 1e-6)
        if hint is not None:
            found = np.any(valid & np.all(wrapped_diff(sols, q[:, None]) < 1e-9, axis=-1), axis=-1)
            assert found.all()


def test_shoulder_singularity_with_zero_d4(rng: np.random.Generator) -> None:
    """With d4 = 0 the wrist-2 point can sit on axis 1: q1 is free, taken from the hint or 0."""
    params = UrParams(d1=0.1273, a2=-0.612, a3=-0.5723, d4=0.0, d5=0.1157, d6=0.0922, base_rpy=(0.0, 0.0, np.pi))
    for _ in range(50):
        T = np.eye(4)
        T[:3, :3] = pin.exp3(rng.normal(size=3))
        p05_dh = np.array([0.0, 0.0, params.d1 + rng.uniform(0.3, 0.9)])
        T_dh = T.copy()
        T_dh[:3, 3] = p05_dh + params.d6 * T_dh[:3, 2]
        T = params.T_root_dhbase @ T_dh
        hint = rng.uniform(-np.pi, np.pi, size=6)
        for q_hint in (None, hint):
            sols, valid = ur_ik(params, T, q_hint=q_hint)
            assert valid.sum() >= 4 and np.all(np.isfinite(sols[valid]))
            pos, rot = pose_errors(ur_fk(params, np.where(valid[:, None], sols, 0)), T)
            assert pos[valid].max() < TOL.ik_pos_m and rot[valid].max() < TOL.ik_rot_rad
            want1 = 0.0 if q_hint is None else hint[0]
            front = valid & (np.arange(8) % 4 < 2)
            assert np.all(wrapped_diff(sols[front, 0], want1) < 1e-12)


def test_unreachable_and_nan() -> None:
    T = pose_matrix([3.0, 0.0, 0.5], [0, 0, 0])
    sols, valid = ur_ik(UR10, T)
    assert not valid.any() and np.isnan(sols).all()
    inside_d4 = pose_matrix([0.0, 0.0, 0.8], [0, 0, 0])   # wrist-2 point closer than d4 to axis 1
    inside_d4[:3, 3] += UR10.d6 * inside_d4[:3, 2]
    assert not ur_ik(UR10, inside_d4)[1].any()
    assert not ur_ik(UR10, np.full((2, 4, 4), np.nan))[1].any()


def test_corrections_are_honoured(rng: np.random.Generator) -> None:
    """Moving the DH base and flange moves the FK poses; the IK follows."""
    params = UrParams(
        d1=0.089159, a2=-0.425, a3=-0.39225, d4=0.10915, d5=0.09465, d6=0.0823,
        base_xyz=(0.1, -0.2, 0.3), base_rpy=(0.1, 0.2, 0.3), flange_xyz=(0.0, 0.01, 0.02), flange_rpy=(0.3, 0.0, -0.2),
    )
    q = rng.uniform(-np.pi, np.pi, size=(500, 6))
    T = ur_fk(params, q)
    sols, valid = ur_ik(params, T)
    pos, rot = pose_errors(ur_fk(params, np.where(valid[..., None], sols, 0)), T[:, None])
    assert pos[valid].max() < TOL.ik_pos_m and rot[valid].max() < TOL.ik_rot_rad


def test_params_from_mapping_ur() -> None:
    yaml_params = {"d1": 0.1273, "a2": -0.612, "a3": -0.5723, "d4": 0.163941, "d5": 0.1157, "d6": 0.0922,
                   "base_rpy": [0, 0, 180]}
    params = params_from_mapping("ur", yaml_params)
    assert isinstance(params, UrParams)
    assert_allclose(params.T_root_dhbase, UR10.T_root_dhbase, atol=1e-15)
    assert params.d4 == UR10.d4 and params.flange_rpy == (0.0, 0.0, 0.0)
    for bad, key in (
        ({**yaml_params, "d7": 0.1}, "ik.params.d7"),
        ({k: v for k, v in yaml_params.items() if k != "d5"}, "ik.params.d5"),
        ({**yaml_params, "base_rpy": [0, 180]}, "ik.params.base_rpy"),
        ({**yaml_params, "a2": 0}, "ik.params.a2"),
        ({**yaml_params, "offsets": [0] * 6}, "ik.params.offsets"),
    ):
        with pytest.raises(RobotModelError) as info:
            params_from_mapping("ur", bad)
        assert info.value.key == key


def test_solve_all_ur10_with_tool_and_turns(ur10: pin.Model, rng: np.random.Generator) -> None:
    n = ur10.nq
    limits = JointLimits(ur10.lowerPositionLimit.copy(), ur10.upperPositionLimit.copy(), np.ones(n), np.ones(n), np.ones(n))
    tool = pose_matrix([0.0, 0.05, 0.25], [0.0, 0.3, 0.0])
    fid = ur10.getFrameId("tool0")
    robot = RobotModel(
        "ur10", Path("ur10"), ur10, pin.GeometryModel(), pin.GeometryModel(), tuple(ur10.names[1:]),
        fid, limits, "ur", UR10, tool,
    )
    q = rng.uniform(-np.pi, np.pi, size=(20, 6))
    T_tcp = pin_fk(ur10, fid, q) @ tool
    table = solve_all(robot, T_tcp)
    V = 3**5                                            # five joints at +-360 deg, the elbow at +-180 deg
    assert table.q.shape == (20, 8 * V, 6) and table.branch.shape == (8 * V,)
    assert np.all(table.branch == np.arange(8 * V) // V)
    assert np.all(table.valid <= table.reachable)
    got = pin_fk(ur10, fid, np.where(table.valid[..., None], table.q, 0)) @ tool
    pos, rot = pose_errors(got, T_tcp[:, None])
    assert pos[table.valid].max() < 1e-9 and rot[table.valid].max() < 1e-9
    assert np.all((table.q[table.valid] >= limits.lower) & (table.q[table.valid] <= limits.upper))
    # Every in-limit q + 2 pi k of the original configuration is among the columns.
    assert (table.valid.sum(axis=-1) >= 2**5).all()
    assert np.all(table.status[~table.valid] == -1) and np.all(table.status[table.valid] >= 0)
    flat = solve_all(robot, T_tcp, expand_turns=False)
    assert flat.q.shape == (20, 8, 6)


@pytest.mark.parametrize(
    "q",
    [
        [0.0, 0.0, 0.0, -1.0, 0.0, 1.0],           # stretched arm, exactly singular wrist: hint q6 = 0 out of reach
        [0.0, 0.0, 0.0, -2.0, 1e-10, 0.0],         # stretched arm, wrist at the singularity threshold
        [0.0, 0.0, 0.0, 0.0, 0.00390625, 0.0],     # stretched arm, wrist near singular
    ],
)
def test_regression_stretched_arm_near_wrist_singularity(q: list[float]) -> None:
    """Found by hypothesis: q6 chosen (or computed) near sin(q5) = 0 moved the wrist-1 point out of
    the fully stretched elbow's reach and every branch came back invalid."""
    qa = np.array(q)
    T = ur_fk(UR10, qa)
    sols, valid = ur_ik(UR10, T)
    assert valid.any()
    pos, rot = pose_errors(ur_fk(UR10, np.where(valid[:, None], sols, 0)), T)
    assert pos[valid].max() < TOL.ik_pos_m and rot[valid].max() < TOL.ik_rot_rad
