"""The paper's planar case worked through for `bench_table_ik.py` (a helper, not a test): the tables,
the paper's route and ours, the regression error, and the figures drawn with matplotlib.

Diane and Anikina's figures 3-6: the stored points of the 3-link arm with 10 deg steps without and
with the part (Fig. 3, 4), with 20 deg steps with the part (Fig. 5), and the k-NN graph with the
route Dijkstra finds on it (Fig. 6). Their route is followed by formula (15) from the start's
stored configuration, the arm's tip (x, y) the point, every k-NN edge usable; we draw it, and the
same route checked: the tip's pose as the point (`PlanarArm.pose`) and an edge used only where
(15) arrives at the far node's stored configuration with the arm and part clear of the container
(`robot.ik.table.follow_edge`), which is what `planner.transfers: associative` does on a six-axis
arm.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from robomax_py.robot.ik.table import (
    JointGrid,
    TableIk,
    TableRoute,
    build_table,
    follow_edge,
    jacobian_interpolation,
    knn_graph,
    route,
)
from robomax_py.robot.planar import Container, PlanarArm

HALF_PI = np.pi / 2
HELD_M = 0.25
# The pick and place points of the route figure (m): the low left shelf to the high right one.
PICK = (-0.8, 0.85)
PLACE = (0.8, 1.45)
# k of the paper's route figure ("k >= 3"), and of the checked route (a pose point's nearest
# neighbours include rows of the other elbow branch, which no edge reaches: 12 found every route
# tried on the planar arm).
PAPER_K = 4
CHECKED_K = 12
# Steps of formula (15) (m) and the arrival tolerance (rad) of the checked route.
STEP_M = 0.005
ARRIVAL_RAD = 0.02


def grid(J: int) -> JointGrid:
    return JointGrid.stepped((-HALF_PI,) * 3, (HALF_PI,) * 3, J)


def point_table(J: int, held: float, box: Container) -> TableIk:
    """The paper's table: tips (x, y) of the free rows."""
    arm = PlanarArm(held=held)
    return build_table(grid(J), arm.tip, lambda q: box.free(arm, q))


def pose_table(points: TableIk, held: float) -> TableIk:
    """The same rows keyed by the tip's pose."""
    x = PlanarArm(held=held).pose(points.q)
    return TableIk(points.q, x, points.grid_size, cKDTree(x))


@dataclass(frozen=True, slots=True, eq=False)
class Followed:
    """A route and the arm's motion along it: rows (m, 3) and which of them are free."""

    route: TableRoute
    rows: np.ndarray
    free: np.ndarray


def paper_route(table: TableIk, held: float, box: Container, k: int = PAPER_K) -> Followed:
    """The paper's: ends by formula (8), Dijkstra over every k-NN edge, (15) from the start."""
    arm = PlanarArm(held=held)
    i, j = (int(np.argmin(np.linalg.norm(table.x - p, axis=1))) for p in (PICK, PLACE))
    found = route(table, i, j, k, lambda a, b: True)
    q = table.q[i].copy()
    rows = [q[None]]
    for v in found.nodes[1:]:
        leg, _ = jacobian_interpolation(q, table.x[v], arm.tip, arm.jacobian, STEP_M)
        rows.append(leg[1:])
        q = leg[-1]
    out = np.vstack(rows)
    return Followed(found, out, box.free(arm, out))


def checked_route(points: TableIk, held: float, box: Container, k: int = CHECKED_K) -> Followed:
    """Ours: the pose as the point, edges checked lazily (arrival and clearance)."""
    arm = PlanarArm(held=held)
    table = pose_table(points, held)
    i, j = (int(np.argmin(np.linalg.norm(points.x - p, axis=1))) for p in (PICK, PLACE))
    legs: dict[tuple[bytes, bytes], np.ndarray] = {}

    def edge_free(a: np.ndarray, b: np.ndarray) -> bool:
        edge = follow_edge(a, b, arm.pose, arm.pose_jacobian, STEP_M, ARRIVAL_RAD)
        ok = edge.arrived and bool(box.free(arm, edge.rows).all())
        if ok:
            legs[(a.tobytes(), b.tobytes())] = edge.rows
        return ok

    found = route(table, i, j, k, edge_free, max_blocked=20_000)
    rows = [table.q[i][None]]
    for u, v in itertools.pairwise(found.nodes):
        a, b = table.q[u], table.q[v]
        leg = legs.get((a.tobytes(), b.tobytes()))
        rows.append((leg if leg is not None else legs[(b.tobytes(), a.tobytes())][::-1])[1:])
    out = np.vstack(rows)
    return Followed(found, out, box.free(arm, out))


