"""The figures of docs/paper-001.md for `bench_paper_001.py --figures DIR` (a helper, not a test),
drawn with matplotlib from robomax's own data on the tending cell with parts on its conveyor:

- `paper_001_voxels.png`: the TCP's free-space voxel grid (`plan.tcp_route.tcp_space`, the map the
  planner searches), a horizontal slice through both door openings and a vertical one through
  CNC 1's; free leaves coloured by their edge, occupied leaves left out (Kholopov et al., Figs. 1, 4:
  the grid refined near the geometry);
- `paper_001_route.png`: one junction through CNC 1's door, the TCP path of the time-aware plan and
  of the classical A* (`PlanOptions(dynamic="astar")`) over those slices, with where each waits;
- `paper_001_timeline.png`: per planner (time-aware, classical A*, waiting at rest) the doors'
  closed windows and the parts passing the pick station as bands, the robot's moves, waits and
  stations as bars, the classical A*'s stops (its dangerous situations) marked.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py.plan import PlanResult
from robomax_py.plan.tcp_route import TcpSpace, dynamic_boxes, tcp_space
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.spec import Box, CellSpec, PathMotion
from robomax_py.world.scene import build_scene

# The horizontal slice's height (m): inside both door openings (0.75-1.6 m), the height at which
# the routes into CNC 1 cross its front wall.
SLICE_Z = 0.95
# The vertical slice: the plane y = 0 through CNC 1's door (x 1.03 m) and its load station.
SLICE_Y = 0.0
# What the slices show (m): the cell round the robot, the machines and the conveyor.
XY_VIEW = ((-1.5, 2.1), (-1.5, 2.1))
XZ_VIEW = ((-1.5, 2.1), (0.0, 2.2))
# The junction drawn in the route figure: the second cycle's conveyor -> CNC 1 (its door closed
# when the robot gets there: the time-aware plan waits in front of it, the classical A* stops);
# the first cycle's in a job of one cycle.
JUNCTION = ("conveyor_pick", "cnc1_load")
JUNCTION_CYCLE = 2
# A part is "at the pick station" while its centre is within this of the station in plan (m): the
# box's half width plus the open gripper's half span, about.
AT_STATION_M = 0.25
DPI = 100
PLANNERS = (("timed", "time-aware"), ("astar", "classical A*"), ("rest", "wait at rest"))


@dataclass(frozen=True, slots=True)
class Plans:
    """The dynamic cell and its plans by mode (`timed`, `astar`, `rest`)."""

    cell: CellSpec
    robot: RobotModel
    results: dict[str, PlanResult]


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def space_of(cell: CellSpec, robot: RobotModel) -> TcpSpace:
    """The TCP's free voxels as the planner builds them (`plan.tour_timing._tcp_space`): the static
    cell's, the dynamic objects' boxes marked with their windows."""
    static = build_scene(replace(cell, dynamic=()), robot)
    return tcp_space(static, robot, cell.process.clearance, dynamic_boxes(build_scene(cell, robot)))


def _boxes(cell: CellSpec, objects: tuple[Any, ...]) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, lo, hi) world AABBs of the cell's box objects (the shipped cell's are axis-aligned)."""
    out = []
    for obj in objects:
        if isinstance(obj.shape, Box):
            half = np.asarray(obj.shape.extents) / 2
            corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
            T = np.asarray(obj.T_world_object)
            pts = corners @ T[:3, :3].T + T[:3, 3]
            out.append((obj.name, pts.min(axis=0), pts.max(axis=0)))
    return out


