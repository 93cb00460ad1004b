"""What a first plan pays numba for the pre-filter's kernels: CPU seconds of compile per compiled
function (its own typing, lowering and LLVM passes, without the functions it calls, which are
listed on their own), from numba's compile events, in a fresh cache; then the compiled kernels'
run time, so that a cheaper compile is not bought with slower kernels.

    python tests/bench/bench_jit_compile.py [CELL]

CELL: the reference cell unless given. Each call is one process: numba keeps what it compiled.
"""

from __future__ import annotations

import argparse
import collections
import os
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("cell", nargs="?", type=Path, default=REFERENCE_CELL)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        # Before numba is imported: a fresh cache, so that every kernel compiles.
        os.environ["NUMBA_CACHE_DIR"] = str(Path(tmp) / "numba")
        os.environ["ROBOMAX_CACHE"] = str(Path(tmp) / "robomax")
        sys.path.insert(0, str(REPO))
        run(args.cell)


def run(cell_path: Path) -> None:
    import numpy as np
    from numba.core import event

    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.world.collision import CollisionWorld
    from robomax_py.world.scene import build_scene

    own: collections.Counter[str] = collections.Counter()
    stack: list[list[float]] = []           # per compile under way: [start, CPU of its nested compiles]

    class Compiles(event.Listener):         # type: ignore[misc]  # numba is untyped
        def on_start(self, ev: event.Event) -> None:
            stack.append([time.process_time(), 0.0])

        def on_end(self, ev: event.Event) -> None:
            start, nested = stack.pop()
            spent = time.process_time() - start
            fn = ev.data["dispatcher"].py_func
            own[f"{fn.__module__.rsplit('.', 1)[-1]}.{fn.__name__}"] += spent - nested
            if stack:
                stack[-1][1] += spent

    event.register("numba:compile", Compiles())
    cell = load_cell(cell_path)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    filt = world._s.prefilter
    if filt is None:
        raise SystemExit(f"{cell_path.name}: its robot has no pre-filter")
    active = np.ones(world.n_pairs, dtype=bool)
    rng = np.random.default_rng(0)
    qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(4000, robot.dof))
    calls = {"uncleared": lambda: filt.uncleared(qs, active),
             "near": lambda: filt.near(qs[:8], active),
             "near_reach": lambda: [filt.near_reach(qs[i:i + 3], active) for i in range(0, 600, 3)],
             "joint_placements": lambda: filt.joint_placements(qs[0])}
    print(f"{cell_path.name}: pre-filter kernels, CPU s")
    print(f"{'first call (compile)':>24} {'run, compiled':>14}")
    for name, call in calls.items():
        start = time.process_time()
        call()
        first = time.process_time() - start
        runs = []
        for _ in range(3):
            start = time.process_time()
            call()
            runs.append(time.process_time() - start)
        print(f"{name:>16} {first:7.2f} {min(runs) * 1e3:11.1f} ms")
    print("compile per function (its own, callees apart):")
    for fn, spent in own.most_common():
        print(f"  {fn:60.60s} {spent:6.2f}")
    print(f"  {'total':60s} {sum(own.values()):6.2f}")


if __name__ == "__main__":
    main()
