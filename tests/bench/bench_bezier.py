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
    follow_arm()
    print()
    for k, v in cpu.items():
        print(f"CPU {k}: median {statistics.median(v):.3f} s")


def follow_arm() -> None:
    """The KR 16 of cells/pick_place.yaml carrying its housing along a Bézier path optimised for
    the housing's TCP limits, from table a to table b at 1 m height, the gripper pointing down."""
    from pathlib import Path

    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.plan.bezier_follow import follow_within_limits
    from robomax_py.robot.solve import solve_all
    from robomax_py.world.collision import CollisionWorld
    from robomax_py.world.scene import build_scene

    cell = load_cell(Path(__file__).resolve().parents[2] / "cells" / "pick_place.yaml")
    robot = load_cell_robot(cell)
    housing = cell.part("housing")
    assert housing.limits is not None
    world = CollisionWorld(robot, build_scene(cell, robot, held=housing), cell.process.clearance)
    waypoints = ARM_WAYPOINTS
    t0 = time.process_time()
    path = optimise_path(waypoints, np.pi / 2 - 0.6, np.pi / 2 + 0.6, housing.limits)[1]
    profile = jerk_limited(path, housing.limits)
    T0 = np.eye(4)
    T0[:2, 3], T0[2, 3] = waypoints[0], ARM_HEIGHT_M
    start = solve_all(robot, T0[None])
    q0 = start.q[0][start.valid[0]][0]
    followed = follow_within_limits(profile, robot, world, ARM_HEIGHT_M, np.eye(3), q0)
    cpu = time.process_time() - t0
    peaks = profile_peaks(profile, path)
    print(f"KR 16 carrying the housing along {len(waypoints) - 1} Bézier segments at z = {ARM_HEIGHT_M} m: TCP profile "
          f"{profile.duration:.3f} s (peaks v {peaks.v:.2f}, a_T {peaks.a_T:.2f}, a_R {peaks.a_R:.2f}); followed in joint "
          f"space {'clean' if followed.ok else followed.problem}, stretched x{followed.slowdown:.2f} for the joint "
          f"limits to {followed.t[-1]:.3f} s, TCP on the path within {followed.tcp_error_m:.1e} m, "
          f"{followed.collision_checks} collision checks with the part; CPU {cpu:.2f} s")


# The arm's path (base frame, m): table a to table b of cells/pick_place.yaml, in front of the rack.
ARM_WAYPOINTS = np.array([[0.25, -0.95], [0.55, -0.6], [0.55, 0.6], [0.25, 0.95]])
ARM_HEIGHT_M = 1.0


if __name__ == "__main__":
    main()
