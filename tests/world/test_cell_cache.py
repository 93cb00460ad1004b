"""robomax_py.world.cell_cache: the cells' decisions shared by the worlds of one arm and tool, and
kept across runs in the cache folder.

What must hold: two worlds of the same arm and tool (whatever the cell's objects) share one array;
the key changes with anything a decision depends on (a piece's shape or placement, a joint, the
margin); decisions a run keeps are read by the next (a new process: the memory emptied), merged with
what another process wrote; a bad entry is a miss, never an error; and a plan reading decisions from
the cache gives what it gives deciding them itself.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.world import cell_cache
from robomax_py.world.acm_cache import joint_bytes
from robomax_py.world.cell_cache import decisions_key, keep_decisions
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.pair_cells import CERTIFIED, UNCERTIFIED, UNKNOWN
from robomax_py.world.scene import build_scene

REFERENCE_CELL = Path(__file__).resolve().parents[2] / "tests" / "data" / "reference" / "cabin_flange.yaml"


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A cache folder of the test's own, and a process memory with nothing in it."""
    monkeypatch.setenv("ROBOMAX_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(cell_cache, "_MEMORY", OrderedDict())
    return tmp_path / "cache" / "cells"


def _world(objects: bool = True) -> tuple[object, CollisionWorld]:
    cell = load_cell(REFERENCE_CELL)
    robot = load_cell_robot(cell)
    if not objects:
        cell = replace(cell, objects=())
    return robot, CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)


def _decisions(world: CollisionWorld) -> np.ndarray:
    assert world._s.prefilter is not None
    return world._s.prefilter.cells.decided


def _decide_some(robot: object, world: CollisionWorld, n: int = 200) -> None:
    rng = np.random.default_rng(4)
    limits = robot.limits  # type: ignore[attr-defined]
    world.are_free(rng.uniform(limits.lower, limits.upper, size=(n, len(limits.lower))))


def test_worlds_of_one_arm_and_tool_share_their_decisions(cache: Path) -> None:
    _, with_objects = _world()
    _, without = _world(objects=False)
    assert _decisions(with_objects) is _decisions(without)


def test_the_key_follows_what_a_decision_depends_on(cache: Path) -> None:
    _, world = _world()
    s = world._s
    assert s.prefilter is not None
    model, gm, tables = s.model, s.geom_model, s.prefilter.cells.tables
    base = decisions_key(model, gm, s.pair_a, s.pair_b, s.pair_margin, tables)
    assert base is not None and base == decisions_key(model, gm, s.pair_a, s.pair_b, s.pair_margin.copy(), tables)
    k = next(k for k, t in enumerate(tables) if t is not None)
    margin = s.pair_margin.copy()
    margin[k] += 1e-3
    assert decisions_key(model, gm, s.pair_a, s.pair_b, margin, tables) != base
    other = [t for t in tables]
    table = other[k]
    assert table is not None
    other[k] = replace(table, low=tuple(x + 1e-6 for x in table.low))
    assert decisions_key(model, gm, s.pair_a, s.pair_b, s.pair_margin, other) != base
    moved = model.copy()
    joint = model.njoints - 1
    moved.jointPlacements[joint] = moved.jointPlacements[joint] * pin.SE3(np.eye(3), np.array([0.0, 0.0, 1e-4]))
    assert decisions_key(moved, gm, s.pair_a, s.pair_b, s.pair_margin, tables) != base
    piece = gm.geometryObjects[int(s.pair_b[k])]
    saved = piece.placement.copy()
    try:
        piece.placement = saved * pin.SE3(np.eye(3), np.array([1e-4, 0.0, 0.0]))
        assert decisions_key(model, gm, s.pair_a, s.pair_b, s.pair_margin, tables) != base
    finally:
        piece.placement = saved
    assert decisions_key(model, gm, s.pair_a, s.pair_b, s.pair_margin, [None] * len(tables)) is None


