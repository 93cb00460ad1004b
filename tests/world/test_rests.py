"""world.motion on a rest (a long weld or wait): checked once per change of the obstacles present
instead of sample by sample, with the same answer. The process cell's door is present for the
first 1.5 s; the arm stands, for 4 s, where the door is."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.motion import check_motion, min_clearance
from robomax_py.world.scene import build_scene

# A configuration of the placed process cell whose gun is in the door (found with the cell's world).
IN_THE_DOOR_DEG = (6.3938, -97.7023, 122.6311, -5.1505, 45.4012, -162.9750)


@pytest.fixture(scope="module")
def door(tmp_path_factory: pytest.TempPathFactory, write_process_cell: Callable[..., Path]):  # type: ignore[no-untyped-def]
    cell = load_cell(write_process_cell(tmp_path_factory.mktemp("rests")))
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    q = np.radians(IN_THE_DOOR_DEG)
    contact = world.first_contact(q, 0.5)
    assert contact is not None and contact.kind_b == "dynamic", contact
    assert world.is_free(q, 2.0)
    return robot, world, q


def _rest(q: np.ndarray, t0: float, t1: float) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(t0, t1, round((t1 - t0) / 0.01) + 1)
    return t, np.repeat(q[None, :], len(t), axis=0) + 1e-15 * np.arange(len(t))[:, None]   # interpolation round-off


def test_a_rest_while_the_door_is_there_collides_from_its_start(door) -> None:  # type: ignore[no-untyped-def]
    robot, world, q = door
    t, qs = _rest(q, 0.0, 4.0)
    found = [v for v in check_motion(world, robot, t, qs).violations if v.kind == "collision"]
    assert len(found) == 1 and found[0].t == 0.0 and "door" in found[0].detail
    assert found[0].t_end is not None and 1.5 <= found[0].t_end <= 1.5 + 0.01 + 1e-9


def test_a_rest_after_the_door_is_gone_is_free(door) -> None:  # type: ignore[no-untyped-def]
    robot, world, q = door
    t, qs = _rest(q, 2.0, 6.0)
    motion = check_motion(world, robot, t, qs)
    assert not [v for v in motion.violations if v.kind == "collision"]
    assert motion.checks < len(t)                # checked once, not sample by sample


def test_the_smallest_clearance_of_a_rest_is_the_sample_by_sample_one(door) -> None:  # type: ignore[no-untyped-def]
    _, world, q = door
    t, qs = _rest(q, 1.0, 3.0)
    brute = min(world.closest(qi, float(ti)).distance for ti, qi in zip(t, qs))
    report = min_clearance(world, t, qs)
    assert report is not None and report.distance_m <= brute
    assert report.distance_m == pytest.approx(brute, abs=1e-9)
