"""Robot-robot collision: the prefiltered check (robot, link and piece spheres before coal) gives
exactly the answer of asking coal about every pair of pieces, on random configurations of two
robots placed close enough to collide often."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.station.bodies import body_poses, clash_map, robot_body, sample_step
from robomax_py.world.scene import build_scene

STATION = Path(__file__).parents[1] / "data" / "station" / "two_robots.yaml"


@pytest.fixture(scope="module")
def bodies():  # type: ignore[no-untyped-def]
    station = load_station(STATION)
    out = []
    for r in station.robots:
        model = load_cell_robot(r.cell)
        out.append(robot_body(r.name, model, build_scene(r.cell, model)))
    # r2 brought to 2.2 m from r1 (facing it), so that random postures often touch.
    T = np.array(out[1].T_world_base)
    T[0, 3] = 2.2
    return out[0], dataclasses.replace(out[1], T_world_base=T)


@pytest.mark.parametrize("margin", [0.0, 0.05])
def test_prefiltered_equals_every_pair(bodies, margin: float) -> None:  # type: ignore[no-untyped-def]
    a, b = bodies
    rng = np.random.default_rng(7)
    lim = a.robot.limits
    qa = rng.uniform(lim.lower, lim.upper, (14, a.robot.dof))
    qb = rng.uniform(lim.lower, lim.upper, (14, b.robot.dof))
    pa, pb = body_poses(a, qa), body_poses(b, qb)
    fast = clash_map(a, pa, b, pb, margin)
    exact = clash_map(a, pa, b, pb, margin, prefilter=False)
    assert 0 < exact.sum() < exact.size          # both answers occur, so the comparison can fail
    np.testing.assert_array_equal(fast, exact)


def test_sample_step_bounds_how_far_points_move(bodies) -> None:  # type: ignore[no-untyped-def]
    a, _ = bodies
    q0 = np.zeros(a.robot.dof)
    q1 = q0.copy()
    q1[0] = 0.1                                   # 0.1 rad about axis 1
    poses = body_poses(a, np.stack([q0, q1]))
    step = sample_step(a, poses)
    moved = np.linalg.norm(poses[1, :, :3, 3] - poses[0, :, :3, 3], axis=1).max()
    assert step >= moved


def test_prefiltered_equals_every_pair_with_slacks(bodies) -> None:  # type: ignore[no-untyped-def]
    a, b = bodies
    rng = np.random.default_rng(11)
    lim = a.robot.limits
    qa = rng.uniform(lim.lower, lim.upper, (12, a.robot.dof))
    qb = rng.uniform(lim.lower, lim.upper, (12, b.robot.dof))
    pa, pb = body_poses(a, qa), body_poses(b, qb)
    sa, sb = rng.uniform(0, 0.1, 12), rng.uniform(0, 0.1, 12)
    fast = clash_map(a, pa, b, pb, 0.01, slack_a=sa, slack_b=sb)
    exact = clash_map(a, pa, b, pb, 0.01, prefilter=False, slack_a=sa, slack_b=sb)
    assert 0 < exact.sum() < exact.size
    np.testing.assert_array_equal(fast, exact)
