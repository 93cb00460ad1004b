"""Pick and place: a held part is checked as part of the gripper (and may rest on its supports), a
part that would hit a shelf makes the planner go round, carried moves keep the part's limits, and
the program grips and releases where the cell says."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from robomax_py.errors import CellFileError
from robomax_py.export.plan_program import program_from_plan
from robomax_py.export.rebuild import rebuild
from robomax_py.export.srcl import parse_program, write_program
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.io.cell_file_jobs import PICK_PLACE_SEAM
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.plan.loads import (
    Loads,
    check_carried_motion,
    holds,
    tcp_block_peaks,
)
from robomax_py.program import Gripper
from robomax_py.robot.solve import solve_all
from robomax_py.spec import Sphere
from robomax_py.transforms import invert
from robomax_py.world.acm import HELD_SUPPORT_PENETRATION_M
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
SHIPPED = REPO / "cells" / "pick_place.yaml"


def _cell_file(tmp_path: Path, transfers: list[dict] | None = None, **edits: object) -> Path:
    data = yaml.safe_load(SHIPPED.read_text())
    if transfers is not None:
        data["pick_place"]["transfers"] = transfers
    for key, value in edits.items():
        node = data
        *parents, last = key.split(".")
        for p in parents:
            node = node[int(p)] if isinstance(node, list) else node[p]
        node[int(last) if isinstance(node, list) else last] = value
    path = tmp_path / "cell.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_transfers_become_grip_and_release_stops() -> None:
    cell = load_cell(SHIPPED)
    (seam,) = cell.seams
    assert seam.name == PICK_PLACE_SEAM and seam.ordered
    assert len(seam.spots) == 2 * 10
    assert [s.action for s in seam.spots[:4]] == ["grip", "release", "grip", "release"]
    first = seam.spots[0]
    assert first.name == "t1_pick_low_1" and first.part == "housing"
    # The TCP where the grasp puts it: 30 mm above the part's centre at low_1.
    np.testing.assert_allclose(first.xyz, [0.8, -0.3, 0.53], atol=1e-12)
    housing = cell.part("housing")
    assert housing.mass == 4.0 and housing.supports == ("rack_high", "rack_low", "table_a", "table_b")


@pytest.mark.parametrize(("key", "value", "named", "problem"), [
    ("pick_place.parts.0.mass", 40.0, "pick_place.parts[0].mass", "rated payload"),
    ("pick_place.transfers.0.to", "nowhere", "pick_place.transfers[0].to", "unknown location"),
    ("pick_place.transfers.0.to", "low_1", "pick_place.transfers[0].to", "goes back"),
    ("pick_place.transfers.0.part", "gear", "pick_place.transfers[0].part", "unknown part"),
    ("pick_place.locations.0.support", ["floor"], "pick_place.locations[0].support[0]", "unknown object"),
    ("pick_place.locations.1.name", "low_1", "pick_place.locations[1].name", "duplicate location"),
    ("dynamic", [{"name": "d", "box": [0.1, 0.1, 0.1], "present": [[0, 1]]}], "dynamic", "do not plan dynamic"),
])
def test_bad_pick_place_sections_name_the_key(tmp_path: Path, key: str, value: object, named: str,
                                              problem: str) -> None:
    with pytest.raises(CellFileError) as err:
        load_cell(_cell_file(tmp_path, **{key: value}))
    assert err.value.key == named and problem in err.value.problem


def test_joint_limits_carrying_a_part_are_interpolated_by_mass() -> None:
    robot = load_cell_robot(load_cell(SHIPPED))
    assert robot.payload_kg == 16.0 and robot.loaded_limits is not None
    half = robot.limits_carrying(8.0)
    np.testing.assert_allclose(half.acceleration, 0.5 * (robot.limits.acceleration + robot.loaded_limits.acceleration),
                               rtol=1e-12)
    np.testing.assert_array_equal(robot.limits_carrying(0.0).acceleration, robot.limits.acceleration)


def test_a_held_part_rests_on_its_support_but_may_not_sink_into_it() -> None:
    """At the grip the part lies on the low board (distance 0): free. The same pose 2 mm lower
    sinks it into the board by more than HELD_SUPPORT_PENETRATION_M: a collision."""
    cell = load_cell(SHIPPED)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot, held=cell.part("housing")), cell.process.clearance)
    spot = cell.seams[0].spots[0]
    T = np.eye(4)
    T[:3, 3] = spot.xyz
    for dz, free in ((0.0, True), (-2 * HELD_SUPPORT_PENETRATION_M, False)):
        Tz = T.copy()
        Tz[2, 3] += dz
        table = solve_all(robot, (invert(np.asarray(cell.T_world_base)) @ Tz)[None])
        q = table.q[0][table.valid[0]][0]
        assert world.is_free(q) is free
        contact = world.first_contact(q)
        assert free or (contact is not None and "rack_low" in contact.describe())


@pytest.mark.parametrize(("part_mesh", "support_mesh", "side"), [
    (True, False, False), (False, True, False), (True, True, False), (True, False, True)])
def test_a_mesh_part_or_support_rests_but_may_not_sink_in(tmp_path: Path, part_mesh: bool, support_mesh: bool,
                                                          side: bool) -> None:
    """coal has no negative margin for a triangle mesh (its BVH collider raises); where the part or
    its support is one, the part is checked against the support lifted 1 mm along the world's up
    as it lies. At rest (distance 0) and 0.5 mm in: free; 2 mm in: a collision with the support,
    also where the gripper holds the part from the side (TCP z horizontal). The meshes are rings
    (closed, not convex: one BVH each)."""
    import trimesh

    edits: dict[str, object] = {}
    if part_mesh:       # the housing's 0.1 m height, its frame at its centre like the box's
        trimesh.creation.annulus(0.02, 0.06, 0.1).export(tmp_path / "ring.stl")
        edits["pick_place.parts.0"] = {"name": "housing", "mesh": "ring.stl", "mass": 4.0,
                                       "grasp": {"xyz": [0, 0, 0.03], "rpy": [90, 0, 0] if side else [0, 0, 0]}}
    if support_mesh:    # a ring board under low_1, its top at the box board's (0.45 m)
        trimesh.creation.annulus(0.03, 0.2, 0.03).export(tmp_path / "board.stl")
        edits["objects.0"] = {"name": "rack_low", "mesh": "board.stl", "pose": {"xyz": [0.8, -0.3, 0.435]}}
    cell = load_cell(_cell_file(tmp_path, **edits))
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot, held=cell.part("housing")), cell.process.clearance)
    assert any("checked lifted" in d.reason for d in world.acm.disabled)
    spot = cell.seams[0].spots[0]
    z, x = -np.asarray(spot.normal), np.asarray(spot.direction)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])          # SPEC: z = -normal, x = direction
    T[:3, 3] = spot.xyz
    for dz, free in ((0.0, True), (-0.5e-3, True), (-2 * HELD_SUPPORT_PENETRATION_M, False)):
        Tz = T.copy()
        Tz[2, 3] += dz
        table = solve_all(robot, (invert(np.asarray(cell.T_world_base)) @ Tz)[None])
        q = table.q[0][table.valid[0]][0]
        assert world.is_free(q) is free, dz
        contact = world.first_contact(q)
        assert free or (contact is not None and "rack_low" in contact.describe())


FENCE_CELL = """
robomax: 1
name: fence
robot: {model: kr16, home: [0, -90, 90, 0, 30, 0]}
tool: gripper_2f
objects:
  - {name: table_a, box: [0.4, 0.4, 0.7], pose: {xyz: [0.9, -0.5, 0.35]}}
  - {name: table_b, box: [0.4, 0.4, 0.7], pose: {xyz: [0.9, 0.5, 0.35]}}
  - {name: fence, box: [0.6, 0.04, 0.82], pose: {xyz: [0.9, 0, 0.41]}}
