"""Detours of straight TCP lines (`planner.detour_moves: lin`, paper 003's detours) against the joint-space
detours, and the paper's Fig. 2 (the discrete orientation space at a spot) drawn for its rebuilt cell
(a script, not a test):

    python tests/bench/bench_tcp_detours.py [--runs 1] [--generated 6] [--seed 0] [--png FILE] [--quick]

Every cell is planned twice in this process, `detour_moves: ptp` and `lin` (the rest of the cell as
written), and the script prints per cell the cycle, the CPU seconds of `plan_cell` (median of
`--runs`; the cycles are the same in every run), the plan's detours, how many of them are lines,
and the line searches the planner made and how many found lines. The cells: the shipped welding
cells (cells/cabin_flange, flanged_panel, frame, ur10_tray and gazelle_cabin, the paper's cell
rebuilt) and `--generated` seeded corpus cells with clamps on the shipped arms
(tests/bench/corpus_cells.py, at most 12 spots).

"Same pairs": each detour between two spots in the joint-space plan is searched again as lines
between the very same two configurations (`plan.tcp_detour.tcp_detour`, the planner's directions
and heights), and both detours are timed alone from rest to rest (`junction.time_junction`: the
joint one with its corner blends, the lines stopping at each via point): how often lines exist
where the joint-space planner needed a detour, and what they cost, free of the differences the two
plans' own searches make.

The figure (--png): every sample of the orientation grid at one spot (default gazelle_cabin's p3,
beside clamp 1), in (alpha, beta, gamma), marked by what the planner makes of it: feasible (the
number of free configurations, IK branches and turns), no IK solution within the joint limits, a
collision at the spot (the pair named in the legend), or the approach line blocked.
--quick plans the paper's cell alone both ways and draws the figure (a smoke run).
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import statistics
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, PlanResult, plan_cell, resolved_options
from robomax_py.plan.candidates import seam_candidates
from robomax_py.plan.graph_detours import LIFT_HEIGHTS_M
from robomax_py.plan.junction import time_junction
from robomax_py.plan.poses import orientation_grid, spot_poses
from robomax_py.plan.program_frames import cell_program_frames
from robomax_py.plan.tcp_detour import status_of, tcp_detour
from robomax_py.program import written_tcp_speed
from robomax_py.robot.solve import solve_all
from robomax_py.spec import CellSpec
from robomax_py.transforms import invert
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
BENCH = Path(__file__).resolve().parent
SHIPPED = ("cabin_flange", "flanged_panel", "frame", "ur10_tray", "gazelle_cabin")
SHIPPED_ARMS = {"kr16", "kr125", "ur10"}
MODES = ("ptp", "lin")


@dataclass(frozen=True, slots=True)
class Run:
    cycle: float
    cpu: list[float]
    detours: int
    lines: int
    searches: int
    found: int
    status: str


def plan_both(cell: CellSpec, robot: Any, runs: int) -> dict[str, tuple[Run, PlanResult]]:
    out = {}
    for mode in MODES:
        cpu, result = [], None
        for _ in range(runs):
            t0 = time.process_time()
            result = plan_cell(cell, robot, PlanOptions(detour_moves=mode))
            cpu.append(time.process_time() - t0)
        assert result is not None
        st = result.stats
        out[mode] = (Run(result.cycle_time, cpu, st.detours if st else 0, st.lin_detours if st else 0,
                         st.tcp_detour_searches if st else 0, st.tcp_detours_found if st else 0, result.status), result)
    return out


@dataclass(frozen=True, slots=True)
class PairRow:
    label: str
    joint_s: float
    line_s: float | None          # None: no lines found
    why: str                      # why none: the two configurations differ, or no free lines


def same_pairs(cell: CellSpec, robot: Any, result: PlanResult) -> list[PairRow]:
    """Each spot-to-spot detour of a joint-space plan against lines between the same configurations."""
    opts = resolved_options(cell, PlanOptions())
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    up = invert(np.asarray(cell.T_world_base))[:3, :3] @ np.array([0.0, 0.0, 1.0])
    written = cell_program_frames(cell).written
    rows = []
    for k, trans in enumerate(result.transitions):
        if trans.kind != "detour" or k == 0 or k >= len(result.spots):
            continue                                   # from or to home: lines are not tried there
        a, b = result.spots[k - 1], result.spots[k]
        qa, qb = np.asarray(a.q_app), np.asarray(b.q_app)
        joint = np.vstack([qa, trans.waypoints[1:-1], qb])
        speed = opts.speed * opts.detour_speed
        timed = time_junction(robot, world, robot.limits, qa, joint, "detour", trans.label, None, None,
                              tcp_speed=opts.tcp_speed * opts.speed, speed=speed)
        joint_s = sum(s.duration for s in timed.segments)
        backs = [(T_app[:3, 3] - T_spot[:3, 3]) / np.linalg.norm(T_app[:3, 3] - T_spot[:3, 3])
                 for T_app, T_spot in ((a.T_app, a.T_spot), (b.T_app, b.T_spot))]
        aways = [(up, up), (backs[0], backs[1]), ((up + backs[0]) / np.sqrt(2), (up + backs[1]) / np.sqrt(2))]
        lin_speed = written_tcp_speed(opts.detour_tcp_speed * opts.speed)
        found = tcp_detour(robot, world, robot.limits, qa, qb, aways, LIFT_HEIGHTS_M, written, opts.speed, lin_speed)
        if found.detour is None or found.detour.poses is None:
            same = int(status_of(robot, qa)[0]) == int(status_of(robot, qb)[0])
            rows.append(PairRow(trans.label, joint_s, None, "no free lines" if same else "other configuration"))
            continue
        lines = time_junction(robot, world, robot.limits, qa, found.detour.waypoints, "detour", trans.label, None,
                              None, tcp_speed=opts.tcp_speed * opts.speed, lin_targets=found.detour.poses[1:],
                              lin_speed=lin_speed)
        rows.append(PairRow(trans.label, joint_s, sum(s.duration for s in lines.segments), ""))
    return rows


def generated_cells(folder: Path, count: int, seed: int) -> list[Path]:
    """The first `count` corpus cells on a shipped arm with at least one clamp, at most 12 spots."""
    sys.path.insert(0, str(BENCH))
    import corpus_cells

    out: list[Path] = []
    index = 0
    while len(out) < count and index < 2000:
        made = corpus_cells.corpus_cell(index, seed=seed, max_spots=12)
        index += 1
        if made.arm in SHIPPED_ARMS and made.n_clamps > 0:
            out.append(made.write(folder))
    return out


def orientation_figure(cell_path: Path, spot_name: str, png: Path) -> str:
    """The paper's Fig. 2 for one spot (see the module docstring); returns a one-line summary."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cell = load_cell(cell_path)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    s, j = next((s, j) for s, seam in enumerate(cell.seams) for j, p in enumerate(seam.spots) if p.name == spot_name)
    seam = cell.seams[s]
    grid = orientation_grid(seam)
    found = seam_candidates(cell, robot, world, s)[0][j]
    counts = np.bincount(found.orient, minlength=len(grid))
    T = invert(np.asarray(cell.T_world_base)) @ spot_poses((seam.spots[j],), grid)[0]
    table = solve_all(robot, T)
    what: list[str] = []
    for o in range(len(grid)):
        if counts[o]:
            what.append("feasible")
            continue
        qs = np.asarray(table.q[o])[np.asarray(table.valid[o])]
        if not len(qs):
            what.append("no IK solution within the joint limits")
            continue
        contacts = [world.first_contact(q) for q in qs]
        named = Counter(c.describe() for c in contacts if c is not None)
        what.append(f"collision: {named.most_common(1)[0][0]}" if len(named) and all(contacts)
                    else "approach line blocked")
    deg = np.degrees(grid.angles)
    kind = ["feasible" if w == "feasible" else w.split(":")[0] if w.startswith("collision") else
            "approach" if w.startswith("approach") else "no IK" for w in what]
    styles = {"no IK": ("darkgrey", "x", "no IK solution within the joint limits"),
              "collision": ("tab:red", "o", "collision at the spot"),
              "approach": ("tab:orange", "s", "approach line blocked")}
    fig = plt.figure(figsize=(12.5, 5.6))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ok = np.array([k == "feasible" for k in kind])
    sc = ax.scatter(deg[ok, 0], deg[ok, 1], deg[ok, 2], c=counts[ok], cmap="viridis", s=30 + 5 * counts[ok],
                    depthshade=False, label=f"feasible ({int(ok.sum())}; colour: free configurations)")
    pairs = Counter(w.split(": ", 1)[1] for w in what if w.startswith("collision"))
    for name, (colour, marker, label) in styles.items():
        sel = np.array([k == name for k in kind])
        if not sel.any():
            continue
        if name == "collision":
            label += " (" + ", ".join(f"{pair} {n}" for pair, n in pairs.most_common()) + ")"
        ax.scatter(deg[sel, 0], deg[sel, 1], deg[sel, 2], c=colour, marker=marker, s=16, depthshade=False,
                   label=f"{label}: {int(sel.sum())}")
    ax.set_xlabel("alpha, deg")
    ax.set_ylabel("beta, deg")
    ax.set_zlabel("gamma, deg")
    for axis, col in ((ax.set_xticks, 0), (ax.set_yticks, 1), (ax.set_zticks, 2)):
        axis(sorted(set(np.round(deg[:, col], 6).tolist())))
    ax.view_init(elev=18, azim=-58)
    ax.set_title(f"{cell.name}/{spot_name}: {len(grid)} orientations ({seam.grid} per angle), "
                 f"{int(ok.sum())} feasible", fontsize=10)
    fig.colorbar(sc, ax=ax, shrink=0.55, pad=0.12, label="free configurations (IK branches x turns)")
    fig.legend(loc="lower left", fontsize=7.5, frameon=False)
    # Right: the electrode axis tilts (alpha, beta) as points, each spin gamma as a tick from it.
    ax2 = fig.add_subplot(1, 2, 2)
    step = max(np.degrees(max(seam.alpha_max, seam.beta_max)) / max(seam.grid - 1, 1), 1.0)
    for (a, b, g), k in zip(deg, kind):
        colour = "tab:green" if k == "feasible" else styles[k][0]
        ax2.plot([b, b + 0.4 * step * np.sin(np.radians(g))], [a, a + 0.4 * step * np.cos(np.radians(g))],
                 color=colour, lw=2.4, solid_capstyle="butt")
        ax2.plot(b, a, "k.", ms=3)
    ax2.set_aspect("equal")
    ax2.set_xlabel("beta: electrode tilted along the seam, deg")
    ax2.set_ylabel("alpha: electrode tilted across the seam, deg")
    ax2.set_title("a point per tilt of the electrode axis, a tick per spin gamma (up: 0, right: 90 deg)\n"
                  "green feasible, red collision, orange approach blocked, grey no IK", fontsize=10)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=110)
    plt.close(fig)
    kinds = Counter(what)
    return f"{cell.name}/{spot_name}: " + ", ".join(f"{k} {v}" for k, v in kinds.most_common())


