"""Associative-memory IK on the paper's planar case (a script, not a test):

    python tests/bench/bench_table_ik.py

The 3-link planar arm (links 1, 0.65, 0.41 m, joints in [-90, 90] deg) at the centre of the floor
of a 2 x 2 m container with shelves (`robot.planar`; the shelves laid out after the paper's figure,
its dimensions not given), held part 0.25 m. Prints the table sizes K* for J = 18 (the paper's
"10 deg": 180/17 = 10.6 deg) and J = 9 ("20 deg": 22.5 deg), without and with the part, beside the
paper's 1,598 / 1,128 / 134, the CPU seconds to build each, and lookups per second (one process,
median of 3): 100,000 random targets in one batch, and one target per call. The target is
100,000 lookups per second.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import statistics
import time

import numpy as np

from robomax_py.robot.ik.table import JointGrid, build_table
from robomax_py.robot.planar import Container, PlanarArm

PAPER = {(18, False): 1598, (18, True): 1128, (9, False): 134}
HELD_M = 0.25


def main() -> None:
    box = Container.storage()
    print(f"{'J':>3s} {'part':>5s} {'K*':>6s} {'paper':>6s} {'rows':>6s} {'build s':>8s}")
    tables = {}
    for J in (18, 9):
        for held in (False, True):
            arm = PlanarArm(held=HELD_M if held else 0.0)
            grid = JointGrid.stepped((-np.pi / 2,) * 3, (np.pi / 2,) * 3, J)
            t0 = time.process_time()
            table = build_table(grid, arm.tip, lambda q, a=arm: box.free(a, q))
            cpu = time.process_time() - t0
            tables[(J, held)] = table
            paper = PAPER.get((J, held))
            print(f"{J:3d} {'yes' if held else 'no':>5s} {len(table):6d} {paper if paper else '-':>6} {grid.size:6d} "
                  f"{cpu:8.2f}")
    table = tables[(18, False)]
    rng = np.random.default_rng(0)
    targets = np.column_stack([rng.uniform(-1.0, 1.0, 100_000), rng.uniform(0.0, 2.0, 100_000)])
    batch, single = [], []
    for _ in range(3):
        t0 = time.process_time()
        table.lookup(targets)
        batch.append(len(targets) / (time.process_time() - t0))
        t0 = time.process_time()
        for t in targets[:20_000]:
            table.nearest(t)
        single.append(20_000 / (time.process_time() - t0))
    print(f"lookups/s (J = 18, K* = {len(table)}): batch of 100,000 {statistics.median(batch):,.0f}, "
          f"one per call {statistics.median(single):,.0f}")


if __name__ == "__main__":
    main()
