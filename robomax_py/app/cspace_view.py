"""The `robomax cspace` command's work: the wrist of a spot, the map's summary and its picture."""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.cspace import (
    CSpaceError,
    CSpaceMap,
    LearnedModel,
    TrainingSettings,
    cover_radius,
    learned_map,
    learned_model,
    surface_points,
)
from robomax_py.plan.poses import nominal_rotation
from robomax_py.robot import RobotModel
from robomax_py.robot.solve import solve_all
from robomax_py.spec import CellSpec
from robomax_py.transforms import invert
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import Scene

DPI = 100
MAX_POINTS = 60_000          # blocked cells drawn at most (an even subsample beyond)


def spot_wrist(cell: CellSpec, robot: RobotModel, name: str, world: CollisionWorld) -> FloatArray:
    """A4-A6 (rad) of the spot's first collision-free IK branch within the limits at its nominal
    orientation.

    `name` is "seam/spot" or a spot name that only one seam has; `world` is the cell's."""
    matches = [(seam, spot) for seam in cell.seams for spot in seam.spots
               if name in (spot.name, f"{seam.name}/{spot.name}")]
    if not matches:
        raise CSpaceError(f"{cell.source}: --wrist: no spot named {name!r} (use home, a spot name or seam/spot)")
    if len(matches) > 1:
        raise CSpaceError(f"{cell.source}: --wrist: {len(matches)} seams have a spot {name!r}; name it as seam/spot")
    _, spot = matches[0]
    T_world_tcp = np.eye(4)
    T_world_tcp[:3, :3] = nominal_rotation(spot)
    T_world_tcp[:3, 3] = spot.xyz
    T_base_tcp = invert(np.asarray(cell.T_world_base)) @ T_world_tcp
    table = solve_all(robot, T_base_tcp[None], q_hint=np.asarray(cell.home, dtype=float), expand_turns=False)
    valid = np.flatnonzero(table.valid[0])
    if not len(valid):
        raise CSpaceError(f"{cell.source}: --wrist: spot {name} has no IK solution within {robot.name}'s limits at "
                          "its nominal orientation")
    # The first branch the arm can weld in: a wrist that folds the gun into the arm blocks every cell.
    for column in valid:
        q = np.asarray(table.q[0, column], dtype=float)
        if world.is_free(q):
            return q[3:]
    raise CSpaceError(f"{cell.source}: --wrist: every IK branch of spot {name} at its nominal orientation collides")


def map_summary(m: CSpaceMap) -> dict[str, object]:
    """What the map holds, in degrees and counts (for the report and --json)."""
    r = m.grid.resolution
    return {
        "resolution": r,
        "cells": m.grid.size,
        "wrist_deg": [round(float(v), 3) for v in np.degrees(m.grid.wrist)],
        "axes_deg": [[round(float(np.degrees(a[0])), 3), round(float(np.degrees(a[-1])), 3)] for a in m.grid.axes],
        "blocked_by_objects": int(m.obstacle.sum()),
        "blocked_by_itself": int(m.self_contact.sum()),
        "free": int((~m.blocked).sum()),
        "checks": m.checks,
        "cpu_s": round(m.cpu_seconds, 3),
        "wall_s": round(m.wall_seconds, 3),
        "method": m.method,
    }


def learned_summary(cell: CellSpec, robot: RobotModel, scene: Scene, exact: CSpaceMap, spacing: float,
                    inflation: float) -> tuple[dict[str, object], LearnedModel]:
    """The learned map on the exact map's grid, how it differs from it cell by cell, and the model."""
    radius = cell.process.clearance + cover_radius(spacing) + inflation
    model, cached = learned_model(cell, robot, exact.grid.wrist, radius, TrainingSettings())
    points = surface_points(scene, spacing)
    m = learned_map(model, points, exact.grid)
    return {
        "learned_blocked_by_objects": int(m.obstacle.sum()),
        "learned_wrongly_free": int((exact.obstacle & ~m.obstacle).sum()),
        "learned_wrongly_blocked": int((~exact.obstacle & m.obstacle).sum()),
        "learned_points": len(points),
        "learned_sphere_radius_m": round(radius, 4),
        "learned_cpu_s": round(m.cpu_seconds, 3),
        "training": "cached" if cached else f"{model.train_cpu_seconds:.1f} s CPU, {model.train_checks:,} checks",
        "training_neurons": len(model.centres),
    }, model


def map_png(m: CSpaceMap, title: str, path: FloatArray | None = None) -> bytes:
    """A 3-D scatter of the blocked cells (objects red, the arm itself grey) over A1-A3 in degrees,
    and a program's path (its A1-A3 samples, (k, 3) rad) as a line when given. The map holds for its
    fixed wrist; the path's wrist moves, so the line is the path's shadow on the map, not a proof."""
    fig, ax = _axes3d()
    rng = np.random.default_rng(0)
    for mask, colour, label in ((m.obstacle, "#d62728", "objects"), (m.self_contact & ~m.obstacle, "#7f7f7f", "itself")):
        idx = np.argwhere(mask)
        if len(idx) > MAX_POINTS:
            idx = idx[np.sort(rng.choice(len(idx), MAX_POINTS, replace=False))]
        q = [np.degrees(m.grid.axes[a][idx[:, a]]) for a in range(3)]
        ax.scatter(q[0], q[1], q[2], s=2, c=colour, alpha=0.35, depthshade=False, label=f"{label} ({int(mask.sum()):,})")
    if path is not None and len(path):
        deg = np.degrees(np.asarray(path, dtype=float)[:, :3])
        ax.plot(deg[:, 0], deg[:, 1], deg[:, 2], color="#1f77b4", linewidth=1.5, label="program")
        ax.scatter(deg[[0, -1], 0], deg[[0, -1], 1], deg[[0, -1], 2], color="#1f77b4", s=25)
    return _png(fig, ax, ("A1 (deg)", "A2 (deg)", "A3 (deg)"), title)


def model_png(model: LearnedModel, distances: tuple[float, ...], title: str) -> bytes:
    """The paper's picture of the learned model: a point obstacle's C-obstacle over (q1 - azimuth,
    q2 - elevation, q3) in degrees at a few distances from the virtual base, one colour each."""
    fig, ax = _axes3d()
    lo, hi = model.profiles(np.asarray(distances, dtype=float))            # (m, B, C)
    mids = np.degrees((model.bands[:-1] + model.bands[1:]) / 2)
    q3 = model.q3
    colours = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")
    for n, d in enumerate(distances):
        b, c, k = np.nonzero((q3[None, None, :] >= lo[n][:, :, None]) & (q3[None, None, :] <= hi[n][:, :, None]))
        ax.scatter(mids[b], np.degrees(model.q2[c]), np.degrees(q3[k]), s=2, alpha=0.4, depthshade=False,
                   c=colours[n % len(colours)], label=f"d = {d:.2f} m ({len(b):,} cells)")
    return _png(fig, ax, ("A1 - azimuth (deg, band centre)", "A2 - elevation (deg)", "A3 (deg)"), title)


def _axes3d() -> tuple[Any, Any]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(8, 7), dpi=DPI)
    return fig, fig.add_subplot(projection="3d")


def _png(fig: Any, ax: Any, labels: tuple[str, str, str], title: str) -> bytes:
    import matplotlib.pyplot as plt

    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_zlabel(labels[2])
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize="small")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI)
    plt.close(fig)
    return buf.getvalue()
