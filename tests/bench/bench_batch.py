"""Batch planning benchmark (a script, not a test).

    python tests/bench/bench_batch.py [--cell CELL] [--n 20] [--runs 3] [--quick] [--no-ray]
    python tests/bench/bench_batch.py --driver 200        the driver's peak memory for 200 cells
    python tests/bench/bench_batch.py --memory            the measurements behind batch_ray's memory model

Throughput (the default): writes `--n` variants of the cell (default: the reference cell; `--quick`:
the small 2-spot test cell) and plans them as a batch with 1 and 2 local worker processes and on a
Ray cluster of 1 and of 2 nodes started on this machine (`ray start`, 1 CPU each: tests/ray_nodes.py).
Reports per setting, as medians over `--runs`: wall time, throughput (cells/min), parallel efficiency
(throughput / (workers x throughput with 1 local worker)), the wall time a cell takes more than in the
local pool with as many workers (the overhead of a Ray task: shipping the cell's files, scheduling, the
task's process), the driver's CPU time per cell (loading the cell to ship it, writing its results),
the largest and median peak RSS of a plan's process, and the statuses. Connecting to Ray and one
untimed warm-up batch of the small cell per setting (fork servers, Ray's worker processes) are not
counted.

`--driver N`: N variants of the small cell planned by `robomax batch --ray-address` on 2 local nodes
(real plans); reports the driver process's peak RSS and CPU seconds (getrusage of the command).

`--overhead N`: N cells through a stand-in worker that plans nothing (it returns a small program at
once), in the local pool (1 worker) and on a Ray cluster of 1 local node: the CPU seconds and wall
time a cell costs besides its plan (driver, node processes and the cell's own process).

`--memory`: plans cells of growing size (the scaling benchmark's open family with orientation grids
of 3, 5 and 7, the clamped family, the shipped cells) one process each and prints each plan's peak
RSS against `batch_ray.task_memory_mb`'s model of it.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import yaml

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

REPO = Path(__file__).resolve().parents[2]
sys.path[:0] = [str(REPO), str(REPO / "tests")]
sys.path.insert(0, str(REPO / "tests" / "bench"))
# Workers (forkserver children, Ray's nodes) import robomax_py from this checkout too.
PATHS = [REPO, REPO / "tests", REPO / "tests" / "bench"]
os.environ["PYTHONPATH"] = os.pathsep.join([*map(str, PATHS), *filter(None, [os.environ.get("PYTHONPATH")])])

from conftest import REFERENCE_CELL, _write_small_cell
from ray_nodes import local_cluster, node_env, session_cpu_s
from scale_cells import scale_cell

from robomax_py.app.batch import BatchOptions, CellOutcome, run_batch, run_local
from robomax_py.app.batch_ray import PLAN_BASE_MB, PLAN_MB_PER_POSE
from robomax_py.io.variants import write_variants


def one_batch(files: list[str], out: Path, jobs: int | None, address: str | None
              ) -> tuple[float, float, tuple[CellOutcome, ...]]:
    """Wall and this process's CPU seconds of one batch, and its outcomes."""
    t0, c0 = time.perf_counter(), time.process_time()
    outcomes = run_batch(files, out, BatchOptions(jobs=jobs), use_ray=address is not None, ray_address=address)
    return time.perf_counter() - t0, time.process_time() - c0, outcomes


