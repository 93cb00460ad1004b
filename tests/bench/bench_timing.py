"""Timing benchmark on the reference cell (a script, not a test).

    python tests/bench/bench_timing.py [CELL] [--runs 3]

The same planned tour timed three ways: (a) toppra, velocity and acceleration limits only, stopping
at every waypoint; (b) jerk-limited (ruckig) moves, stopping at detour waypoints; (c) (b) with detour
corners blended where the blended path checks free. Reports medians of the cycle time, the time
spent timing, and the ratio of the cycle time to a straight-move lower bound (`robomax_py.app.bench.
lower_bound`): the weld times plus, for every rest-to-rest move (home -> spot -> spot ... -> home),
the slowest joint's time-optimal trapezoid time (velocity and acceleration limits).
"""

from __future__ import annotations

import argparse
import os
import statistics
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from robomax_py.app.bench import lower_bound
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"
VARIANTS = {
    "(a) toppra vel/acc": PlanOptions(jerk_limited=False, blend=False),
    "(b) jerk-limited": PlanOptions(jerk_limited=True, blend=False),
    "(c) jerk-limited + blending": PlanOptions(jerk_limited=True, blend=True),
}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("cell", nargs="?", default=str(REFERENCE_CELL))
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    cell = load_cell(args.cell)
    robot = load_cell_robot(cell)
    print(f"cell {cell.name}: {args.runs} runs, medians (timing stage: wall seconds)")
    print(f"{'variant':32s} {'cycle s':>9s} {'timing s':>9s} {'/ bound':>8s}")
    bound = None
    for name, options in VARIANTS.items():
        cycles, seconds = [], []
        for _ in range(args.runs):
            result = plan_cell(cell, robot, options)
            assert result.status == "planned", result.message
            assert result.stats is not None
            cycles.append(result.cycle_time)
            seconds.append(result.stats.seconds["timing"])
            bound = bound or lower_bound(result, robot.limits)
        c = statistics.median(cycles)
        print(f"{name:32s} {c:9.3f} {statistics.median(seconds):9.3f} {c / bound:8.3f}")
    print(f"{'straight-move lower bound':32s} {bound:9.3f}")


if __name__ == "__main__":
    main()
