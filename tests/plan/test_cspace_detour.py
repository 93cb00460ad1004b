"""robomax_py.plan.cspace_detour: detours through the local A1-A3 map, and `planner.detours`.

What must hold: a detour it offers starts at qa, ends at qb and every segment is free by the swept
check (checked here again, independently); it finds detours round the reference cell's objects for
blocked straight moves; the cell key takes roadmap / cspace / both and refuses anything else.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from robomax_py.cspace.grid import nearest_cell, neighbour_moves
from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions
from robomax_py.plan.cspace_detour import (
    ENCLOSURE_STEPS,
    LIMIT_INSET_RAD,
    MARGIN_RAD,
    REPAIR_BUDGET,
    RESOLUTION,
    _LazyCells,
    _repaired_path,
    grid_detour,
    local_grid,
    move_times,
)
from robomax_py.plan.results import resolved_options
from robomax_py.timing import ptp_time_estimate
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.collision_results import SegmentCheck
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"


@pytest.fixture(scope="module")
def reference():  # type: ignore[no-untyped-def]
    assert REFERENCE_CELL.is_file(), "the reference cell (tests/data/reference) is shipped with the repository"
    cell = load_cell(REFERENCE_CELL)
    robot = load_cell_robot(cell)
    return cell, robot, CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)


def test_detours_are_free_and_join_their_ends(reference, rng: np.random.Generator) -> None:  # type: ignore[no-untyped-def]
    _, robot, world = reference
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    home = np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])
    found = tried = 0
    while tried < 12:
        qa, qb = home + rng.uniform(-0.8, 0.8, size=(2, robot.dof))
        qa, qb = np.clip(qa, lo, hi), np.clip(qb, lo, hi)
        if not (world.is_free(qa) and world.is_free(qb)) or world.segment_free(qa, qb):
            continue                                   # a blocked move between two free ends
        tried += 1
        det, checks = grid_detour(world, robot.limits, qa, qb)
        assert checks > 0
        if det is None:
            continue
        found += 1
        np.testing.assert_array_equal(det.waypoints[0], qa)
        np.testing.assert_array_equal(det.waypoints[-1], qb)
        assert all(world.segment_free(a, b) for a, b in zip(det.waypoints[:-1], det.waypoints[1:]))
        assert np.isfinite(det.time_estimate) and det.checks == checks
    assert found >= 3


def test_the_cell_key_chooses_the_back_end(tmp_path: Path) -> None:
    data = yaml.safe_load(REFERENCE_CELL.read_text())
    (tmp_path / "parts").symlink_to(REFERENCE_CELL.parent / "parts")
    for value in ("roadmap", "cspace", "both"):
        data.setdefault("planner", {})["detours"] = value
        path = tmp_path / f"cell_{value}.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False))
        cell = load_cell(path)
        assert cell.planner.detours == value
        assert resolved_options(cell, PlanOptions()).detours == value
        assert resolved_options(cell, PlanOptions(detours="roadmap")).detours == "roadmap"
    data["planner"]["detours"] = "astar"
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(CellFileError, match="planner.detours"):
        load_cell(path)


class _WallAtStart:
    """A stand-in world: every configuration whose first three joints lie within `radius` (rad, any
    of them) of `centre` is blocked, the rest free; counts the configurations it was asked about."""

    def __init__(self, centre: np.ndarray, radius: float) -> None:
        self.centre, self.radius, self.asked = centre, radius, 0

    def are_free(self, configs: np.ndarray) -> np.ndarray:
        self.asked += len(configs)
        return np.asarray(np.max(np.abs(configs[:, :3] - self.centre[:3]), axis=1) > self.radius)


def test_a_map_whose_start_cell_is_blocked_is_not_checked_further(reference) -> None:  # type: ignore[no-untyped-def]
    """The cell nearest qa blocked (qa itself free, next to an obstacle): no way through the map,
    found by checking the two end cells alone, not the whole grid."""
    _, robot, _ = reference
    qa = np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])
    qb = qa + np.array([0.6, 0.3, -0.2, 0.1, 0.0, 0.0])
    world = _WallAtStart(qa, 0.05)        # the grid's cells lie ~0.07 rad apart: the nearest one is within
    det, checks = grid_detour(world, robot.limits, qa, qb)  # type: ignore[arg-type]
    assert det is None
    assert checks == world.asked == 2


class _PlateInACorridor:
    """A stand-in world on the local map's grid (`axes`): free cells are a corridor along A1 at the
    A2-A3 cell (c2, c3), and a loop round beside it (A3 index c3 + 1 and c3 + 2 at A1 indices k - 1
    and k); between the A1 samples k - 1 and k stands a plate of no thickness, 1.6 cells either
    side of the corridor's cell on A2 and A3. A straight move is blocked when its A1-A3 line passes
    through the plate. The corridor's way is the shortest and is blocked between two free cells in
    the middle of the path; the loop's outer column (c3 + 2) is the one way past, longer by two
    moves along A3 alone. Counts the blocked moves it was asked about."""

    def __init__(self, axes: list[np.ndarray], k: int, c2: int, c3: int) -> None:
        self.axes, self.k, self.c2, self.c3 = axes, k, c2, c3
        self.a1 = 0.5 * (axes[0][k - 1] + axes[0][k])
        self.half2, self.half3 = 1.6 * (axes[1][1] - axes[1][0]), 1.6 * (axes[2][1] - axes[2][0])
        self.blocked_moves = 0

    def are_free(self, configs: np.ndarray) -> np.ndarray:
        i, j, l = (np.abs(configs[:, n, None] - self.axes[n][None, :]).argmin(axis=1) for n in range(3))
        loop = np.isin(i, (self.k - 1, self.k)) & np.isin(l, (self.c3 + 1, self.c3 + 2))
        return np.asarray((j == self.c2) & ((l == self.c3) | loop))

    def check_segment(self, q0: np.ndarray, q1: np.ndarray) -> SegmentCheck:
        d0, d1 = q0[0] - self.a1, q1[0] - self.a1
        free = True
        if d0 * d1 < 0:                                  # the move crosses the plate's plane
            at = q0[1:3] + d0 / (d0 - d1) * (q1[1:3] - q0[1:3])
            free = not (abs(at[0] - self.axes[1][self.c2]) < self.half2
                        and abs(at[1] - self.axes[2][self.c3]) < self.half3)
        self.blocked_moves += not free
        return SegmentCheck(free=free, checks=1, states=2, narrow_phase_tests=0, s_contact=None)


def test_a_blocked_move_between_free_cells_is_searched_round(reference) -> None:  # type: ignore[no-untyped-def]
    """Every cell of the corridor free, but its move between two middle cells blocked by the plate:
    that move is taken out of the map's graph and the map searched again until the way round the
    plate is found, whose every move is free."""
    _, robot, _ = reference
    qa = np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])
    qb = qa + np.array([0.6, 0.0, 0.0, 0.2, 0.0, 0.0])
    axes, _ = local_grid(qa, qb, robot.limits.lower, robot.limits.upper, RESOLUTION, MARGIN_RAD)
    _, c2, c3 = nearest_cell(axes, qa)
    world = _PlateInACorridor(axes, int(np.searchsorted(axes[0], 0.5 * (qa[0] + qb[0]))), c2, c3)
    det, checks = grid_detour(world, robot.limits, qa, qb)  # type: ignore[arg-type]
    assert world.blocked_moves > 0                             # the map's first path met the plate
    assert det is not None
    np.testing.assert_array_equal(det.waypoints[0], qa)
    np.testing.assert_array_equal(det.waypoints[-1], qb)
    assert all(world.check_segment(a, b).free for a, b in zip(det.waypoints[:-1], det.waypoints[1:]))
    assert np.isclose(det.waypoints[:, 2], axes[2][c3 + 2]).any()   # past the plate at its outer column
    assert det.checks == checks


@pytest.mark.parametrize("at", ["upper", "lower"])
def test_the_grid_keeps_inside_the_joint_limits(at: str) -> None:
    # A detour between configurations on a limit: the timed path through cells lying on it
    # overshoots the limit (by ~1e-6 rad, refused by the timing), so no cell may lie on it.
    lower, upper = np.array([-3.0, -1.7, -1.0, -3.5, -2.0, -6.9]), np.array([3.0, 1.9, 1.1345, 3.5, 2.0, 6.9])
    edge = upper if at == "upper" else lower
    qa = np.where(np.arange(6) == 2, edge, 0.2)
    qb = qa.copy()
    qb[0] += 0.3
    axes, configs = local_grid(qa, qb, lower, upper, 24, 0.5)
    assert np.all(configs[:, :3] >= lower[:3] + LIMIT_INSET_RAD - 1e-12)
    assert np.all(configs[:, :3] <= upper[:3] - LIMIT_INSET_RAD + 1e-12)
    assert abs(axes[2][-1 if at == "upper" else 0] - (edge[2] - (1 if at == "upper" else -1) * LIMIT_INSET_RAD)) < 1e-12


class _BlockedCells:
    """A stand-in world on the local map's grid: the configurations whose A1-A3 lie on a cell of
    `blocked` ((r, r, r) bool) are blocked, every straight move is free; counts what it was asked."""

    def __init__(self, axes: list[np.ndarray], blocked: np.ndarray) -> None:
        self.axes, self.blocked, self.asked = axes, blocked, 0

    def are_free(self, configs: np.ndarray) -> np.ndarray:
        self.asked += len(configs)
        i, j, k = (np.abs(configs[:, n, None] - self.axes[n][None, :]).argmin(axis=1) for n in range(3))
        return np.asarray(~self.blocked[i, j, k])

    def check_segment(self, q0: np.ndarray, q1: np.ndarray) -> SegmentCheck:
        return SegmentCheck(free=True, checks=1, states=2, narrow_phase_tests=0, s_contact=None)


def _joined(blocked: np.ndarray, a: tuple[int, ...], b: tuple[int, ...]) -> bool:
    """Whether free cells a and b are 26-connected through free cells: scipy's labelling of the
    whole grid, the definition the map's answer must agree with."""
    labels, _ = ndimage.label(~blocked, structure=np.ones((3, 3, 3), dtype=bool))
    return bool(labels[a] == labels[b])


