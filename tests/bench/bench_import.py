"""Figures for arms from ROS-Industrial (tests/data/rosi): `import-urdf` time (CPU s, median of
--runs), the fitted solver's FK agreement with the URDF, and IK round trips over random poses.

    python tests/bench/bench_import.py [--runs 5] [--poses 2000]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from robomax_py.app.import_urdf import import_urdf
from robomax_py.io.robot import load_robot_spec
from robomax_py.robot import fk_flange, load_robot
from robomax_py.robot.ik.fit import fk_agreement
from robomax_py.robot.solve import solve_all

ROSI = Path(__file__).resolve().parent.parent / "data" / "rosi"
ARMS = {
    "irb2400": ROSI / "abb_irb2400_support/urdf/irb2400.xacro",
    "m20ia": ROSI / "fanuc_m20ia_support/urdf/m20ia.xacro",
    "kr120r2500pro": ROSI / "kuka_kr120_support/urdf/kr120r2500pro.xacro",
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--poses", type=int, default=2000)
    args = ap.parse_args()
    print(f"{'arm':15} {'import CPU s (median)':>22} {'FK vs URDF (m)':>15} {'IK pos err max (m)':>19} {'q recovered':>12}")
    for name, source in ARMS.items():
        cpu = []
        for _ in range(args.runs):
            with tempfile.TemporaryDirectory() as tmp:
                t0 = time.process_time()
                folder = import_urdf(source, Path(tmp) / name, (ROSI,)).folder
                cpu.append(time.process_time() - t0)
                robot = load_robot(load_robot_spec(folder / "robot.yaml"))
        agree = fk_agreement(robot.model, robot.flange_frame_id, robot.ik_params, samples=1000)
        rng = np.random.default_rng(0)
        qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(args.poses, 6))
        qs = qs[np.abs(np.sin(qs[:, 4])) > 1e-3]
        T = fk_flange(robot, qs)
        table = solve_all(robot, T)
        err = 0.0
        for i in range(len(qs)):
            sols = table.q[i][table.valid[i]]
            err = max(err, float(np.abs(fk_flange(robot, sols)[:, :3, 3] - T[i, :3, 3]).max()))
        recovered = np.mean([
            np.abs(np.angle(np.exp(1j * (table.q[i][table.valid[i]] - qs[i])))).max(axis=1).min() < 1e-6
            for i in range(len(qs))])
        print(f"{name:15} {statistics.median(cpu):>22.3f} {agree.position_m:>15.1e} {err:>19.1e} {recovered:>11.1%}")


if __name__ == "__main__":
    main()
