"""Voxel free-space benchmark (a script, not a test): python tests/bench/bench_voxels.py [CELL...]

Builds the adaptive voxel map (`world.voxels`) of each cell's static objects over a cube round the
robot's reach (x, y in +-3.2 m, z from -0.5 to 2.9 m, base frame) at precision limits of 40, 20 and
10 mm, no inflation; prints leaves, free leaves, coal tests and the CPU seconds of this process
(median of 3). The target: a shipped cell in < 2 s at 10 mm on one core.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import statistics
import sys
import time
from pathlib import Path

import numpy as np

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.world.scene import build_scene
from robomax_py.world.voxels import build_voxels

REPO = Path(__file__).resolve().parents[2]
CELLS = [REPO / "tests" / "data" / "reference" / "cabin_flange.yaml", *sorted((REPO / "cells").glob("*.yaml"))]
LO, HI = np.array([-3.2, -3.2, -0.5]), np.array([3.2, 3.2, 2.9])


def main() -> None:
    cells = [Path(a) for a in sys.argv[1:]] or CELLS
    print(f"{'cell':28s} {'mm':>4s} {'leaves':>9s} {'free':>8s} {'tests':>11s} {'CPU s':>7s}")
    for path in cells:
        cell = load_cell(path)
        scene = build_scene(cell, load_cell_robot(cell))
        for precision in (0.04, 0.02, 0.01):
            seconds = []
            for _ in range(3):
                t0 = time.process_time()
                v = build_voxels(scene, LO, HI, precision)
                seconds.append(time.process_time() - t0)
            print(f"{path.parent.name + '/' + path.stem:28s} {precision * 1000:4.0f} {len(v.edge):9,} "
                  f"{int(v.free.sum()):8,} {v.tests:11,} {statistics.median(seconds):7.2f}", flush=True)


if __name__ == "__main__":
    main()