process: {approach: 0.1, clearance: 0.01}
pick_place:
  parts:
    - {name: block, box: [0.1, 0.1, 0.1], mass: 2.0, grasp: {xyz: [0, 0, 0.03]}}
  locations:
    - {name: a, pose: {xyz: [0.9, -0.5, 0.75]}, support: [table_a]}
    - {name: b, pose: {xyz: [0.9, 0.5, 0.75]}, support: [table_b]}
  transfers:
    - {part: block, from: a, to: b}
"""


@pytest.mark.slow
def test_a_part_that_would_hit_the_fence_makes_the_planner_go_round(tmp_path: Path) -> None:
    """Table to table over a fence 0.82 m high: the gripper's fingertips pass 60 mm above it, the
    block hanging below them would not. With the block the carried move detours; with a 1 mm
    stand-in part it goes straight. The program rebuilds exactly and is clean in the carried
    check, which finds the block in the fence when the straight move is put back."""
    path = tmp_path / "fence.yaml"
    path.write_text(FENCE_CELL)
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot, PlanOptions())
    assert result.status == "planned", result.message
    carried = result.transitions[1]
    assert carried.part == "block" and carried.kind == "detour"
    tiny = replace(cell, parts=tuple(replace(p, shape=Sphere(0.001)) for p in cell.parts))
    straight = plan_cell(tiny, robot, PlanOptions())
    assert straight.status == "planned" and straight.transitions[1].kind == "move"
    loads = Loads.of(cell, robot)
    empty = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    a, b = straight.transitions[1].waypoints[0], straight.transitions[1].waypoints[-1]
    assert empty.check_segment(a, b).free and not loads.worlds["block"].check_segment(a, b).free
    program = parse_program(write_program(program_from_plan(result)))
    assert [i.action for i in program.instructions if isinstance(i, Gripper)] == ["grip", "release"]
    rebuilt = rebuild(program, cell, robot, "fence.srcl")
    assert rebuilt.problems == []
    np.testing.assert_array_equal(rebuilt.trajectory.q, result.trajectory.q)
    spots = _spot_entries(result)
    assert check_carried_motion(cell, robot, empty, loads.worlds, result.trajectory.t, result.trajectory.q, spots).clean
    # Every dialect states the carried lines' acceleration and reads it back.
    from robomax_py.export import DIALECTS, choose_formats
    from robomax_py.export.plan_program import planned_program
    from robomax_py.program import LinMove

    planned = planned_program(result)
    wanted = [ins.accel for ins in planned.program.instructions if isinstance(ins, LinMove)]
    assert min(wanted) < 1.0
    for dialect in (DIALECTS[name] for name in choose_formats("all", robot).names):
        texts = dialect.write(dialect.adapt(planned, robot), robot)
        main = next(name for name in texts if name.endswith(dialect.extensions[0]))
        parsed = dialect.parse(texts, main, robot)
        got = [ins.accel for ins in parsed.program.instructions if isinstance(ins, LinMove)]
        assert got == pytest.approx(wanted, abs=0.005), dialect.name
    # The straight plan's motion checked with the real block: the block is found in the fence.
    found = check_carried_motion(cell, robot, empty, loads.worlds, straight.trajectory.t, straight.trajectory.q,
                                 _spot_entries(straight))
    assert any(v.kind == "collision" and "block" in v.detail and "fence" in v.detail for v in found.violations)


@pytest.mark.slow
def test_unloaded_tcp_limits_slow_the_empty_moves(tmp_path: Path) -> None:
    """`pick_place.unloaded`: the moves without a part keep those TCP limits (here tight enough
    to slow them), the carried move the part's."""
    path = tmp_path / "fence.yaml"
    path.write_text(FENCE_CELL.replace("pick_place:\n", "pick_place:\n  unloaded: {v: 1.0, a_T: 3, a_R: 3, j_T: 30, j_R: 30}\n"))
    cell = load_cell(path)
    assert cell.tcp_limits is not None and cell.tcp_limits.a_T == 3
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot, PlanOptions())
    assert result.status == "planned", result.message
    empty_moves = [t for t in result.transitions if t.part is None]
    assert empty_moves and all(t.speed is not None and t.accel < 1.0 for t in empty_moves)
    loads = Loads.of(cell, robot)
    empty = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    assert check_carried_motion(cell, robot, empty, loads.worlds, result.trajectory.t, result.trajectory.q,
                                _spot_entries(result)).clean