def _slice(ax: Any, space: TcpSpace, cell: CellSpec, axis: int, value: float, view: tuple[tuple[float, float], ...],
           fade: float = 1.0, windows: bool = False) -> Any:
    """Draw the free leaves cut by the plane {axis = value} (axis 2: horizontal, 1: vertical x-z),
    coloured by edge (with `windows`: those near a dynamic object, blocked in its windows, edged in
    red); the static objects' sections in grey and the doors hatched. Returns the colour mapping
    (for a colour bar)."""
    from matplotlib.cm import ScalarMappable
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import BoundaryNorm
    from matplotlib.patches import Rectangle

    vox = space.voxels
    shown = [a for a in range(3) if a != axis]
    cut = vox.free & (vox.corner[:, axis] <= value) & (value < vox.corner[:, axis] + vox.edge)
    lo = vox.corner[cut][:, shown]
    e = vox.edge[cut]
    polys = np.stack([lo, lo + np.c_[e, 0 * e], lo + np.c_[e, e], lo + np.c_[0 * e, e]], axis=1)
    levels = np.unique(vox.level)
    norm = BoundaryNorm(np.append(levels, levels[-1] + 1) - 0.5, len(levels))
    cmap = _cmap(len(levels))
    ax.add_collection(PolyCollection(list(polys), array=vox.level[cut], cmap=cmap, norm=norm, edgecolors="white",
                                     linewidths=0.15, alpha=fade))
    if windows:
        # space.door_windows is per free leaf, in the order of the free leaves.
        timed = np.zeros(len(vox.free), dtype=bool)
        timed[np.flatnonzero(vox.free)] = [bool(w) for w in space.door_windows]
        ax.add_collection(PolyCollection(list(polys[timed[cut]]), facecolors="none", edgecolors="crimson", linewidths=0.6,
                                         zorder=1))
    for name, blo, bhi in _boxes(cell, cell.objects):
        if blo[axis] <= value <= bhi[axis]:
            ax.add_patch(Rectangle(_xy(blo[shown]), *_xy((bhi - blo)[shown]), facecolor="0.55", edgecolor="0.3", lw=0.5,
                                   zorder=2))
    for name, blo, bhi in _boxes(cell, tuple(d for d in cell.dynamic if d.door)):
        if blo[axis] - 0.05 <= value <= bhi[axis] + 0.05:
            ax.add_patch(Rectangle(_xy(blo[shown]), *_xy((bhi - blo)[shown]), facecolor="none", edgecolor="crimson", lw=1.2,
                                   hatch="////", zorder=3))
            ax.annotate(name, (blo[shown] + bhi[shown]) / 2, xytext=(4, 4), textcoords="offset points", fontsize=7,
                        color="crimson", zorder=6, bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8})
    ax.set_xlim(*view[0])
    ax.set_ylim(*view[1])
    ax.set_aspect("equal")
    names = "xyz"
    ax.set_xlabel(f"{names[shown[0]]}, m")
    ax.set_ylabel(f"{names[shown[1]]}, m")
    mapping = ScalarMappable(norm=norm, cmap=cmap)
    mapping.set_array(levels)
    return mapping


def _xy(v: np.ndarray) -> tuple[float, float]:
    return float(v[0]), float(v[1])


def _cmap(n: int) -> Any:
    from matplotlib.colors import ListedColormap

    plt = _pyplot()
    return ListedColormap(plt.get_cmap("viridis_r")(np.linspace(0.0, 1.0, n)))


def _colourbar(fig: Any, ax: Any, mapping: Any, space: TcpSpace) -> None:
    levels = np.unique(space.voxels.level)
    bar = fig.colorbar(mapping, ax=ax, ticks=levels, fraction=0.04, pad=0.02)
    bar.ax.set_yticklabels([f"{space.voxels.root_edge / 2 ** int(d):.3g}" for d in levels], fontsize=7)
    bar.set_label("free leaf edge, m", fontsize=8)


def voxels_figure(out: Path, plans: Plans, space: TcpSpace) -> Path:
    plt = _pyplot()
    vox = space.voxels
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 5.0), dpi=DPI, gridspec_kw={"width_ratios": [1.0, 1.05]})
    _slice(axes[0], space, plans.cell, 2, SLICE_Z, XY_VIEW, windows=True)
    axes[0].set_title(f"horizontal slice z = {SLICE_Z} m (both door openings)", fontsize=9)
    mapping = _slice(axes[1], space, plans.cell, 1, SLICE_Y, XZ_VIEW, windows=True)
    axes[1].set_title(f"vertical slice y = {SLICE_Y} m (CNC 1's door)", fontsize=9)
    _colourbar(fig, axes[1], mapping, space)
    fig.suptitle(f"TCP free space: {int(vox.free.sum())} free of {len(vox.free)} leaves, refined to "
                 f"{vox.edge.min():.3g} m near the objects (grown by {vox.inflation:.3f} m: tool reach + clearance)\n"
                 "grey: objects (occupied leaves left out); hatched: doors, free in the grid; red-edged: leaves near a "
                 "dynamic object, blocked in its windows", fontsize=8)
    fig.subplots_adjust(top=0.86, left=0.06, right=0.97, wspace=0.15)
    return _save(fig, out / "paper_001_voxels.png")


