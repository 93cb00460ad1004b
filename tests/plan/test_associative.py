"""Carried moves planned by Diane and Anikina's method (`planner.transfers: associative`): the
table's route is a shortest path of its k-NN graph (checked against networkx's Dijkstra on a graph
built by brute force, an independent implementation), the TCP point's Jacobian agrees with finite
differences, and the shipped pick-and-place cell cut to two transfers plans with each carried move
through its table's stored rows, clean in the independent carried-motion check and in
`robomax verify`."""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import networkx as nx
import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree
from typer.testing import CliRunner

import robomax_py as rm
from robomax_py.app.cli import app
from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.plan.associative import (
    NEIGHBOURS,
    STEP_RAD,
    AssociativeSettings,
    TcpPoints,
    TransferTable,
    plan_transfer,
    transfer_table,
)
from robomax_py.plan.loads import Loads, check_carried_motion
from robomax_py.robot.ik.table import TableIk, TableRoute, knn_graph, route
from robomax_py.robot.solve import config_text
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
SHIPPED = REPO / "cells" / "pick_place.yaml"
# Route lengths are sums of the same float distances in another order.
LENGTH_RTOL = 1e-9
# Joint values as programs state them: 4 decimals of a degree.
WRITTEN_RAD = np.radians(1e-4)


def _brute_knn(x: np.ndarray, k: int) -> nx.Graph:
    """The k-NN graph by brute force (every distance), as networkx holds it."""
    g = nx.Graph()
    g.add_nodes_from(range(len(x)))
    d = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=2)
    np.fill_diagonal(d, np.inf)
    for i, row in enumerate(np.argsort(d, axis=1, kind="stable")[:, :k]):
        for j in row.tolist():
            g.add_edge(i, j, weight=float(d[i, j]))
    return g


def _same_graph(x: np.ndarray, k: int) -> nx.Graph:
    """The route's own k-NN graph (`knn_graph`) in networkx, its lengths the points' distances."""
    g = nx.Graph()
    built = knn_graph(x, k)
    g.add_nodes_from(range(len(x)))
    length = np.linalg.norm(x[built.a] - x[built.b], axis=1)
    g.add_weighted_edges_from(zip(built.a.tolist(), built.b.tolist(), length.tolist()))
    return g


def _check_shortest(graph: nx.Graph, found: TableRoute, start: int, goal: int, x: np.ndarray) -> None:
    """The route against networkx's Dijkstra on the graph less the edges the route found blocked."""
    open_graph = graph.copy()
    open_graph.remove_edges_from(found.blocked)
    if not found.found:
        assert not nx.has_path(open_graph, start, goal)
        return
    assert found.nodes[0] == start and found.nodes[-1] == goal
    for u, v in itertools.pairwise(found.nodes):
        assert open_graph.has_edge(u, v)
    walked = sum(float(np.linalg.norm(x[u] - x[v])) for u, v in itertools.pairwise(found.nodes))
    assert walked == pytest.approx(found.length, rel=LENGTH_RTOL)
    assert nx.dijkstra_path_length(open_graph, start, goal) == pytest.approx(found.length, rel=LENGTH_RTOL)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(3, 8))
def test_the_route_is_a_shortest_path_of_the_knn_graph(seed: int, k: int) -> None:
    """Random points (no ties), edges crossing a wall with one gap blocked: the lazy route equals
    networkx's Dijkstra on the brute-force graph less the edges it found blocked."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(0.0, 1.0, size=(160, 3))
    table = TableIk(x, x, len(x), cKDTree(x))

    def free(a: np.ndarray, b: np.ndarray) -> bool:
        # The wall x = 0.5, open where y > 0.8: an edge crossing it elsewhere is blocked.
        if (a[0] - 0.5) * (b[0] - 0.5) >= 0:
            return True
        s = (0.5 - a[0]) / (b[0] - a[0])
        return bool(a[1] + s * (b[1] - a[1]) > 0.8)

    graph = _brute_knn(x, k)
    g = knn_graph(x, k)
    assert {(int(a), int(b)) for a, b in zip(g.a, g.b)} == {(min(u, v), max(u, v)) for u, v in graph.edges}
    start, goal = int(np.argmin(x[:, 0])), int(np.argmax(x[:, 0]))
    found = route(table, start, goal, k, free, max_blocked=10_000)
    assert found.status in ("found", "no_route")
    for a, b in found.blocked:
        assert not free(x[a], x[b])
    for u, v in itertools.pairwise(found.nodes):
        assert free(x[u], x[v])
    _check_shortest(graph, found, start, goal, x)


WELD_CELL = """
robomax: 1
name: weld
robot: {model: kr16, home: [0, -90, 90, 0, 30, 0]}
tool: spot_gun_light
objects:
  - {name: plate, box: [0.3, 0.3, 0.01], pose: {xyz: [1.0, 0, 0.5]}, workpiece: true}
process: {clearance: 0.005}
planner: {transfers: associative}
seams:
  - name: s
    spots:
      - {name: a, xyz: [1.0, 0, 0.505], normal: [0, 0, 1], direction: [1, 0, 0]}
