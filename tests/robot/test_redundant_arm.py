"""A seven-joint arm (the LBR iiwa 14 R820's kinematics, `urdf_case.iiwa14_urdf`): its approach lines
and LIN moves follow one configuration continuously through the self-motion, where solutions found
afresh at each pose jump from one point of it to another."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from urdf_case import iiwa14_urdf

import robomax_py.timing._lin_track as lin_track
from robomax_py.app.import_urdf import import_urdf
from robomax_py.io.robot import load_robot_spec, shipped_robots_dir
from robomax_py.robot import RobotModel, fk_flange, load_robot
from robomax_py.robot.solve import config_text, redundant, solve_branches, solve_lines
from robomax_py.timing.lin import lin_path
from robomax_py.timing.paths import spline_path
from robomax_py.timing.topp import time_path

# The planner's own bound on a joint's step between two approach-line samples 10 mm apart
# (`plan.candidates.BRANCH_JUMP_RAD`).
JUMP_RAD = 0.2
# numeric IK accepts a solution within 1e-6 m and 1e-6 rad of its pose; FK of it by Pinocchio
# agrees to round-off beyond that.
POSE_M = POSE_RAD = 2e-6
# Joint motion per metre of TCP travel along a LIN move well inside the workspace: the lines here
# reach 42 rad/m at most; a jump across the self-motion between two samples is thousands.
SMOOTH_RAD_PER_M = 100.0


@pytest.fixture(scope="module")
def iiwa(tmp_path_factory: pytest.TempPathFactory) -> RobotModel:
    root = tmp_path_factory.mktemp("iiwa")
    folder = import_urdf(iiwa14_urdf(root / "iiwa.urdf"), root / "iiwa").folder
    return load_robot(load_robot_spec(folder / "robot.yaml"))


def _approach_lines(robot: RobotModel, n: int, samples: int = 4) -> np.ndarray:
    """(n, samples, 4, 4) flange poses: 30 mm lines along each pose's z, ending at the pose of a
    random configuration inside 80 % of the limits."""
    rng = np.random.default_rng(3)
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    T = fk_flange(robot, rng.uniform(0.8 * lower, 0.8 * upper, size=(n, robot.dof)))
    lines = np.repeat(T[:, None], samples, axis=1)
    for k in range(samples):
        lines[:, k, :3, 3] += T[:, :3, 2] * 0.03 * (1.0 - k / (samples - 1))
    return lines


def _jumps(q: np.ndarray) -> np.ndarray:
    """(n, K) the largest joint step along each line of q (n, L, K, dof); inf where a sample is missing."""
    step = np.abs(np.diff(q, axis=1)).max(axis=(1, 3))
    return np.where(np.isnan(step), np.inf, step)


def test_the_arm_is_redundant_and_a_six_axis_arm_is_not(iiwa: RobotModel) -> None:
    kr16 = load_robot(load_robot_spec(shipped_robots_dir() / "kr16" / "robot.yaml"))
    assert redundant(iiwa) and not redundant(kr16)
    # No configuration word: a six-axis arm's bits do not name one of its configurations.
    assert config_text(iiwa, np.full(7, 0.3)) == ""
    assert config_text(kr16, np.full(6, 0.3)) != ""


def test_approach_lines_follow_their_spot_configuration(iiwa: RobotModel) -> None:
    lines = _approach_lines(iiwa, 40)
    followed = solve_lines(iiwa, lines)
    whole = followed.valid.all(axis=1)                                         # (n, K)
    at_spot = followed.valid[:, -1]
    smooth = whole & (_jumps(followed.q) <= JUMP_RAD)
    # Every sample of a followed line solves its pose (Pinocchio's FK, not the solver's chain) and
    # keeps the spot's status.
    data = iiwa.model.createData()
    for i, k in zip(*np.nonzero(whole)):
        assert np.all(followed.status[i, :, k] == followed.status[i, -1, k])
        for at in range(lines.shape[1]):
            pin.framesForwardKinematics(iiwa.model, data, followed.q[i, at, k])
            got = data.oMf[iiwa.flange_frame_id]
            assert np.linalg.norm(got.translation - lines[i, at, :3, 3]) < POSE_M
            assert np.linalg.norm(pin.log3(got.rotation.T @ lines[i, at, :3, :3])) < POSE_RAD
    # Measured: 96 of 144 spot solutions followed smoothly to the approach point (the others leave
    # the limits, change status or pass a singularity); solved afresh at each pose, none of them.
    assert smooth.sum() >= 0.5 * at_spot.sum()
    fresh = solve_branches(iiwa, lines)
    assert (fresh.valid.all(axis=1) & (_jumps(fresh.q) <= JUMP_RAD)).sum() <= 0.1 * at_spot.sum()


def _lin_moves(robot: RobotModel, lines: range | tuple[int, ...] = range(20),
               path_tol: float | None = None) -> list[np.ndarray]:
    """The joint paths, as rows (s, q...), of `lines` of twenty 0.1 m LIN moves from random
    configurations in random directions (the moves that leave the workspace or the limits left out)."""
    rng = np.random.default_rng(5)
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    starts = rng.uniform(0.7 * lower, 0.7 * upper, size=(20, robot.dof))
    ways = rng.normal(size=(20, 3))
    ways /= np.linalg.norm(ways, axis=1)[:, None]
    paths = []
    for q0, way in zip(starts[list(lines)], ways[list(lines)]):
        T0 = fk_flange(robot, q0[None])[0]
        T1 = T0.copy()
        T1[:3, 3] += 0.1 * way
        found = lin_path(robot, T0, T1, 0, q_start=q0, **({} if path_tol is None else {"path_tol": path_tol}))
        if found.ok:
            paths.append(np.column_stack([found.s, found.q]))
    return paths


def _rate(path: np.ndarray) -> float:
    """The largest joint step per metre of TCP travel between two samples of (s, q...) rows."""
    return float(np.max(np.max(np.abs(np.diff(path[:, 1:], axis=0)), axis=1) / np.diff(path[:, 0])))


def test_lin_moves_follow_one_configuration_through_the_self_motion(iiwa: RobotModel,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    paths = _lin_moves(iiwa)
    assert len(paths) >= 12                                    # 15 of 20 measured
    assert max(_rate(p) for p in paths) < SMOOTH_RAD_PER_M
    # TOPP-RA times each (a jump across the self-motion made it "not controllable" in a plan).
    for path in paths[:3]:
        assert time_path(spline_path(path[:, 0], path[:, 1:]), iiwa.limits).duration > 0.0
    # Held to a far tighter line, move 6 is refined (midpoints added between its samples): each
    # midpoint continues its neighbour too.
    [loose] = _lin_moves(iiwa, (6,))
    [tight] = _lin_moves(iiwa, (6,), path_tol=1e-6)
    assert len(tight) > len(loose) and _rate(tight) < SMOOTH_RAD_PER_M
    # Continued in the start's column, as a six-axis arm is, move 13 jumps (4,290 rad/m measured).
    monkeypatch.setattr(lin_track, "redundant", lambda robot: False)
    [jumping] = _lin_moves(iiwa, (13,))
    assert _rate(jumping) > SMOOTH_RAD_PER_M