def _segment(result: PlanResult, junction: tuple[str, str]) -> tuple[int, int, list[tuple[int, int, str]]]:
    """Sample indices from the retract at the junction's start to the approach's end at its goal,
    and the wait phases in it (i_start, i_end, label)."""
    a, b = junction
    traj = result.trajectory
    assert traj is not None
    start = next(p for p in traj.phases if p.kind in ("weld", "station") and p.label.endswith("/" + a))
    end = next(p for p in traj.phases if p.kind == "approach" and p.label.endswith("/" + b))
    waits = [(p.i_start, p.i_end, p.label) for p in traj.phases
             if p.kind == "wait" and start.t_end - 1e-9 <= p.t_start and p.t_end <= end.t_end + 1e-9]
    return start.i_end, end.i_end, waits


def _junction(result: PlanResult) -> tuple[str, str]:
    names = {s.name for s in result.spots}
    cycle = max(c for c in range(1, JUNCTION_CYCLE + 1) if f"c{c}_{JUNCTION[0]}" in names)
    return f"c{cycle}_{JUNCTION[0]}", f"c{cycle}_{JUNCTION[1]}"


def route_figure(out: Path, plans: Plans, space: TcpSpace) -> Path:
    plt = _pyplot()
    junction = _junction(plans.results["timed"])
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 5.0), dpi=DPI, gridspec_kw={"width_ratios": [1.0, 1.05]})
    _slice(axes[0], space, plans.cell, 2, SLICE_Z, XY_VIEW, fade=0.35)
    _slice(axes[1], space, plans.cell, 1, SLICE_Y, XZ_VIEW, fade=0.35)
    styles = {"timed": ("tab:green", "time-aware"), "astar": ("tab:red", "classical A*")}
    for mode, (colour, name) in styles.items():
        result = plans.results[mode]
        traj = result.trajectory
        assert traj is not None
        i0, i1, waits = _segment(result, junction)
        tcp = fk_tcp(plans.robot, traj.q[i0:i1 + 1])[:, :3, 3]
        t0, t1 = traj.t[i0], traj.t[i1]
        for ax, shown in ((axes[0], [0, 1]), (axes[1], [0, 2])):
            ax.plot(tcp[:, shown[0]], tcp[:, shown[1]], color=colour, lw=2.0, zorder=4,
                    label=f"{name}: gripped at {t0:.2f} s, at the load station at {t1:.2f} s" if shown == [0, 1] else None)
            ax.plot(*tcp[0, shown], "o", color="black", ms=4, zorder=5)
            ax.plot(*tcp[-1, shown], "s", color="black", ms=4, zorder=5)
            for w0, w1, label in waits:
                p = fk_tcp(plans.robot, traj.q[w0])[:3, 3]
                what = "stops at rest" if mode == "astar" else "waits"
                ax.plot(*p[shown], "X" if mode == "astar" else "o", color=colour, ms=10, mec="black", zorder=6,
                        label=(f"{name} {what} {traj.t[w1] - traj.t[w0]:.1f} s ({label.removeprefix('wait for ')})"
                               if shown == [0, 1] else None))
    axes[0].legend(loc="upper left", fontsize=7, framealpha=0.9)
    axes[0].set_title(f"TCP paths seen from above, over the slice z = {SLICE_Z} m", fontsize=9)
    axes[1].set_title(f"seen from the side, over the slice y = {SLICE_Y} m", fontsize=9)
    fig.suptitle(f"junction {junction[0]} -> {junction[1]} through CNC 1's door (circle: start, square: "
                 "goal); the door is closed when the robot gets there", fontsize=9)
    fig.subplots_adjust(top=0.88, left=0.06, right=0.97, wspace=0.15)
    return _save(fig, out / "paper_001_route.png")


