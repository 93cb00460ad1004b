"""Collision-checking benchmark (not a test): python tests/bench/bench_collision.py [--quick]

The reference cell (kr125 + spot_gun_c, cabin_flange objects), random configurations uniformly
within the joint limits, one core: BLAS pinned to one thread before numpy loads, times are CPU
seconds of this process (time.process_time) so other load on the machine does not distort them.
Each rate is the median of 5 runs (after one warm-up run). Reported with the broad phase (default)
and without it (every enabled pair to the narrow phase, same early exit, same answers).
Modes: the default (bounding-volume pre-filter, then coal's exact test of the pairs it leaves),
coal's broad phase alone (Pinocchio's manager, the mode before the pre-filter; same run, for the
ratio) and the exhaustive narrow phase. Target: >= 250,000 configuration checks/s.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from robomax_py.app.bench import median_cpu_seconds
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

RUNS = 5
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"
SEGMENT_MAX_DEG = 10.0          # random short segments: each joint moves by at most this


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cell", type=Path, default=REFERENCE_CELL)
    parser.add_argument("--quick", action="store_true", help="fewer samples (smoke run)")
    args = parser.parse_args()
    n_configs = 4000 if args.quick else 20000
    n_segments = 40 if args.quick else 200
    rng = np.random.default_rng(0)

    t0 = time.process_time()
    cell = load_cell(args.cell)
    robot = load_cell_robot(cell)
    scene = build_scene(cell, robot)
    t1 = time.process_time()
    broad = CollisionWorld(robot, scene, cell.process.clearance)
    t2 = time.process_time()
    exhaustive = broad.copy(broad_phase=False)
    manager = broad.copy(prefilter=False)

    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    qs = rng.uniform(lower, upper, size=(n_configs, robot.dof))
    step = np.radians(SEGMENT_MAX_DEG)
    seg_a = rng.uniform(lower, upper, size=(n_segments, robot.dof))
    seg_b = np.clip(seg_a + rng.uniform(-step, step, size=seg_a.shape), lower, upper)

    # Answers and work per query, once (identical for both modes by construction; checked here too).
    free = broad.are_free(qs)
    if not (exhaustive.are_free(qs[: n_configs // 5]) == free[: n_configs // 5]).all():
        raise SystemExit("broad phase and exhaustive narrow phase disagree")
    tests = {}
    for label, world in (("broad", broad), ("exhaustive", exhaustive)):
        checks = [world.check(q) for q in qs[:2000]]
        tests[label] = (
            float(np.mean([c.narrow_phase_tests for c in checks])),
            float(np.mean([c.narrow_phase_tests for c in checks if c.free] or [0.0])),
        )
    seg_checks = [broad.check_segment(a, b) for a, b in zip(seg_a, seg_b)]
    seg_free = float(np.mean([s.free for s in seg_checks]))
    seg_states = float(np.mean([s.states for s in seg_checks]))
    seg_done = float(np.mean([s.checks for s in seg_checks]))

    rows = []
    for label, world, n in (("pre-filter", broad, n_configs), ("coal broad phase", manager, n_configs),
                            ("exhaustive", exhaustive, max(n_configs // 10, 500))):
        sub = qs[:n]
        m = n_segments if world is broad else max(n_segments // 10, 10)
        # Each lambda is timed before the loop moves on; the defaults bind this round's values.
        single = n / median_cpu_seconds(lambda w=world, s=sub: [w.is_free(q) for q in s], RUNS)
        batch = n / median_cpu_seconds(lambda w=world, s=sub: w.are_free(s), RUNS)
        seg_time = median_cpu_seconds(
            lambda w=world, m=m: [w.segment_free(a, b) for a, b in zip(seg_a[:m], seg_b[:m])], RUNS)
        rows.append((label, single, batch, m / seg_time, seg_done * m / seg_time))

    print(f"cell {cell.name}: robot {robot.name}, tool {cell.tool.name}, clearance {cell.process.clearance} m")
    print(f"pieces: {broad.geometry_model.ngeoms}, enabled pairs: {broad.n_pairs}, "
          f"disabled by the ACM: {len(broad.acm.disabled)}")
    print(f"build: cell+robot+scene {t1 - t0:.2f} s CPU, collision world (ACM incl.) {t2 - t1:.2f} s CPU")
    print(f"random configurations: {n_configs}, free {free.mean():.1%}; "
          f"segments: {n_segments} (<= {SEGMENT_MAX_DEG:g} deg per joint), free {seg_free:.1%}, "
          f"{seg_states:.0f} states each on average, {seg_done:.0f} checked (early exit)")
    print(f"lever arms (m/rad): {np.array2string(broad.lever_arms, precision=2)}")
    print()
    header = ("mode", "is_free /s", "are_free /s", "segments /s", "seg. states /s")
    print(f"{header[0]:<17}" + "".join(f"{h:>16}" for h in header[1:]))
    for label, single, batch, segs, states in rows:
        print(f"{label:<17}{single:>16,.0f}{batch:>16,.0f}{segs:>16,.1f}{states:>16,.0f}")
    print()
    bt, bt_free = tests["broad"]
    et, et_free = tests["exhaustive"]
    print("narrow-phase pair tests per configuration (mean over 2000; free configurations in brackets):")
    print(f"  broad phase {bt:8.2f} ({bt_free:.2f})   exhaustive {et:8.2f} ({et_free:.2f})   "
          f"of {broad.n_pairs} enabled pairs")
    print(f"  broad phase skips {1 - bt / max(et, 1e-9):.1%} of the narrow-phase tests "
          f"({1 - bt_free / max(et_free, 1e-9):.1%} on free configurations); "
          f"speed ratio vs exhaustive is_free {rows[0][1] / rows[2][1]:.1f}x, are_free {rows[0][2] / rows[2][2]:.1f}x")
    print(f"pre-filter vs coal's broad phase alone (same run): is_free {rows[0][1] / rows[1][1]:.2f}x, "
          f"are_free {rows[0][2] / rows[1][2]:.2f}x, swept states {rows[0][4] / rows[1][4]:.2f}x")
    target = 250_000
    print(f"target >= {target:,} checks/s: {'met' if rows[0][2] >= target else 'NOT met'} "
          f"(are_free {rows[0][2]:,.0f}/s, is_free {rows[0][1]:,.0f}/s)")


if __name__ == "__main__":
    main()
