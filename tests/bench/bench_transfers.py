"""Pick-and-place transfers planned by Diane and Anikina's method (`planner.transfers: associative`)
against the default planner (`moves`), on the shipped pick-and-place cell (a script, not a test):

    python tests/bench/bench_transfers.py [--transfers N] [--runs 3] [--out DIR] [--sweep]

Plans cells/pick_place.yaml (its first N transfers, default all 10) both ways and prints per
transfer the time from leaving the pick to arriving at the place (retract, carried move, approach),
and for the associative plan the transfer's table (grid rows, stored rows K*), its route (nodes,
edges checked and found blocked), the largest distance of the interpolated point from its edge's
line (the TCP pose's point, m), the largest distance of the timed TCP from the polyline through
the TCP at the route's nodes (the program flies by them), and the CPU of planning the transfer
again from its two ends (table and route). Then the cycle, the planning CPU (`time.process_time` of `plan_cell` in one
process, median of the runs, after a warm-up plan), and the checks: the planner's own, SRCL
written and proven (`write_programs`), and `verify_program` of the written file.

--sweep plans the associative cell once per setting instead (the grid step, k, waypoints along
the route's edges; `plan.associative.AssociativeSettings`, set here as the planner's default) and
prints the cycle, the sum of the transfers and the planning CPU of each.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import math
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

import robomax_py as rm
from robomax_py.plan import associative
from robomax_py.plan.associative import AssociativeSettings, plan_transfer
from robomax_py.plan.loads import Loads
from robomax_py.robot import fk_tcp

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "cells" / "pick_place.yaml"


def _cell(transfers: int | None, option: str) -> rm.LoadedCell:
    data = yaml.safe_load(CELL.read_text())
    if transfers is not None:
        data["pick_place"]["transfers"] = data["pick_place"]["transfers"][:transfers]
    data.setdefault("planner", {})["transfers"] = option
    return rm.load_cell(data, base_dir=CELL.parent)


def _transfer_times(result: rm.PlanResult) -> list[float]:
    spots = result.spots
    return [spots[k + 1].t_arrive - spots[k].t_leave for k in range(0, len(spots) - 1, 2)]


def _off_route(cell: rm.LoadedCell, result: rm.PlanResult, trans: rm.Transition) -> float:
    """The largest distance (m) of the timed TCP from the polyline through the TCP at the
    transition's waypoints, over its samples."""
    traj = result.trajectory
    assert traj is not None
    phases = traj.phases_of(trans.kind, trans.label)
    t0, t1 = phases[0].t_start, phases[-1].t_end
    keep = (traj.t >= t0) & (traj.t <= t1)
    p = fk_tcp(cell.robot, traj.q[keep])[:, :3, 3]
    nodes = fk_tcp(cell.robot, np.asarray(trans.waypoints))[:, :3, 3]
    a, b = nodes[:-1], nodes[1:]
    ab = b - a
    t = np.clip(np.einsum("mkd,kd->mk", p[:, None, :] - a[None], ab) / np.maximum((ab * ab).sum(axis=1), 1e-12), 0, 1)
    d = np.linalg.norm(p[:, None, :] - (a[None] + t[..., None] * ab[None]), axis=2)
    return float(d.min(axis=1).max())


SWEEP = (
    ("20°, k 6", AssociativeSettings(k=6)),
    ("20°, k 12", AssociativeSettings(k=12)),
    ("20°, k 24", AssociativeSettings(k=24)),
    ("20°, k 48 (default)", AssociativeSettings()),
    ("20°, k 72", AssociativeSettings(k=72)),
    ("10°, k 48", AssociativeSettings(step=math.radians(10))),
    ("20°, k 48, rows every 0.1 m", AssociativeSettings(waypoint_spacing=0.1)),
)


