"""plan_cell end to end on small cells: detours around clamps, seam order, failure reasons, the SPEC §5
trajectory contract, determinism, and (slow) optimised vs baseline on the reference cell.

The small cells are cut from the reference cell's geometry (kr125 + spot_gun_c, the cabin panel on its
table, clamp1) with a 3x3 alpha/beta grid at gamma = 0, so each plan takes one or two seconds.
"""

from __future__ import annotations

import itertools
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from numpy.testing import assert_allclose

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, PlanResult, plan_cell, verify_trajectory
from robomax_py.plan.poses import orientation_grid, spot_poses
from robomax_py.robot import fk_tcp, reach
from robomax_py.robot.solve import solve_all
from robomax_py.spec import CellSpec
from robomax_py.timing import ptp_time_estimate
from robomax_py.transforms import invert
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
# Frozen copy of the reference cell (cells/cabin_flange.yaml is now our own cabin-panel cell).
REFERENCE_CELL = REPO / "tests" / "data" / "flange_cell" / "cabin_flange.yaml"
PANEL_STL = REPO / "tests" / "data" / "flange_cell" / "parts" / "cabin_panel.stl"

SAMPLE_STEP_S = 0.010          # SPEC §5: samples at most 10 ms apart
TIME_TOL_S = 1e-9
JOINT_TOL_RAD = 1e-9
SPOT_POS_TOL_M = 1e-4          # SPEC §5: TCP at the spot within 0.1 mm while welding
ZERO_SPEED_TOL_RAD_S = 1e-9    # "at zero speed" while welding
VELOCITY_SLACK = 0.01          # finite-difference joint speeds may exceed the limit by 1 %
COST_TOL_S = 1e-9

# Reference-cell geometry (tests/data/flange_cell/cabin_flange.yaml), copied so that editing the reference cell does not
# silently change these tests.
OBJECTS: dict[str, dict[str, Any]] = {
    "table": {"name": "table", "box": [0.8, 2, 0.62], "pose": {"xyz": [1.85, 0, 0.31]}},
    "fixture_plate": {"name": "fixture_plate", "box": [0.5, 1.6, 0.18], "pose": {"xyz": [1.8, 0, 0.71]}},
    "cabin_panel": {"name": "cabin_panel", "mesh": "parts/cabin_panel.stl", "workpiece": True},
    "clamp1_jaw": {"name": "clamp1_jaw", "box": [0.05, 0.11, 0.07],
                   "pose": {"xyz": [1.337, -0.2695, 0.9063], "rpy": [0, 0, 82.333]}},
    "clamp1_arm": {"name": "clamp1_arm", "box": [0.04, 0.54, 0.04],
                   "pose": {"xyz": [1.6491, -0.3115, 0.9233], "rpy": [0, 0, 82.333]}},
    "clamp1_post": {"name": "clamp1_post", "box": [0.05, 0.06, 0.1433],
                    "pose": {"xyz": [1.887, -0.3435, 0.8716], "rpy": [0, 0, 82.333]}},
}
PANEL_ON_TABLE = ("table", "fixture_plate", "cabin_panel")
CLAMP1 = ("clamp1_jaw", "clamp1_arm", "clamp1_post")
SPOTS: dict[str, dict[str, Any]] = {
    "s5": {"name": "s5", "xyz": [1.31475, -0.36715, 0.86056], "normal": [-0.983207, 0.182493, 0],
           "direction": [0.182246, 0.981877, 0.051994]},
    "s6": {"name": "s6", "xyz": [1.34136, -0.16944, 0.87103], "normal": [-0.996457, 0.084101, 0],
           "direction": [0.083984, 0.995075, 0.052654]},
    "s7": {"name": "s7", "xyz": [1.34672, -0.08479, 0.87551], "normal": [-0.999114, 0.042075, 0],
           "direction": [0.042016, 0.997721, 0.05279]},
    "s8": {"name": "s8", "xyz": [1.3485, 0, 0.88], "normal": [-1, 0, 0], "direction": [0, 0.998603, 0.052836]},
    "s10": {"name": "s10", "xyz": [1.34136, 0.16944, 0.88897], "normal": [-0.996457, -0.084101, 0],
            "direction": [-0.083984, 0.995075, 0.052654]},
}
# 4 m from the base, far beyond the kr125's ~2.6 m flange reach.
FAR_SPOT = {"name": "far", "xyz": [4.0, 0, 1.0], "normal": [-1, 0, 0], "direction": [0, 1, 0]}
# On the table top under the panel, its normal pointing down into the table: the moving electrode's side
# (and so the gun body) would have to be inside the table.
INTO_TABLE_SPOT = {"name": "into_table", "xyz": [1.5, 0, 0.62], "normal": [0, 0, -1], "direction": [0, 1, 0]}


