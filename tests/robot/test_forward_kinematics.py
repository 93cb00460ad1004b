"""Every forward-kinematics implementation against the one core, in one place.

The core is Pinocchio's (`robot.model.fk_flange`: `pin.framesForwardKinematics` on the model built
from the robot's URDF). The others exist for speed or for a closed form, and each must give the core's
answer:

- the batched numpy chain of the numeric IK and the configuration indicators (`robot.ik._chain`:
  frame pose, joint frames, frame Jacobian);
- the compiled pre-filter's joint frames (`world.prefilter`, numba);
- the closed forms of the IK solvers (`opw_fk`, `ur_fk`), for each robot whose robot.yaml names one.

Tolerances: 1e-12 m (and rotation-matrix entries) for the chains, which multiply the same six
placements in another order (round-off of a few 3x3 products). The closed forms compose other
factors: the OPW arms agree to 1e-14, the UR10 to 1.5e-11 (its URDF's joint frames carry rpy of
pi/2 written to 16 digits, whose sines and cosines are not exactly 1 and 0), hence 1e-10.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from robomax_py.io.robot import load_robot_spec
from robomax_py.robot import RobotModel, fk_flange, load_robot
from robomax_py.robot.ik._chain import (
    chain_to_frame,
    frame_pose,
    frame_pose_and_jacobian,
    joint_frames,
)
from robomax_py.robot.ik.opw import OpwParams, opw_fk
from robomax_py.robot.ik.ur import UrParams, ur_fk
from robomax_py.world.prefilter import Prefilter

REPO = Path(__file__).resolve().parents[2]
LIBRARY = sorted(p.parent.name for p in (REPO / "robomax_py" / "robots").glob("*/robot.yaml"))
CHAIN_TOL = 1e-12            # m, and rotation-matrix entries
CLOSED_FORM_TOL = 1e-10      # m, and rotation-matrix entries


def _robot(name: str) -> RobotModel:
    return load_robot(load_robot_spec(REPO / "robomax_py" / "robots" / name / "robot.yaml"))


ROBOTS = {name: _robot(name) for name in LIBRARY}


def _q(robot: RobotModel, u: list[float]) -> np.ndarray:
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    q: np.ndarray = lo + np.asarray(u[: robot.dof]) * (hi - lo)
    return q


def test_the_library_is_covered() -> None:
    """The shipped robots are the ones tested here (a new robot folder joins by itself)."""
    assert {"kr16", "kr125", "ur10"} <= set(ROBOTS)


@pytest.mark.parametrize("name", LIBRARY)
@settings(max_examples=40, deadline=None)
@given(u=st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6))
def test_numpy_chain_is_the_core(name: str, u: list[float]) -> None:
    robot = ROBOTS[name]
    model, fid = robot.model, robot.flange_frame_id
    q = _q(robot, u)
    chain = chain_to_frame(model, fid)
    core = fk_flange(robot, q)
    assert_allclose(frame_pose(chain, q[None])[0], core, atol=CHAIN_TOL, rtol=0)
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    R, p, J = frame_pose_and_jacobian(chain, q[None])
    assert_allclose(R[:, :, 0], core[:3, :3], atol=CHAIN_TOL, rtol=0)
    assert_allclose(p[:, 0], core[:3, 3], atol=CHAIN_TOL, rtol=0)
    assert_allclose(J[0], pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED), atol=CHAIN_TOL, rtol=0)
    frames = joint_frames(chain, q[None])[0]
    for j, jid in enumerate(chain.joints):
        assert_allclose(frames[j], data.oMi[jid].homogeneous, atol=CHAIN_TOL, rtol=0)


@pytest.mark.parametrize("name", LIBRARY)
@settings(max_examples=40, deadline=None)
@given(u=st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6))
def test_prefilter_kernel_is_the_core(name: str, u: list[float]) -> None:
    robot = ROBOTS[name]
    model = robot.model
    q = _q(robot, u)
    filt = Prefilter.of(model, robot.collision_model, [False] * robot.collision_model.ngeoms,
                        np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0))
    assert filt is not None
    rot, trans = filt.joint_placements(q)
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    for j in range(model.njoints):
        assert_allclose(rot[j], data.oMi[j].rotation, atol=CHAIN_TOL, rtol=0)
        assert_allclose(trans[j], data.oMi[j].translation, atol=CHAIN_TOL, rtol=0)


@pytest.mark.parametrize("name", LIBRARY)
def test_closed_form_is_the_core(name: str) -> None:
    """The closed form robot.yaml names, over 200 configurations within the limits."""
    robot = ROBOTS[name]
    params = robot.ik_params
    closed = {OpwParams: opw_fk, UrParams: ur_fk}.get(type(params))
    if closed is None:
        pytest.skip(f"{name}: {robot.ik_solver} IK has no closed-form forward kinematics")
    rng = np.random.default_rng(20261204)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, size=(200, robot.dof))
    assert_allclose(closed(params, q), fk_flange(robot, q), atol=CLOSED_FORM_TOL, rtol=0)