def _spot_entries(result: object) -> list[dict]:
    return [{"seam": p.seam, "name": p.name, "t_arrive": p.t_arrive, "t_leave": p.t_leave}
            for p in result.spots]  # type: ignore[attr-defined]


@pytest.mark.slow
def test_carried_moves_keep_the_parts_limits_and_unloaded_timing_would_not(tmp_path: Path) -> None:
    path = _cell_file(tmp_path, [{"part": "housing", "from": "low_1", "to": "a_1"},
                                 {"part": "bracket", "from": "a_2", "to": "b_1"}])
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot, PlanOptions())
    assert result.status == "planned", result.message
    parts = [t.part for t in result.transitions]
    assert parts == [None, "housing", None, "bracket", None]
    for t in result.transitions:
        if t.part is not None:
            assert t.speed is not None and t.accel < 1.0       # slowed for the part
    traj = result.trajectory
    loads = Loads.of(cell, robot)
    empty = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots = [{"seam": p.seam, "name": p.name, "t_arrive": p.t_arrive, "t_leave": p.t_leave} for p in result.spots]
    assert check_carried_motion(cell, robot, empty, loads.worlds, traj.t, traj.q, spots).clean
    # The same cell planned as if the parts weighed nothing and had no limits breaks them.
    light = replace(cell, parts=tuple(replace(p, limits=None, mass=0.0) for p in cell.parts), tcp_limits=None)
    fast = plan_cell(light, robot, PlanOptions())
    assert fast.status == "planned" and fast.cycle_time < result.cycle_time
    fast_spots = [{"seam": p.seam, "name": p.name, "t_arrive": p.t_arrive, "t_leave": p.t_leave} for p in fast.spots]
    found = check_carried_motion(cell, robot, empty, loads.worlds, fast.trajectory.t, fast.trajectory.q, fast_spots)
    assert {v.kind for v in found.violations} & {"tcp_limit", "acceleration"}


