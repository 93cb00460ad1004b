"""Junctions fly by only where the flown path checks free and is faster; the electrodes keep the axis."""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, PlanResult, plan_cell
from robomax_py.plan import junction as junction_module
from robomax_py.plan.junction import time_junction
from robomax_py.robot import JointLimits, fk_tcp
from robomax_py.spec import CellSpec, frozen_array
from robomax_py.timing import concatenate
from robomax_py.world.collision import SegmentCheck

# Distance (rad) from the polyline beyond which the strict world reports a collision.
OFF_POLYLINE_RAD = 1e-6
# TCP distance from the electrode axis allowed within the approach distance, m (the LIN path
# tolerance is 1e-5 m between samples; the dense samples here lie on the refined joint path).
ON_AXIS_TOL_M = 2e-5
# Relative slack on the TCP speed measured by finite differences of 4 ms samples.
TCP_SPEED_RTOL = 0.01
# toppra holds its limits at grid points; between them the joint speed may exceed them slightly
# (seen: 0.4 %), within the 1 % the timing tolerates.
SPEED_RTOL = 0.01

LIMITS = JointLimits(
    lower=frozen_array([-3.0] * 3), upper=frozen_array([3.0] * 3), velocity=frozen_array([1.0] * 3),
    acceleration=frozen_array([3.0] * 3), jerk=frozen_array([30.0] * 3),
)
WAYPOINTS = np.array([[0.0, 0.0, 0.0], [0.6, 0.0, 0.0], [0.6, 0.6, 0.0], [1.2, 0.6, 0.2]])


def _distance_to_polyline(p: np.ndarray) -> float:
    best = np.inf
    for a, b in itertools.pairwise(WAYPOINTS):
        d = b - a
        s = np.clip(np.dot(p - a, d) / np.dot(d, d), 0.0, 1.0)
        best = min(best, float(np.linalg.norm(p - (a + s * d))))
    return best


class _SegmentWorld:
    """A stand-in collision world judging a path segment by segment."""

    def segment_free(self, q0: np.ndarray, q1: np.ndarray) -> bool:
        raise NotImplementedError

    def check_path(self, points: np.ndarray) -> SegmentCheck:
        for k, (a, b) in enumerate(itertools.pairwise(points), start=1):
            if not self.segment_free(a, b):
                return SegmentCheck(False, k, len(points), 0, None)
        return SegmentCheck(True, max(len(points) - 1, 1), len(points), 0, None)


class StrictWorld(_SegmentWorld):
    """Free only on the waypoint polyline: any corner cut 'collides'."""

    def segment_free(self, q0: np.ndarray, q1: np.ndarray) -> bool:
        return all(_distance_to_polyline(q0 + s * (q1 - q0)) <= OFF_POLYLINE_RAD for s in np.linspace(0, 1, 5))


class OpenWorld(_SegmentWorld):
    def segment_free(self, q0: np.ndarray, q1: np.ndarray) -> bool:
        return True


def _detour(world: Any) -> Any:
    # No LIN moves in this junction, so no robot model is needed.
    return time_junction(None, world, LIMITS, WAYPOINTS[0], WAYPOINTS, "detour", "d", None, None,  # type: ignore[arg-type]
                         tcp_speed=0.5)


def _duration(junction: Any) -> float:
    return sum(s.duration for s in junction.segments)


def test_blocked_corners_fall_back_to_stopping_on_the_polyline() -> None:
    junction = _detour(StrictWorld())
    assert junction.corner_radius == 0.0 and junction.junction_radius == 0.0
    for seg in junction.segments:
        assert max(_distance_to_polyline(q) for q in seg.q) <= OFF_POLYLINE_RAD
    assert len(junction.segments) == len(WAYPOINTS) - 1          # a rest-to-rest move per leg