def _walls(rng: np.random.Generator, r: int, walls: int, holes: Callable[[], int]) -> np.ndarray:
    """(r, r, r) bool: `walls` blocked planes of cells across the map, each across a random axis
    at a random place, with holes() random cells of it free again."""
    blocked = np.zeros((r,) * 3, dtype=bool)
    for _ in range(walls):
        axis, at = int(rng.integers(3)), int(rng.integers(r))
        wall = [slice(None)] * 3
        wall[axis] = slice(at, at + 1)
        blocked[tuple(wall)] = True
        for _ in range(holes()):
            hole = [int(rng.integers(r)) for _ in range(3)]
            hole[axis] = at
            blocked[tuple(hole)] = False
    return blocked


def _ends(robot, qa: np.ndarray, qb: np.ndarray):  # type: ignore[no-untyped-def]
    axes, _ = local_grid(qa, qb, robot.limits.lower, robot.limits.upper, RESOLUTION, MARGIN_RAD)
    return axes, nearest_cell(axes, qa), nearest_cell(axes, qb)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31), walls=st.integers(0, 3), pockets=st.integers(0, 2), near=st.booleans())
def test_the_map_finds_no_way_exactly_where_its_ends_are_not_joined(reference, seed: int, walls: int,  # type: ignore[no-untyped-def]
                                                                    pockets: int, near: bool) -> None:
    """Walls across the map and pockets round either end (a shell of blocked cells one to three
    steps out, sometimes cut by the map's edge or holed), every straight move free: a detour exactly
    where the two end cells are joined through free cells (scipy's labelling of the whole grid);
    an end walled in close by is told without checking the whole map."""
    _, robot, _ = reference
    rng = np.random.default_rng(seed)
    qa = np.radians([0.0, -90.0, 90.0, 0.0, 30.0, 0.0])
    qb = qa + (rng.uniform(-0.08, 0.08, size=6) if near else rng.uniform(-0.8, 0.8, size=6))
    axes, start, goal = _ends(robot, qa, qb)
    r = RESOLUTION
    blocked = _walls(rng, r, walls, lambda: int(rng.uniform() < 0.3))      # a hole in a wall or none
    for _ in range(pockets):
        centre = start if rng.uniform() < 0.5 else goal
        out = int(rng.integers(1, 4))
        box = tuple(slice(max(0, c - out), c + out + 1) for c in centre)
        inner = tuple(slice(max(0, c - out + 1), c + out) for c in centre)
        shell = np.zeros_like(blocked)
        shell[box] = True
        shell[inner] = False
        if rng.uniform() < 0.3:                                   # a hole in the shell
            holes = np.argwhere(shell)
            shell[tuple(holes[rng.integers(len(holes))])] = False
        blocked |= shell
    blocked[start] = blocked[goal] = False
    world = _BlockedCells(axes, blocked)
    det, checks = grid_detour(world, robot.limits, qa, qb)  # type: ignore[arg-type]
    assert (det is not None) == _joined(blocked, start, goal)
    assert checks >= world.asked


