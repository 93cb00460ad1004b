"""The sequencer's batched probe and its usable detours kept per spot pair: the same answers as asking
pair by pair, configuration by configuration, and rebuilding the list over every detour."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, resolved_options
from robomax_py.plan.candidates import seam_candidates
from robomax_py.plan.graph import PROBE_STATES, Sequencer
from robomax_py.plan.roadmap import Detour
from robomax_py.plan.sequence import HOME
from robomax_py.timing import ptp_time_estimate
from robomax_py.world.collision import CollisionWorld, bisection_order
from robomax_py.world.scene import build_scene
from tests.conftest import SmallCell


class _HalfSpace:
    """A world blocked where joint 1 is above `cut`, counting the configurations it was asked about."""

    def __init__(self, cut: float) -> None:
        self.cut, self.asked = cut, 0

    def is_free(self, q: np.ndarray) -> bool:
        self.asked += 1
        return bool(q[1] <= self.cut)

    def are_free(self, qs: np.ndarray) -> np.ndarray:
        self.asked += len(qs)
        return np.asarray(qs[:, 1] <= self.cut)

    def __getattr__(self, name: str) -> Any:
        raise AttributeError(name)


def _sequencer(tmp_path: Path, write_small_cell: SmallCell) -> Sequencer:
    cell = load_cell(write_small_cell(tmp_path, "batches"))
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots = [c for s in range(len(cell.seams)) for c in seam_candidates(cell, robot, world, s)[0]]
    options = resolved_options(cell, PlanOptions(detours="roadmap"))
    return Sequencer(cell, robot, world, None, spots, options, np.random.default_rng(0))  # type: ignore[arg-type]


def test_probe_row_and_coarse_checks_match_pair_by_pair(tmp_path: Path, write_small_cell: SmallCell) -> None:
    seq = _sequencer(tmp_path, write_small_cell)
    ids = [HOME, *range(len(seq.spots))]
    assert len(ids) == 3
    for x, i in enumerate(ids[:-1]):
        others = ids[x + 1:]
        batched = seq._probe_row(i, others)
        for j, got in zip(others, batched, strict=True):
            ri, rj = seq._rows(i), seq._rows(j)
            est = ptp_time_estimate(seq.q(i)[ri][:, None, :], seq.q(j)[rj][None, :, :], seq.limits, seq.options.speed)
            a, b = np.unravel_index(int(np.argmin(est)), est.shape)
            assert got == (int(ri[a]), int(rj[b]))
    # Coarse probes: the first blocked state of each move and the checks, as one move at a time.
    starts = np.concatenate([seq.q(i) for i in range(len(seq.spots))])
    goals = starts[::-1].copy()
    cut = float(np.median(np.concatenate([starts[:, 1], goals[:, 1]])))
    fractions = bisection_order(PROBE_STATES - 1) / (PROBE_STATES - 1)
    one_by_one = _HalfSpace(cut)
    expected = []
    for qa, qb in zip(starts, goals, strict=True):
        first = -1
        for k, f in enumerate(fractions):
            if not one_by_one.is_free(qa + f * (qb - qa)):
                first = k
                break
        expected.append(first)
    assert -1 in expected and any(k >= 0 for k in expected)     # both verdicts occur
    batched_world = _HalfSpace(cut)
    seq.world = batched_world  # type: ignore[assignment]
    seq.checks = 0
    assert seq._coarse_blocked(0, starts, goals).tolist() == expected
    assert seq.checks == batched_world.asked == one_by_one.asked


def test_usable_detours_kept_per_pair_match_a_rebuilt_list(tmp_path: Path, write_small_cell: SmallCell) -> None:
    seq = _sequencer(tmp_path, write_small_cell)
    n = len(seq.spots)

    def rebuilt(i: int, j: int) -> list[tuple[float, ...] | None]:
        out: list[tuple[float, ...] | None] = []
        for di, dj, det in seq.detours:
            if di == i or dj == j:
                out.append(tuple(det.waypoints.ravel()))
            elif dj == i or di == j:
                out.append(tuple(det.waypoints[::-1].ravel()))
            else:
                out.append(None)
        return out

    def kept(i: int, j: int) -> list[tuple[float, ...] | None]:
        return [tuple(d.waypoints.ravel()) if d.waypoints.size else None for d in seq.vias_for(i, j)]

    rng = np.random.default_rng(1)
    pairs = [(HOME, 0), (0, 1), (1, 0), (n - 1, HOME), (0, n - 1)]
    for step in range(6):
        i, j = pairs[step % len(pairs)]
        det = Detour(rng.uniform(-1, 1, size=(3, 6)), 1.0 + step, 0)
        seq.detours.append((i, j, det))
        for a, b in pairs:
            assert kept(a, b) == rebuilt(a, b)


def test_matrices_kept_only_where_a_verdict_cannot_change_them(tmp_path: Path, write_small_cell: SmallCell) -> None:
    from robomax_py.plan.graph_knowledge import MAX_BLOCKED_STRAIGHT

    seq = _sequencer(tmp_path, write_small_cell)
    i, j = 0, 1
    n_i, n_j = len(seq.q(i)), len(seq.q(j))
    assert n_i * n_j > MAX_BLOCKED_STRAIGHT + 2
    pairs = [(a, b) for a in range(n_i) for b in range(n_j)]

    def fresh() -> np.ndarray:
        return seq._costs(i, j, np.arange(n_i), np.arange(n_j))

    m = seq.full_cost(i, j)
    seq._record_straight(i, pairs[0][0], j, pairs[0][1], True)      # a new free move: priced as before
    assert seq.full_cost(i, j) is m and np.array_equal(m, fresh())
    seq._record_straight(i, pairs[0][0], j, pairs[0][1], True)      # the same verdict again
    assert seq.full_cost(i, j) is m
    seq._record_straight(i, pairs[1][0], j, pairs[1][1], False)        # blocked: the matrix is made again
    m = seq.full_cost(i, j)
    assert np.isinf(m[pairs[1]]) and np.array_equal(m, fresh())
    for a, b in pairs[2:2 + MAX_BLOCKED_STRAIGHT]:                     # mostly blocked: free moves alone offered
        seq._record_straight(i, a, j, b, False)
    m = seq.full_cost(i, j)
    a, b = pairs[2 + MAX_BLOCKED_STRAIGHT]
    seq._record_straight(i, a, j, b, True)                              # now a free move changes the prices
    assert seq.full_cost(i, j) is not m and np.array_equal(seq.full_cost(i, j), fresh())
    assert np.isfinite(seq.full_cost(i, j)[a, b])


def test_a_remade_matrix_reuses_its_straight_estimate(tmp_path: Path, write_small_cell: SmallCell,
                                                     monkeypatch: Any) -> None:
    """A matrix made again after a blocked move keeps its straight-move estimate (a function of the
    configurations alone): the same prices as estimated afresh, without estimating them again; the
    estimate is asked anew when the rows change."""
    import robomax_py.plan.graph_knowledge as knowledge

    seq = _sequencer(tmp_path, write_small_cell)
    i, j = 0, 1
    n_i, n_j = len(seq.q(i)), len(seq.q(j))
    asked: list[tuple[int, ...]] = []

    def counted(q0: np.ndarray, q1: np.ndarray, *args: Any, **kwargs: Any) -> np.ndarray:
        out = ptp_time_estimate(q0, q1, *args, **kwargs)
        asked.append(out.shape)
        return out

    monkeypatch.setattr(knowledge, "ptp_time_estimate", counted)
    seq.full_cost(i, j)
    assert asked == [(n_i, n_j)]
    seq._record_straight(i, 0, j, 0, False)                         # blocked: the matrix is made again
    m = seq.full_cost(i, j)
    assert asked == [(n_i, n_j)]                                    # ... on the estimate kept
    assert np.isinf(m[0, 0]) and np.array_equal(m, seq._costs(i, j, np.arange(n_i), np.arange(n_j)))
    seq._full_straight[(i, j)] = (np.arange(n_i - 1), np.arange(n_j), np.zeros((n_i - 1, n_j)))
    seq._forget(i, j)
    assert np.array_equal(seq.full_cost(i, j), m)                   # other rows kept: estimated afresh
