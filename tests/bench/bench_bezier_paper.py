"""The minimum-time quintic Bézier method of Benko Loknar, Klančar and Blažič as published, on their
warehouse (tests/bench/paper_warehouse.py): table 2's nine loop times beside the paper's, the
paper's constraints measured on every profile from its positions alone, the project's own Bézier
profile (box limits, `timing.bezier`) measured against the same constraints, and the paths and
profiles drawn.

    python tests/bench/bench_bezier_paper.py [--evaluations 1500] [--out DIR] [--save-turns FILE]
                                             [--wall-clearance 0] [--quick]

Each of the six turns (three drop-offs, optimised for the loaded and for the unloaded robot) is
optimised for the travel time of its two-step jerk-limited profile (`timing.frenet_shape`, grid
2 cm), starting from a round turn; every leg is then timed on a 1 cm grid under both limit sets.
--quick: no optimisation (every leg on the round turn), 2 cm grid, no box-limit comparison: the
smoke run. --wall-clearance keeps the turns that far (m) from the wall (the assumed floor plan's
sensitivity). --save-turns writes the optimised turns' parameters as JSON (tests/data/bezier_paper_turns.json
is such a file: tests/timing/test_bezier_paper.py recomputes table 2 on it). CPU is
`time.process_time` of one process.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from paper_warehouse import (
    DROP_OFFS,
    FLOOR_X,
    LOADED,
    LOWER_Y,
    MIRROR,
    MIRROR_X,
    PAPER_TABLE2,
    PICK_UP,
    RACK_END_X,
    RACK_LENGTH,
    ROWS,
    SCALES,
    START,
    UNLOADED,
    UPPER_Y,
    Turn,
    leg_chain,
    loop_times,
    shape,
)

from robomax_py.spec import TcpLimits
from robomax_py.timing.frenet_measure import (
    ConstraintPeaks,
    FrenetSeries,
    frenet_series,
    peaks,
)
from robomax_py.timing.frenet_profile import FrenetProfile, frenet_profile
from robomax_py.timing.frenet_shape import optimise_shape
from robomax_py.timing.quintic_chain import QuinticChain

LIMITS = {"F": LOADED, "N": UNLOADED}
NAMES = {"F": "loaded", "N": "unloaded"}
MEASURE_DT_S = 0.005


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--evaluations", type=int, default=1500, help="profiles per turn optimisation")
    ap.add_argument("--out", type=Path, default=Path("bench_bezier_paper"), help="folder for the PNGs")
    ap.add_argument("--quick", action="store_true", help="no optimisation, coarse grid (smoke run)")
    ap.add_argument("--save-turns", type=Path, default=None, help="write the turns' parameters (JSON) here")
    ap.add_argument("--wall-clearance", type=float, default=0.0, help="keep the turns this far (m) from the wall")
    args = ap.parse_args()
    step = 0.02 if args.quick else 0.01
    cpu: dict[str, float] = {}

    # The turns: x[(drop-off, "F" | "N")], the path optimised for the loaded / unloaded robot.
    turns: dict[tuple[str, str], np.ndarray] = {}
    for x in DROP_OFFS:
        for p in "FN":
            t0 = time.process_time()
            if args.quick:
                turns[(x, p)] = START
            else:
                turn = Turn(DROP_OFFS[x][0], RACK_END_X - FLOOR_X + args.wall_clearance)
                turns[(x, p)] = optimise_shape(shape(turn), START, SCALES, LIMITS[p], args.evaluations).x
            cpu[f"optimise turn {x} {NAMES[p]}"] = time.process_time() - t0

    if args.save_turns is not None:
        data = {x: {p: [round(float(v), 12) for v in turns[(x, p)]] for p in "FN"} for x in DROP_OFFS}
        args.save_turns.write_text(json.dumps(data, indent=1) + "\n")
    chains = {k: leg_chain(Turn(DROP_OFFS[k[0]][0]), v) for k, v in turns.items()}
    profiles: dict[tuple[str, str, str], FrenetProfile] = {}
    measured: dict[tuple[str, str, str], tuple[FrenetSeries, ConstraintPeaks]] = {}
    t_profile = t_measure = 0.0
    for (x, p), chain in chains.items():
        for lim in "FN":
            t0 = time.process_time()
            prof = frenet_profile(chain, LIMITS[lim], step)
            t1 = time.process_time()
            series = _measure(chain, prof)
            t_profile += t1 - t0
            t_measure += time.process_time() - t1
            profiles[(x, p, lim)] = prof
            measured[(x, p, lim)] = (series, peaks(series, LIMITS[lim]))
    cpu["12 leg profiles"] = t_profile
    cpu["12 measurements from positions"] = t_measure

    table = loop_times({k: v.duration for k, v in profiles.items()})
    _print_table(table)
    _print_legs(profiles, chains)
    _print_peaks(measured, profiles)
    if not args.quick:
        t0 = time.process_time()
        _print_box_method(chains[("A'", "F")], chains[("A'", "N")])
        cpu["box-limit profiles (2)"] = time.process_time() - t0
    t0 = time.process_time()
    args.out.mkdir(parents=True, exist_ok=True)
    _draw_paths(chains, args.out / "bezier_paper_paths.png")
    _draw_profiles(measured, args.out / "bezier_paper_profiles.png")
    cpu["plots"] = time.process_time() - t0
    print(f"\nPNGs: {args.out / 'bezier_paper_paths.png'}, {args.out / 'bezier_paper_profiles.png'}")
    print()
    for k, v in cpu.items():
        print(f"CPU {k}: {v:.2f} s")


def _measure(chain: QuinticChain, prof: FrenetProfile) -> FrenetSeries:
    """The profile's motion sampled every MEASURE_DT_S from its positions (`frenet_measure`)."""
    t = np.arange(0.0, prof.duration + MEASURE_DT_S, MEASURE_DT_S)
    s = prof.at_time(t)[0]
    return frenet_series(t, chain.points(s))


