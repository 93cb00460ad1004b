"""Batch planning benchmark (a script, not a test).

    python tests/bench/bench_batch.py [--cell CELL] [--n 20] [--runs 3] [--quick] [--no-ray]

Writes `--n` variants of the cell (default: the reference cell; `--quick`: the small 2-spot test
cell) and plans them as a batch with 1 and 2 local worker processes and on a local Ray with 2 CPUs.
Reports per setting, as medians over `--runs`: wall time, throughput (cells/min), parallel
efficiency (throughput with 2 workers / (2 x throughput with 1)), the largest and median peak RSS of
a worker process (each worker measures its own, getrusage), and the statuses. Ray's start-up
(ray.init) is timed separately; it and one untimed warm-up batch of the small cell per setting (the fork
server's imports, Ray's worker processes) are not counted in the throughput.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tests"))
# Workers (forkserver children, Ray workers) import robomax_py from this checkout too.
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH", "")) if p)

from conftest import REFERENCE_CELL, _write_small_cell

from robomax_py.app.batch import BatchOptions, CellOutcome, run_batch
from robomax_py.io.variants import write_variants


def one_batch(files: list[str], out: Path, jobs: int, use_ray: bool) -> tuple[float, tuple[CellOutcome, ...]]:
    t0 = time.perf_counter()
    outcomes = run_batch(files, out, BatchOptions(jobs=jobs), use_ray=use_ray)
    return time.perf_counter() - t0, outcomes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cell", type=Path, default=REFERENCE_CELL, help="cell to make variants of")
    ap.add_argument("--n", type=int, default=20, help="variants per batch")
    ap.add_argument("--runs", type=int, default=3, help="repetitions (medians are reported)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="the small 2-spot test cell instead of --cell")
    ap.add_argument("--no-ray", action="store_true", help="skip the Ray setting")
    args = ap.parse_args()

    tmp = Path(tempfile.mkdtemp(prefix="bench_batch_"))
    cell = _write_small_cell(tmp / "src", "small") if args.quick else args.cell
    variants = write_variants(cell, args.n, args.seed, tmp / "variants")
    files = [str(v.path) for v in variants]
    print(f"{len(files)} variants of {cell} in {tmp / 'variants'}; {os.cpu_count()} CPU(s), "
          f"load average {os.getloadavg()[0]:.2f}", flush=True)

    settings: list[tuple[str, int, bool]] = [("local, 1 worker", 1, False), ("local, 2 workers", 2, False)]
    ray_start = None
    if not args.no_ray:
        try:
            import ray
        except ImportError:
            print("ray is not installed: the Ray setting is skipped")
        else:
            t0 = time.perf_counter()
            ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False,
                     runtime_env={"env_vars": {"PYTHONPATH": os.environ["PYTHONPATH"]}})
            ray_start = time.perf_counter() - t0
            settings.append(("Ray local, 2 CPUs", 2, True))

    walls: dict[str, list[float]] = {name: [] for name, _, _ in settings}
    rss: dict[str, list[float]] = {name: [] for name, _, _ in settings}
    statuses: dict[str, Counter[str]] = {name: Counter() for name, _, _ in settings}
    reference: dict[str, bytes] = {}
    # Untimed warm-up on the small cell: the fork server's imports, Ray's worker processes.
    warm = [str(_write_small_cell(tmp / "warm", f"warm{k}")) for k in range(2)]
    for name, jobs, use_ray in settings:
        one_batch(warm[:jobs], tmp / "warmup", jobs, use_ray)
    for run in range(args.runs):
        for name, jobs, use_ray in settings:
            out = tmp / f"out_{run}_{jobs}_{int(use_ray)}"
            wall, outcomes = one_batch(files, out, jobs, use_ray)
            walls[name].append(wall)
            rss[name].extend(o.peak_rss_mb for o in outcomes if o.peak_rss_mb is not None)
            statuses[name] = Counter(o.status for o in outcomes)
            programs = {p.name: p.read_bytes() for p in sorted(out.iterdir())          # the sets' files, not their
                    if not p.name.startswith(("summary", "."))}                  # hidden folders
            if not reference:
                reference = programs
            same = "same programs" if programs == reference else "PROGRAMS DIFFER"
            print(f"run {run + 1}/{args.runs} {name}: {wall:.1f} s, {same}", flush=True)

    n = len(files)
    thr = {name: n / (statistics.median(w) / 60) for name, w in walls.items()}
    print()
    print("| setting | wall (s) | cells/min | efficiency | peak RSS max / median (MiB) | statuses |")
    print("|---|---|---|---|---|---|")
    base = thr["local, 1 worker"]
    for name, jobs, _ in settings:
        eff = thr[name] / (jobs * base)
        r = rss[name]
        mem = f"{max(r):.0f} / {statistics.median(r):.0f}" if r else "-"
        st = ", ".join(f"{v} {k}" for k, v in sorted(statuses[name].items()))
        print(f"| {name} | {statistics.median(walls[name]):.1f} | {thr[name]:.2f} | {eff:.2f} | {mem} | {st} |")
    if ray_start is not None:
        print(f"\nRay start-up (ray.init, not counted above): {ray_start:.1f} s")
    print(f"parallel efficiency, 2 local workers: {thr['local, 2 workers'] / (2 * base):.2f} "
          f"(medians over {args.runs} run(s); output in {tmp})")


if __name__ == "__main__":
    main()
