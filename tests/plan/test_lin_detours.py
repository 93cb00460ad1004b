"""Detours of straight TCP lines through via points (`planner.detour_moves: lin`, paper 003's detours):
the small clamp cell (s5, s6 of the reference cell with clamp1 on the flange between them, whose
straight joint move hits the clamp) plans round the clamp on lines; every sample of every line lies
on its straight segment and is free by the exact collision check (no pre-filter, no broad phase,
every pair through coal); the lines keep one configuration; the programs are LIN statements that
`robomax verify` passes in SRCL and KRL, and fails where a line is moved into the clamp or made
faster than the cell's detour line speed. The lines' own search: a line into the clamp is blocked,
two candidates of different configuration are never joined. The cell keys are validated."""

from __future__ import annotations

import itertools
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, EXIT_VIOLATIONS, app
from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, PlanResult, plan_cell, resolved_options
from robomax_py.plan.candidates import seam_candidates
from robomax_py.plan.program_frames import cell_program_frames
from robomax_py.plan.tcp_detour import follow_lines, status_of, tcp_detour
from robomax_py.program import LinMove
from robomax_py.publish import publish
from robomax_py.robot import fk_tcp
from robomax_py.spec import CellSpec
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.verify import read_program
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene
from tests.plan.test_plan import CLAMP1, PANEL_ON_TABLE, SPOTS, write_cell

runner = CliRunner()
# The TCP on a detour's line: within the approach lines' straightness tolerance (0.1 mm; the lines
# are followed to 0.01 mm between IK samples, `timing.lin`).
LINE_TOL_M = TOL.straight_tol_m
# A line's end is its written target within this (m): the program's 0.001 mm decimals.
TARGET_TOL_M = 1e-6


def _clamp_cell(folder: Path, **planner: Any) -> Path:
    """s5 and s6 with clamp1 between them, seam `flange`, `planner` keys added."""
    path = write_cell(folder, [SPOTS["s5"], SPOTS["s6"]], PANEL_ON_TABLE + CLAMP1)
    data = yaml.safe_load(path.read_text())
    data["name"] = "clamp_lin"
    data["seams"][0]["name"] = "flange"
    data["planner"].update(planner)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def lin_plan(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, CellSpec, Any, PlanResult]:
    path = _clamp_cell(tmp_path_factory.mktemp("lin"), detour_moves="lin")
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    return path, cell, robot, plan_cell(cell, robot, PlanOptions())


def _exact_world(cell: CellSpec, robot: Any) -> CollisionWorld:
    return CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance).copy(broad_phase=False,
                                                                                         prefilter=False)


def test_the_clamp_is_passed_on_straight_collision_free_tcp_lines(lin_plan: tuple[Path, CellSpec, Any,
                                                                                  PlanResult]) -> None:
    _, cell, robot, result = lin_plan
    assert result.status == "planned", result.message
    assert result.options.detour_moves == "lin"
    (between,) = [t for t in result.transitions if t.label == "s5 -> s6"]
    assert between.kind == "detour" and between.lin_targets is not None
    assert result.stats is not None and result.stats.lin_detours >= 1
    world = _exact_world(cell, robot)
    # The premise: the straight joint move between the two approach configurations hits clamp1.
    blocked = world.check_segment(between.waypoints[0], between.waypoints[-1])
    assert not blocked.free and blocked.s_contact is not None
    q_hit = between.waypoints[0] + blocked.s_contact * (between.waypoints[-1] - between.waypoints[0])
    contact = world.first_contact(q_hit)
    assert contact is not None and "clamp1" in contact.describe()
    traj = result.trajectory
    assert traj is not None
    lines = [t for t in result.transitions if t.lin_targets is not None]
    checked = 0
    for trans in lines:
        assert trans.lin_targets is not None
        legs = traj.phases_of("detour", trans.label)
        assert len(legs) == len(trans.lin_targets) == len(trans.waypoints) - 1 == len(trans.lin_configs)
        for leg, target in zip(legs, trans.lin_targets):
            q = traj.q[leg.i_start:leg.i_end + 1]
            p = fk_tcp(robot, q)[:, :3, 3]
            a, b = p[0], p[-1]
            assert np.linalg.norm(b - np.asarray(target)[:3, 3]) <= TARGET_TOL_M
            u = (b - a) / np.linalg.norm(b - a)
            rel = p - a
            along = rel @ u
            off = np.linalg.norm(rel - along[:, None] * u[None, :], axis=1)
            assert off.max() <= LINE_TOL_M, f"{trans.label}: {off.max() * 1000:.4f} mm off its line"
            assert along.min() >= -LINE_TOL_M and along.max() <= np.linalg.norm(b - a) + LINE_TOL_M
            assert len(set(status_of(robot, q).tolist())) == 1, "the configuration changes along a line"
            for q0, q1 in itertools.pairwise(q):
                assert world.check_segment(q0, q1).free, f"{trans.label}: a step of a line collides"
            checked += len(q)
    assert checked > 20


