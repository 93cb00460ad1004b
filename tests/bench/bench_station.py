"""Multi-robot stations: the full method against two baselines on the same seeded stations
(tests/bench/station_cells.py), docs/stations.md's figures.

  (a) nearest: each spot to the nearest robot that reaches it, each robot sequenced alone, collisions
      resolved by waiting, first come first served;
  (b) minmax: the min-max assignment, zone orders by look-ahead, no re-assignment;
  (c) full: (b), another spot order where the robot that ends last waits (`station.reorder`),
      re-assignment where waits cost more than another assignment, then spots moved away from the
      robot whose own cycle is the makespan where it waits for nobody (`station.unload`).

Per station and method: makespan, total waits, interlocks written, planning CPU (and per stage:
reach, assignment, robots' plans, diagrams, coordination), gap to the lower bound (`station.bound`),
the order changes tried, skipped for what they could gain at most (`reorder.most_gain`) and kept;
then the growth: CPU and makespan against spots at a fixed number of robots (with the exponent of
CPU in spots, a least-squares fit of log CPU on log spots) and against robots at a fixed number of
spots.

    PYTHONPATH=. python tests/bench/bench_station.py [--quick] [--sizes 2x40,4x120] [--methods full]
        [--seeds 1] [--first-seed 0] [--arms shipped|drawn|kr125,ur10] [--json FILE]

The default is the growth study (sizes GROWTH, the full method); the three methods side by side:
`--sizes 4x24,4x40,6x48 --methods nearest,minmax,full`. Each row is the CPU of one plan in one
process; the first of a run also pays the compilation of the planner's kernels where numba's cache
does not hold them yet. `--quick` (the CI smoke run) plans one tiny station by every method.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.station.pipeline import StationOptions, plan_station
from tests.bench.station_cells import station, write

METHODS = ("nearest", "minmax", "full")
# The growth study: spots 40-300 at 4 robots and 120-300 at 6, robots 2-6 at 120 spots.
GROWTH = "4x40,4x80,4x120,4x200,4x300,2x120,6x120,6x200,6x300"


def run(path: Path, methods: tuple[str, ...]) -> list[dict[str, object]]:
    st = load_station(path)
    models = {r.name: load_cell_robot(r.cell) for r in st.robots}
    rows: list[dict[str, object]] = []
    for method in methods:
        t0 = time.process_time()
        plan = plan_station(st, models, StationOptions(method=method))  # type: ignore[arg-type]
        cpu = time.process_time() - t0
        row: dict[str, object] = {"station": st.name, "robots": len(st.robots), "spots": len(st.spots),
                                  "method": method, "status": plan.status, "cpu_s": round(cpu, 2),
                                  "bound_s": round(plan.bound.value, 3),
                                  "bound_parts_s": [round(plan.bound.single, 3), round(plan.bound.shared, 3),
                                                    round(plan.bound.partition, 3)],
                                  "stages_s": {k: round(v, 2) for k, v in plan.seconds.items()}}
        if plan.status == "planned" and plan.coordination is not None:
            sched = plan.coordination.schedule
            row.update(makespan_s=round(plan.makespan, 3), waits_s=round(sum(sched.waited(r) for r in sched.ends), 3),
                       interlocks=len(plan.coordination.interlocks),
                       gap=round((plan.makespan - plan.bound.value) / plan.makespan, 3), reassigned=plan.rounds,
                       orders_tried=plan.orders_tried, orders_skipped=plan.orders_skipped,
                       orders_kept=[c.why for c in plan.order_changes])
        else:
            row["message"] = plan.message
        rows.append(row)
        print(json.dumps(row), flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="one tiny station (the CI smoke run)")
    ap.add_argument("--sizes", default=GROWTH, help="robots x spots, comma-separated")
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--arms", default="shipped",
                    help='"shipped" (the shipped example\'s), "drawn" (from the seed) or a list, repeated to the robots')
    ap.add_argument("--methods", default="full", help=f"comma-separated, of {', '.join(METHODS)}")
    ap.add_argument("--json", type=Path, help="write every row here")
    args = ap.parse_args()
    sizes = [(2, 8)] if args.quick else [tuple(int(v) for v in s.split("x")) for s in args.sizes.split(",")]
    methods = METHODS if args.quick else tuple(args.methods.split(","))
    rows: list[dict[str, object]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for robots, spots in sizes:
            for seed in range(args.first_seed, args.first_seed + args.seeds):
                # The shipped example's arms: KR 125-class in front, UR10 behind (arms drawn at random
                # leave corner spots that no robot reaches on some seeds). With these the seed changes
                # nothing: the station's only draw is its arms.
                arms: list[str] | None = ["kr125"] * ((robots + 1) // 2) + ["ur10"] * (robots // 2)
                if args.arms == "drawn":
                    arms = None
                elif args.arms != "shipped":
                    arms = (args.arms.split(",") * robots)[:robots]
                path = write(Path(tmp), station(robots, spots, seed, arms))
                rows += run(path, methods)
    table(rows)
    growth(rows)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")


def table(rows: list[dict[str, object]]) -> None:
    print(f"\n{'station':<24} {'method':<8} {'makespan':>9} {'waits':>7} {'locks':>5} {'gap':>6} {'cpu':>7} {'orders':>6}"
          "  stages")
    for r in rows:
        stages = " ".join(f"{k} {v}" for k, v in dict(r["stages_s"]).items())  # type: ignore[call-overload]
        print(f"{r['station']:<24} {r['method']:<8} {r.get('makespan_s', float('nan')):>9} "
              f"{r.get('waits_s', float('nan')):>7} {r.get('interlocks', '-'):>5} {r.get('gap', '-'):>6} "
              f"{r['cpu_s']:>7} {len(r.get('orders_kept', [])):>3}/{r.get('orders_tried', 0):<2}  {stages}")


def growth(rows: list[dict[str, object]]) -> None:
    """CPU and makespan (medians over seeds) against spots per robot count and against robots per
    spot count, and the exponent of CPU in spots (log-log least squares)."""
    cell: dict[tuple[str, int, int], list[dict[str, object]]] = defaultdict(list)
    for r in rows:
        cell[(str(r["method"]), int(r["robots"]), int(r["spots"]))].append(r)  # type: ignore[call-overload]

    def med(rs: list[dict[str, object]], key: str) -> float:
        vals = [float(r[key]) for r in rs if key in r]  # type: ignore[arg-type]
        return float(np.median(vals)) if vals else math.nan

    for axis, other in (("spots", "robots"), ("robots", "spots")):
        groups: dict[tuple[str, int], list[tuple[int, float, float]]] = defaultdict(list)
        for (method, robots, spots), rs in sorted(cell.items()):
            fixed, varied = (robots, spots) if axis == "spots" else (spots, robots)
            groups[(method, fixed)].append((varied, med(rs, "cpu_s"), med(rs, "makespan_s")))
        for (method, fixed), pts in groups.items():
            if len(pts) < 2:
                continue
            print(f"\n{method}, {fixed} {other}: {axis:>6} {'cpu s':>8} {'makespan s':>11}")
            for varied, cpu, span in pts:
                print(f"{'':>{len(method) + len(str(fixed)) + len(other) + 4}}{varied:>6} {cpu:>8.1f} {span:>11.2f}")
            planned = [p for p in pts if math.isfinite(p[2])]
            if axis == "spots" and len(planned) >= 2:
                x, y = np.log([p[0] for p in planned]), np.log([p[1] for p in planned])
                print(f"  CPU ~ spots^{np.polyfit(x, y, 1)[0]:.2f} (least squares on log-log over the "
                      f"{len(planned)} planned sizes)")


if __name__ == "__main__":
    main()
