"""Minimum-time quintic Bézier paths for a point robot (Benko Loknar, Klančar, Blažič), the
structure of their Table 2 on a planar layout of ours, and the comparison with toppra and ruckig.

    python tests/bench/bench_bezier.py [--repeat 3]

Layout: pick-up at (0, 0) facing +x, round two rack corners at (6, 1) and (8, 6), drop-off at
(14, 7) facing +x (m). Limits are the paper's (unloaded: v 1.5, a_R 4, a_T 2, j_R 10, j_T 8;
loaded: v 1.5, a_R 1, a_T 0.5, j_R 2.5, j_T 2). The path is optimised once for each limit set;
each is then timed under both. Times are the jerk-limited profiles' travel times; CPU is the
median over the repeats.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from robomax_py.spec import TcpLimits
from robomax_py.timing.bezier import jerk_limited, optimise_path, profile_peaks
from robomax_py.timing.path_baselines import ruckig_per_segment_time, toppra_time

UNLOADED = TcpLimits(v=1.5, a_T=2.0, a_R=4.0, j_T=8.0, j_R=10.0)
LOADED = TcpLimits(v=1.5, a_T=0.5, a_R=1.0, j_T=2.0, j_R=2.5)
WAYPOINTS = np.array([[0.0, 0.0], [6.0, 1.0], [8.0, 6.0], [14.0, 7.0]])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    cpu: dict[str, list[float]] = {}
    rows = {}
    for _ in range(args.repeat):
        paths = {}
        for name, lim in (("unloaded", UNLOADED), ("loaded", LOADED)):
            t0 = time.process_time()
            paths[name] = optimise_path(WAYPOINTS, 0.0, 0.0, lim)[1]
            cpu.setdefault(f"optimise path for {name}", []).append(time.process_time() - t0)
        for run, lim in (("unloaded", UNLOADED), ("loaded", LOADED)):
            for opt in ("unloaded", "loaded"):
                t0 = time.process_time()
                prof = jerk_limited(paths[opt], lim)
                cpu.setdefault(f"profile {run} on {opt} path", []).append(time.process_time() - t0)
                peaks = profile_peaks(prof, paths[opt])
                rows[(run, opt)] = (prof.duration, peaks)
        for run, lim in (("unloaded", UNLOADED), ("loaded", LOADED)):
            t0 = time.process_time()
            rows[("toppra", run)] = toppra_time(paths[run], lim)
            cpu.setdefault(f"toppra {run}", []).append(time.process_time() - t0)
            t0 = time.process_time()
            rows[("ruckig", run)] = ruckig_per_segment_time(paths[run], lim)
            cpu.setdefault(f"ruckig {run}", []).append(time.process_time() - t0)
    print("| limits | path optimised for | travel time | peak v / a_T / a_R / j_T / j_R |")
    print("|---|---|---|---|")
    for (run, opt), (duration, p) in sorted((k, v) for k, v in rows.items() if k[0] in ("unloaded", "loaded")):
        print(f"| {run} | {opt} | {duration:.3f} s | {p.v:.3f} / {p.a_T:.3f} / {p.a_R:.3f} / {p.j_T:.3f} / {p.j_R:.3f} |")
    print()
    print("| limits (own path) | jerk-limited Bézier profile | toppra (v, a only) | ruckig per segment |")
    print("|---|---|---|---|")
    for run in ("unloaded", "loaded"):
        print(f"| {run} | {rows[(run, run)][0]:.3f} s | {rows[('toppra', run)]:.3f} s | {rows[('ruckig', run)]:.3f} s |")
    print()
    for k, v in cpu.items():
        print(f"CPU {k}: median {statistics.median(v):.3f} s")


if __name__ == "__main__":
    main()
