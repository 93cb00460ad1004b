"""The experiment of Kholopov, Makarov and Kladov (time-constrained trajectories in a robotised
cell: a 6-axis arm, two CNC machines with doors, a conveyor) on the shipped tending cell, with the
paper's table beside ours (a script, not a test):

    python tests/bench/bench_paper_001.py [CELL] [--runs 3] [--cycles N] [--figures DIR]

Two scenarios, as the paper's:
- static: the same cell with its dynamic objects absent (no doors, nothing moving); the
  time-aware planner and the classical A* plan the same program there;
- dynamic: the doors on their schedules, plus parts carried along the conveyor past the pick
  station (`dynamic[i].path` with `repeat`: one every 8 s, 6 s from end to end).

Planned four ways in one process (CPU seconds of planning, median of --runs):
- `timed`: the time-aware planner (`planner.dynamic: timed`, the default);
- `astar`: the classical A* of the paper (`planner.dynamic: astar`): the same graph, heuristic and
  timing with time ignored, then checked in time; where its route meets a dynamic object at its
  time the robot must stop at rest before it (each stop is one of the paper's dangerous
  situations: its robot stopped there in an emergency);
- `rest`: the dynamic objects planned as absent, then waits at rest before a move meeting one;
- `absent`: the dynamic objects ignored altogether, only to count its hazards (intervals closer
  than the clearance to a present dynamic object: collisions a real cell would have).

For each: the cycle time over the job's cycles, parts per hour (cycles / cycle time), the stops or
hazards, and the machines' idle time waiting for the robot (door open to the robot's arrival at the
machine's station, summed over the openings served, as a share of the cycle).

With --figures DIR it also draws the figures of docs/paper-001.md from the dynamic scenario's
plans into DIR (`paper_001_figures.py`: the voxel grid, one junction's routes, the timelines).
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import statistics
import sys
import tempfile
import time
from collections import Counter
from dataclasses import replace
from pathlib import Path

import yaml

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, PlanResult, plan_cell
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_tending import hazards, machine_waits

REPO = Path(__file__).resolve().parents[2]

# The paper's table ("Сравнение результатов классического и адаптированного A* в двух сценариях"):
# cycle time without / with time parameters (s), reduction (%), dangerous situations of the
# classical A* / of the proposed method, equipment idle time without / with (%).
PAPER = {
    "static": {"cycle": (120.0, 116.0), "gain": 3.0, "danger": (0, 0), "idle": (15.0, 12.0)},
    "dynamic": {"cycle": (140.0, 133.0), "gain": 5.0, "danger": (2, 0), "idle": (18.0, 13.0)},
}

# Parts passing the conveyor's pick station (cells/tending.yaml: the conveyor's top at 0.75 m,
# the station at x 0.7, y -0.95): a 0.15 m box carried along x at 0.25 m/s, one every 8 s.
CONVEYOR_PARTS = {
    "name": "passing_part", "box": [0.15, 0.15, 0.15], "repeat": 8.0, "count": 12,
    "path": [{"t": 0.0, "xyz": [-0.25, -1.0, 0.83]}, {"t": 6.0, "xyz": [1.25, -1.0, 0.83]}],
}


def dynamic_cell(path: Path, folder: Path, cycles: int | None) -> Path:
    """The cell with parts passing on its conveyor (and its cycles set), written to `folder`."""
    data = yaml.safe_load(path.read_text())
    data["dynamic"] = [*data.get("dynamic", []), CONVEYOR_PARTS]
    if cycles is not None:
        data["tending"]["cycles"] = cycles
    out = folder / f"{data.get('name', path.stem)}_conveyor.yaml"
    out.write_text(yaml.safe_dump(data, sort_keys=False))
    return out


def plan(cell: CellSpec, robot: RobotModel, mode: str) -> PlanResult:
    if mode == "absent":
        return plan_cell(replace(cell, dynamic=()), robot, PlanOptions())
    return plan_cell(cell, robot, PlanOptions(dynamic=mode))


def measured(cell: CellSpec, robot: RobotModel, mode: str, runs: int) -> tuple[PlanResult, float]:
    """The plan and the median CPU seconds of `runs` plans (the plans are the same every run)."""
    cpu = []
    result = None
    for _ in range(runs):
        t0 = time.process_time()
        result = plan(cell, robot, mode)
        cpu.append(time.process_time() - t0)
    assert result is not None
    return result, statistics.median(cpu)


def row(cell: CellSpec, robot: RobotModel, scenario: str, mode: str, runs: int,
        keep: dict[str, PlanResult] | None = None) -> dict[str, float] | None:
    """Print the row of one plan; the plan is put in `keep` under its mode where given."""
    result, cpu = measured(cell, robot, mode, runs)
    if keep is not None:
        keep[mode] = result
    if result.status != "planned":
        print(f"{scenario:8s} {mode:7s} {result.status}: {result.message[:160]}")
        return None
    cycles = len(cell.seams[0].spots) // max(1, len({s.name.split('_', 1)[1] for s in cell.seams[0].spots}))
    stops = sum(1 for t in result.transitions if t.wait is not None) if mode == "astar" else 0
    n_hazards, least = hazards(cell, robot, result) if cell.dynamic else (0, float("inf"))
    waits = machine_waits(cell, result)
    idle = 100 * sum(waits.values()) / (len(waits) * result.cycle_time) if waits else 0.0
    per_hour = 3600.0 * cycles / result.cycle_time
    danger = stops if mode == "astar" else n_hazards
    by_object = Counter(t.wait.obstacle for t in result.transitions if t.wait is not None)
    print(f"{scenario:8s} {mode:7s} {result.cycle_time:8.3f} {per_hour:9.1f} {cpu:6.1f} {danger:7d} {idle:7.1f}"
          f" {least * 1000 if least != float('inf') else float('nan'):9.0f}  "
          + ", ".join(f"{k} {v}" for k, v in sorted(by_object.items())))
    return {"cycle": result.cycle_time, "danger": danger, "idle": idle, "per_hour": per_hour}


def figures(out: Path, cell: CellSpec, robot: RobotModel, kept: dict[str, PlanResult]) -> None:
    from paper_001_figures import Plans, draw_all

    if any(kept[m].status != "planned" for m in ("timed", "astar", "rest")):
        print("figures: not drawn, a plan of the dynamic scenario failed")
        return
    for path in draw_all(out, Plans(cell, robot, kept)):
        print(f"figure: {path} ({path.stat().st_size / 1024:.0f} KB)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0] if __doc__ else None)
    parser.add_argument("cell", nargs="?", type=Path, default=REPO / "cells" / "tending.yaml")
    parser.add_argument("--runs", type=int, default=3, help="plans per row; the CPU column is their median")
    parser.add_argument("--cycles", type=int, default=None, help="the job's cycles (default: the cell's)")
    parser.add_argument("--figures", type=Path, default=None, metavar="DIR",
                        help="also draw the paper page's figures (PNG) of the dynamic scenario into DIR")
    args = parser.parse_args()
    kept: dict[str, PlanResult] = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = dynamic_cell(args.cell, Path(tmp), args.cycles)
        dynamic = load_cell(path)
        robot = load_cell_robot(dynamic)
        static = replace(dynamic, dynamic=())
        print(f"{dynamic.name}: {len(dynamic.seams[0].spots)} station visits; dynamic: "
              + ", ".join(d.name for d in dynamic.dynamic))
        print(f"{'scenario':8s} {'planner':7s} {'cycle s':>8s} {'parts/h':>9s} {'CPU s':>6s} {'danger':>7s} "
              f"{'idle %':>7s} {'least mm':>9s}  waits by object")
        ours: dict[str, dict[str, dict[str, float] | None]] = {"static": {}, "dynamic": {}}
        for mode in ("timed", "astar"):
            ours["static"][mode] = row(static, robot, "static", mode, args.runs)
        for mode in ("timed", "astar", "rest", "absent"):
            ours["dynamic"][mode] = row(dynamic, robot, "dynamic", mode, args.runs, kept)
        if args.figures is not None:
            figures(args.figures, dynamic, robot, kept)
    print("\nbeside the paper (classical A* -> time-aware):")
    for scenario, paper in PAPER.items():
        a, b = ours[scenario].get("astar"), ours[scenario].get("timed")
        if a is None or b is None:
            print(f"  {scenario}: not planned both ways")
            continue
        gain = 100 * (1 - b["cycle"] / a["cycle"])
        print(f"  {scenario:8s} cycle paper {paper['cycle'][0]:.0f} -> {paper['cycle'][1]:.0f} s "
              f"(-{paper['gain']:.0f} %), ours {a['cycle']:.2f} -> {b['cycle']:.2f} s ({-gain:+.2f} %); "
              f"parts/h paper {3600 / paper['cycle'][0]:.1f} -> {3600 / paper['cycle'][1]:.1f} per part-cycle, "
              f"ours {a['per_hour']:.1f} -> {b['per_hour']:.1f}; dangerous situations paper "
              f"{paper['danger'][0]} -> {paper['danger'][1]}, ours {a['danger']:.0f} -> {b['danger']:.0f}; "
              f"idle paper {paper['idle'][0]:.0f} -> {paper['idle'][1]:.0f} %, ours {a['idle']:.1f} -> {b['idle']:.1f} %")


if __name__ == "__main__":
    main()