def test_an_end_in_a_pocket_is_told_from_the_cells_round_it(reference) -> None:  # type: ignore[no-untyped-def]
    """qb's cell walled in two steps out: no way, found from the two blocks round the ends."""
    _, robot, _ = reference
    qa = np.radians([0.0, -90.0, 90.0, 0.0, 30.0, 0.0])
    qb = qa + np.array([0.6, 0.3, -0.2, 0.1, 0.0, 0.0])
    axes, _, goal = _ends(robot, qa, qb)
    blocked = np.zeros((RESOLUTION,) * 3, dtype=bool)
    blocked[tuple(slice(g - 2, g + 3) for g in goal)] = True
    blocked[tuple(slice(g - 1, g + 2) for g in goal)] = False
    world = _BlockedCells(axes, blocked)
    det, checks = grid_detour(world, robot.limits, qa, qb)  # type: ignore[arg-type]
    assert det is None
    assert world.asked <= 2 + 2 * ((2 * ENCLOSURE_STEPS + 1) ** 3 - 1) and checks == world.asked
    # The same pocket with one hole in its shell: the way out is found, the cells beyond the blocks
    # round the ends checked where the map's paths look at them, not all of them.
    blocked[goal[0] + 2, goal[1], goal[2]] = False
    world = _BlockedCells(axes, blocked)
    det, _ = grid_detour(world, robot.limits, qa, qb)  # type: ignore[arg-type]
    assert det is not None
    assert 2 * (2 * ENCLOSURE_STEPS + 1) ** 3 - 1 < world.asked < RESOLUTION ** 3


