"""Candidate filtering: the vectorised tests, which expand the turn variants of only the spot's IK
row and of the approach lines valid there, give what a plain scan over every orientation and column
of the whole IK table (`solve_all`) gives — the same candidates with the table's own values, and
the same rejection counts in the same order."""

from __future__ import annotations

from collections import Counter
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan.candidates import (
    BRANCH_JUMP_RAD,
    Rejection,
    _line_verdict,
    _spot_candidates,
)
from robomax_py.plan.poses import approach_poses, orientation_grid, spot_poses
from robomax_py.robot import prismatic_mask
from robomax_py.robot.ik.turns import wrap_to_pi
from robomax_py.robot.solve import expand_branches, solve_branches
from robomax_py.transforms import invert
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]


def _scan(robot, world, q, valid, reachable):  # type: ignore[no-untyped-def]
    """The filter as a plain loop (the reference the vectorised version must equal)."""
    revolute = ~prismatic_mask(robot.model)
    rejected: Counter[Rejection] = Counter()
    keep = []
    m, _, n_col = valid.shape
    for o in range(m):
        for k in range(n_col):
            if not reachable[o, -1, k]:
                continue
            if not valid[o, -1, k]:
                rejected[Rejection("joint_limit")] += 1
                continue
            line = q[o, :, k].copy()
            spot = line[-1].copy()
            line[:, revolute] = spot[revolute] + wrap_to_pi(line[:, revolute] - spot[revolute])
            with np.errstate(invalid="ignore"):
                jump = np.abs(np.diff(line, axis=0)).max()
            if not reachable[o, :, k].all() or jump > BRANCH_JUMP_RAD:
                rejected[Rejection("approach_branch")] += 1
                continue
            if not robot.limits.contains(line).all():
                rejected[Rejection("approach_joint_limit")] += 1
                continue
            verdict = _line_verdict(world, line)
            if not verdict.free:
                rejected[verdict.reason] += 1
                continue
            keep.append((o, k))
        if not reachable[o, -1].any():
            rejected[Rejection("unreachable")] += n_col
    return keep, rejected


@pytest.mark.parametrize("cell_path, spot", [
    (REPO / "tests" / "data" / "reference" / "cabin_flange.yaml", 0),   # limits on the line
    (REPO / "cells" / "ur10_tray.yaml", 0),                                      # blocked lines, turns
])
def test_filter_equals_a_plain_scan(cell_path: Path, spot: int) -> None:
    assert cell_path.is_file(), f"{cell_path} is shipped with the repository"
    cell = load_cell(cell_path)
    seam = replace(cell.seams[0], spots=cell.seams[0].spots[spot:spot + 1])
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    grid = orientation_grid(seam)
    T_spot = invert(np.asarray(cell.T_world_base)) @ spot_poses(seam.spots, grid)
    T_line = np.stack([approach_poses(T_spot, cell.process.approach * f) for f in np.linspace(1, 0, 4)], axis=2)
    branches = solve_branches(robot, T_line)
    table = expand_branches(branches)                   # what solve_all returns: every variant of every pose
    got, _ = _spot_candidates(robot, world, seam, grid, 0, branches, 0)
    keep, rejected = _scan(robot, world, table.q[0], table.valid[0], table.reachable[0])
    assert list(zip(got.orient.tolist(), got.column.tolist())) == keep
    assert list(got.rejected.items()) == list(rejected.items())
    o, k = got.orient, got.column
    np.testing.assert_array_equal(got.q_spot, table.q[0, o, -1, k])    # the table's values
    assert got.status.tolist() == table.status[0, o, -1, k].tolist()
    assert got.turn.tolist() == table.turn[0, o, -1, k].tolist()
    revolute = ~prismatic_mask(robot.model)
    line = table.q[0, o, :, k]                                          # (c, L, n), unwrapped towards the spot
    line[..., revolute] = line[:, -1:, revolute] + wrap_to_pi(line[..., revolute] - line[:, -1:, revolute])
    np.testing.assert_array_equal(got.app_path, line)
    assert Rejection("joint_limit") in rejected and any(r.kind == "collision" and r.detail for r in rejected)
    assert {"approach_joint_limit", "approach_blocked"} & {r.kind for r in rejected}      # line tests exercised