def test_the_next_run_reads_what_this_one_kept(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    robot, world = _world()
    _decide_some(robot, world)
    mine = _decisions(world).copy()
    assert (mine == CERTIFIED).any() and (mine == UNCERTIFIED).any()
    keep_decisions()
    assert len(list(cache.glob("*.npz"))) == 1
    monkeypatch.setattr(cell_cache, "_MEMORY", OrderedDict())       # as a new process
    _, again = _world()
    np.testing.assert_array_equal(_decisions(again), mine)


def test_another_process_decisions_are_merged(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    robot, world = _world()
    _decide_some(robot, world)
    keep_decisions()
    written = _decisions(world).copy()
    # Another process, which decided other cells (taken here as the first's undecided ones).
    monkeypatch.setattr(cell_cache, "_MEMORY", OrderedDict())
    _, other = _world()
    theirs = _decisions(other)
    theirs[:] = UNKNOWN
    gap = np.flatnonzero(written == UNKNOWN)[:50]
    theirs[gap] = UNCERTIFIED
    keep_decisions()
    monkeypatch.setattr(cell_cache, "_MEMORY", OrderedDict())
    _, third = _world()
    merged = _decisions(third)
    assert (merged[gap] == UNCERTIFIED).all()
    decided = written != UNKNOWN
    np.testing.assert_array_equal(merged[decided], written[decided])


@pytest.mark.parametrize("content", [b"not an npz", "wrong size", "wrong values", "wrong type"])
def test_a_bad_entry_is_a_miss_and_is_written_again(cache: Path, monkeypatch: pytest.MonkeyPatch,
                                                    content: bytes | str) -> None:
    robot, world = _world()
    _decide_some(robot, world, 50)
    keep_decisions()
    (path,) = cache.glob("*.npz")
    size = len(_decisions(world))
    if content == "wrong size":
        np.savez(path, decided=np.zeros(size + 1, dtype=np.int8))
    elif content == "wrong values":
        np.savez(path, decided=np.full(size, 7, dtype=np.int8))
    elif content == "wrong type":
        np.savez(path, decided=np.ones(size, dtype=np.float64))
    else:
        path.write_bytes(content)  # type: ignore[arg-type]
    monkeypatch.setattr(cell_cache, "_MEMORY", OrderedDict())
    robot, again = _world()
    assert not _decisions(again).any()
    _decide_some(robot, again, 50)
    keep_decisions()
    with np.load(path) as data:
        np.testing.assert_array_equal(data["decided"], _decisions(again))


@pytest.mark.slow
def test_a_plan_from_kept_decisions_is_the_plan_deciding_them(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The reference cell planned with no decisions, then as a new process reading the kept ones:
    the same spots, configurations and samples."""
    cell = load_cell(REFERENCE_CELL)
    robot = load_cell_robot(cell)
    first = plan_cell(cell, robot, PlanOptions())
    assert first.status == "planned" and list(cache.glob("*.npz"))
    monkeypatch.setattr(cell_cache, "_MEMORY", OrderedDict())
    second = plan_cell(cell, robot, PlanOptions())
    assert second.status == "planned"
    assert second.cycle_time == first.cycle_time
    assert second.trajectory is not None and first.trajectory is not None
    np.testing.assert_array_equal(second.trajectory.q, first.trajectory.q)
    assert [(s.name, s.config) for s in second.spots] == [(s.name, s.config) for s in first.spots]


def test_a_joint_about_another_axis_is_another_key() -> None:
    """Joints Pinocchio names alike (a revolute joint about any axis; FANUC's J3 turns about -y) but
    that move otherwise give other keys, as do passive joints of other multipliers."""
    model = pin.Model()
    about = [model.addJoint(0, pin.JointModelRevoluteUnaligned(np.array(axis)), pin.SE3.Identity(), f"j{k}")
             for k, axis in enumerate(([0.0, 1.0, 0.0], [0.0, -1.0, 0.0]))]
    assert joint_bytes(model.joints[about[0]]) != joint_bytes(model.joints[about[1]])
    followers = [model.addJoint(about[0], pin.JointModelMimic(model.joints[about[0]], scale, 0.0), pin.SE3.Identity(),
                                f"m{k}") for k, scale in enumerate((1.0, -1.0))]
    assert joint_bytes(model.joints[followers[0]]) != joint_bytes(model.joints[followers[1]])