def test_free_corners_are_flown_and_faster() -> None:
    stop = _detour(StrictWorld())
    flown = _detour(OpenWorld())
    assert flown.corner_radius > 0.0
    assert _duration(flown) < _duration(stop)
    traj = concatenate(flown.segments)
    assert_allclose(traj.q[0], WAYPOINTS[0], atol=1e-9)
    assert_allclose(traj.q[-1], WAYPOINTS[-1], atol=1e-9)
    # Only where the corners are cut does the path leave the polyline, by less than the radius.
    assert max(_distance_to_polyline(q) for q in traj.q) <= flown.corner_radius


def test_exact_stop_bound_is_below_its_time_and_changes_no_choice(monkeypatch: pytest.MonkeyPatch) -> None:
    stop = _detour(StrictWorld())                                # the exact-stop motion itself
    bounds: list[float] = []
    real_bound = junction_module._exact_lower_bound

    def spy(*args: Any) -> float:
        bounds.append(real_bound(*args))
        return bounds[-1]

    exact_timings = []
    real_time_shape = junction_module._time_shape

    def count(shape: Any, *rest: Any) -> Any:
        exact_timings.extend([1] if all(step.flyby == 0.0 for chain in shape.chains for step in chain) else [])
        return real_time_shape(shape, *rest)

    monkeypatch.setattr(junction_module, "_exact_lower_bound", spy)
    monkeypatch.setattr(junction_module, "_time_shape", count)
    flown = _detour(OpenWorld())
    assert bounds and max(bounds) <= _duration(stop)
    assert not exact_timings                                     # the bound spared timing it
    # Without the bound the exact-stop motion is always timed: the same variant is chosen.
    monkeypatch.setattr(junction_module, "_exact_lower_bound", lambda *args: 0.0)
    forced = _detour(OpenWorld())
    assert (forced.corner_radius, forced.junction_radius) == (flown.corner_radius, flown.junction_radius)
    assert _duration(forced) == _duration(flown)


def test_a_flyby_competing_with_the_exact_stop_is_timed_only_where_its_path_is_free(
        monkeypatch: pytest.MonkeyPatch) -> None:
    # Where every cut corner collides, no fly-by variant is timed: its path is checked first.
    timed: list[float] = []
    real = junction_module._time_shape

    def spy(shape: Any, *rest: Any) -> Any:
        timed.append(max(float(np.max(p.radii, initial=0.0)) for p in shape.paths))
        return real(shape, *rest)

    monkeypatch.setattr(junction_module, "_time_shape", spy)
    stop = _detour(StrictWorld())
    assert stop.corner_radius == 0.0 and timed == [0.0]               # the exact-stop motion alone
    timed.clear()
    flown = _detour(OpenWorld())
    assert flown.corner_radius > 0.0 and timed and max(timed) > 0.0


def test_exact_stop_bound_changes_no_plan(monkeypatch: pytest.MonkeyPatch, small_plan: Any) -> None:
    cell, robot, result = small_plan
    monkeypatch.setattr(junction_module, "_exact_lower_bound", lambda *args: 0.0)
    forced = plan_cell(cell, robot, PlanOptions())
    assert forced.trajectory is not None and result.trajectory is not None
    assert np.array_equal(forced.trajectory.t, result.trajectory.t)
    assert np.array_equal(forced.trajectory.q, result.trajectory.q)


@pytest.fixture(scope="module")
def small_plan(tmp_path_factory: pytest.TempPathFactory, write_small_cell: Any) -> tuple[CellSpec, Any, PlanResult]:
    path: Path = write_small_cell(tmp_path_factory.mktemp("junction"))
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    return cell, robot, plan_cell(cell, robot, PlanOptions())