def _print_table(table: dict[tuple[str, str], dict[str, float]]) -> None:
    print("Table 2: loop time A -> X -> A (s), ours beside the paper's")
    print()
    print("| loaded leg on | unloaded leg on | drop-off | ours | paper | difference |")
    print("|---|---|---|---|---|---|")
    for row in ROWS:
        for x in DROP_OFFS:
            ours, paper = table[row][x], PAPER_TABLE2[row][x]
            print(f"| {row[0]}_path | {row[1]}_path | {x} | {ours:.3f} | {paper:.3f} | {100 * (ours / paper - 1):+.1f} % |")
    print()
    print("Row differences (s): a leg on the other load's path, against both on their own paths")
    print()
    print("| drop-off | loaded robot on N_path (ours / paper) | unloaded robot on F_path (ours / paper) |")
    print("|---|---|---|")
    own = ("F", "N")
    for x in DROP_OFFS:
        print(f"| {x} | {table[('N', 'N')][x] - table[own][x]:+.3f} / {PAPER_TABLE2[('N', 'N')][x] - PAPER_TABLE2[own][x]:+.3f} "
              f"| {table[('F', 'F')][x] - table[own][x]:+.3f} / {PAPER_TABLE2[('F', 'F')][x] - PAPER_TABLE2[own][x]:+.3f} |")
    print()


def _print_legs(profiles: dict[tuple[str, str, str], FrenetProfile], chains: dict[tuple[str, str], QuinticChain]) -> None:
    print("Half loops A -> X (s): the turn optimised for the loaded (F) or unloaded (N) robot, timed under both")
    print()
    print("| X | path | length (m) | loaded | unloaded |")
    print("|---|---|---|---|---|")
    for (x, p), chain in chains.items():
        print(f"| {x} | {p}_path | {chain.length:.3f} | {profiles[(x, p, 'F')].duration:.3f} | "
              f"{profiles[(x, p, 'N')].duration:.3f} |")
    scaled = [k for k, v in profiles.items() if v.limit_scale < 1.0]
    if scaled:
        print(f"\n(made inside scaled limits, `frenet_profile`'s retry: {scaled})")
    print()