def throughput(args: argparse.Namespace, tmp: Path) -> None:
    cell = _write_small_cell(tmp / "src", "small") if args.quick else args.cell
    variants = write_variants(cell, args.n, args.seed, tmp / "variants")
    files = [str(v.path) for v in variants]
    warm = [str(_write_small_cell(tmp / "warm", f"warm{k}")) for k in range(2)]
    print(f"{len(files)} variants of {cell} in {tmp / 'variants'}; {os.cpu_count()} CPU(s), "
          f"load average {os.getloadavg()[0]:.2f}", flush=True)
    walls: dict[str, list[float]] = {}
    cpus: dict[str, list[float]] = {}
    rss: dict[str, list[float]] = {}
    statuses: dict[str, Counter[str]] = {}
    workers: dict[str, int] = {}
    reference: dict[str, bytes] = {}

    def measure(name: str, jobs: int, address: str | None) -> None:
        workers[name] = jobs
        one_batch(warm[:jobs], tmp / "warmup", jobs if address is None else None, address)
        for run in range(args.runs):
            out = tmp / f"out_{name.replace(' ', '_').replace(',', '')}_{run}"
            wall, cpu, outcomes = one_batch(files, out, jobs if address is None else None, address)
            walls.setdefault(name, []).append(wall)
            cpus.setdefault(name, []).append(cpu)
            rss.setdefault(name, []).extend(o.peak_rss_mb for o in outcomes if o.peak_rss_mb is not None)
            statuses[name] = Counter(o.status for o in outcomes)
            programs = {p.name: p.read_bytes() for p in sorted(out.iterdir())          # the sets' files, not their
                        if p.suffix in (".srcl", ".json") and not p.name.startswith(".")   # hidden folders
                        and not p.name.endswith(".manifest.json")}
            if not reference:
                reference.update(programs)
            same = "same programs" if programs == reference else "PROGRAMS DIFFER"
            print(f"run {run + 1}/{args.runs} {name}: {wall:.1f} s, driver {cpu:.1f} CPU s, {same}", flush=True)

    measure("local, 1 worker", 1, None)
    measure("local, 2 workers", 2, None)
    connect: dict[str, float] = {}
    if not args.no_ray:
        import ray

        env = node_env(PATHS)
        os.environ.update({k: v for k, v in env.items() if k.startswith("RAY_")})
        for nodes in (1, 2):
            with local_cluster(Path(tempfile.mkdtemp(prefix="nodes_", dir=tmp)), nodes, env) as cluster:
                name = f"Ray, {nodes} node(s)"
                t0 = time.perf_counter()
                ray.init(address=cluster.address, log_to_driver=False)
                connect[name] = time.perf_counter() - t0
                try:
                    measure(name, nodes, cluster.address)
                finally:
                    ray.shutdown()

    n = len(files)
    thr = {name: n / (statistics.median(w) / 60) for name, w in walls.items()}
    base = thr["local, 1 worker"]
    print()
    print("| setting | wall (s) | cells/min | efficiency | extra wall per cell vs local (s) | driver CPU per cell (s) "
          "| plan peak RSS max / median (MiB) | statuses |")
    print("|---|---|---|---|---|---|---|---|")
    for name, w in walls.items():
        jobs = workers[name]
        local = f"local, {jobs} worker" + ("s" if jobs > 1 else "")
        extra = "" if name.startswith("local") else f"{(statistics.median(w) - statistics.median(walls[local])) * jobs / n:.2f}"
        r = rss[name]
        mem = f"{max(r):.0f} / {statistics.median(r):.0f}" if r else "-"
        st = ", ".join(f"{v} {k}" for k, v in sorted(statuses[name].items()))
        print(f"| {name} | {statistics.median(w):.1f} | {thr[name]:.2f} | {thr[name] / (jobs * base):.2f} | {extra} "
              f"| {statistics.median(cpus[name]) / n:.3f} | {mem} | {st} |")
    for name, s in connect.items():
        print(f"connecting to the cluster ({name}, not counted above): {s:.1f} s")
    print(f"medians over {args.runs} run(s); output in {tmp}")