def _table(rows: list[tuple[str, dict[str, tuple[Run, PlanResult]]]]) -> None:
    print("| cell | spots | joint-space: cycle / CPU / detours | lines: cycle / CPU / detours (of them lines) | "
          "line searches found | cycle change |")
    print("|---|---|---|---|---|---|")
    for name, both in rows:
        p, lin = both["ptp"][0], both["lin"][0]
        spots = len(both["ptp"][1].spots)
        if p.status != "planned" or lin.status != "planned":
            print(f"| {name} | {spots} | {p.status} | {lin.status} | | |")
            continue
        change = 100.0 * (lin.cycle / p.cycle - 1.0)
        print(f"| {name} | {spots} | {p.cycle:.3f} s / {statistics.median(p.cpu):.1f} s / {p.detours} | "
              f"{lin.cycle:.3f} s / {statistics.median(lin.cpu):.1f} s / {lin.detours} ({lin.lines}) | "
              f"{lin.found} of {lin.searches} | {change:+.1f} % |")


def _pairs(all_pairs: list[tuple[str, list[PairRow]]]) -> None:
    print()
    print("| cell | spot-to-spot detours | lines exist | none: other configuration / no free lines | "
          "joint-space s | lines s (where they exist) |")
    print("|---|---|---|---|---|---|")
    ratios = []
    for name, rows in all_pairs:
        have = [r for r in rows if r.line_s is not None]
        other = sum(r.why == "other configuration" for r in rows)
        free = sum(r.why == "no free lines" for r in rows)
        ratios += [r.line_s / r.joint_s for r in have if r.line_s is not None]
        joint = ", ".join(f"{r.joint_s:.3f}" for r in have) or "-"
        line = ", ".join(f"{r.line_s:.3f}" for r in have if r.line_s is not None) or "-"
        print(f"| {name} | {len(rows)} | {len(have)} | {other} / {free} | {joint} | {line} |")
    total = sum(len(rows) for _, rows in all_pairs)
    if ratios:
        print(f"\nlines exist for {len(ratios)} of {total} spot-to-spot detours; lines / joint-space time: median "
              f"{statistics.median(ratios):.2f}, range {min(ratios):.2f}-{max(ratios):.2f}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=1, help="plans per cell and mode (CPU median)")
    ap.add_argument("--generated", type=int, default=6, help="seeded corpus cells with clamps")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--png", type=Path, default=Path("paper003_orientations.png"))
    ap.add_argument("--figure-cell", type=Path, default=REPO / "cells" / "gazelle_cabin.yaml")
    ap.add_argument("--figure-spot", default="p3")
    ap.add_argument("--quick", action="store_true", help="the paper's cell alone and the figure (smoke run)")
    args = ap.parse_args()
    names = ["gazelle_cabin"] if args.quick else list(SHIPPED)
    paths = [REPO / "cells" / f"{n}.yaml" for n in names]
    with tempfile.TemporaryDirectory() as tmp:
        if not args.quick and args.generated > 0:
            paths += generated_cells(Path(tmp), args.generated, args.seed)
        rows, pairs = [], []
        for path in paths:
            cell = load_cell(path)
            robot = load_cell_robot(cell)
            both = plan_both(cell, robot, 1 if args.quick else args.runs)
            rows.append((cell.name, both))
            if both["ptp"][0].status == "planned":
                pairs.append((cell.name, same_pairs(cell, robot, both["ptp"][1])))
            print(f"{cell.name}: " + "; ".join(f"{m} {r.status} {r.cycle:.3f} s, {statistics.median(r.cpu):.1f} s CPU"
                                               for m, (r, _) in both.items()), flush=True)
    print()
    _table(rows)
    _pairs(pairs)
    print()
    print("figure:", orientation_figure(args.figure_cell, args.figure_spot, args.png), "->", args.png)


if __name__ == "__main__":
    main()
