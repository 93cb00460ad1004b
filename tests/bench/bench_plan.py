"""Planner benchmark on the reference cell (a script, not a test).

    python tests/bench/bench_plan.py [CELL] [--runs 5]

Reports medians over the runs of: planning time (one core), cycle time of the optimiser vs both
baselines (the published method and teach-in, `plan.METHODS`; same timing layer, same run),
collision checks spent;
and the detour table: the published method built a configuration-space map over the first three
axes at resolution r and searched it (their figures for r = 20 / 50 / 100: 8,000 tests in 0.3 s,
25,000 in 22.3 s, 1,000,000 in 122.2 s on a 3 GHz CPU). We rebuild that map for the same detour
(around clamp 1, between the optimiser's configurations at s5 and s6) with our collision checker,
and compare with the detours the planner actually uses (lift, roadmap).
"""

from __future__ import annotations

import argparse
import collections
import os
import statistics
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import itertools

import numpy as np

from robomax_py.cspace.grid import nearest_cell
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, method_options, plan_cell
from robomax_py.plan.cspace_detour import local_grid
from robomax_py.plan.graph import Sequencer as _Sequencer
from robomax_py.plan.results import resolved_options
from robomax_py.plan.roadmap import Roadmap
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"
PUBLISHED = {20: (8_000, 0.3), 50: (25_000, 22.3), 100: (1_000_000, 122.2)}


def cpu() -> float:
    return time.process_time()


