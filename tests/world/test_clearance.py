"""world.motion.min_clearance: the per-pair skipping gives exactly the brute-force minimum.

On the reference cell (kr125 with the C-gun, clamps, the cabin panel as a mesh) a seeded random
joint walk is sampled; the smallest distance over every sample computed pair by pair with
`CollisionWorld.closest` must equal what `min_clearance` reports before its refinement step, to the
bit, and the refined value can only be lower.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.motion import _closest_sample, min_clearance
from robomax_py.world.scene import build_scene


@pytest.fixture(scope="module")
def world(reference_cell_path: Path) -> tuple[CollisionWorld, np.ndarray]:
    cell = load_cell(reference_cell_path)
    robot = load_cell_robot(cell)
    return CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance), np.asarray(cell.home)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_skipping_finds_the_brute_force_minimum(world: tuple[CollisionWorld, np.ndarray], seed: int) -> None:
    w, home = world
    rng = np.random.default_rng(seed)
    # A walk that comes near the part and the clamps: small steps from home towards the flange.
    goal = np.array([0.0, -0.35, 0.55, 0.0, 0.6, 0.0]) + rng.uniform(-0.3, 0.3, 6)
    steps = np.linspace(0.0, 1.0, 120)[:, None]
    q = home + steps * (goal - home) + rng.normal(0.0, 0.002, (120, 6))
    brute = [w.distance(qi) for qi in q]
    i, d = _closest_sample(w, q)
    assert d == min(brute)
    assert i == int(np.argmin(brute))
    report = min_clearance(w, np.arange(len(q)) * 0.01, q)
    assert report is not None and report.distance_m <= d
