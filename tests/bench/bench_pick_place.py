"""Pick and place: planning CPU and cycle of the shipped cell (10 transfers), the same cell with
the parts' limits ignored, and growing numbers of transfers.

    python tests/bench/bench_pick_place.py [--repeat 3] [--sizes 2,5,10,20] [--quick]

CPU is `time.process_time` of `plan_cell` (one process, one core), the median of the repeats.
"With limits ignored" plans the same cell with massless parts without TCP limits: its motion is
then checked against the real parts' limits, to show what the limits change.
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import replace
from pathlib import Path

import yaml

from robomax_py.export.fanuc import program_name
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.plan.loads import Loads, check_carried_motion
from robomax_py.program import identifier
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "cells" / "pick_place.yaml"


def _spots(result):
    return [{"seam": p.seam, "name": p.name, "t_arrive": p.t_arrive, "t_leave": p.t_leave} for p in result.spots]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sizes", default="2,5,10,20")
    ap.add_argument("--out", type=Path, default=Path("/tmp/bench_pick_place"))
    ap.add_argument("--quick", action="store_true", help="the shipped cell once, nothing else (smoke run)")
    ap.add_argument("--generated", type=Path, default=None,
                    help="plan and verify every cell in this folder (tests/bench/pick_place_cells.py) instead")
    args = ap.parse_args()
    if args.generated is not None:
        generated(args.generated, args.out)
        return
    args.out.mkdir(parents=True, exist_ok=True)
    cell = load_cell(CELL)
    robot = load_cell_robot(cell)
    cpu, results = [], []
    for _ in range(1 if args.quick else args.repeat):
        t0 = time.process_time()
        results.append(plan_cell(cell, robot, PlanOptions()))
        cpu.append(time.process_time() - t0)
    result = results[0]
    assert all(r.cycle_time == result.cycle_time for r in results)
    loads = Loads.of(cell, robot)
    empty = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    check = check_carried_motion(cell, robot, empty, loads.worlds, result.trajectory.t, result.trajectory.q,
                                 _spots(result))
    carried = [t for t in result.transitions if t.part]
    print(f"shipped cell, 10 transfers: {result.status}, cycle {result.cycle_time:.3f} s, planning CPU median "
          f"{statistics.median(cpu):.2f} s ({', '.join(f'{c:.2f}' for c in cpu)}), carried moves {len(carried)} "
          f"({sum(t.kind == 'detour' for t in carried)} detours), carried check {'clean' if check.clean else check.violations}")
    if args.quick:
        return
    print("| limits applied | cycle |")
    print("|---|---|")
    for label, variant in (
        ("none (massless parts, no TCP limits)", replace(cell, parts=tuple(replace(p, limits=None, mass=0.0) for p in cell.parts),
                                                         tcp_limits=None)),
        ("joint limits for the parts' masses only", replace(cell, parts=tuple(replace(p, limits=None) for p in cell.parts),
                                                            tcp_limits=None)),
        ("the parts' TCP limits only", replace(cell, parts=tuple(replace(p, mass=0.0) for p in cell.parts))),
        ("all (the cell as written)", cell),
    ):
        print(f"| {label} | {plan_cell(variant, robot, PlanOptions()).cycle_time:.3f} s |")
    light = replace(cell, parts=tuple(replace(p, limits=None, mass=0.0) for p in cell.parts), tcp_limits=None)
    fast = plan_cell(light, robot, PlanOptions())
    broken = check_carried_motion(cell, robot, empty, loads.worlds, fast.trajectory.t, fast.trajectory.q, _spots(fast))
    kinds: dict[str, int] = {}
    for v in broken.violations:
        kinds[v.kind] = kinds.get(v.kind, 0) + 1
    print(f"limits ignored: cycle {fast.cycle_time:.3f} s; against the parts' limits: {kinds}")
    data = yaml.safe_load(CELL.read_text())
    base = data["pick_place"]["transfers"]
    print("| transfers | planning CPU (median) | cycle |")
    print("|---|---|---|")
    for n in (int(x) for x in args.sizes.split(",")):
        data["pick_place"]["transfers"] = [base[k % len(base)] for k in range(n)]
        path = args.out / f"pick_place_{n}.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False))
        c = load_cell(path)
        times, res = [], None
        for _ in range(args.repeat):
            t0 = time.process_time()
            res = plan_cell(c, robot, PlanOptions())
            times.append(time.process_time() - t0)
        assert res is not None
        print(f"| {n} | {statistics.median(times):.2f} s | {res.cycle_time:.3f} s ({res.status}) |")


def generated(folder: Path, out: Path) -> None:
    """Each cell planned in this process (CPU), then through the CLI in all six formats, each
    verified by `robomax verify` (exit codes)."""
    import subprocess
    import sys

    print("| cell | robot | transfers | status | planning CPU | cycle | carried detours | verify (6 formats) |")
    print("|---|---|---|---|---|---|---|---|")
    for path in sorted(folder.glob("*.yaml")):
        cell = load_cell(path)
        robot = load_cell_robot(cell)
        t0 = time.process_time()
        result = plan_cell(cell, robot, PlanOptions())
        cpu = time.process_time() - t0
        n = len(cell.seams[0].spots) // 2
        if result.status != "planned":
            print(f"| {cell.name} | {cell.robot.name} | {n} | {result.status}: {result.message[:90]} | {cpu:.2f} s | | | |")
            continue
        target = out / cell.name
        run = subprocess.run([sys.executable, "-m", "robomax_py", "plan", str(path), "-o", str(target), "--format", "all"],
                             capture_output=True, text=True, check=False)
        verdicts = []
        for ext in (".json", ".srcl", ".src", ".mod", ".ls", ".script"):
            fanuc = ext == ".ls"       # a TP program's file is named as the program (fanuc.program_name)
            program = target / f"{program_name(identifier(cell.name)) if fanuc else cell.name}{ext}"
            if run.returncode != 0 or not program.is_file():
                verdicts.append(f"{ext}: not written")
                continue
            check = subprocess.run([sys.executable, "-m", "robomax_py", "verify", str(path), str(program)],
                                   capture_output=True, text=True, check=False)
            verdicts.append("ok" if check.returncode == 0 else f"{ext}: exit {check.returncode}")
        detours = sum(1 for t in result.transitions if t.part and t.kind == "detour")
        summary = "all clean" if all(v == "ok" for v in verdicts) else ", ".join(v for v in verdicts if v != "ok")
        print(f"| {cell.name} | {cell.robot.name} | {n} | planned | {cpu:.2f} s | {result.cycle_time:.3f} s | "
              f"{detours} | {summary} |", flush=True)


if __name__ == "__main__":
    main()