def test_joint_detours_plan_the_same_cell_unchanged_by_default(tmp_path: Path) -> None:
    """Without the key a detour is joint moves, as before (and the lines cost no search)."""
    cell = load_cell(_clamp_cell(tmp_path))
    assert resolved_options(cell, PlanOptions()).detour_moves == "ptp"
    result = plan_cell(cell, load_cell_robot(cell), PlanOptions())
    assert result.status == "planned", result.message
    assert all(t.lin_targets is None for t in result.transitions)
    assert result.stats is not None and result.stats.tcp_detour_searches == 0 and result.stats.lin_detours == 0
    assert any(t.kind == "detour" for t in result.transitions)


@pytest.fixture(scope="module")
def written(lin_plan: tuple[Path, CellSpec, Any, PlanResult], tmp_path_factory: pytest.TempPathFactory) -> Path:
    _, cell, robot, result = lin_plan
    folder = tmp_path_factory.mktemp("lin_programs")
    files, _ = publish(result, cell, robot, ("srcl", "krl"))
    for name, text in files.items():
        (folder / name).write_text(text)
    return folder


@pytest.mark.parametrize("program", ["clamp_lin.srcl", "clamp_lin.src"])
def test_the_lines_are_written_as_lin_and_verify_clean(lin_plan: tuple[Path, CellSpec, Any, PlanResult],
                                                        written: Path, program: str) -> None:
    path, _, robot, result = lin_plan
    _, _, parsed = read_program(robot, written / program)      # as `robomax verify` reads it
    lines = [ins for ins in parsed.program.instructions if isinstance(ins, LinMove)]
    # An approach and a retract per spot, and a line to each point of each detour of lines.
    n_detour = sum(len(t.waypoints) - 1 for t in result.transitions if t.lin_targets is not None)
    assert n_detour >= 1 and len(lines) == 2 * len(result.spots) + n_detour
    done = runner.invoke(app, ["verify", str(path), str(written / program)])
    assert done.exit_code == EXIT_OK, done.output


def _edit_detour_line(text: str, edit: Any) -> str:
    """The SRCL program with the first detour LIN statement after 'detour point 1' edited."""
    lines = text.splitlines(keepends=True)
    k = next(i for i, line in enumerate(lines) if "MOVE LIN" in line and "detour point 2" in line)
    lines[k] = edit(lines[k])
    return "".join(lines)


def test_verify_fails_a_detour_line_moved_into_the_clamp_or_too_fast(lin_plan: tuple[Path, CellSpec, Any,
                                                                                     PlanResult],
                                                                      written: Path, tmp_path: Path) -> None:
    path, cell, _, _ = lin_plan
    text = (written / "clamp_lin.srcl").read_text()

    def lowered(line: str) -> str:       # the via point across the clamp brought down onto the flange
        return re.sub(r"POS\(([-\d.]+), ([-\d.]+), ([-\d.]+)\)",
                      lambda m: f"POS({m[1]}, {m[2]}, {float(m[3]) - 120.0:.3f})", line, count=1)

    def faster(line: str) -> str:
        return re.sub(r"SPEED [\d.]+ MM/S", f"SPEED {1000.0 * cell.planner.detour_tcp_speed + 200.0:.3f} MM/S", line)

    for tag, edit, expect in (("low", lowered, "collision"), ("fast", faster, "detour line speed")):
        program = tmp_path / f"clamp_lin_{tag}.srcl"
        program.write_text(_edit_detour_line(text, edit))
        done = runner.invoke(app, ["verify", str(path), str(program)])
        assert done.exit_code == EXIT_VIOLATIONS, done.output
        assert expect in " ".join(done.output.split()), done.output


def test_a_line_into_the_clamp_is_blocked_and_other_configurations_are_not_joined(
        lin_plan: tuple[Path, CellSpec, Any, PlanResult]) -> None:
    _, cell, robot, result = lin_plan
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    s5, s6 = (seam_candidates(cell, robot, world, 0)[0][k] for k in (0, 1))
    (between,) = [t for t in result.transitions if t.label == "s5 -> s6"]
    qa, qb = between.waypoints[0], between.waypoints[-1]
    # The single line from s5's approach point to s6's runs along the flange through the clamp's jaw.
    straight = follow_lines(robot, world, qa, [fk_tcp(robot, qb)], q_goal=qb)
    assert not straight.ok and straight.reason == "blocked" and straight.checks > 0
    status_a = int(status_of(robot, qa)[0])
    other = [q for q in s6.q_app if int(status_of(robot, q)[0]) != status_a]
    assert other, "s6 has candidates in another configuration"
    up = np.array([0.0, 0.0, 1.0])
    found = tcp_detour(robot, world, robot.limits, qa, other[0], [(up, up)], (0.15,),
                       cell_program_frames(cell).written, 1.0, 1.0)
    assert found.detour is None and found.checks == 0
    assert len(s5) > 0


@pytest.mark.parametrize(("key", "value"), [("detour_moves", "spline"), ("detour_tcp_speed", 3.0),
                                            ("detour_tcp_speed", 0)])
def test_bad_detour_keys_are_named(tmp_path: Path, key: str, value: object) -> None:
    path = _clamp_cell(tmp_path, **{key: value})
    with pytest.raises(CellFileError, match=f"planner.{key}"):
        load_cell(path)