def grid_detour(world: CollisionWorld, q_start: np.ndarray, q_goal: np.ndarray, lower: np.ndarray,
                upper: np.ndarray, r: int, learned: object = None) -> tuple[int, float, bool, int, bool]:
    """The published method: test every cell of an r^3 grid over A1-A3, then search the free cells.

    The grid is the planner's local map grid (`plan.cspace_detour.local_grid`): the start/goal box
    widened by 0.5 rad on A1-A3 (within limits), the wrist interpolated along the straight A1-A3
    line from start to goal. Returns (tests, seconds, path found, waypoints, swept check free).
    """
    t0 = cpu()
    axes, qs = local_grid(q_start, q_goal, lower, upper, r, 0.5)
    free = np.zeros(len(qs), dtype=bool)
    if learned is None:
        for k in range(0, len(qs), 4096):
            free[k:k + 4096] = world.are_free(qs[k:k + 4096])
        tests = len(qs)
    else:
        # The learned model's map holds for one wrist (the start's): no check at all, then the
        # path is swept-checked with the wrist interpolated, like the exact map's.
        from robomax_py.cspace import CSpaceGrid, learned_map
        model, points = learned
        blocked = learned_map(model, points, CSpaceGrid(axes=tuple(axes), wrist=q_start[3:])).blocked  # type: ignore[arg-type]
        free = ~blocked.reshape(-1)
        world_self = world.restricted(obstacles=False, self_pairs=True)
        for k in range(0, len(qs), 4096):          # self contact is not the model's: checked exactly
            free[k:k + 4096] &= world_self.are_free(qs[k:k + 4096])
        tests = len(qs)

    free3 = free.reshape(r, r, r)
    start, goal = nearest_cell(axes, q_start), nearest_cell(axes, q_goal)
    prev = {start: start}
    queue = collections.deque([start])
    steps = [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if (a, b, c) != (0, 0, 0)]
    while queue:
        cur = queue.popleft()
        if cur == goal:
            break
        for d in steps:
            nxt = (cur[0] + d[0], cur[1] + d[1], cur[2] + d[2])
            if all(0 <= nxt[k] < r for k in range(3)) and nxt not in prev and free3[nxt]:
                prev[nxt] = cur
                queue.append(nxt)
    found = goal in prev
    seconds = cpu() - t0
    cells = []
    if found:
        node = goal
        while node != start:
            cells.append(node)
            node = prev[node]
        cells.append(start)
    # The map only tests cell centres: sweep the path it found with our 2 mm bound to see if it holds.
    index = {c: k for k, c in enumerate(np.ndindex(r, r, r))}
    waypoints = [q_start, *[qs[index[c]] for c in reversed(cells[1:-1])], q_goal] if found else []
    sweep_free = found and all(world.segment_free(a, b) for a, b in itertools.pairwise(waypoints))
    return tests, seconds, found, max(0, len(cells) - 1), sweep_free


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("cell", nargs="?", default=str(REFERENCE_CELL))
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--resolutions", default="20,50,100")
    parser.add_argument("--learned", action="store_true", help="also the detour through the learned map (trains once)")
    args = parser.parse_args()

    cell = load_cell(args.cell)
    robot = load_cell_robot(cell)
    rows: dict[str, list[float]] = collections.defaultdict(list)
    last = {}
    for _ in range(args.runs):
        for tag in ("optimised", "published", "teach-in"):
            t0 = cpu()
            result = plan_cell(cell, robot, method_options(tag))
            seconds = cpu() - t0
            assert result.status == "planned", result.message
            st = result.stats
            assert st is not None
            rows[f"{tag} planning s"].append(seconds)
            rows[f"{tag} cycle s"].append(result.cycle_time)
            rows[f"{tag} collision checks"].append(
                st.candidate_checks + st.sequencing_checks + st.verify_checks + st.roadmap_checks)
            for stage, s in st.seconds.items():
                rows[f"{tag} stage {stage} s"].append(s)
            last[tag] = result
    print(f"cell {cell.name}: {args.runs} runs, CPU seconds of one process")
    print(f"{'quantity':40s} {'median':>12s} {'min':>12s} {'max':>12s}")
    for name, values in rows.items():
        print(f"{name:40s} {statistics.median(values):12.3f} {min(values):12.3f} {max(values):12.3f}")
    opt = statistics.median(rows["optimised cycle s"])
    for tag in ("published", "teach-in"):
        base = statistics.median(rows[f"{tag} cycle s"])
        print(f"cycle time optimised / {tag} = {opt / base:.4f}  ({100 * (1 - opt / base):.1f} % shorter)")

    # Detour table: around clamp 1, between the optimiser's configurations at s5 and s6.
    res = last["optimised"]
    by_name = {s.name: s for s in res.spots}
    q5, q6 = by_name["s5"].q_app, by_name["s6"].q_app
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    straight = world.check_segment(q5, q6)
    learned = None
    if args.learned:
        from robomax_py.cspace import cover_radius, learned_model, surface_points

        t0 = cpu()
        radius = cell.process.clearance + cover_radius(0.1) + 0.06
        model, cached = learned_model(cell, robot, q5[3:], radius)
        learned = (model, surface_points(build_scene(cell, robot), 0.1))
        print(f"\nlearned model for the wrist at s5: {'from the cache' if cached else 'trained'} in {cpu() - t0:.1f} s CPU "
              f"({model.train_checks:,} training checks, {len(model.centres)} neurons)")
    print(f"\ndetour s5 -> s6 (straight move free: {straight.free}, {straight.checks} checks to find out)")
    print(f"{'method':34s} {'tests':>10s} {'seconds':>9s}  result")
    for r in (int(x) for x in args.resolutions.split(",")):
        tests, seconds, found, length, sweep_free = grid_detour(world, q5, q6, robot.limits.lower, robot.limits.upper, r)
        pub_tests, pub_s = PUBLISHED.get(r, (float("nan"), float("nan")))
        print(f"{'published, resolution ' + str(r):34s} {pub_tests:>10,} {pub_s:>9.1f}  (3 GHz CPU, their checker)")
        print(f"{'C-space grid here, resolution ' + str(r):34s} {tests:>10,} {seconds:>9.2f}  "
              + (f"path of {length} steps; swept 2 mm check: {'free' if sweep_free else 'BLOCKED (grid too coarse)'}"
                 if found else "no path"))
        if learned is not None:
            tests, seconds, found, length, sweep_free = grid_detour(
                world, q5, q6, robot.limits.lower, robot.limits.upper, r, learned)
            print(f"{'learned map, resolution ' + str(r):34s} {tests:>10,} {seconds:>9.2f}  "
                  + (f"path of {length} steps; swept 2 mm check: {'free' if sweep_free else 'BLOCKED'}"
                     if found else "no path") + " (tests: self contact only; objects from the model)")
    rng = np.random.default_rng(cell.planner.seed)
    from robomax_py.plan.candidates import seam_candidates
    spots, _ = seam_candidates(cell, robot, world, 0)
    i5 = next(k for k, c in enumerate(spots) if c.name == "s5")
    i6 = next(k for k, c in enumerate(spots) if c.name == "s6")
    a5 = int(np.argmin(np.abs(spots[i5].q_app - q5).sum(axis=1)))
    a6 = int(np.argmin(np.abs(spots[i6].q_app - q6).sum(axis=1)))
    t0 = cpu()
    anchors = np.vstack([cell.home[None, :], *[c.q_app for c in spots]])
    roadmap = Roadmap(world, robot.limits, anchors, rng, 600, 12, seeds=anchors)
    roadmap_s = cpu() - t0
    # A sequencer built as the planner builds it (only its lift detour is used), on the same world.
    seq = _Sequencer(cell, robot, world, roadmap, spots, resolved_options(cell, PlanOptions()), rng)
    t0 = cpu()
    lift = seq._lift_detour(i5, a5, i6, a6)
    print(f"{'lift (up, across, down), ours':34s} {(lift.checks if lift else seq.checks):>10,} {cpu() - t0:>9.3f}  "
          f"{'found, ' + str(len(lift.waypoints)) + ' waypoints' if lift else 'none'}")
    t0 = cpu()
    det = roadmap.query(q5, q6)
    print(f"{'lazy roadmap (600 nodes), ours':34s} {roadmap.sampling_checks + roadmap.edge_checks:>10,} "
          f"{roadmap_s + cpu() - t0:>9.3f}  {'found, ' + str(len(det.waypoints)) + ' waypoints' if det else 'none'}")
    from robomax_py.plan.cspace_detour import grid_detour as local_map_detour

    t0 = cpu()
    det, spent = local_map_detour(world, robot.limits, q5, q6)
    print(f"{'local C-space map (24^3), ours':34s} {spent:>10,} {cpu() - t0:>9.3f}  "
          f"{'found, ' + str(len(det.waypoints)) + ' waypoints' if det else 'none'}")


if __name__ == "__main__":
    main()
