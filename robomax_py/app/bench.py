"""`robomax bench`: the speed of this machine on the figures that matter, in one table.

IK poses/s and collision checks/s of the cell's robot (CPU seconds of this process, one thread,
median of several runs, so other load on the machine distorts them little); the cell's planning
time (wall and CPU, median); and its cycle time against both baselines (the published method and
teach-in) and a lower bound (`lower_bound`), all measured in the same run.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robomax_py.plan import PlanOptions, PlanResult, method_options, plan_cell
from robomax_py.program import written_tcp_speed
from robomax_py.robot import JointLimits, RobotModel, fk_tcp
from robomax_py.robot.solve import solve_all
from robomax_py.spec import CellSpec
from robomax_py.timing import ptp_time_estimate
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene


@dataclass(frozen=True, slots=True)
class BenchRow:
    name: str
    value: float
    unit: str
    note: str = ""


def median_cpu_seconds(fn: Callable[[], object], runs: int) -> float:
    """Median CPU seconds of `runs` calls of fn, after one warm-up call."""
    fn()
    times = []
    for _ in range(runs):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return max(statistics.median(times), 1e-9)


def ik_rate(robot: RobotModel, n: int, runs: int, rng: np.random.Generator, expand_turns: bool = True) -> float:
    """Poses/s of `solve_all` (every branch, turn variants if asked) on FK poses of random configurations."""
    qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(n, robot.dof))
    T = fk_tcp(robot, qs)
    return n / median_cpu_seconds(lambda: solve_all(robot, T, expand_turns=expand_turns), runs)


def collision_rate(world: CollisionWorld, robot: RobotModel, n: int, runs: int, rng: np.random.Generator) -> float:
    """Configuration checks/s of `are_free` on random configurations within the limits."""
    qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(n, robot.dof))
    return n / median_cpu_seconds(lambda: world.are_free(qs), runs)


def lower_bound(result: PlanResult, limits: JointLimits) -> float:
    """A time no program welding the result's configurations in its order can beat (s).

    The robot rests at home and at every spot (welding). Per leg between two rests, the larger of:

    - the slowest joint's time-optimal trapezoid from rest to rest (velocity and acceleration),
      whatever the path;
    - the process's mandated lines at their speed limit plus the move between them: the half of
      the retract line next to the sheet and the half of the next approach line (a fly-by may cut
      the far halves, never these; the TCP keeps at most the line speed on them), and between
      their ends, the approach points, the slowest joint at its velocity limit (no rest assumed
      there).

    Plus the weld times. The second term makes the bound fair to a process whose approach and
    retract lines take much of the cycle: the rest-to-rest term alone counts them at joint speed.
    """
    if result.trajectory is None or result.home is None:
        raise ValueError("lower_bound needs a planned result")
    home = np.asarray(result.home, dtype=float)
    rests = np.array([home, *[s.q_spot for s in result.spots], home])
    points = np.array([home, *[s.q_app for s in result.spots], home])
    line_speed = written_tcp_speed(float(result.options.tcp_speed or 0.0) * float(result.options.speed or 1.0))
    half_lines = np.array([0.0, *[0.5 * float(np.linalg.norm(s.T_app[:3, 3] - s.T_spot[:3, 3]))
                                  for s in result.spots], 0.0])
    line_s = half_lines / line_speed if line_speed > 0 else np.zeros_like(half_lines)
    rest_to_rest = ptp_time_estimate(rests[:-1], rests[1:], limits, straight=False)
    between = np.max(np.abs(points[1:] - points[:-1]) / np.asarray(limits.velocity, dtype=float), axis=-1)
    legs = np.maximum(rest_to_rest, line_s[:-1] + between + line_s[1:])
    return float(np.sum(legs)) + sum(s.weld_time for s in result.spots)


def run_bench(
    cell: CellSpec, robot: RobotModel, runs: int = 3, quick: bool = False,
    on_step: Callable[[str], None] = lambda step: None,
) -> list[BenchRow]:
    """Every figure of the table, measured now."""
    rng = np.random.default_rng(0)
    n = 2_000 if quick else 10_000
    on_step("IK")
    ik = ik_rate(robot, n, max(runs, 3), rng)
    ik_wrapped = ik_rate(robot, n, max(runs, 3), rng, expand_turns=False)
    on_step("collision checks")
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    checks = collision_rate(world, robot, n, max(runs, 3), rng)
    walls, cpus = [], []
    result: PlanResult | None = None
    for k in range(runs):
        on_step(f"planning {cell.name} ({k + 1}/{runs})")
        w0, c0 = time.perf_counter(), time.process_time()
        result = plan_cell(cell, robot, PlanOptions())
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
        if result.status != "planned":
            raise RuntimeError(f"{cell.name} did not plan: {result.message}")
    assert result is not None
    baselines = {}
    for method in ("published", "teach-in"):
        on_step(f"{method} baseline {cell.name}")
        baselines[method] = plan_cell(cell, robot, method_options(method))
    bound = lower_bound(result, robot.limits)
    cycle = result.cycle_time
    rows = [
        BenchRow(f"IK ({robot.name}, {robot.ik_solver}, all branches), batched", ik_wrapped, "poses/s", "CPU, median"),
        BenchRow(f"IK ({robot.name}, all branches x turn variants)", ik, "poses/s", "CPU, median"),
        BenchRow(f"collision checks ({cell.name})", checks, "configs/s", "CPU, median"),
        BenchRow(f"planning {cell.name}, wall", statistics.median(walls), "s", f"median of {runs}"),
        BenchRow(f"planning {cell.name}, CPU", statistics.median(cpus), "s", f"median of {runs}"),
        BenchRow("cycle time, optimised", cycle, "s"),
    ]
    for method, base in baselines.items():
        label = f"cycle time, {method} baseline"
        if base.status == "planned":
            rows.append(BenchRow(label, base.cycle_time, "s", f"optimised is {1 - cycle / base.cycle_time:.1%} shorter"))
        else:
            rows.append(BenchRow(label, float("nan"), "s", f"infeasible: {base.message}"))
    rows.append(BenchRow("lower bound (rests, lines)", bound, "s", f"optimised / bound = {cycle / bound:.3f}"))
    return rows
