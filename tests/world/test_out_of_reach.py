"""Objects the arm cannot reach are proved apart ("out of reach") and left out of every check: the
reach spheres hold every robot and tool point in every configuration, far objects add no pair,
and a cell with 200 far-away boxes plans exactly as without them."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
import yaml

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.world.acm import KIND_OBJECT, ROBOT_KINDS, reach_spheres
from robomax_py.world.bounds import support_points
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

SmallCell = Callable[..., Path]


def _with_boxes(path: Path, boxes: list[dict[str, Any]]) -> Path:
    data = yaml.safe_load(path.read_text())
    data["objects"] += boxes
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def far_boxes(n: int) -> list[dict[str, Any]]:
    """n boxes on a ring 12-20 m from the robot (the small cell's kr125 reaches about 3 m)."""
    out = []
    for i in range(n):
        a, r = 2 * math.pi * i / n, 12.0 + (i % 5) * 2.0
        out.append({"name": f"far{i}", "box": [0.5, 0.5, 1.0],
                    "pose": {"xyz": [round(r * math.cos(a), 4), round(r * math.sin(a), 4), 0.5]}})
    return out


def test_the_reach_spheres_hold_every_robot_and_tool_point(tmp_path: Path, write_small_cell: SmallCell,
                                                           rng: np.random.Generator) -> None:
    spec = load_cell(write_small_cell(tmp_path))
    robot = load_cell_robot(spec)
    world = CollisionWorld(robot, build_scene(spec, robot), spec.process.clearance)
    gm = world.geometry_model
    shared = world._s                                     # the pieces' kinds, as the ACM sorted them
    moving = [p.kind in ROBOT_KINDS for p in shared.pieces]
    spheres = reach_spheres(robot.model, gm, moving)
    assert len(spheres) == 1
    centre, radius = spheres[0]
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    data, gdata = robot.model.createData(), gm.createData()
    farthest = 0.0
    for q in rng.uniform(lo, hi, size=(300, len(lo))):
        pin.updateGeometryPlacements(robot.model, data, gm, gdata, q)
        for k, g in enumerate(gm.geometryObjects):
            if moving[k] and g.parentJoint != 0:
                pts = support_points(g.geometry, gdata.oMg[k].homogeneous)
                farthest = max(farthest, float(np.max(np.linalg.norm(pts - centre, axis=1))))
    assert farthest <= radius
    assert radius < 2 * farthest                          # a bound, but not a useless one


def test_far_objects_add_no_pair_and_near_ones_stay_checked(tmp_path: Path, write_small_cell: SmallCell) -> None:
    plain = load_cell(write_small_cell(tmp_path / "a"))
    robot = load_cell_robot(plain)
    world = CollisionWorld(robot, build_scene(plain, robot), plain.process.clearance)
    crowded = load_cell(_with_boxes(write_small_cell(tmp_path / "b"), far_boxes(200)
                                    + [{"name": "near", "box": [0.2, 0.2, 0.2], "pose": {"xyz": [0.0, 2.0, 1.0]}}]))
    far_world = CollisionWorld(robot, build_scene(crowded, robot), crowded.process.clearance)
    out_of_reach = {d.piece_b.split(":")[1].split("[")[0] for d in far_world.acm.disabled if d.reason == "out of reach"}
    assert out_of_reach == {f"far{i}" for i in range(200)}
    near = [p for p in far_world.acm.enabled if any(f"{KIND_OBJECT}:near[" in n for n in p)]
    assert near and far_world.n_pairs == world.n_pairs + len(near)


@pytest.mark.slow
def test_a_cell_with_200_far_boxes_plans_exactly_as_without(tmp_path: Path, write_small_cell: SmallCell) -> None:
    results = []
    for name, boxes in (("plain", []), ("crowded", far_boxes(200))):
        spec = load_cell(_with_boxes(write_small_cell(tmp_path / name), boxes))
        results.append(plan_cell(spec, load_cell_robot(spec), PlanOptions()))
    a, b = results
    assert a.status == b.status == "planned"
    assert a.trajectory is not None and b.trajectory is not None
    np.testing.assert_array_equal(a.trajectory.t, b.trajectory.t)
    np.testing.assert_array_equal(a.trajectory.q, b.trajectory.q)
    assert a.clearance == b.clearance
