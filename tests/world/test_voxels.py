"""robomax_py.world.voxels: adaptive voxel free space of a cell's static objects.

What must hold: the leaves tile the root cube; a free leaf is farther than the inflation from every
object piece (coal's distance, an independent query); a point inside an object is never free;
far from the objects the leaves stay large and near them they reach the precision limit.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import coal
import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.world.scene import build_scene
from robomax_py.world.voxels import build_voxels

SmallCell = Callable[..., Path]
LO, HI = np.array([-1.0, -2.0, -0.2]), np.array([3.0, 2.0, 2.0])
PRECISION_M, INFLATION_M = 0.05, 0.02


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell):  # type: ignore[no-untyped-def]
    cell = load_cell(write_small_cell(tmp_path_factory.mktemp("vox"), "small"))
    robot = load_cell_robot(cell)
    scene = build_scene(cell, robot)
    return scene, build_voxels(scene, LO, HI, PRECISION_M, INFLATION_M)


def test_leaves_tile_the_root(small) -> None:  # type: ignore[no-untyped-def]
    _, v = small
    root = float((HI - LO).max())
    assert np.isclose(float(np.sum(v.edge ** 3)), root ** 3, rtol=1e-9)
    assert v.edge.min() >= PRECISION_M - 1e-12 and v.edge.max() > 8 * PRECISION_M   # fine near, coarse far
    assert v.free.any() and (~v.free).any()


def test_a_free_leaf_is_farther_than_the_inflation_from_every_piece(small, rng: np.random.Generator) -> None:  # type: ignore[no-untyped-def]
    scene, v = small
    free = np.flatnonzero(v.free)
    # the smallest free leaves (next to the objects) and a random sample of the rest
    picked = np.concatenate([free[np.argsort(v.edge[free])[:150]], rng.choice(free, 150, replace=False)])
    for n in picked:
        box = coal.Box(v.edge[n], v.edge[n], v.edge[n])
        place = coal.Transform3s(np.eye(3), v.corner[n] + v.edge[n] / 2)
        for obj in scene.obstacles:
            T = np.asarray(obj.T_base_object)
            for geom in obj.pieces:
                result = coal.DistanceResult()
                d = coal.distance(box, place, geom, coal.Transform3s(T[:3, :3], T[:3, 3]), coal.DistanceRequest(), result)
                assert d > INFLATION_M - 1e-9, (n, obj.name, d)


def test_points_inside_an_object_are_not_free(small, rng: np.random.Generator) -> None:  # type: ignore[no-untyped-def]
    scene, v = small
    table = next(o for o in scene.obstacles if o.name == "table")
    T = np.asarray(table.T_base_object)
    half = np.asarray(table.pieces[0].halfSide)
    local = rng.uniform(-half, half, size=(500, 3))
    points = local @ T[:3, :3].T + T[:3, 3]
    assert not v.is_free(points).any()
    assert not v.is_free(np.array([[50.0, 0.0, 0.0]])).any()          # outside the root: not free


def test_bad_arguments_are_refused(small) -> None:  # type: ignore[no-untyped-def]
    scene, _ = small
    for kwargs in ({"precision": 0.0}, {"precision": float("nan")}, {"precision": 0.1, "inflation": -1.0}):
        with pytest.raises(ValueError):
            build_voxels(scene, LO, HI, **kwargs)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="hi > lo"):
        build_voxels(scene, HI, LO, 0.1)


def test_leaf_lookup_equals_a_scan_of_every_leaf(small, rng: np.random.Generator) -> None:  # type: ignore[no-untyped-def]
    _, v = small
    root = float((HI - LO).max())
    points = rng.uniform(LO - 0.3, LO + root + 0.3, size=(2000, 3))       # some outside the root
    inside = np.all((points[:, None, :] >= v.corner[None]) & (points[:, None, :] < v.corner[None] + v.edge[None, :, None]),
                    axis=2)
    assert (inside.sum(axis=1) <= 1).all()                                 # leaves do not overlap
    scan = np.where(inside.any(axis=1), np.argmax(inside, axis=1), -1)
    np.testing.assert_array_equal(v.leaf_of(points), scan)
    assert (scan >= 0).any() and (scan < 0).any()