def test_approach_points_are_flown_by_and_the_electrodes_keep_the_axis(small_plan: Any) -> None:
    """Junctions fly by where it is faster, and within the approach distance of every spot the TCP
    is on the electrode axis: a fly-by continues the line beyond the approach point."""
    cell, robot, result = small_plan
    assert result.status == "planned", result.message
    traj = result.trajectory
    flown = [t for t in result.transitions if t.flyby_radius > 0]
    assert flown, [t.flyby_radius for t in result.transitions]
    assert all(t.retract_T is not None or t.approach_q is not None for t in flown)
    approach = cell.process.approach
    for spot in result.spots:
        axis = spot.T_spot[:3, 2]                 # the electrode axis: TCP z
        p = fk_tcp(robot, traj.q)[:, :3, 3]
        rel = p - spot.T_spot[:3, 3]
        along = rel @ axis                        # distance along the axis, away from the sheet
        off = np.linalg.norm(rel - along[:, None] * axis, axis=1)
        near = np.linalg.norm(rel, axis=1) <= approach
        assert np.any(near & (along > 0.5 * approach))
        assert float(np.max(off[near])) <= ON_AXIS_TOL_M
        assert float(np.min(along[near])) >= -ON_AXIS_TOL_M
        # At rest on the spot for the weld.
        weld = (traj.t >= spot.t_arrive) & (traj.t <= spot.t_leave)
        assert float(np.max(np.linalg.norm(rel[weld], axis=1))) <= 1e-4
        assert float(np.max(np.abs(traj.qd[weld]))) == 0.0
    for t in flown:                               # flown by: the robot does not stop at the joins
        phase = traj.phases_of(t.kind, t.label)[0]
        inside = (traj.t > phase.t_start) & (traj.t < phase.t_end)
        assert np.all(np.linalg.norm(traj.qd[inside], axis=1) > 0)


def test_tcp_speed_holds_on_lines_and_their_joins(small_plan: Any) -> None:
    _cell, robot, result = small_plan
    traj = result.trajectory
    p = fk_tcp(robot, traj.q)[:, :3, 3]
    v = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(traj.t)
    limit = result.options.tcp_speed * (1 + TCP_SPEED_RTOL)
    for kind in ("approach", "retract"):
        for phase in traj.phases_of(kind):
            k = np.arange(phase.i_start, phase.i_end)
            assert float(np.max(v[k])) <= limit, f"{kind} {phase.label}: TCP at {np.max(v[k]):.3f} m/s"


def test_without_flyby_every_junction_stops() -> None:
    from robomax_py.plan.junction import split_chains
    from robomax_py.timing.chain import LinStep, PtpStep

    steps = [LinStep(np.eye(4), 0.5, flyby=0.02), PtpStep(np.zeros(3), flyby=0.0), PtpStep(np.ones(3), flyby=0.1),
             LinStep(np.eye(4), 0.5)]
    assert [len(c) for c in split_chains(steps)] == [2, 2]


def test_per_move_speeds_are_planned_written_and_rebuilt(tmp_path: Path, write_small_cell: Any, small_plan: Any) -> None:
    import yaml

    from robomax_py.export.plan_program import program_from_plan
    from robomax_py.export.rebuild import rebuild
    from robomax_py.export.srcl import parse_program, write_program
    from robomax_py.program import LinMove, PtpMove

    path: Path = write_small_cell(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["planner"] = {"seed": 0, "speed": 0.5, "detour_speed": 0.5, "tcp_speed": 0.25}
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    slow = plan_cell(cell, robot, PlanOptions())
    assert slow.status == "planned", slow.message
    assert slow.cycle_time > small_plan[2].cycle_time
    program = parse_program(write_program(program_from_plan(slow)))
    ptp = [i for i in program.instructions if isinstance(i, PtpMove)]
    assert {i.speed for i in ptp if "detour point" in i.comment} == {0.25}
    assert {i.speed for i in ptp[1:] if "detour point" not in i.comment and "->" in i.comment} == {0.5}
    assert {i.speed_mm_s for i in program.instructions if isinstance(i, LinMove)} == {125.0}
    # Joint speeds within the stated fractions (chains move at their slowest PTP's speed).
    traj = slow.trajectory
    vmax = robot.limits.velocity
    for kind, fraction in (("move", 0.5), ("detour", 0.25)):
        for phase in traj.phases_of(kind):
            qd = np.abs(traj.qd[phase.i_start:phase.i_end + 1])
            assert np.all(qd <= fraction * vmax * (1 + SPEED_RTOL)), f"{kind} {phase.label}"
    rebuilt = rebuild(program, cell, robot, "slow.srcl")
    assert rebuilt.problems == []
    np.testing.assert_array_equal(rebuilt.trajectory.q, traj.q)