def write_cell(
    directory: Path, spots: list[dict[str, Any]], objects: tuple[str, ...], *, ordered: bool = True
) -> Path:
    """A one-seam cell file (SPEC §3) in `directory`, the panel mesh copied beside it when used."""
    directory.mkdir(parents=True, exist_ok=True)
    if "cabin_panel" in objects:
        (directory / "parts").mkdir(exist_ok=True)
        shutil.copy(PANEL_STL, directory / "parts" / PANEL_STL.name)
    cell = {
        "robomax": 1,
        "name": "small",
        "robot": {"model": "kr125", "base": {"xyz": [0, 0, 0]}, "home": [0, -90, 90, 0, 0, 0]},
        "tool": "spot_gun_c",
        "objects": [OBJECTS[name] for name in objects],
        "seams": [{
            "name": "seam",
            "ordered": ordered,
            "tolerance": {"alpha": 10, "beta": 10, "gamma": [0, 0]},
            "grid": 3,
            "spots": spots,
        }],
        "process": {"weld_time": 0.5, "approach": 0.03, "clearance": 0},
        "planner": {"seed": 0},
    }
    path = directory / "cell.yaml"
    path.write_text(yaml.safe_dump(cell, sort_keys=False))
    return path


def plan_file(path: Path, options: PlanOptions = PlanOptions()) -> tuple[CellSpec, Any, PlanResult]:
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    return cell, robot, plan_cell(cell, robot, options)


def world_of(cell: CellSpec, robot: Any) -> CollisionWorld:
    return CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)


def estimated_cycle_time(cell: CellSpec, robot: Any, result: PlanResult) -> float:
    """The planner's own estimate of a planned tour (rest-to-rest PTP times along every transition's
    polyline, plus LIN approach/retract estimated as PTP, plus the dwells)."""
    lim = robot.limits
    total = sum(float(np.sum(ptp_time_estimate(t.waypoints[:-1], t.waypoints[1:], lim))) for t in result.transitions)
    total += sum(2 * float(ptp_time_estimate(s.q_app, s.q_spot, lim)) + cell.process.weld_time for s in result.spots)
    return total


@pytest.fixture(scope="module")
def clamp_plan(tmp_path_factory: pytest.TempPathFactory) -> tuple[CellSpec, Any, PlanResult]:
    """s5 and s6, ordered, with clamp1 standing on the flange between them."""
    path = write_cell(tmp_path_factory.mktemp("clamp"), [SPOTS["s5"], SPOTS["s6"]], PANEL_ON_TABLE + CLAMP1)
    return plan_file(path)


# ---------------------------------------------------------------------------------------------- 1


def test_clamp_between_spots_gives_a_collision_free_detour(clamp_plan: tuple[CellSpec, Any, PlanResult]) -> None:
    cell, robot, result = clamp_plan
    assert result.status == "planned", result.message
    assert [s.name for s in result.spots] == ["s5", "s6"]
    between = [t for t in result.transitions if t.label == "s5 -> s6"]
    assert len(between) == 1
    detour = between[0]
    assert detour.kind == "detour"
    assert len(detour.waypoints) >= 3
    # The detour starts and ends at the two spots' approach configurations.
    assert_allclose(detour.waypoints[0], result.spots[0].q_app, atol=JOINT_TOL_RAD)
    assert_allclose(detour.waypoints[-1], result.spots[1].q_app, atol=JOINT_TOL_RAD)

    world = world_of(cell, robot)
    # The premise: the straight joint move between those two configurations hits clamp1.
    q0, q1 = detour.waypoints[0], detour.waypoints[-1]
    straight = world.check_segment(q0, q1)
    assert not straight.free
    assert straight.s_contact is not None
    contact = world.first_contact(q0 + straight.s_contact * (q1 - q0))
    assert contact is not None and "clamp1" in contact.describe()
    # Every leg of every detour is free.
    for trans in result.transitions:
        if trans.kind != "detour":
            continue
        for p0, p1 in zip(trans.waypoints[:-1], trans.waypoints[1:]):
            assert world.check_segment(p0, p1).free, f"{trans.label}: blocked leg {p0} -> {p1}"
    assert result.trajectory is not None
    assert verify_trajectory(world, robot, result.trajectory).clean


