"""Machine tending with time windows, compared in one run (a script, not a test):

    python tests/bench/bench_tending.py [CELL] [--variants N] [--seed S] [--cycles 1,2,4,8] [--generated DIR]

Plans the tending cell (default `cells/tending.yaml`) three ways in the same process:
- `timed`: the time-aware planner (`planner.dynamic: timed`, the default): time-windowed A* over
  the roadmap, waiting in front of a door or going round it;
- `rest`: today's way, the dynamic obstacles planned as absent, then waiting at rest before a move
  that would meet one (`planner.dynamic: rest`);
- `astar`: the classical A* of the paper (`PlanOptions(dynamic="astar")`): the time-aware
  search's graph with time ignored, then a stop at rest wherever its route meets a door at its
  time (docs/paper-001.md);
- `absent`: the dynamic obstacles ignored altogether, only to count the hazards it would run into;
  it is no program anyone should run.

For each it prints the cycle time, the CPU seconds of planning, each machine's wait for the robot
(from its door opening to the robot's arrival at its station, summed over the openings the robot
serves, and as a share of the cycle), and hazardous approaches: separate intervals of the program in
which the robot comes closer than `process.clearance` to a dynamic object while that object is
present (dense samples, 10 ms apart). With --variants N it also plans N seeded schedules of the same
cell (each machine's start, machining time and period drawn at random) both ways and prints the
cycle-time gain of `timed` over `rest` per variant (never negative by construction: the planner
keeps a time-aware move only where it finishes sooner). With --cycles it plans the cell with each
number of cycles instead, both ways, and prints how the CPU seconds grow with the job's size; with
--generated DIR it plans the seeded cells of `tests/bench/tending_cells.py` in DIR both ways.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import statistics
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, PlanResult, plan_cell
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec, MachineSpec
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]


def hazards(cell: CellSpec, robot: RobotModel, result: PlanResult) -> tuple[int, float]:
    """(intervals closer than the clearance to a present dynamic object, the least such distance m)."""
    world = CollisionWorld(robot, build_scene(replace(cell, objects=()), robot), 0.0).restricted(self_pairs=False)
    traj = result.trajectory
    assert traj is not None
    near = []
    least = np.inf
    for t, q in zip(traj.t, traj.q):
        d = world.closest(q, float(t)).distance
        least = min(least, d)
        near.append(d < cell.process.clearance)
    starts = sum(1 for i, n in enumerate(near) if n and (i == 0 or not near[i - 1]))
    return starts, float(least)


def machine_waits(cell: CellSpec, result: PlanResult) -> dict[str, float]:
    """Per machine: seconds from each door opening to the robot's arrival at the machine's station."""
    machine_of = {s.name: s.machine for seam in cell.seams for s in seam.spots}
    out = {}
    for m in cell.machines:
        arrivals = sorted(s.t_arrive for s in result.spots if machine_of.get(s.name) == m.name)
        total = 0.0
        for k, (_, opens) in enumerate(m.windows):
            closes = m.windows[k + 1][0] if k + 1 < len(m.windows) else np.inf
            served = [t for t in arrivals if opens <= t < closes]
            if served:
                total += served[0] - opens
        out[m.name] = total
    return out


def plan(cell: CellSpec, robot: RobotModel, mode: str) -> tuple[PlanResult, float]:
    t0 = time.process_time()
    if mode == "absent":
        result = plan_cell(replace(cell, dynamic=()), robot, PlanOptions())
    else:
        result = plan_cell(cell, robot, PlanOptions(dynamic=mode))
    return result, time.process_time() - t0


def variant(cell: CellSpec, rng: np.random.Generator) -> CellSpec:
    """The same cell with each machine's schedule drawn at random (period 12-20 s, machining 40-80 %)."""
    cycles = len(cell.seams[0].spots) // max(1, len({s.name.split("_", 1)[1] for s in cell.seams[0].spots}))
    machines, doors = [], {}
    for m in cell.machines:
        period = float(rng.uniform(12.0, 20.0))
        machining = float(rng.uniform(0.4, 0.8)) * period
        start = float(rng.uniform(0.0, period))
        windows = tuple((round(start + k * period, 3), round(start + k * period + machining, 3)) for k in range(cycles))
        machines.append(MachineSpec(m.name, m.door, windows))
        doors[m.door] = windows
    dynamic = tuple(replace(d, present=doors.get(d.name, d.present)) for d in cell.dynamic)
    return replace(cell, machines=tuple(machines), dynamic=dynamic)


def generated(paths: list[Path]) -> None:
    """Each generated cell planned both ways: status, cycle, CPU, and the timed plan's verdict."""
    print(f"{'cell':16s} {'robot':6s} {'visits':>6s} {'timed':>28s} {'rest':>28s}")
    both, only_timed, only_rest, gains = 0, 0, 0, []
    for path in paths:
        cell = load_cell(path)
        robot = load_cell_robot(cell)
        (timed, t_cpu), (rest, r_cpu) = plan(cell, robot, "timed"), plan(cell, robot, "rest")

        def shown(r: PlanResult, cpu: float) -> str:
            return f"{r.cycle_time:8.3f} s {cpu:5.1f} CPU" if r.status == "planned" else f"{r.status} {cpu:5.1f} CPU"

        print(f"{cell.name:16s} {cell.robot.name:6s} {len(cell.seams[0].spots):6d} {shown(timed, t_cpu):>28s} "
              f"{shown(rest, r_cpu):>28s}")
        for r in (timed, rest):
            if r.status != "planned":
                print(f"    {'timed' if r is timed else 'rest'}: {r.message[:150]}")
        ok_t, ok_r = timed.status == "planned", rest.status == "planned"
        both += ok_t and ok_r
        only_timed += ok_t and not ok_r
        only_rest += ok_r and not ok_t
        if ok_t and ok_r:
            gains.append(100 * (1 - timed.cycle_time / rest.cycle_time))
    print(f"planned by both {both}, by timed only {only_timed}, by rest only {only_rest}, of {len(paths)}")
    if gains:
        print(f"cycle gain where both planned: min {min(gains):.2f} %, median {statistics.median(gains):.2f} %, "
              f"max {max(gains):.2f} %")