@dataclass(frozen=True, slots=True)
class RegressionError:
    """The lookup's error over targets reached by free random configurations (m): the nearest
    stored point's distance (the regression (6)), and after one step of (15) from its row."""

    J: int
    held: bool
    stored: int
    lookup: tuple[float, float, float]          # median, 95th percentile, largest
    refined: tuple[float, float, float]


def regression_error(J: int, held: float, box: Container, targets: int, rng: np.random.Generator) -> RegressionError:
    arm = PlanarArm(held=held)
    table = point_table(J, held, box)
    q = rng.uniform(-HALF_PI, HALF_PI, size=(targets * 3, 3))
    q = q[box.free(arm, q)][:targets]
    x = arm.tip(q)
    q_star, err = table.lookup(x)
    refined = np.empty(len(x))
    for n, (qs, target) in enumerate(zip(q_star, x)):
        J_ = arm.jacobian(qs)
        # One damped least-squares step of (15) from the stored row towards the target.
        step = J_.T @ np.linalg.solve(J_ @ J_.T + 1e-6 * np.eye(2), target - arm.tip(qs[None])[0])
        refined[n] = float(np.linalg.norm(arm.tip((qs + step)[None])[0] - target))

    def stats(e: np.ndarray) -> tuple[float, float, float]:
        return float(np.median(e)), float(np.percentile(e, 95)), float(e.max())

    return RegressionError(J, held > 0, len(table), stats(err), stats(refined))


def draw(out: Path, name: str, box: Container, title: str, table: TableIk, held: float,
         graph_k: int | None = None, routes: tuple[tuple[Followed, TableIk, str, str], ...] = ()) -> Path:
    """One figure: the container, the stored points, optionally the k-NN graph and routes (the
    route's nodes joined in its colour, the tip's path dotted, colliding steps marked)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Rectangle

    fig, ax = plt.subplots(figsize=(6.4, 6.4), dpi=100)
    for x0, y0, x1, y1 in box.rects:
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, color="0.75", lw=0))
    if graph_k is not None:
        g = knn_graph(table.x, graph_k, table.tree)
        ax.add_collection(LineCollection(np.stack([table.x[g.a, :2], table.x[g.b, :2]], axis=1), colors="0.6",
                                         linewidths=0.5, zorder=1))
    ax.scatter(table.x[:, 0], table.x[:, 1], s=6, c="tab:blue", zorder=2)
    arm = PlanarArm(held=held)
    for followed, keyed, colour, label in routes:
        if not followed.route.found:
            continue
        nodes = np.array(followed.route.nodes)
        tips = PlanarArm().tip(keyed.q[nodes])
        ax.plot(tips[:, 0], tips[:, 1], color=colour, lw=2.2, zorder=3, label=label)
        path = arm.tip(followed.rows)
        ax.plot(path[:, 0], path[:, 1], ":", color=colour, lw=1, zorder=3)
        bad = ~followed.free
        if bad.any():
            ax.scatter(path[bad, 0], path[bad, 1], s=8, c="red", zorder=4,
                       label=f"{label}: {int(bad.sum())} of {len(bad)} steps in collision")
        for q in (followed.rows[0], followed.rows[-1]):
            segs = arm.segments(q[None])[0]
            colours = ["0.2"] * len(arm.links) + ["tab:orange"] * (len(segs) - len(arm.links))
            ax.add_collection(LineCollection(segs, colors=colours, linewidths=2, zorder=5))
    ax.set_xlim(-1.1, 1.1)
    ax.set_ylim(-0.1, 2.1)
    ax.set_aspect("equal")
    ax.set_xlabel("x, m")
    ax.set_ylabel("y, m")
    ax.set_title(title, fontsize=9)
    if any(f.route.found for f, *_ in routes):
        ax.legend(loc="lower center", fontsize=7)
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    path_png = out / name
    fig.savefig(path_png)
    plt.close(fig)
    return path_png