# ---------------------------------------------------------------------------------------------- 2


ZIGZAG = ["s8", "s6", "s10", "s7"]


def test_ordered_seam_keeps_its_order_and_unordered_may_reorder(tmp_path: Path) -> None:
    spots = [SPOTS[name] for name in ZIGZAG]
    cell_o, robot_o, ordered = plan_file(write_cell(tmp_path / "ordered", spots, PANEL_ON_TABLE, ordered=True))
    cell_f, robot_f, free = plan_file(write_cell(tmp_path / "free", spots, PANEL_ON_TABLE, ordered=False))
    assert ordered.status == "planned", ordered.message
    assert free.status == "planned", free.message

    assert [s.name for s in ordered.spots] == ZIGZAG
    arrive = [s.t_arrive for s in ordered.spots]
    assert all(b > a for a, b in itertools.pairwise(arrive)), "spots are not listed in weld order"

    free_order = [s.name for s in free.spots]
    assert sorted(free_order) == sorted(ZIGZAG)
    # The given order zigzags along the flange; a planner free to reorder should not keep it.
    assert free_order != ZIGZAG
    assert estimated_cycle_time(cell_f, robot_f, free) <= estimated_cycle_time(cell_o, robot_o, ordered) + COST_TOL_S


def test_given_order_keeps_the_file_order_and_chooses_among_every_candidate(tmp_path: Path) -> None:
    """The published method (given order, the DP over every orientation sample and branch) between
    the teach-in baseline (nominal orientation, first branch) and the order search."""
    path = write_cell(tmp_path / "free", [SPOTS[name] for name in ZIGZAG], PANEL_ON_TABLE, ordered=False)
    cell, robot, optimised = plan_file(path)
    _, _, published = plan_file(path, PlanOptions(given_order=True))
    _, _, teach_in = plan_file(path, PlanOptions(baseline=True))
    for result in (optimised, published, teach_in):
        assert result.status == "planned", result.message
    assert [s.name for s in published.spots] == [s.name for s in teach_in.spots] == ZIGZAG
    assert (published.method, teach_in.method, optimised.method) == ("published", "teach-in", "optimised")
    # Same order, a superset of the candidates: the DP's estimate is no worse.
    estimate = [estimated_cycle_time(cell, robot, r) for r in (optimised, published, teach_in)]
    assert estimate[0] <= estimate[1] + COST_TOL_S and estimate[1] <= estimate[2] + COST_TOL_S
    # The optimiser weighs the file's order as the published method plans it and keeps the shorter.
    assert optimised.cycle_time <= published.cycle_time + 1e-9
    assert optimised.order is not None and published.order is None and teach_in.order is None
    assert optimised.order.kept in ("searched", "given") and optimised.order.describe().startswith("searched (")


# ---------------------------------------------------------------------------------------------- 3


def test_spot_out_of_reach_is_reported_unreachable(tmp_path: Path) -> None:
    path = write_cell(tmp_path, [SPOTS["s7"], FAR_SPOT, SPOTS["s8"]], PANEL_ON_TABLE)
    _cell, robot, result = plan_file(path)
    # Independent of the IK: the spot lies beyond the TCP's reach from the axis-1 line
    # (sampled flange reach + tool offset, with 0.5 m to spare for the sampling).
    tool_offset = float(np.linalg.norm(np.asarray(robot.T_flange_tcp)[:3, 3]))
    assert np.hypot(*FAR_SPOT["xyz"][:2]) > reach(robot) + tool_offset + 0.5

    assert result.status == "infeasible"
    assert result.trajectory is None
    assert [(f.seam, f.name, f.reason) for f in result.failures] == [("seam", "far", "unreachable")]
    assert "far" in result.message


