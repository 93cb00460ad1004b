"""`robomax bench`: the speed of this machine on the figures that matter, in one table.

IK poses/s and collision checks/s of the cell's robot (CPU seconds of this process, one thread,
median of several runs, so other load on the machine distorts them little); the cell's planning
time (wall and CPU, median); and its cycle time against the published baseline and a straight-move
lower bound, all measured in the same run.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robomax_py.plan import PlanOptions, PlanResult, plan_cell
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
    """Weld times + per rest-to-rest move the slowest joint's trapezoid time (velocity, acceleration).

    The robot is at rest at home and at every spot (welding); between two such rests no motion under
    the same joint limits is faster than the slowest joint's time-optimal trapezoid, whatever the
    path (approach lines, detours and fly-by only add to it). So this bounds every program that welds
    the chosen configurations in the chosen order.
    """
    if result.trajectory is None or result.home is None:
        raise ValueError("lower_bound needs a planned result")
    rests = np.array([result.home, *[s.q_spot for s in result.spots], result.home])
    moves = float(np.sum(ptp_time_estimate(rests[:-1], rests[1:], limits, straight=False)))
    return moves + sum(s.weld_time for s in result.spots)


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
    on_step(f"baseline {cell.name}")
    base = plan_cell(cell, robot, PlanOptions(baseline=True))
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
    if base.status == "planned":
        rows.append(BenchRow("cycle time, published baseline", base.cycle_time, "s",
                             f"optimised is {1 - cycle / base.cycle_time:.1%} shorter"))
    else:
        rows.append(BenchRow("cycle time, published baseline", float("nan"), "s", f"infeasible: {base.message}"))
    rows.append(BenchRow("straight-move lower bound", bound, "s", f"optimised / bound = {cycle / bound:.3f}"))
    return rows
