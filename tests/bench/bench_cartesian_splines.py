"""Cartesian moves as Bézier splines (`planner.cartesian_moves: spline`) against LIN/PTP with fly-by
(a script, not a test):

    python tests/bench/bench_cartesian_splines.py [--runs 3] [--quick] [--json FILE]

Each cell is planned both ways in this process (the rest of the cell as written: gazelle_cabin
with its `detour_moves: lin`, cabin_flange with joint-space detours) and the script prints per
cell and way: the cycle, the CPU seconds of `plan_cell` (median of `--runs`), how many junctions
between two spots switched to a spline and the time each way; then, for the spline plan, per
dialect, how far the written program's motion as the controller runs it (read back and rebuilt,
`publish`) is from the planned one: the largest TCP distance from the planned path (mm), the
largest joint distance (deg), the largest shift of a weld (ms) and the rebuilt cycle; and the
largest distance of the planned spline (through the written points) from the Bézier path it was
sampled from. --quick: the tests' small spline cell, one run, three dialects (a smoke run).
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.publish import publish
from robomax_py.robot import RobotModel

REPO = Path(__file__).resolve().parents[2]
CELLS = (REPO / "robomax_py" / "examples" / "gazelle_cabin.yaml", REPO / "robomax_py" / "examples" / "cabin_flange.yaml")
QUICK_CELL = REPO / "tests" / "data" / "spline_cell" / "spline_cell.yaml"
FORMATS = ("srcl", "krl", "rapid", "fanuc", "urscript")
QUICK_FORMATS = ("krl", "rapid", "urscript")


def _plan(cell: Any, robot: RobotModel, way: str, runs: int) -> tuple[Any, float]:
    cpu = []
    result = None
    for _ in range(runs):
        t0 = time.process_time()
        result = plan_cell(cell, robot, PlanOptions(cartesian_moves=way))
        cpu.append(time.process_time() - t0)
    assert result is not None and result.status == "planned", getattr(result, "message", "")
    return result, statistics.median(cpu)


def measure(path: Path, runs: int, formats: tuple[str, ...], warm: bool = True) -> dict[str, Any]:
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    if warm:
        plan_cell(cell, robot)                  # compiled and cached once, outside the timed runs
    out: dict[str, Any] = {"cell": cell.name}
    for way in ("lin", "spline"):
        result, cpu = _plan(cell, robot, way, runs)
        row: dict[str, Any] = {"cycle_s": round(result.cycle_time, 3), "plan_cpu_s": round(cpu, 2)}
        choices = [t for t in result.transitions if t.choice is not None]
        if way == "spline":
            row["junctions"] = len(choices)
            row["switched"] = sum(t.choice.chosen == "spline" for t in choices if t.choice)
            row["moves"] = [{"between": t.label, "chosen": c.chosen, "flyby_s": round(c.flyby_time, 3),
                             "spline_s": None if c.spline_time is None else round(c.spline_time, 3), "note": c.note,
                             "as_lines_s": None if t.spline is None or t.spline.lines_time is None
                             else round(t.spline.lines_time, 3)}
                            for t in choices if (c := t.choice) is not None]
            devs = [t.spline.deviation_m for t in result.transitions if t.spline is not None]
            row["bezier_deviation_mm"] = round(1000.0 * max(devs), 3) if devs else None
            _, checked = publish(result, cell, robot, formats)
            row["dialects"] = {
                c.format: {"path_mm": round(c.difference.tcp_mm, 3), "joint_deg": round(c.difference.joint_deg, 4),
                           "weld_shift_ms": round(1000.0 * c.difference.time_s, 1),
                           "cycle_s": round(c.report.cycle_time if c.report is not None else result.cycle_time, 3)}
                for c in checked}
        out[way] = row
    return out


def _print(rows: list[dict[str, Any]]) -> None:
    for r in rows:
        lin, spl = r["lin"], r["spline"]
        print(f"{r['cell']}: cycle {lin['cycle_s']:.3f} s as lines / PTP with fly-by, {spl['cycle_s']:.3f} s with "
              f"splines ({spl['switched']} of {spl['junctions']} junctions switched); plan CPU {lin['plan_cpu_s']:.2f} s "
              f"/ {spl['plan_cpu_s']:.2f} s (median); spline off its Bézier path by at most "
              f"{spl['bezier_deviation_mm']} mm")
        for m in spl["moves"]:
            print(f"  {m['between']:>10}: {m['chosen']:6}  fly-by {m['flyby_s']:.3f} s  spline "
                  + (f"{m['spline_s']:.3f} s" if m["spline_s"] is not None else f"none ({m['note']})")
                  + ("" if m["as_lines_s"] is None else f"  as lines {m['as_lines_s']:.3f} s"))
        for fmt, d in spl["dialects"].items():
            print(f"  {fmt:>10}: path {d['path_mm']:.3f} mm, joints {d['joint_deg']:.4f} deg, welds shifted "
                  f"{d['weld_shift_ms']:.1f} ms, cycle {d['cycle_s']:.3f} s")


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    cells, runs, formats = ((QUICK_CELL,), 1, QUICK_FORMATS) if args.quick else (CELLS, args.runs, FORMATS)
    rows = [measure(path, runs, formats, warm=not args.quick) for path in cells]
    _print(rows)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