def driver_memory(args: argparse.Namespace, tmp: Path) -> None:
    cell = _write_small_cell(tmp / "src", "small")
    files = [str(v.path) for v in write_variants(cell, args.driver, args.seed, tmp / "variants")]
    env = node_env(PATHS)
    # The command runs under a small wrapper whose only child it is: getrusage(RUSAGE_CHILDREN) there
    # is the command's own (on Ray it starts no process of its own).
    wrapper = ("import json, resource, subprocess, sys\n"
               "done = subprocess.run(sys.argv[1:], capture_output=True)\n"
               "r = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
               "print(json.dumps({'code': done.returncode, 'rss_mib': r.ru_maxrss / 1024, "
               "'cpu_s': r.ru_utime + r.ru_stime, 'out': done.stdout.decode()}))\n")
    with local_cluster(tmp / "nodes", 2, env) as cluster:
        t0 = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", wrapper, sys.executable, "-m", "robomax_py", "batch", *files,
                               "-o", str(tmp / "out"), "--ray-address", cluster.address, "--json"],
                              env=env, capture_output=True, check=True)
        wall = time.perf_counter() - t0
    got = json.loads(done.stdout)
    statuses = Counter(c["status"] for c in json.loads(got["out"])["cells"])
    print(f"{len(files)} cells on 2 local nodes: exit {got['code']}, {wall:.0f} s wall, driver peak RSS "
          f"{got['rss_mib']:.0f} MiB, driver CPU {got['cpu_s']:.1f} s ({dict(statuses)})")


def overhead(args: argparse.Namespace, tmp: Path) -> None:
    from batch_stand_in import stand_in_worker

    cell = _write_small_cell(tmp / "src", "small")
    files = [str(v.path) for v in write_variants(cell, args.overhead, args.seed, tmp / "variants")]
    warm = files[:2]
    n = len(files)
    rows = []
    # The local pool: this process and its children (the fork server and the cells' processes).
    run_batch(warm, tmp / "warm_local", BatchOptions(jobs=1), worker=stand_in_worker)
    c0, k0, t0 = time.process_time(), _children_cpu_s(), time.perf_counter()
    run_batch(files, tmp / "local", BatchOptions(jobs=1), worker=stand_in_worker)
    rows.append(("local, 1 worker", time.perf_counter() - t0, time.process_time() - c0, _children_cpu_s() - k0))
    import ray

    env = node_env(PATHS)
    os.environ.update({k: v for k, v in env.items() if k.startswith("RAY_")})
    with local_cluster(tmp / "nodes", 1, env) as cluster:
        ray.init(address=cluster.address, log_to_driver=False)
        try:
            run_batch(warm, tmp / "warm_ray", BatchOptions(), worker=stand_in_worker, use_ray=True)
            session = cluster.nodes[0].proc.pid
            c0, k0, t0 = time.process_time(), session_cpu_s(session), time.perf_counter()
            run_batch(files, tmp / "ray", BatchOptions(), worker=stand_in_worker, use_ray=True)
            rows.append(("Ray, 1 node", time.perf_counter() - t0, time.process_time() - c0, session_cpu_s(session) - k0))
            # The node's processes at rest for as long: what the raylet, GCS and monitors take anyway.
            idle0, t1 = session_cpu_s(session), time.perf_counter()
            time.sleep(rows[-1][1])
            idle = (session_cpu_s(session) - idle0) * rows[-1][1] / (time.perf_counter() - t1)
            resident = _resident_mib(session)
        finally:
            ray.shutdown()
    print(f"{n} cells through a stand-in worker that plans nothing; load average {os.getloadavg()[0]:.2f}")
    print("| setting | wall per cell (s) | driver CPU per cell (s) | CPU per cell elsewhere (s) |")
    print("|---|---|---|---|")
    for name, wall, driver, other in rows:
        print(f"| {name} | {wall / n:.3f} | {driver / n:.3f} | {other / n:.3f} |")
    print(f"the Ray node at rest for as long as the batch took: {idle / n:.3f} CPU s per cell of it")
    print("(elsewhere: the local pool's fork server and cells' processes; on Ray every process of the node: "
          "raylet, Ray worker, fork server, the cells' processes)")
    print("resident memory on the node after the batch, MiB: " +
          ", ".join(f"{k}: {' + '.join(f'{v:.0f}' for v in vs)}" for k, vs in resident.items()))