def sweep(cell: rm.LoadedCell) -> None:
    rm.plan_cell(cell)                                            # warm-up
    print(f"{'setting':30s} {'cycle s':>8s} {'transfers s':>11s} {'CPU s':>6s}")
    for name, settings in SWEEP:
        # The planner takes the method's defaults; a bench may change them, the package never does.
        associative.associative_moves.__defaults__ = (settings,)
        t0 = time.process_time()
        result = rm.plan_cell(cell)
        cpu = time.process_time() - t0
        if result.status != "planned":
            print(f"{name:30s} {result.message}")
            continue
        print(f"{name:30s} {result.cycle_time:8.3f} {sum(_transfer_times(result)):11.3f} {cpu:6.2f}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--transfers", type=int, default=None, help="the cell's first N transfers (default: all)")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", type=Path, default=None, help="write the SRCL programs here (default: a temporary folder)")
    ap.add_argument("--sweep", action="store_true", help="the associative plan once per setting (step, k, waypoints)")
    args = ap.parse_args()
    if args.sweep:
        sweep(_cell(args.transfers, "associative"))
        return
    cells = {option: _cell(args.transfers, option) for option in ("moves", "associative")}
    rm.plan_cell(cells["moves"])                                  # warm-up: compiled kernels, caches
    results: dict[str, rm.PlanResult] = {}
    cpu: dict[str, float] = {}
    for option, cell in cells.items():
        runs = []
        for _ in range(args.runs):
            t0 = time.process_time()
            results[option] = rm.plan_cell(cell)
            runs.append(time.process_time() - t0)
        cpu[option] = statistics.median(runs)
        assert results[option].status == "planned", results[option].message
    moves, assoc = results["moves"], results["associative"]
    cell = cells["associative"]
    loads = Loads.of(cell.spec, cell.robot)
    assert loads is not None
    carried = [t for t in assoc.transitions if t.part is not None]
    print(f"{'transfer':42s} {'moves s':>8s} {'assoc. s':>8s} {'rows':>7s} {'K*':>7s} {'nodes':>5s} {'edges':>6s} "
          f"{'blocked':>7s} {'line mm':>7s} {'route mm':>8s} {'CPU s':>6s}")
    for k, (tm, ta, trans) in enumerate(zip(_transfer_times(moves), _transfer_times(assoc), carried)):
        wp = np.asarray(trans.waypoints)
        t0 = time.process_time()
        again = plan_transfer(cell.robot, loads.worlds[str(trans.part)], wp[0], wp[-1])
        route_cpu = time.process_time() - t0
        r = again.route
        print(f"{trans.label:42s} {tm:8.3f} {ta:8.3f} {again.grid_rows:7,d} {again.stored:7,d} "
              f"{len(r.nodes):5d} {r.edge_checks:6d} {len(r.blocked):7d} {1000 * again.line_error:7.1f} "
              f"{1000 * _off_route(cell, assoc, trans):8.1f} {route_cpu:6.2f}")
    print(f"{'sum of transfers':42s} {sum(_transfer_times(moves)):8.3f} {sum(_transfer_times(assoc)):8.3f}")
    print(f"{'cycle':42s} {moves.cycle_time:8.3f} {assoc.cycle_time:8.3f}")
    print(f"{'planning CPU s (median of ' + str(args.runs) + ')':42s} {cpu['moves']:8.2f} {cpu['associative']:8.2f}")
    stages = assoc.stats.seconds if assoc.stats else {}
    print("associative stages: " + ", ".join(f"{k} {v:.2f}" for k, v in stages.items()))
    out = args.out or Path(tempfile.mkdtemp(prefix="bench_transfers_"))
    for option, result in results.items():
        written = rm.write_programs(cells[option], result, out / option)
        srcl = next(p for p in written if p.suffix == ".srcl")
        report = rm.verify_program(cells[option], srcl)
        print(f"{option}: {srcl} written and proven; verify: {'clean' if report.clean else report.violations[0]}")


if __name__ == "__main__":
    main()