def test_spot_whose_every_orientation_collides_is_reported_collision(tmp_path: Path) -> None:
    path = write_cell(tmp_path, [SPOTS["s7"], INTO_TABLE_SPOT, SPOTS["s8"]], PANEL_ON_TABLE)
    cell, robot, result = plan_file(path)

    # Independent check of the premise: the spot is reachable within the joint limits at some grid
    # orientation, and every such configuration collides.
    seam = cell.seams[0]
    T_base_tcp = invert(np.asarray(cell.T_world_base)) @ spot_poses((seam.spots[1],), orientation_grid(seam))[0]
    table = solve_all(robot, T_base_tcp)
    qs = table.q[table.valid]
    assert len(qs) > 0
    world = world_of(cell, robot)
    assert not any(world.is_free(q) for q in qs)

    assert result.status == "infeasible"
    assert [(f.seam, f.name, f.reason) for f in result.failures] == [("seam", "into_table", "collision")]


# ---------------------------------------------------------------------------------------------- 4


def test_trajectory_meets_spec_section_5(clamp_plan: tuple[CellSpec, Any, PlanResult]) -> None:
    cell, robot, result = clamp_plan
    assert result.status == "planned", result.message
    traj = result.trajectory
    assert traj is not None
    t, q, qd = np.asarray(traj.t), np.asarray(traj.q), np.asarray(traj.qd)
    dt = np.diff(t)
    assert (dt > 0).all()
    assert dt.max() <= SAMPLE_STEP_S + TIME_TOL_S
    assert_allclose(q[0], cell.home, atol=JOINT_TOL_RAD)
    assert_allclose(q[-1], cell.home, atol=JOINT_TOL_RAD)
    assert abs(result.cycle_time - (t[-1] - t[0])) <= TIME_TOL_S

    lim = robot.limits
    assert lim.contains(q, JOINT_TOL_RAD).all()
    speed = np.abs(np.diff(q, axis=0)) / dt[:, None]
    assert (speed <= lim.velocity * (1 + VELOCITY_SLACK)).all(), f"worst ratio {(speed / lim.velocity).max():.4f}"

    T_base_world = invert(np.asarray(cell.T_world_base))
    spots = {s.name: s for s in cell.seams[0].spots}
    assert [s.name for s in result.spots] == ["s5", "s6"]
    for plan in result.spots:
        assert abs((plan.t_leave - plan.t_arrive) - cell.process.weld_time) <= TIME_TOL_S
        during = (t >= plan.t_arrive - TIME_TOL_S) & (t <= plan.t_leave + TIME_TOL_S)
        assert during.sum() >= 2
        want = (T_base_world @ np.append(spots[plan.name].xyz, 1.0))[:3]
        got = fk_tcp(robot, q[during])[:, :3, 3]
        assert_allclose(got, np.broadcast_to(want, got.shape), atol=SPOT_POS_TOL_M)
        assert_allclose(qd[during], 0.0, atol=ZERO_SPEED_TOL_RAD_S)
        idx = np.flatnonzero(during)
        fd_speed = np.abs(np.diff(q[idx], axis=0)) / np.diff(t[idx])[:, None]
        assert_allclose(fd_speed, 0.0, atol=ZERO_SPEED_TOL_RAD_S)


# ---------------------------------------------------------------------------------------------- 5


def test_planning_twice_gives_identical_results(clamp_plan: tuple[CellSpec, Any, PlanResult]) -> None:
    cell, _robot, first = clamp_plan
    second = plan_cell(load_cell(cell.source), load_cell_robot(cell))
    assert first.status == second.status == "planned"
    assert [s.name for s in first.spots] == [s.name for s in second.spots]
    for a, b in zip(first.spots, second.spots):
        assert np.array_equal(a.angles, b.angles)
        assert a.config == b.config
        assert np.array_equal(a.q_spot, b.q_spot)
        assert np.array_equal(a.q_app, b.q_app)
        assert np.array_equal([a.t_arrive, a.t_leave], [b.t_arrive, b.t_leave])   # bit-identical, by design
    assert [(t.kind, t.label) for t in first.transitions] == [(t.kind, t.label) for t in second.transitions]
    for a, b in zip(first.transitions, second.transitions):
        assert np.array_equal(a.waypoints, b.waypoints)
    assert first.trajectory is not None and second.trajectory is not None
    for name in ("t", "q", "qd", "qdd"):
        assert np.array_equal(getattr(first.trajectory, name), getattr(second.trajectory, name)), name


# ---------------------------------------------------------------------------------------------- 6


