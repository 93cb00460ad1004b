"""How the planner's cost grows with the cell (a script, not a test).

    python tests/bench/bench_scale.py [--sizes 8,15,30,60,120,240] [--families open,clamped,interleaved]
                                      [--runs 1] [--against DIR] [--against-max 30] [--timeout 1800]
    python tests/bench/bench_scale.py --cells CELL... [--runs 3] [--against DIR]
    python tests/bench/bench_scale.py --corpus frame,panel [--sizes 30,60,120,240] [--no-baseline]

Cells come from `scale_cells.py` (seeded, one KR 125 with the C-gun, N spots on flange rows, three
families), or with `--corpus FAMILIES` from `corpus_cells.scaled_cell` (four fixtures holding one
corpus part each round a KR 125, N / 4 spots per part; shapes the planner was not tuned on). Each plan runs in a fresh process (so peak memory is the plan's own and nothing is
warm), one thread. Per family and N it prints the median over the runs of: CPU seconds of the plan
(imports and cell loading excluded) and its split into candidates, sequencing, timing and the
rest (world, roadmap, verify, clearance), each stage's share of the process's wall clock
applied to its CPU seconds; collision checks by stage, sequencing
rounds, peak resident memory, the cycle time and its ratio to the published baseline (same
timing layer, planned in the same process) and to the rest-to-rest lower bound
(`robomax_py.app.bench.lower_bound`); then the growth exponent per family, fitted by least squares
to log CPU over log N for N >= 30.

`--against DIR` plans the same cells with the robomax_py found in DIR (e.g. a `git worktree` of an
older commit) in the same run, up to N = `--against-max`, and prints the CPU ratio.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))

from corpus_cells import scaled_cell
from scale_cells import FAMILIES, write_scale_cell

CHILD = r"""
import json, os, resource, sys, time
os.environ.setdefault("OMP_NUM_THREADS", "1")
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.app.bench import lower_bound
cell = load_cell(sys.argv[1]); robot = load_cell_robot(cell)
c0 = time.process_time()
r = plan_cell(cell, robot)
cpu = time.process_time() - c0
out = {"status": r.status, "message": r.message[:300], "cpu": cpu,
       "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}
if r.status == "planned":
    s = r.stats
    out.update(cycle=r.cycle_time, bound=lower_bound(r, robot.limits), stages=s.seconds, rounds=s.rounds,
               checks={"candidates": s.candidate_checks, "sequencing": s.sequencing_checks,
                       "roadmap": s.roadmap_checks, "verify": s.verify_checks}, detours=s.detours)
    if sys.argv[2] == "1":
        b = plan_cell(cell, robot, PlanOptions(baseline=True))
        out["baseline"] = b.cycle_time if b.status == "planned" else None
print("RESULT " + json.dumps(out))
"""


def run_child(cell: Path, code_dir: Path, baseline: bool, timeout: float) -> dict:
    env = dict(os.environ, PYTHONPATH=str(code_dir), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    try:
        done = subprocess.run([sys.executable, "-c", CHILD, str(cell), "1" if baseline else "0"], env=env,
                              capture_output=True, text=True, timeout=timeout, cwd=str(code_dir), check=False)
    except subprocess.TimeoutExpired:
        return {"status": "timeout", "cpu": math.nan}
    for line in done.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[len("RESULT "):])
    return {"status": "crashed", "cpu": math.nan, "message": done.stderr[-500:]}


def median_of(rows: list[dict], key: str) -> float:
    values = [r[key] for r in rows if isinstance(r.get(key), (int, float))]
    return statistics.median(values) if values else math.nan


def growth(points: list[tuple[int, float]]) -> float:
    """Least-squares slope of log cpu over log n."""
    pts = [(math.log(n), math.log(c)) for n, c in points if n >= 30 and c > 0 and math.isfinite(c)]
    if len(pts) < 2:
        return math.nan
    mx = sum(x for x, _ in pts) / len(pts)
    my = sum(y for _, y in pts) / len(pts)
    return sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)


HEADER = (f"{'family':12s} {'N':>4s} {'CPU s':>7s} {'cand':>6s} {'seq':>6s} {'time':>6s} {'other':>6s} "
          f"{'checks k':>9s} {'seq k':>7s} {'rounds':>6s} {'MB':>6s} {'cycle s':>8s} {'/base':>6s} "
          f"{'/bound':>6s} {'vs old':>7s}")


def report_row(family: str, n: int, rows: list[dict], old: list[dict]) -> float:
    """Print one table row; returns the median CPU seconds."""
    ok = [r for r in rows if r["status"] == "planned"]
    cpu = median_of(rows, "cpu")
    if not ok:
        print(f"{family:12s} {n:4d} {rows[0]['status']}: {rows[0].get('message', '')[:90]}", flush=True)
        return cpu
    # Stage clocks are wall seconds of one single-threaded process: each stage's share of the wall
    # is its share of the CPU (other load on the machine stretches them alike).
    stage = {k: statistics.median(r["stages"].get(k, 0.0) / sum(r["stages"].values()) * r["cpu"] for r in ok)
             for k in ("candidates", "sequencing", "timing")}
    other = max(cpu - sum(stage.values()), 0.0)
    checks = statistics.median(sum(r["checks"].values()) for r in ok) / 1e3
    seq = statistics.median(r["checks"]["sequencing"] + r["checks"]["roadmap"] for r in ok) / 1e3
    base = ok[0].get("baseline")
    cycle = median_of(ok, "cycle")
    vs_old = ""
    if old:
        old_cpu = median_of(old, "cpu")
        vs_old = f"{cpu / old_cpu:7.2f}" if math.isfinite(old_cpu) else f"{old[0]['status']:>7s}"
    print(f"{family:12s} {n:4d} {cpu:7.1f} {stage['candidates']:6.1f} {stage['sequencing']:6.1f} "
          f"{stage['timing']:6.1f} {other:6.1f} {checks:9.0f} {seq:7.0f} "
          f"{median_of(ok, 'rounds'):6.0f} {median_of(rows, 'peak_mb'):6.0f} {cycle:8.3f} "
          f"{(cycle / base if base else math.nan):6.3f} {cycle / median_of(ok, 'bound'):6.3f} {vs_old}", flush=True)
    return cpu


def print_saved(paths: list[Path]) -> None:
    """The table of runs saved by --json (several files are merged in order)."""
    print(HEADER)
    by_family: dict[str, list[tuple[int, dict]]] = {}
    for path in paths:
        for key, runs in json.loads(path.read_text(encoding="utf-8")).items():
            family, n = key.split("/")
            by_family.setdefault(family, []).append((int(n), runs))
    for family, entries in by_family.items():
        points = [(n, report_row(family, n, runs["new"], runs["old"])) for n, runs in sorted(entries, key=lambda e: e[0])]
        print(f"{family:12s} growth exponent (CPU ~ N^k, N >= 30): k = {growth(points):.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="8,15,30,60,120,240")
    ap.add_argument("--families", default=",".join(FAMILIES))
    ap.add_argument("--corpus", default=None,
                    help="corpus families (e.g. frame,panel): cells from corpus_cells.scaled_cell instead")
    ap.add_argument("--no-baseline", action="store_true", help="skip planning the published baseline")
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--against", type=Path, default=None, help="a tree holding another robomax_py to compare")
    ap.add_argument("--against-max", type=int, default=30, help="largest N planned with --against")
    ap.add_argument("--timeout", type=float, default=1800.0)
    ap.add_argument("--json", type=Path, default=None, help="also write every run's figures here")
    ap.add_argument("--table", type=Path, nargs="+", default=None, help="print the table of saved --json files")
    ap.add_argument("--cells", type=Path, nargs="+", default=None,
                    help="plan these cell files instead of generated ones (each --runs times, --against too)")
    args = ap.parse_args()
    if args.table:
        print_saved(args.table)
        return
    if args.cells:
        print(HEADER, flush=True)
        saved: dict[str, dict] = {}
        for cell in args.cells:
            cell = cell.resolve()
            rows = [run_child(cell, REPO, baseline=(k == 0 and not args.no_baseline), timeout=args.timeout)
                    for k in range(args.runs)]
            old = [run_child(cell, args.against, baseline=False, timeout=args.timeout)
                   for _ in range(args.runs)] if args.against else []
            label = f"{cell.parent.name}/{cell.stem}"       # two folders may hold cells of one name
            saved[f"{label}/0"] = {"new": rows, "old": old}
            report_row(label, 0, rows, old)
            if args.json:
                args.json.write_text(json.dumps(saved, indent=1), encoding="utf-8")
        return
    sizes = [int(x) for x in args.sizes.split(",")]
    families = (args.corpus or args.families).split(",")
    everything: dict[str, dict] = {}
    with tempfile.TemporaryDirectory() as tmp:
        print(HEADER, flush=True)
        for family in families:
            points = []
            for n in sizes:
                if args.corpus:
                    cell = scaled_cell(family, n, args.seed).write(Path(tmp) / f"{family}_{n}")
                else:
                    cell = write_scale_cell(Path(tmp), family, n, args.seed)
                rows = [run_child(cell, REPO, baseline=(k == 0 and not args.no_baseline), timeout=args.timeout)
                        for k in range(args.runs)]
                old = [run_child(cell, args.against, baseline=False, timeout=args.timeout)
                       for _ in range(args.runs)] if args.against and n <= args.against_max else []
                everything[f"{family}/{n}"] = {"new": rows, "old": old}
                points.append((n, report_row(family, n, rows, old)))
                if args.json:      # after every cell, so a long run that is stopped keeps what it measured
                    args.json.write_text(json.dumps(everything, indent=1), encoding="utf-8")
            print(f"{family:12s} growth exponent (CPU ~ N^k, N >= 30): k = {growth(points):.2f}", flush=True)


if __name__ == "__main__":
    main()