def _part_passes(cell: CellSpec, horizon: float) -> list[tuple[float, float]]:
    """Windows in which a moving part's centre is within AT_STATION_M of the pick station in plan."""
    station = next(s for seam in cell.seams for s in seam.spots if s.name.endswith("conveyor_pick"))
    out: list[tuple[float, float]] = []
    for obj in cell.dynamic:
        motion = obj.motion
        if not isinstance(motion, PathMotion):
            continue
        for k in range(motion.count):
            t0 = k * (motion.repeat or 0.0)
            if t0 > horizon:
                break
            ts = np.linspace(motion.t[0], motion.t[-1], 601)
            xy = np.stack([np.interp(ts, motion.t, motion.T_world_object[:, i, 3]) for i in (0, 1)], axis=1)
            near = np.linalg.norm(xy - station.xyz[:2], axis=1) < AT_STATION_M
            if near.any():
                out.append((t0 + ts[near][0], t0 + ts[near][-1]))
    return out


PHASE_COLOURS = {"weld": "0.15", "station": "0.15", "wait": "orange"}


def timeline_figure(out: Path, plans: Plans) -> Path:
    plt = _pyplot()
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    horizon = max(r.cycle_time for r in plans.results.values()) + 1.0
    fig, axes = plt.subplots(len(PLANNERS), 1, figsize=(11.0, 6.2), dpi=DPI, sharex=True)
    machines = plans.cell.machines
    parts = _part_passes(plans.cell, horizon)
    rows = [f"{m.name} door closed" for m in machines] + ["part at the pick station", "robot"]
    for ax, (mode, name) in zip(axes, PLANNERS):
        result = plans.results[mode]
        traj = result.trajectory
        assert traj is not None
        for y, m in enumerate(machines):
            ax.broken_barh([(a, b - a) for a, b in m.windows], (y - 0.35, 0.7), color="crimson", alpha=0.55)
        y_part = len(machines)
        ax.broken_barh([(a, b - a) for a, b in parts], (y_part - 0.35, 0.7), color="tab:purple", alpha=0.55)
        y_robot = y_part + 1
        for p in traj.phases:
            colour = PHASE_COLOURS.get(p.kind, "tab:blue")
            if p.kind == "wait" and mode == "astar":
                colour = "red"
            elif p.kind == "wait" and mode == "rest":
                colour = "0.6"
            ax.broken_barh([(p.t_start, p.duration)], (y_robot - 0.4, 0.8), color=colour, lw=0)
        if mode == "astar":
            # A stop at rest may span several wait phases (one per object it waits for): one marker.
            waits = [p for p in traj.phases if p.kind == "wait"]
            stops = [p for k, p in enumerate(waits) if k == 0 or waits[k - 1].t_end < p.t_start - 1e-6]
            ax.plot([p.t_start for p in stops], [y_robot + 0.75] * len(stops), "v", color="red", ms=7, clip_on=False)
        ax.set_yticks(range(len(rows)))
        ax.set_yticklabels(rows, fontsize=7)
        ax.set_ylim(-0.6, y_robot + 0.9)
        ax.set_title(f"{name} (`{mode}`): cycle {result.cycle_time:.3f} s"
                     + (f", {sum(1 for t in result.transitions if t.wait is not None)} stops at rest where its "
                        "route meets a door or a part (dangerous situations)" if mode == "astar" else ""),
                     fontsize=8, loc="left")
        ax.grid(axis="x", color="0.85", lw=0.5)
        ax.set_axisbelow(True)
    axes[-1].set_xlim(0, horizon)
    axes[-1].set_xlabel("time from program start, s")
    legend = [Patch(color="tab:blue", label="move"), Patch(color="0.15", label="at a station (grip / release)"),
              Patch(color="orange", label="wait inside a planned move"), Patch(color="red", label="stop at rest (A*)"),
              Patch(color="0.6", label="wait at rest"), Patch(color="crimson", alpha=0.55, label="door closed"),
              Patch(color="tab:purple", alpha=0.55, label=f"part within {AT_STATION_M} m of the pick station"),
              Line2D([], [], marker="v", color="red", ls="", label="dangerous stop")]
    fig.legend(handles=legend, loc="lower center", ncol=4, fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return _save(fig, out / "paper_001_timeline.png")


def _save(fig: Any, path: Path) -> Path:
    plt = _pyplot()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def draw_all(out: Path, plans: Plans) -> list[Path]:
    space = space_of(plans.cell, plans.robot)
    return [voxels_figure(out, plans, space), route_figure(out, plans, space), timeline_figure(out, plans)]
