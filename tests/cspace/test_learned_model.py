"""robomax_py.cspace.learned, points and cache: the learned point model of the ROBOMAX C-space method.

What must hold: the triangular basis interpolates (a partition of unity, exact at its centres);
the network fits every training profile within its tolerance; the virtual base's coordinates turn
a point about A1 and raise it in the arm's plane as the model assumes; surface points cover every
surface within the stated radius; a model comes back from the cache identical, and a stale or
damaged file is trained again; on a small cell the learned map with a stated inflation misses no
blocked cell of the exact map (coarse settings, so it runs in seconds; the full figures are the
README's).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import trimesh

from robomax_py.cspace import (
    CSpaceGrid,
    build_map,
    cover_radius,
    learned_map,
    learned_model,
    surface_points,
)
from robomax_py.cspace.learned import (
    TrainingSettings,
    VirtualBase,
    _basis,
    _fit,
    from_arrays,
    to_arrays,
)
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.world.scene import build_scene

SmallCell = Callable[..., Path]
COARSE = TrainingSettings(q1_step_deg=10.0, q23_step_deg=8.0, d_step=0.1, band_deg=30.0)
SPACING_M = 0.15
INFLATION_M = 0.1           # measured: 0 wrongly free cells on this cell at resolution 12 (see the test)


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell):  # type: ignore[no-untyped-def]
    folder = tmp_path_factory.mktemp("learned")
    cell = load_cell(write_small_cell(folder, "small"))
    robot = load_cell_robot(cell)
    radius = cell.process.clearance + cover_radius(SPACING_M) + INFLATION_M
    model, cached = learned_model(cell, robot, np.asarray(cell.home)[3:], radius, COARSE, folder / "cache")
    assert not cached
    return folder, cell, robot, radius, model


def test_triangular_basis_is_a_partition_of_unity_exact_at_its_centres() -> None:
    centres = np.array([0.0, 0.3, 0.5, 1.2])
    d = np.linspace(-0.5, 2.0, 101)
    F = _basis(d, centres)
    np.testing.assert_allclose(F.sum(axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(_basis(centres, centres), np.eye(4), atol=1e-12)
    # halfway between two centres each has weight 1/2
    np.testing.assert_allclose(_basis(np.array([0.4]), centres)[0], [0, 0.5, 0.5, 0], atol=1e-12)


def test_the_models_profiles_are_the_networks_output(small) -> None:  # type: ignore[no-untyped-def]
    model = small[4]
    d = np.concatenate([np.linspace(-0.2, model.d_max + 0.3, 257), model.centres])
    lo, hi = model.profiles(d)
    full = _basis(d, model.centres) @ model.weights
    B, C = len(model.bands) - 1, len(model.q2)
    np.testing.assert_allclose(lo.reshape(len(d), -1), full[:, :B * C], atol=1e-12)
    np.testing.assert_allclose(hi.reshape(len(d), -1), full[:, B * C:], atol=1e-12)


def test_network_grows_until_every_profile_fits() -> None:
    d = np.linspace(0.0, 3.0, 31)
    targets = np.stack([np.sin(3 * d), np.where(d > 1.5, 1.0, -1.0)], axis=1)    # smooth, and a jump
    settings = TrainingSettings(start_neurons=4, tolerance_steps=0.5)
    centres, weights, error = _fit(d, targets, settings, q23_step=0.1)
    assert error <= 0.5 and 4 < len(centres) <= len(d)
    assert np.abs(_basis(d, centres) @ weights - targets).max() <= 0.05 + 1e-12


def test_network_stops_growing_at_max_neurons() -> None:
    d = np.linspace(0.0, 3.0, 31)
    targets = np.stack([np.sin(3 * d), np.where(d > 1.5, 1.0, -1.0)], axis=1)
    free = _fit(d, targets, TrainingSettings(start_neurons=4, tolerance_steps=0.5), q23_step=0.1)
    capped = _fit(d, targets, TrainingSettings(start_neurons=4, tolerance_steps=0.5, max_neurons=6), q23_step=0.1)
    assert len(free[0]) > 6 and len(capped[0]) == 6
    assert capped[2] > 0.5 >= free[2]                # held at 6 neurons, the fit misses its tolerance


def test_virtual_base_coordinates_follow_a1_and_the_arm_plane(small) -> None:  # type: ignore[no-untyped-def]
    _, _, robot, _, model = small
    base = model.base
    fresh = VirtualBase.of(robot)
    np.testing.assert_array_equal(base.origin, fresh.origin)
    assert (base.q1_sign, base.q2_sign) == (fresh.q1_sign, fresh.q2_sign)
    p = base.origin + np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [math.cos(0.3), 0.0, math.sin(0.3)]])
    d, az, el = base.coordinates(p)
    np.testing.assert_allclose(d, [1.0, 2.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(az, [0.0, math.pi / 2, 0.0], atol=1e-12)
    np.testing.assert_allclose(el, [0.0, 0.0, 0.3], atol=1e-12)
    assert base.q1_sign in (1.0, -1.0) and base.q2_sign in (1.0, -1.0)


def test_surface_points_cover_every_surface_within_the_cover_radius(small) -> None:  # type: ignore[no-untyped-def]
    _, cell, robot, _, _ = small
    scene = build_scene(cell, robot)
    points = surface_points(scene, SPACING_M)
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    rng = np.random.default_rng(0)
    for obj in scene.obstacles:
        T = np.asarray(obj.T_base_object)
        for geom in obj.pieces:
            from robomax_py.cspace.points import _piece_mesh

            mesh = _piece_mesh(geom)
            assert mesh is not None
            samples = trimesh.sample.sample_surface(mesh, 300, seed=rng.integers(1 << 30))[0] @ T[:3, :3].T + T[:3, 3]
            gap, _ = tree.query(samples)
            assert gap.max() <= cover_radius(SPACING_M) + 1e-9


def test_the_cache_returns_the_same_model_and_retrains_a_bad_file(small) -> None:  # type: ignore[no-untyped-def]
    folder, cell, robot, radius, model = small
    again, cached = learned_model(cell, robot, np.asarray(cell.home)[3:], radius, COARSE, folder / "cache")
    assert cached
    np.testing.assert_array_equal(again.weights, model.weights)
    np.testing.assert_array_equal(again.centres, model.centres)
    assert from_arrays(to_arrays(model), "another key") is None
    (path,) = list((folder / "cache").glob("*.npz"))
    path.write_bytes(b"not a zip file")
    trained, cached = learned_model(cell, robot, np.asarray(cell.home)[3:], radius, COARSE, folder / "cache")
    assert not cached and np.array_equal(trained.weights, model.weights)   # training is deterministic


def test_learned_map_misses_no_blocked_cell_with_the_stated_inflation(small) -> None:  # type: ignore[no-untyped-def]
    _, cell, robot, _, model = small
    exact = build_map(cell, robot, "home", 12)
    points = surface_points(build_scene(cell, robot), SPACING_M)
    learned = learned_map(model, points, exact.grid)
    assert exact.obstacle.any()
    assert not (exact.obstacle & ~learned.obstacle).any()          # wrongly free: none
    assert (~learned.obstacle).sum() > 0.5 * (~exact.obstacle).sum()  # and not everything blocked
    other = CSpaceGrid.of(robot, 12, np.asarray(cell.home)[3:] + 0.1)
    with pytest.raises(Exception, match="another wrist"):
        learned_map(model, points, other)