def test_two_ends_in_one_pocket_are_joined(reference) -> None:  # type: ignore[no-untyped-def]
    """qa and qb a step apart inside one small pocket: their free cells stay inside the block round
    each, but they hold each other, so the way between them is found."""
    _, robot, _ = reference
    qa = np.radians([0.0, -90.0, 90.0, 0.0, 30.0, 0.0])
    qb = qa + np.array([0.05, 0.0, 0.0, 0.0, 0.0, 0.0])
    axes, start, goal = _ends(robot, qa, qb)
    assert start != goal and max(abs(a - b) for a, b in zip(start, goal)) <= 1
    lo = [min(a, b) - 1 for a, b in zip(start, goal)]
    hi = [max(a, b) + 2 for a, b in zip(start, goal)]
    blocked = np.zeros((RESOLUTION,) * 3, dtype=bool)
    blocked[tuple(slice(l, h) for l, h in zip(lo, hi))] = True
    blocked[tuple(slice(l + 1, h - 1) for l, h in zip(lo, hi))] = False
    world = _BlockedCells(axes, blocked)
    det, _ = grid_detour(world, robot.limits, qa, qb)  # type: ignore[arg-type]
    assert det is not None


def test_an_end_against_the_maps_edge_is_walled_in_by_the_edge_and_its_pocket(reference) -> None:  # type: ignore[no-untyped-def]
    """qb on A2's lower limit (the map's edge there): a pocket open only towards the edge walls it in."""
    _, robot, _ = reference
    qa = np.radians([0.0, -90.0, 90.0, 0.0, 30.0, 0.0])
    qb = qa + np.array([0.4, 0.0, -0.2, 0.1, 0.0, 0.0])
    qb[1] = robot.limits.lower[1] + 0.01
    axes, _, goal = _ends(robot, qa, qb)
    assert goal[1] == 0
    blocked = np.zeros((RESOLUTION,) * 3, dtype=bool)
    blocked[goal[0] - 2:goal[0] + 3, 0:3, goal[2] - 2:goal[2] + 3] = True
    blocked[goal[0] - 1:goal[0] + 2, 0:2, goal[2] - 1:goal[2] + 2] = False
    world = _BlockedCells(axes, blocked)
    det, _ = grid_detour(world, robot.limits, qa, qb)  # type: ignore[arg-type]
    assert det is None
    assert world.asked <= 2 + 2 * ((2 * ENCLOSURE_STEPS + 1) ** 3 - 1)


