"""IK throughput benchmark (not a test): python tests/bench/bench_ik.py [--quick]

Single core: BLAS is pinned to one thread before numpy loads, and times are CPU seconds of this
process (time.process_time), so other load on the machine does not distort them. Each figure is the
median of 5 runs. Target: >= 200,000 OPW poses/s batched.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import sys
from collections.abc import Callable
from importlib import metadata
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from robomax_py.app.bench import median_cpu_seconds
from robomax_py.robot.ik._chain import chain_to_frame, frame_pose
from robomax_py.robot.ik.numeric import numeric_ik
from robomax_py.robot.ik.opw import OpwParams, opw_fk, opw_ik
from robomax_py.robot.ik.turns import expand, turn_shifts
from robomax_py.robot.ik.ur import UR10_EXAMPLE_ROBOT_DATA, ur_fk, ur_ik

RUNS = 5
KR16 = OpwParams(
    a1=0.26, a2=0.035, b=0.0, c1=0.675, c2=0.68, c3=0.67, c4=0.158,
    offsets=(0.0, -np.pi / 2, 0.0, 0.0, 0.0, 0.0), sign_corrections=(-1, 1, 1, -1, 1, -1),
)


def median_rate(fn: Callable[[], object], items: int) -> float:
    """items per CPU second, median over RUNS calls of fn (after one warm-up call)."""
    return items / median_cpu_seconds(fn, RUNS)


def ur10_urdf() -> str:
    for f in metadata.files("example-robot-data") or []:
        if str(f).endswith("ur_description/urdf/ur10_robot.urdf"):
            return str(f.locate())
    raise SystemExit("example-robot-data's ur10_robot.urdf not found")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="smaller batches")
    args = parser.parse_args()
    batch = 2_000 if args.quick else 10_000
    single = 200 if args.quick else 1_000
    rng = np.random.default_rng(0)

    q_kr = rng.uniform(-np.pi, np.pi, size=(batch, 6))
    T_kr = opw_fk(KR16, q_kr)
    q_ur = rng.uniform(-np.pi, np.pi, size=(batch, 6))
    T_ur = ur_fk(UR10_EXAMPLE_ROBOT_DATA, q_ur)
    model = pin.buildModelFromUrdf(ur10_urdf())
    data = model.createData()
    fid = model.getFrameId("tool0")
    chain = chain_to_frame(model, fid)
    kr_lower = np.radians([-185, -155, -130, -350, -130, -350])
    kr_upper = np.radians([185, 35, 154, 350, 130, 350])
    variants = turn_shifts(kr_lower, kr_upper)

    def opw_one_at_a_time() -> None:
        for T in T_kr[:single]:
            opw_ik(KR16, T)

    def ur_one_at_a_time() -> None:
        for T in T_ur[:single]:
            ur_ik(UR10_EXAMPLE_ROBOT_DATA, T)

    def pin_fk() -> None:
        for q in q_ur[:single]:
            pin.framesForwardKinematics(model, data, q)

    def opw_with_turns() -> None:
        q, valid = opw_ik(KR16, T_kr)
        expand(q, valid, variants)

    n_numeric = 100 if args.quick else 500
    rows = [
        ("OPW IK (kr16), batched", lambda: opw_ik(KR16, T_kr), batch, "poses/s"),
        ("OPW IK (kr16), one pose per call", opw_one_at_a_time, single, "poses/s"),
        (f"OPW IK + {variants.count} turn variants + limits", opw_with_turns, batch, "poses/s"),
        ("UR IK (ur10), batched", lambda: ur_ik(UR10_EXAMPLE_ROBOT_DATA, T_ur), batch, "poses/s"),
        ("UR IK (ur10), one pose per call", ur_one_at_a_time, single, "poses/s"),
        ("OPW FK (closed form), batched", lambda: opw_fk(KR16, q_kr), batch, "configs/s"),
        ("Pinocchio FK (ur10), one per call", pin_fk, single, "configs/s"),
        ("numpy chain FK (ur10), batched", lambda: frame_pose(chain, q_ur), batch, "configs/s"),
        (
            "numeric IK (ur10), 32 seeds, batched",
            lambda: numeric_ik(model, fid, T_ur[:n_numeric], model.lowerPositionLimit, model.upperPositionLimit,
                               np.random.default_rng(1), 32),
            n_numeric,
            "poses/s",
        ),
    ]
    width = max(len(r[0]) for r in rows)
    print(f"{'benchmark':<{width}}  {'rate':>12}  unit       (median of {RUNS}, CPU time, 1 thread)")
    for name, fn, items, unit in rows:
        print(f"{name:<{width}}  {median_rate(fn, items):>12,.0f}  {unit}")


if __name__ == "__main__":
    main()