def scale(path: Path, counts: list[int]) -> None:
    """CPU seconds of planning against the number of cycles (station visits grow with it), both ways."""
    import math
    import tempfile

    import yaml

    data = yaml.safe_load(path.read_text())
    rows = []
    print(f"{'cycles':>6s} {'visits':>6s} {'timed s':>8s} {'rest s':>7s} {'timed cycle':>11s} {'rest cycle':>10s}")
    with tempfile.TemporaryDirectory() as tmp:
        for n in counts:
            data["tending"]["cycles"] = n
            copy = Path(tmp) / f"tending_{n}.yaml"
            copy.write_text(yaml.safe_dump(data, sort_keys=False))
            cell = load_cell(copy)
            robot = load_cell_robot(cell)
            (timed, t_cpu), (rest, r_cpu) = plan(cell, robot, "timed"), plan(cell, robot, "rest")
            rows.append((n, t_cpu, r_cpu))
            print(f"{n:6d} {len(cell.seams[0].spots):6d} {t_cpu:8.1f} {r_cpu:7.1f} {timed.cycle_time:11.3f} "
                  f"{rest.cycle_time:10.3f}", flush=True)
    if len(rows) >= 2:
        (n0, t0, r0), (n1, t1, r1) = rows[0], rows[-1]
        print(f"growth from {n0} to {n1} cycles: timed N^{math.log(t1 / t0) / math.log(n1 / n0):.2f}, "
              f"rest N^{math.log(r1 / r0) / math.log(n1 / n0):.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0] if __doc__ else None)
    parser.add_argument("cell", nargs="?", type=Path, default=REPO / "cells" / "tending.yaml")
    parser.add_argument("--variants", type=int, default=0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--cycles", type=str, default="",
                        help="comma-separated cycle counts: plan the cell with each, both ways, and print the CPU growth")
    parser.add_argument("--generated", type=Path, default=None,
                        help="plan every cell in this folder (tests/bench/tending_cells.py) both ways")
    args = parser.parse_args()
    if args.generated is not None:
        generated(sorted(args.generated.glob("*.yaml")))
        return
    if args.cycles:
        scale(args.cell, [int(c) for c in args.cycles.split(",")])
        return
    cell = load_cell(args.cell)
    robot = load_cell_robot(cell)
    print(f"{cell.name}: {len(cell.seams[0].spots)} station visits, machines "
          + ", ".join(f"{m.name} closed {list(m.windows)}" for m in cell.machines))
    print(f"{'planner':8s} {'status':10s} {'cycle s':>8s} {'CPU s':>6s} {'hazards':>8s} {'least m':>8s}  machine waits for the robot")
    cycles = {}
    for mode in ("timed", "rest", "astar", "absent"):
        result, cpu = plan(cell, robot, mode)
        if result.status != "planned":
            print(f"{mode:8s} {result.status:10s} {result.message[:100]}")
            continue
        n, least = hazards(cell, robot, result)
        waits = machine_waits(cell, result)
        cycles[mode] = result.cycle_time
        shown = ", ".join(f"{k} {v:.2f} s ({100 * v / result.cycle_time:.1f} %)" for k, v in waits.items())
        print(f"{mode:8s} {result.status:10s} {result.cycle_time:8.3f} {cpu:6.1f} {n:8d} {least:8.3f}  {shown}")
    if "timed" in cycles and "rest" in cycles:
        print(f"timed vs rest: cycle {100 * (cycles['timed'] / cycles['rest'] - 1):+.2f} %")
    if args.variants:
        rng = np.random.default_rng(args.seed)
        gains = []
        outcomes: list[tuple[bool, bool]] = []
        print(f"\n{args.variants} seeded schedules (seed {args.seed}):")
        for i in range(args.variants):
            v = variant(cell, rng)
            (timed, _), (rest, _) = plan(v, robot, "timed"), plan(v, robot, "rest")
            if timed.status != "planned" or rest.status != "planned":
                failed = rest if rest.status != "planned" else timed
                print(f"  {i}: timed {timed.status}, rest {rest.status}: {failed.message[:100]}")
                outcomes.append((timed.status == "planned", rest.status == "planned"))
                continue
            outcomes.append((True, True))
            gain = 100 * (1 - timed.cycle_time / rest.cycle_time)
            gains.append(gain)
            print(f"  {i}: rest {rest.cycle_time:7.3f} s, timed {timed.cycle_time:7.3f} s, shorter by {gain:5.2f} %")
        print(f"planned: timed {sum(t for t, _ in outcomes)}, rest {sum(r for _, r in outcomes)} of {len(outcomes)}")
        if gains:
            print(f"gain where both planned: min {min(gains):.2f} %, median {statistics.median(gains):.2f} %, "
                  f"max {max(gains):.2f} %")


if __name__ == "__main__":
    main()