"""


@pytest.fixture(scope="module")
def two_transfers(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The shipped cell cut to two transfers, the low board to the high one (a straight move sweeps
    the part through the high board's edge) and table a to the low board, planned associatively."""
    data = yaml.safe_load(SHIPPED.read_text())
    data["name"] = "two_transfers"
    data["pick_place"]["transfers"] = [{"part": "housing", "from": "low_2", "to": "high_1"},
                                       {"part": "bracket", "from": "a_2", "to": "low_1"}]
    data["planner"]["transfers"] = "associative"
    folder = tmp_path_factory.mktemp("associative")
    path = folder / "two_transfers.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot, PlanOptions())
    return {"path": path, "cell": cell, "robot": robot, "result": result}


def test_the_option_is_read_and_defaults_to_moves(tmp_path: Path) -> None:
    assert load_cell(SHIPPED).planner.transfers == "moves"
    data = yaml.safe_load(SHIPPED.read_text())
    data["planner"]["transfers"] = "sideways"
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(CellFileError) as err:
        load_cell(bad)
    assert err.value.key == "planner.transfers"
    # In a cell that carries nothing the option changes nothing: a warning says so.
    (tmp_path / "weld.yaml").write_text(WELD_CELL)
    notices = load_cell(tmp_path / "weld.yaml").notices
    assert [n.key for n in notices if "pick_place" in n.message] == ["planner.transfers"]


def test_carried_moves_follow_their_routes_through_stored_rows(two_transfers: dict[str, Any]) -> None:
    """Each carried move is a detour through the route its table gives for its two ends; every
    waypoint between them is a row of that table's grid (formula (11)) and free with the part."""
    cell, robot, result = two_transfers["cell"], two_transfers["robot"], two_transfers["result"]
    assert result.status == "planned", result.message
    loads = Loads.of(cell, robot)
    assert loads is not None
    carried = [t for t in result.transitions if t.part is not None]
    assert [t.part for t in carried] == ["housing", "bracket"]
    for trans in carried:
        assert trans.kind == "detour"
        wp = np.asarray(trans.waypoints)
        # The two ends in one IK branch (the configuration status; turns may differ).
        assert config_text(robot, wp[0]).split()[0] == config_text(robot, wp[-1]).split()[0]
        world = loads.worlds[str(trans.part)]
        again = plan_transfer(robot, world, wp[0], wp[-1])
        assert again.status == "routed"
        # Planned from the ends as written: the same route, as written.
        np.testing.assert_allclose(wp, again.waypoints, atol=WRITTEN_RAD)
        memory = transfer_table(robot, world, TcpPoints(robot), wp[0], wp[-1], AssociativeSettings())
        assert isinstance(memory, TransferTable)
        inner = wp[1:-1]
        start = np.asarray(memory.grid.start)
        spacing = (np.asarray(memory.grid.end) - start) / (np.asarray(memory.grid.counts) - 1)
        index = (inner - start) / spacing
        np.testing.assert_allclose(index, np.round(index), atol=1e-4)
        assert np.all(spacing <= STEP_RAD + 1e-12)
        assert world.are_free(inner).all()
        # The route is a shortest path of the table's k-NN graph (less the edges found blocked),
        # networkx's Dijkstra on the same graph.
        _check_shortest(_same_graph(memory.table.x, NEIGHBOURS), again.route, memory.start, memory.goal,
                        memory.table.x)


def test_the_plan_is_clean_in_the_independent_checks_and_verifies(two_transfers: dict[str, Any],
                                                                  tmp_path: Path) -> None:
    cell, robot, result = two_transfers["cell"], two_transfers["robot"], two_transfers["result"]
    loads = Loads.of(cell, robot)
    assert loads is not None
    empty = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots = [{"seam": p.seam, "name": p.name, "t_arrive": p.t_arrive, "t_leave": p.t_leave} for p in result.spots]
    traj = result.trajectory
    assert check_carried_motion(cell, robot, empty, loads.worlds, traj.t, traj.q, spots).clean
    out = tmp_path / "programs"
    loaded = rm.load_cell(two_transfers["path"])
    written = rm.write_programs(loaded, result, out)           # each program read back, rebuilt, proven
    srcl = next(p for p in written if p.suffix == ".srcl")
    verified = CliRunner().invoke(app, ["verify", str(two_transfers["path"]), str(srcl)], env={"COLUMNS": "200"})
    assert verified.exit_code == 0, verified.output
    assert "clean" in verified.output


@settings(max_examples=20, deadline=None)
@given(st.lists(st.floats(-1.5, 1.5), min_size=6, max_size=6))
def test_the_tcp_points_jacobian_matches_finite_differences(two_transfers: dict[str, Any], q: list[float]) -> None:
    points = TcpPoints(two_transfers["robot"])
    qa = np.array(q)
    h = 1e-6
    numeric = np.stack([(points.points(qa + h * e) - points.points(qa - h * e))[0] / (2 * h) for e in np.eye(6)], axis=1)
    np.testing.assert_allclose(points.jacobian(qa), numeric, atol=1e-6)