def _resident_mib(session: int) -> dict[str, list[float]]:
    """VmRSS of the node's task processes, MiB, by kind: Ray's worker processes (`ray::...` but
    Ray's own agents) and the fork servers they started."""
    from ray_nodes import processes

    found: dict[str, list[float]] = {}
    for pid, _, _, cmd in processes(session):
        kind = ("fork server" if "multiprocessing.forkserver" in cmd else
                "Ray worker" if cmd.startswith("ray::") and "Agent" not in cmd else None)
        if kind is None:
            continue
        try:
            line = next(x for x in Path(f"/proc/{pid}/status").read_text().splitlines() if x.startswith("VmRSS:"))
        except (OSError, StopIteration):
            continue
        found.setdefault(kind, []).append(int(line.split()[1]) / 1024)
    return found


def _children_cpu_s() -> float:
    """CPU seconds of this process's children it waited for (the cells' processes are the fork
    server's children: counted once the fork server ends) and of the live fork server's."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    total = usage.ru_utime + usage.ru_stime
    ticks = os.sysconf("SC_CLK_TCK")
    for pid in _descendants(os.getpid()):
        try:
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += sum(int(v) for v in fields[11:15]) / ticks
    return total


def _descendants(pid: int) -> list[int]:
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                parent = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(parent, []).append(int(entry.name))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def memory_model(args: argparse.Namespace, tmp: Path) -> None:
    from robomax_py.app.batch_ship import survey

    folder = tmp / "cells"
    folder.mkdir()
    files = [str(_write_small_cell(folder, "small"))]
    for family, n, grid in [("open", 8, 5), ("open", 30, 5), ("open", 60, 5), ("open", 120, 5), ("open", 240, 5),
                            ("open", 60, 3), ("open", 60, 7), ("clamped", 60, 5)]:
        data = scale_cell(family, n)
        for seam in data["seams"]:
            seam["grid"] = grid
        data["name"] = f"{family}_{n}_grid{grid}"
        path = folder / f"{data['name']}.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False))
        files.append(str(path))
    files += [str(REPO / "cells" / f"{c}.yaml") for c in ("cabin_flange", "frame", "ur10_tray", "tending")]
    outcomes = run_local(files, BatchOptions(jobs=1))
    print("| cell | spots | poses | peak RSS (MiB) | model (MiB) | peak / model |")
    print("|---|---|---|---|---|---|")
    for file, o in zip(files, outcomes, strict=True):
        poses = survey(file).poses
        model = PLAN_BASE_MB + PLAN_MB_PER_POSE * poses
        peak = o.peak_rss_mb or 0.0
        print(f"| {Path(file).stem} | {o.spots} | {poses:,} | {peak:.0f} | {model:.0f} | {peak / model:.2f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cell", type=Path, default=REFERENCE_CELL, help="cell to make variants of")
    ap.add_argument("--n", type=int, default=20, help="variants per batch")
    ap.add_argument("--runs", type=int, default=3, help="repetitions (medians are reported)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="the small 2-spot test cell instead of --cell")
    ap.add_argument("--no-ray", action="store_true", help="skip the Ray settings")
    ap.add_argument("--driver", type=int, metavar="N", help="measure the driver's peak memory for N cells instead")
    ap.add_argument("--overhead", type=int, metavar="N", help="measure the cost of a cell besides its plan instead")
    ap.add_argument("--memory", action="store_true", help="measure plans' peak memory against the model instead")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_batch_"))
    if args.driver:
        driver_memory(args, tmp)
    elif args.overhead:
        overhead(args, tmp)
    elif args.memory:
        memory_model(args, tmp)
    else:
        throughput(args, tmp)


if __name__ == "__main__":
    main()
