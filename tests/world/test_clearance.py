"""world.motion.min_clearance: the per-pair skipping gives exactly the brute-force minimum.

On the reference cell (kr125 with the C-gun, clamps, the cabin panel as a mesh) a seeded random
joint walk is sampled; the smallest distance over every sample computed pair by pair with
`CollisionWorld.closest` must equal what `min_clearance` reports before its refinement step, to the
bit; the refined value is the brute-force minimum over the sub-steps either side of that sample
(every pair computed with `closest`), also to the bit. The pre-filter's screen it skips pairs by
leaves out only pairs farther apart than the distance it was made for, by coal's own distance.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.motion import (
    MIN_CLEARANCE_SUBSTEPS,
    _closest_sample,
    min_clearance,
)
from robomax_py.world.scene import build_scene


def _brute_refined(w: CollisionWorld, t: np.ndarray, q: np.ndarray, i: int, d: float) -> float:
    """The sample's minimum lowered by every pair's distance at the sub-steps of the steps either side."""
    best = d
    for k in (i - 1, i):
        if 0 <= k < len(t) - 1:
            for s in np.linspace(0.0, 1.0, MIN_CLEARANCE_SUBSTEPS + 1)[1:-1]:
                best = min(best, w.closest(q[k] + s * (q[k + 1] - q[k]), float(t[k] + s * (t[k + 1] - t[k]))).distance)
    return best


@pytest.fixture(scope="module")
def world(reference_cell_path: Path) -> tuple[CollisionWorld, np.ndarray]:
    cell = load_cell(reference_cell_path)
    robot = load_cell_robot(cell)
    return CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance), np.asarray(cell.home)


@pytest.mark.parametrize(("seed", "prefilter"), [(0, True), (1, True), (2, True), (0, False)])
def test_skipping_finds_the_brute_force_minimum(world: tuple[CollisionWorld, np.ndarray], seed: int,
                                                prefilter: bool) -> None:
    """With the pre-filter the screen leaves pairs out as well; without it, only the motion bound."""
    w, home = world
    w = w if prefilter else w.copy(prefilter=False)
    assert (w.distance_screen(0.0) is not None) == prefilter
    rng = np.random.default_rng(seed)
    # A walk that comes near the part and the clamps: small steps from home towards the flange.
    goal = np.array([0.0, -0.35, 0.55, 0.0, 0.6, 0.0]) + rng.uniform(-0.3, 0.3, 6)
    steps = np.linspace(0.0, 1.0, 120)[:, None]
    q = home + steps * (goal - home) + rng.normal(0.0, 0.002, (120, 6))
    brute = [w.distance(qi) for qi in q]
    i, d = _closest_sample(w, q)
    assert d == min(brute)
    assert i == int(np.argmin(brute))
    t = np.arange(len(q)) * 0.01
    report = min_clearance(w, t, q)
    assert report is not None and report.distance_m == _brute_refined(w, t, q, i, d)


@pytest.mark.parametrize("seed", [0, 1])
def test_with_obstacles_that_come_and_go_the_minimum_is_the_brute_force_one(reference_cell_path: Path, seed: int) -> None:
    """A box that is present only in two windows, placed where the walk passes: the per-pair skipping
    counts each pair only while it exists and still gives exactly the sample-by-sample minimum."""
    import dataclasses

    from robomax_py.robot.model import fk_flange
    from robomax_py.spec import Box, ObjectSpec
    from robomax_py.transforms import pose_matrix

    cell = load_cell(reference_cell_path)
    robot = load_cell_robot(cell)
    rng = np.random.default_rng(seed)
    home = np.asarray(cell.home)
    goal = np.array([0.0, -0.35, 0.55, 0.0, 0.6, 0.0]) + rng.uniform(-0.3, 0.3, 6)
    steps = np.linspace(0.0, 1.0, 120)[:, None]
    q = home + steps * (goal - home) + rng.normal(0.0, 0.002, (120, 6))
    t = np.arange(len(q)) * 0.01
    near = np.asarray(fk_flange(robot, q[70]))[:3, 3] + rng.uniform(-0.1, 0.1, 3) + [0.0, 0.0, 0.25]
    box = ObjectSpec("door", Box((0.3, 0.3, 0.05)), np.asarray(cell.T_world_base) @ pose_matrix(near, [0.0, 0.0, 0.0]),
                     present=((0.3, 0.6), (0.9, 1.0)))
    cell = dataclasses.replace(cell, dynamic=(box,))
    w = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    assert w.has_dynamic
    brute = [w.closest(qi, float(ti)).distance for qi, ti in zip(q, t, strict=True)]
    i, d = _closest_sample(w, q, t)
    assert d == min(brute)
    assert i == int(np.argmin(brute))
    report = min_clearance(w, t, q)
    assert report is not None and report.distance_m == _brute_refined(w, t, q, i, d)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(fraction=st.floats(0.0, 1.0), offset=st.lists(st.floats(-0.3, 0.3), min_size=6, max_size=6),
       rank=st.integers(0, 40), below=st.sampled_from([0.0, 1e-7, 1e-3]))
def test_a_screen_leaves_out_only_pairs_farther_than_its_distance(
        world: tuple[CollisionWorld, np.ndarray], fraction: float, offset: list[float], rank: int, below: float) -> None:
    """At configurations between home and the part, a screen made for (just below) one of the
    configuration's smallest pair distances leaves out no pair at or below that distance; the pair
    at exactly that distance is kept."""
    w, home = world
    goal = np.array([0.0, -0.35, 0.55, 0.0, 0.6, 0.0]) + np.asarray(offset)
    q = home + fraction * (goal - home)
    every = np.arange(w.n_pairs)
    exact = w.pair_distances(q, every)
    distance = max(float(np.sort(exact)[rank]) - below, 0.0)      # a screen is for distances >= 0
    wanted = np.ones(w.n_pairs, dtype=bool)
    wanted[::3] = False                               # only the pairs asked about come back
    screen = w.distance_screen(distance)
    assert screen is not None
    kept = w.pairs_within(q, wanted, screen)
    assert np.all(wanted[kept]) and np.all(np.diff(kept) > 0)
    left_out = np.setdiff1d(every[wanted], kept)
    assert np.all(exact[left_out] > distance)
    assert np.all(np.isin(np.flatnonzero(wanted & (exact <= distance)), kept))


def test_a_screen_is_for_distances_of_at_least_zero(world: tuple[CollisionWorld, np.ndarray]) -> None:
    w, _ = world
    with pytest.raises(ValueError, match="distance"):
        w.distance_screen(-1e-3)