@pytest.mark.parametrize("side", [1, -1])
def test_a_pocket_open_on_one_side_only_is_not_walled_in(reference, side: int) -> None:  # type: ignore[no-untyped-def]
    """qb's cell inside a block of blocked cells as large as the box round it, a corridor leading
    out through one A1 side of the block alone: its free cells reach that side, so the end is not taken
    for walled in and the way out is found."""
    _, robot, _ = reference
    qa = np.radians([0.0, -90.0, 90.0, 0.0, 30.0, 0.0])
    qb = qa + np.array([0.6, 0.3, -0.2, 0.1, 0.0, 0.0])
    axes, start, goal = _ends(robot, qa, qb)
    s = ENCLOSURE_STEPS
    assert all(s < g < RESOLUTION - s - 1 for g in goal)
    assert max(abs(a - b) for a, b in zip(start, goal)) > s
    blocked = np.zeros((RESOLUTION,) * 3, dtype=bool)
    blocked[tuple(slice(g - s, g + s + 1) for g in goal)] = True
    blocked[tuple(slice(g - 1, g + 2) for g in goal)] = False                  # the pocket
    corridor = slice(goal[0], goal[0] + s + 1) if side > 0 else slice(goal[0] - s, goal[0] + 1)
    blocked[corridor, goal[1], goal[2]] = False
    world = _BlockedCells(axes, blocked)
    det, _ = grid_detour(world, robot.limits, qa, qb)  # type: ignore[arg-type]
    assert det is not None


class _BlockedCellsAndMoves(_BlockedCells):
    """`_BlockedCells`, and the straight moves between the cell pairs of `cut` ((low, high) cell
    indices, C order) blocked."""

    def __init__(self, axes: list[np.ndarray], blocked: np.ndarray, cut: set[tuple[int, int]]) -> None:
        super().__init__(axes, blocked)
        self.cut = cut

    def _cell(self, q: np.ndarray) -> int:
        return int(np.ravel_multi_index(tuple(int(np.abs(self.axes[n] - q[n]).argmin()) for n in range(3)),
                                        self.blocked.shape))

    def check_segment(self, q0: np.ndarray, q1: np.ndarray) -> SegmentCheck:
        a, b = sorted((self._cell(q0), self._cell(q1)))
        return SegmentCheck(free=(a, b) not in self.cut, checks=1, states=2, narrow_phase_tests=0, s_contact=None)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31), walls=st.integers(0, 3), cut_share=st.sampled_from([0.0, 0.002, 0.01]))
