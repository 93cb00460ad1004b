"""Robot-robot collision: the prefiltered check (link spheres over blocks of samples, then link and
piece spheres per sample pair, before coal) gives exactly the answer of asking coal about every pair
of pieces, on random configurations and random motions of two robots placed close enough to collide
often (`bodies`, tests/station/conftest.py)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.station.bodies import body_poses, clash_map, sample_step


@pytest.mark.parametrize("margin", [0.0, 0.05])
def test_prefiltered_equals_every_pair(bodies, random_poses, margin: float) -> None:  # type: ignore[no-untyped-def]
    a, b = bodies
    pa, pb = random_poses(7, 14)
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


@settings(max_examples=8, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**32 - 1), ka=st.integers(1, 10), kb=st.integers(1, 10), block=st.integers(1, 4),
       margin=st.sampled_from([0.0, 0.02]), apart=st.floats(1.4, 2.4), slacks=st.booleans())
def test_blocks_of_motion_keep_the_exact_answer(bodies, seed: int, ka: int, kb: int, block: int,  # type: ignore[no-untyped-def]
                                                 margin: float, apart: float, slacks: bool) -> None:
    """Random motions (random walks in joint space, so that a block's samples lie close together as
    a trajectory's do), blocks of 1-4 samples (the last one short), any slacks: the same map as coal
    asked of every pair."""
    a, b = bodies
    T = np.array(b.T_world_base)
    T[0, 3] = apart
    b = dataclasses.replace(b, T_world_base=T)
    rng = np.random.default_rng(seed)

    def walk(body, k: int):  # type: ignore[no-untyped-def]
        lim = body.robot.limits
        q0 = rng.uniform(lim.lower, lim.upper)
        return np.clip(q0 + np.cumsum(rng.normal(0.0, 0.15, (k, body.robot.dof)), axis=0), lim.lower, lim.upper)

    pa, pb = body_poses(a, walk(a, ka)), body_poses(b, walk(b, kb))
    sa = rng.uniform(0, 0.05, ka) if slacks else None
    sb = rng.uniform(0, 0.05, kb) if slacks else None
    fast = clash_map(a, pa, b, pb, margin, slack_a=sa, slack_b=sb, block=block)
    exact = clash_map(a, pa, b, pb, margin, prefilter=False, slack_a=sa, slack_b=sb)
    np.testing.assert_array_equal(fast, exact)
