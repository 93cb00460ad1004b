"""Multi-robot stations: the full method against two baselines on the same seeded stations
(tests/bench/station_cells.py), docs/stations.md's figures.

  (a) nearest: each spot to the nearest robot that reaches it, each robot sequenced alone, collisions
      resolved by waiting, first come first served;
  (b) minmax: the min-max assignment, zone orders by look-ahead, no re-assignment;
  (c) full: (b) and re-assignment where waits cost more than another assignment.

Per station and method: makespan, total waits, interlocks written, planning CPU, gap to the lower
bound; and growth with robots and spots.

    PYTHONPATH=. python tests/bench/bench_station.py [--quick] [--sizes 2x40,4x120] [--seeds 1] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.station.pipeline import StationOptions, plan_station
from tests.bench.station_cells import station, write

METHODS = ("nearest", "minmax", "full")


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
                                  "bound_s": round(plan.bound.value, 3)}
        if plan.status == "planned" and plan.coordination is not None:
            sched = plan.coordination.schedule
            row.update(makespan_s=round(plan.makespan, 3), waits_s=round(sum(sched.waited(r) for r in sched.ends), 3),
                       interlocks=len(plan.coordination.interlocks),
                       gap=round((plan.makespan - plan.bound.value) / plan.makespan, 3), reassigned=plan.rounds)
        else:
            row["message"] = plan.message
        rows.append(row)
        print(json.dumps(row), flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="one tiny station (the CI smoke run)")
    ap.add_argument("--sizes", default="2x40,4x80,6x120", help="robots x spots, comma-separated")
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--json", type=Path, help="write every row here")
    args = ap.parse_args()
    sizes = [(2, 4)] if args.quick else [tuple(int(v) for v in s.split("x")) for s in args.sizes.split(",")]
    methods = tuple(args.methods.split(","))
    rows: list[dict[str, object]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for robots, spots in sizes:
            for seed in range(args.seeds):
                arms = ["kr125", "ur10"] if args.quick else None
                path = write(Path(tmp), station(robots, spots, seed, arms))
                rows += run(path, methods)
    print(f"\n{'station':<24} {'method':<8} {'makespan':>9} {'waits':>7} {'locks':>5} {'gap':>6} {'cpu':>7}")
    for r in rows:
        print(f"{r['station']:<24} {r['method']:<8} {r.get('makespan_s', float('nan')):>9} "
              f"{r.get('waits_s', float('nan')):>7} {r.get('interlocks', '-'):>5} {r.get('gap', '-'):>6} {r['cpu_s']:>7}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