def test_the_lazy_search_finds_the_fully_checked_maps_shortest_path(reference, seed: int, walls: int,  # type: ignore[no-untyped-def]
                                                                     cut_share: float) -> None:
    """Cells checked only where the map's paths look (`_repaired_path`), the path found costs what
    the shortest path over the free cells and free moves of the fully known map costs (scipy's
    Dijkstra over every cell's and move's answer, asked up front; relative 1e-12), and a path is
    found exactly where that map joins the ends."""
    _, robot, _ = reference
    rng = np.random.default_rng(seed)
    qa = np.radians([0.0, -90.0, 90.0, 0.0, 30.0, 0.0])
    qb = qa + rng.uniform(-0.8, 0.8, size=6)
    axes, configs = local_grid(qa, qb, robot.limits.lower, robot.limits.upper, RESOLUTION, MARGIN_RAD)
    r = RESOLUTION
    start, goal = (int(np.ravel_multi_index(nearest_cell(axes, q), (r, r, r))) for q in (qa, qb))
    blocked = _walls(rng, r, walls, lambda: int(rng.integers(0, 4)))       # up to three holes in a wall
    flat_blocked = blocked.ravel()
    flat_blocked[[start, goal]] = False
    src, dst = neighbour_moves((r, r, r))
    free_move = ~flat_blocked[src] & ~flat_blocked[dst]
    picked = free_move & (src < dst) & (rng.uniform(size=len(src)) < cut_share)
    cut = set(zip(src[picked].tolist(), dst[picked].tolist()))
    world = _BlockedCellsAndMoves(axes, blocked, cut)

    weight = ptp_time_estimate(configs[src], configs[dst], robot.limits) + 1e-9
    n = r ** 3
    cut_codes = [u * n + v for u, v in cut] + [v * n + u for u, v in cut]
    known = free_move & ~np.isin(src * n + dst, cut_codes)
    graph = coo_matrix((weight[known], (src[known], dst[known])), shape=(n, n)).tocsr()
    expected = dijkstra(graph, directed=True, indices=start)[goal]

    free = np.zeros(r ** 3, dtype=bool)
    checked = np.zeros(r ** 3, dtype=bool)
    free[[start, goal]] = checked[[start, goal]] = True
    cells = _LazyCells(world, configs, free, checked)  # type: ignore[arg-type]
    path, _ = _repaired_path(world, cells, r, weight, qa, qb, start, goal,  # type: ignore[arg-type]
                             max_checks=int(REPAIR_BUDGET * len(configs)))
    assert (path is not None) == bool(np.isfinite(expected))
    if path is not None:
        inner = path[1:-1]
        total = float(np.sum(ptp_time_estimate(inner[:-1], inner[1:], robot.limits) + 1e-9))
        assert abs(total - expected) <= 1e-12 * expected
        assert cells.checks <= r ** 3 - 2


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31), r=st.integers(2, 7), coincide=st.booleans())
def test_the_maps_move_times_are_the_estimates_bit_for_bit(reference, seed: int, r: int,  # type: ignore[no-untyped-def]
                                                            coincide: bool) -> None:
    """`move_times` estimates each pair of opposite moves once: the floats are `ptp_time_estimate`'s
    of every move (cells that coincide on some joints too, whose differences are exactly zero)."""
    _, robot, _ = reference
    rng = np.random.default_rng(seed)
    configs = rng.uniform(-2.0, 2.0, size=(r ** 3, 6))
    if coincide:
        configs[:, rng.integers(6)] = 0.25
    src, dst = neighbour_moves((r, r, r))
    expected = ptp_time_estimate(configs[src], configs[dst], robot.limits)
    np.testing.assert_array_equal(move_times(configs, (r, r, r), robot.limits), expected)