def test_holds_run_from_the_grip_to_the_release() -> None:
    cell = load_cell(SHIPPED)
    spots = [{"seam": "transfers", "name": "t1_pick_low_1", "t_arrive": 1.0, "t_leave": 1.3},
             {"seam": "transfers", "name": "t1_place_a_1", "t_arrive": 5.0, "t_leave": 5.25},
             {"seam": "transfers", "name": "t2_pick_low_2", "t_arrive": 7.0, "t_leave": 7.3}]
    first, second = holds(cell, spots)
    assert (first.part, first.t_start, first.t_end) == ("housing", 1.0, 5.25)
    assert (second.part, second.t_start, second.t_end) == ("housing", 7.0, float("inf"))


def test_block_peaks_span_the_segments() -> None:
    from robomax_py.timing import Segment

    robot = load_cell_robot(load_cell(SHIPPED))
    t = np.linspace(0.0, 1.0, 101)
    q = np.zeros((101, 6)) + np.array([0, -np.pi / 2, np.pi / 2, 0, 0.5, 0])
    fast = q.copy()
    fast[:, 0] = 0.5 * np.sin(2 * np.pi * t)                    # a quick joint-1 swing
    zero = np.zeros_like(q)
    still = Segment(t, q, zero, zero, kind="move")
    swing = Segment(t, fast, zero, zero, kind="approach")
    assert tcp_block_peaks(robot, [still]).v[0] < 1e-9
    assert tcp_block_peaks(robot, [still, swing]).v[0] > 0.5