def _print_peaks(measured: dict[tuple[str, str, str], tuple[FrenetSeries, ConstraintPeaks]],
                 profiles: dict[tuple[str, str, str], FrenetProfile]) -> None:
    print("The paper's constraints (2a-2c), measured from positions every 5 ms (largest over the 6 legs of each load)")
    print()
    print("| limits | v / v_max | a_T / a_Tmax | a_R / a_Rmax | j_T / j_Tmax | j_R / j_Rmax | acc. ellipse | jerk ellipse |")
    print("|---|---|---|---|---|---|---|---|")
    for lim in "FN":
        rows = [pk for (x, p, ll), (_, pk) in measured.items() if ll == lim]
        limits = LIMITS[lim]
        print(f"| {NAMES[lim]} | {max(r.v for r in rows) / limits.v:.4f} | {max(r.a_T for r in rows) / limits.a_T:.4f} "
              f"| {max(r.a_R for r in rows) / limits.a_R:.4f} | {max(r.j_T for r in rows) / limits.j_T:.4f} "
              f"| {max(r.j_R for r in rows) / limits.j_R:.4f} | {max(r.accel_ellipse for r in rows):.4f} "
              f"| {max(r.jerk_ellipse for r in rows):.4f} |")
    print()


def _print_box_method(loaded_path: QuinticChain, unloaded_path: QuinticChain) -> None:
    """The project's own Bézier profile (`timing.bezier.jerk_limited`: box limits on v, a_T, a_R and
    on the rates of change of a_T and a_R) on the paper's turns, measured against the paper's
    constraints with its own speed spline (formula 7)."""
    from robomax_py.timing.bezier import BezierPath, jerk_limited

    print("The project's box-limit profile (timing.bezier) on the same paths, against the paper's constraints")
    print()
    print("| leg | its time (s) | paper's method (s) | j_T / j_Tmax | acc. ellipse | jerk ellipse |")
    print("|---|---|---|---|---|---|")
    for name, chain, limits in (("A -> A' loaded, F_path", loaded_path, LOADED),
                                ("A -> A' unloaded, N_path", unloaded_path, UNLOADED)):
        path = BezierPath(np.asarray(chain.control))
        prof = jerk_limited(path, limits)
        j_t, acc, jerk = _box_against_paper(prof.s, prof.v, path, limits)
        ours = frenet_profile(chain, limits).duration
        print(f"| {name} | {prof.duration:.3f} | {ours:.3f} | {j_t:.3f} | {acc:.3f} | {jerk:.3f} |")
    print()


def _box_against_paper(s_grid: np.ndarray, v_grid: np.ndarray, path: object, limits: TcpLimits) -> tuple[float, float, float]:
    """Largest j_T / j_Tmax and ellipse values of a `timing.bezier` profile (its clamped spline of
    v^2 over arclength), evaluated 8 times finer than its grid with the paper's formulas."""
    from scipy.interpolate import CubicSpline

    from robomax_py.timing.bezier import _curvature_at

    spline = CubicSpline(s_grid, v_grid**2, bc_type="clamped")
    s = np.linspace(0.0, s_grid[-1], 8 * (len(s_grid) - 1) + 1)
    kappa, dkappa = _curvature_at(path, s)  # type: ignore[arg-type]
    b = np.maximum(spline(s), 0.0)
    v = np.sqrt(b)
    a_t = spline(s, 1) / 2.0
    j_t = v * spline(s, 2) / 2.0 - kappa**2 * v**3
    j_r = 3.0 * kappa * v * a_t + dkappa * v**3
    acc = (a_t / limits.a_T) ** 2 + (kappa * b / limits.a_R) ** 2
    jerk = (j_t / limits.j_T) ** 2 + (j_r / limits.j_R) ** 2
    return float(np.abs(j_t).max() / limits.j_T), float(acc.max()), float(jerk.max())


def _floor(ax: object) -> None:
    """Racks, walls, aisle centre lines and the stops of the assumed floor plan."""
    from matplotlib.patches import Rectangle

    for y0 in (LOWER_Y - 2.5, LOWER_Y + 0.5, UPPER_Y + 0.5):          # rows 2 m deep, aisles 1 m wide
        ax.add_patch(Rectangle((RACK_END_X, y0), RACK_LENGTH, 2.0, color="0.85", zorder=0))  # type: ignore[attr-defined]
    for xw in (RACK_END_X - FLOOR_X, RACK_END_X + RACK_LENGTH + FLOOR_X):
        ax.axvline(xw, color="0.3", lw=2)  # type: ignore[attr-defined]
    for y in (LOWER_Y, UPPER_Y):
        ax.axhline(y, color="0.7", lw=0.8, ls=":")  # type: ignore[attr-defined]
    ax.plot(*PICK_UP, "ks")  # type: ignore[attr-defined]
    ax.annotate("A", PICK_UP, xytext=(4, -12), textcoords="offset points")  # type: ignore[attr-defined]
    for name, p in DROP_OFFS.items():
        ax.plot(*p, "k^")  # type: ignore[attr-defined]
        ax.annotate(name, p, xytext=(4, 6), textcoords="offset points")  # type: ignore[attr-defined]
    ax.set_aspect("equal")  # type: ignore[attr-defined]
    ax.set_xlim(RACK_END_X - FLOOR_X - 0.5, RACK_END_X + RACK_LENGTH + FLOOR_X + 0.5)  # type: ignore[attr-defined]
    ax.set_ylim(0.5, 9.5)  # type: ignore[attr-defined]


