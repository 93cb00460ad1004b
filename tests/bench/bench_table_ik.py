"""Associative-memory IK on the paper's planar case, and the table solver on a six-axis arm (a
script, not a test):

    python tests/bench/bench_table_ik.py [--figures DIR] [--quick] [--solvers]

The 3-link planar arm (links 1, 0.65, 0.41 m, joints in [-90, 90] deg) at the centre of the floor
of a 2 x 2 m container with shelves (`robot.planar`; the shelves laid out after the paper's figure,
its dimensions not given), held part 0.25 m. Prints:

- the table sizes K* for J = 18 (the paper's "10 deg": 180/17 = 10.6 deg) and J = 9 ("20 deg":
  22.5 deg), without and with the part, beside the paper's 1,598 (J = 18, no part), 1,128 (J = 18,
  part) and 134 (J = 9, part; the paper gives no count for J = 9 without it), and the CPU seconds
  to build each;
- the regression error against the grid step (the paper's open question): over targets reached by
  free random configurations, the distance of the nearest stored point (median, 95th percentile,
  largest) and the same after one step of formula (15) from its row;
- the route of the paper's Fig. 6 (J = 9 with the part, k = 4: the tip as the point, every k-NN
  edge, (15) from the start) and the checked route (the tip's pose as the point, edges used where
  (15) arrives and stays clear; J = 37), with the steps of each in collision;
- lookups per second (one process, median of 3): 100,000 random targets in one batch, and one
  target per call (not in --quick).

--figures DIR draws Fig. 3-6 as PNG there (docs/figures holds the documentation's copies).
--solvers prints the six-axis table the documentation cites instead: the KR 16 with
`ik.solver: table` (steps [30, 30, 30, 90, 60, 90] deg) against `numeric`, over 500 random
reachable flange poses: poses solved, solutions per pose, CPU. --quick: the figures and errors at
fewer steps and targets (a smoke run).
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import table_ik_figures as figs

from robomax_py.robot.planar import Container

# The paper's K* (Diane and Anikina, section IV): (J, part held) -> stored rows.
PAPER = {(18, False): 1598, (18, True): 1128, (9, True): 134}
ERROR_STEPS = (5, 9, 13, 18, 25, 37)
QUICK_ERROR_STEPS = (9, 18)
CHECKED_J = 37


def counts(box: Container) -> None:
    print(f"{'J':>3s} {'step':>6s} {'part':>5s} {'K*':>6s} {'paper':>6s} {'rows':>6s} {'build s':>8s}")
    for J in (18, 9):
        for held in (False, True):
            t0 = time.process_time()
            table = figs.point_table(J, figs.HELD_M if held else 0.0, box)
            cpu = time.process_time() - t0
            paper = PAPER.get((J, held))
            print(f"{J:3d} {180 / (J - 1):5.1f}° {'yes' if held else 'no':>5s} {len(table):6d} "
                  f"{paper if paper else '-':>6} {table.grid_size:6d} {cpu:8.2f}")


def errors(box: Container, steps: tuple[int, ...], targets: int) -> None:
    print(f"\nregression error against the grid step ({targets:,} targets per row, mm: median / 95 % / largest)")
    print(f"{'J':>3s} {'step':>6s} {'part':>5s} {'K*':>6s}  {'nearest stored point':>24s}  {'after one step of (15)':>24s}")
    rng = np.random.default_rng(0)
    for J in steps:
        for held in (0.0, figs.HELD_M):
            e = figs.regression_error(J, held, box, targets, rng)
            look = " / ".join(f"{1000 * v:.1f}" for v in e.lookup)
            ref = " / ".join(f"{1000 * v:.2f}" for v in e.refined)
            print(f"{J:3d} {180 / (J - 1):5.1f}° {'yes' if held else 'no':>5s} {e.stored:6d}  {look:>24s}  {ref:>24s}")


def routes(box: Container, out: Path | None, checked_J: int) -> None:
    print(f"\nroutes from {figs.PICK} to {figs.PLACE} m carrying the part")
    paper_table = figs.point_table(9, figs.HELD_M, box)
    t0 = time.process_time()
    paper = figs.paper_route(paper_table, figs.HELD_M, box)
    cpu_paper = time.process_time() - t0
    points = figs.point_table(checked_J, figs.HELD_M, box)
    t0 = time.process_time()
    checked = figs.checked_route(points, figs.HELD_M, box)
    cpu_checked = time.process_time() - t0
    for name, J, f, cpu in (("paper (tip, every edge)", 9, paper, cpu_paper),
                            ("checked (pose, lazy)", checked_J, checked, cpu_checked)):
        r = f.route
        bad = int((~f.free).sum())
        checks = f"{r.edge_checks} edges checked ({len(r.blocked)} blocked)" if f is checked else "no edge checked"
        print(f"  {name:24s} J = {J:2d}: {r.status}, {len(r.nodes)} nodes, length {r.length:.3f}, {checks}, "
              f"{bad} of {len(f.rows)} steps in collision, {cpu:.2f} s CPU")
    # Where the paper's integration ends against the stored configuration of its last node.
    drift = np.abs(paper.rows[-1] - paper_table.q[paper.route.nodes[-1]]).max() if paper.route.found else float("nan")
    print(f"  the paper's (15) arrives {np.degrees(drift):.0f} deg (largest joint) from the goal's stored configuration")
    if out is None:
        return
    J18 = 18
    empty, held = figs.point_table(J18, 0.0, box), figs.point_table(J18, figs.HELD_M, box)
    written = [
        figs.draw(out, "associative_fig3.png", box, f"Fig. 3: stored points, J = {J18} ({180 / (J18 - 1):.1f}°), no part: "
                  f"K* = {len(empty):,} (paper 1,598)", empty, 0.0),
        figs.draw(out, "associative_fig4.png", box, f"Fig. 4: stored points, J = {J18}, {figs.HELD_M} m part: "
                  f"K* = {len(held):,} (paper 1,128)", held, figs.HELD_M),
        figs.draw(out, "associative_fig5.png", box, f"Fig. 5: stored points, J = 9 (22.5°), {figs.HELD_M} m part: "
                  f"K* = {len(paper_table)} (paper 134)", paper_table, figs.HELD_M),
        figs.draw(out, "associative_fig6.png", box, f"Fig. 6: k-NN graph (k = {figs.PAPER_K}) and the route, J = 9 with "
                  "the part;\nthe tip as the point, every edge, (15) from the start", paper_table, figs.HELD_M, figs.PAPER_K,
                  ((paper, paper_table, "tab:purple", "the paper's route"),)),
        figs.draw(out, "associative_fig6_checked.png", box, f"The checked route, J = {checked_J} with the part:\nthe "
                  f"pose as the point, k = {figs.CHECKED_K}, edges where (15) arrives clear", points, figs.HELD_M,
                  None, ((checked, points, "tab:green", "checked route"),)),
    ]
    for p in written:
        print(f"wrote {p}")


def lookups(box: Container) -> None:
    table = figs.point_table(18, 0.0, box)
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
    print(f"\nlookups/s (J = 18, K* = {len(table)}): batch of 100,000 {statistics.median(batch):,.0f}, "
          f"one per call {statistics.median(single):,.0f}")


def solvers(poses: int) -> None:
    """The KR 16 with the table solver (three numbers of seeds) and the numeric one."""
    from robomax_py.io.robot import load_robot_spec
    from robomax_py.robot import fk_flange, load_robot
    from robomax_py.robot.ik import pose_table
    from robomax_py.robot.ik.numeric import NumericIkParams
    from robomax_py.robot.ik.pose_table import TableIkParams, flange_table
    from robomax_py.robot.solve import solve_all

    repo = Path(__file__).resolve().parents[2]
    robot = load_robot(load_robot_spec(repo / "robomax_py" / "robots" / "kr16" / "robot.yaml"))
    step = tuple(np.radians([30, 30, 30, 90, 60, 90]))
    rng = np.random.default_rng(3)
    qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(poses, robot.dof))
    T = fk_flange(robot, qs)
    ready = []
    for _ in range(2):
        pose_table._MEMORY.clear()                    # as a new process: built, or read from the cache
        t0 = time.process_time()
        table = flange_table(robot.model, robot.flange_frame_id, np.asarray(robot.limits.lower),
                             np.asarray(robot.limits.upper), TableIkParams(step))
        ready.append(time.process_time() - t0)
    print(f"KR 16 table, steps [30, 30, 30, 90, 60, 90] deg: {len(table):,} rows, ready in {ready[0]:.2f} s CPU "
          f"(built, unless the cache held it), then read back from the cache in {ready[1]:.2f} s")
    print(f"{'seeds per pose':28s} {'poses solved':>13s} {'solutions per pose':>19s} {f'CPU for {poses} poses':>18s}")
    variants = [(f"table, {n} nearest rows", "table", TableIkParams(step, neighbours=n)) for n in (16, 32, 64)]
    variants += [(f"numeric, {n} random", "numeric", NumericIkParams(seeds=n)) for n in (16, 32)]
    for name, solver, params in variants:
        r = replace(robot, ik_solver=solver, ik_params=params)
        t0 = time.process_time()
        found = solve_all(r, T)
        cpu = time.process_time() - t0
        solved = found.valid.any(axis=-1)
        print(f"{name:28s} {100 * solved.mean():12.1f} % {found.valid.sum(axis=-1).mean():19.1f} {cpu:16.2f} s")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--figures", type=Path, default=None, help="draw the paper's Fig. 3-6 as PNG in this folder")
    ap.add_argument("--quick", action="store_true", help="fewer steps and targets, no lookup timing (a smoke run)")
    ap.add_argument("--solvers", action="store_true", help="the six-axis solver table instead")
    ap.add_argument("--poses", type=int, default=500, help="random reachable poses of --solvers")
    args = ap.parse_args()
    if args.solvers:
        solvers(args.poses)
        return
    box = Container.storage()
    counts(box)
    errors(box, QUICK_ERROR_STEPS if args.quick else ERROR_STEPS, 2000 if args.quick else 20_000)
    routes(box, args.figures, CHECKED_J)
    if not args.quick:
        lookups(box)


if __name__ == "__main__":
    main()