@pytest.mark.slow
def test_optimiser_beats_baseline_on_reference_cell() -> None:
    cell = load_cell(REFERENCE_CELL)
    robot = load_cell_robot(cell)
    optimised = plan_cell(cell, robot)
    baseline = plan_cell(cell, robot, PlanOptions(baseline=True))
    assert optimised.status == "planned", optimised.message
    assert baseline.status == "planned", baseline.message
    assert baseline.baseline and not optimised.baseline
    assert optimised.cycle_time < baseline.cycle_time


def _failing_checks(monkeypatch: pytest.MonkeyPatch, failures: int) -> list[bool]:
    """verify_trajectory made to report a collision at the motion's second sample for its first
    `failures` calls (as if a blend grazed an object); the real verdicts of every call, in order."""
    from robomax_py.plan import checked_tour

    real = checked_tour.verify_trajectory
    seen: list[bool] = []

    def check(world: Any, robot: Any, traj: Any, *args: Any, **kwargs: Any) -> Any:
        got = real(world, robot, traj, *args, **kwargs)
        seen.append(got.clean)
        if len(seen) <= failures:
            return type(got)((_violation(traj),), got.checks)
        return got

    monkeypatch.setattr(checked_tour, "verify_trajectory", check)
    return seen


def test_a_blended_junction_that_fails_its_check_is_timed_again_stopping_at_its_corners(
    tmp_path: Path, write_small_cell: Any, monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Two generated cells (a KR 120 frame and flange) failed with 'the timed program failed its own
    check: collision: tool_body vs part' at a fly-by blend, though the same tour timed without
    blends is free. Only the junction the violation falls in (the first: home to the first
    approach point) is timed again without fly-by; the others keep theirs."""
    from robomax_py.plan import tour_timing

    cell = load_cell(write_small_cell(tmp_path, "small"))
    robot = load_cell_robot(cell)
    blended = plan_cell(cell, robot, PlanOptions())
    seen = _failing_checks(monkeypatch, 1)
    timed_after: list[int] = []               # per junction timed: the checks made before it
    real_time_junction = tour_timing.time_junction

    def counted(*args: Any, **kwargs: Any) -> Any:
        timed_after.append(len(seen))
        return real_time_junction(*args, **kwargs)

    monkeypatch.setattr(tour_timing, "time_junction", counted)
    result = plan_cell(cell, robot, PlanOptions())
    assert result.status == "planned", result.message
    assert len(seen) == 2 and result.options.blend is True
    # The re-timing between the two checks times the changed junction alone; the others are kept.
    assert timed_after.count(0) >= len(result.transitions) and timed_after.count(1) == 1
    first, *rest = result.transitions
    assert first.flyby_radius == 0.0 and first.blend_radius == 0.0
    assert [(t.flyby_radius, t.blend_radius) for t in rest] == [(t.flyby_radius, t.blend_radius)
                                                                for t in blended.transitions[1:]]
    assert any(t.flyby_radius > 0.0 for t in rest), "no fly-by left to keep: the test shows nothing"
    assert verify_trajectory(world_of(cell, robot), robot, result.trajectory).clean  # type: ignore[arg-type]


def test_a_tour_whose_junctions_keep_failing_is_timed_without_blends(
    tmp_path: Path, write_small_cell: Any, monkeypatch: pytest.MonkeyPatch,
) -> None:
    """When the junctions stopped at their corners still fail (here: every retiming's check made
    to fail), the whole tour is timed without blends, the straight moves the sequencer proved free."""
    from robomax_py.plan.checked_tour import EXACT_JUNCTION_ROUNDS

    cell = load_cell(write_small_cell(tmp_path, "small"))
    robot = load_cell_robot(cell)
    seen = _failing_checks(monkeypatch, 1 + EXACT_JUNCTION_ROUNDS)
    result = plan_cell(cell, robot, PlanOptions())
    assert result.status == "planned", result.message
    assert len(seen) == 2 + EXACT_JUNCTION_ROUNDS and result.options.blend is False
    assert all(t.flyby_radius == 0.0 and t.blend_radius == 0.0 for t in result.transitions)
    assert verify_trajectory(world_of(cell, robot), robot, result.trajectory).clean  # type: ignore[arg-type]


def _violation(traj: Any) -> Any:
    from robomax_py.world.motion import Violation

    return Violation(float(traj.t[1]), "collision", "tool_body vs part (made up)")