def _draw_paths(chains: dict[tuple[str, str], QuinticChain], out: Path) -> None:
    """For each drop-off the loop of table 2's fastest row: the loaded leg on the path optimised for
    the loaded robot (solid), the unloaded leg back on its own (dashed; the mirror image of the
    leg to the mirrored drop-off, run backwards); the other load's path faint."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(15, 4.6))
    FigureCanvasAgg(fig)
    for k, x in enumerate(DROP_OFFS):
        ax = fig.add_subplot(1, 3, k + 1)
        _floor(ax)
        for p, style, colour, alpha in (("F", "-", "C3", 1.0), ("N", "-", "C3", 0.3)):
            pts = chains[(x, p)].points(np.linspace(0.0, chains[(x, p)].length, 600))
            ax.plot(pts[:, 0], pts[:, 1], style, color=colour, alpha=alpha, lw=1.8,
                    label=f"to {x}, loaded, {p}_path" if alpha == 1.0 else f"to {x} on {p}_path")
        for p, style, colour, alpha in (("N", "--", "C0", 1.0), ("F", "--", "C0", 0.3)):
            back = chains[(MIRROR[x], p)]
            pts = back.points(np.linspace(0.0, back.length, 600))
            ax.plot(2 * MIRROR_X - pts[:, 0], pts[:, 1], style, color=colour, alpha=alpha, lw=1.8,
                    label=f"back, unloaded, {p}_path" if alpha == 1.0 else f"back on {p}_path")
        ax.set_title(f"A -> {x} -> A")
        ax.legend(fontsize=7, loc="upper center", ncol=2)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def _draw_profiles(measured: dict[tuple[str, str, str], tuple[FrenetSeries, ConstraintPeaks]], out: Path) -> None:
    """Speed, accelerations, jerks and both ellipses against time, measured from positions, for
    the A' loop's two legs on their own paths; the limits dashed."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(13, 10))
    FigureCanvasAgg(fig)
    legs = ((("A'", "F", "F"), "A -> A' loaded, F_path"), (("A'", "N", "N"), "A' -> A unloaded, N_path"))
    for col, (key, title) in enumerate(legs):
        series, _ = measured[key]
        limits = LIMITS[key[2]]
        rows = (("speed (m/s)", ((series.v, "v", limits.v),)),
                ("acceleration (m/s^2)", ((series.a_T, "a_T", limits.a_T), (series.a_R, "a_R", limits.a_R))),
                ("jerk (m/s^3)", ((series.j_T, "j_T", limits.j_T), (series.j_R, "j_R", limits.j_R))),
                ("ellipse (2b, 2c)", (((series.a_T / limits.a_T) ** 2 + (series.a_R / limits.a_R) ** 2, "acceleration", 1.0),
                                      ((series.j_T / limits.j_T) ** 2 + (series.j_R / limits.j_R) ** 2, "jerk", 1.0))))
        for r, (label, curves) in enumerate(rows):
            ax = fig.add_subplot(4, 2, 2 * r + col + 1)
            for c, (y, name, lim) in enumerate(curves):
                ax.plot(series.t, y, color=f"C{c}", lw=1.2, label=name)
                ax.axhline(lim, color=f"C{c}", ls="--", lw=0.8)
                if r in (1, 2):
                    ax.axhline(-lim, color=f"C{c}", ls="--", lw=0.8)
            ax.set_ylabel(label)
            ax.legend(fontsize=8, loc="upper right")
            if r == 0:
                ax.set_title(title)
            if r == 3:
                ax.set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(out, dpi=100)


if __name__ == "__main__":
    main()
