"""The parts that keep sequencing cheap on large cells: representatives for the order search, and
the up-front probe (near pairs in full, far pairs coarsely)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, resolved_options
from robomax_py.plan.candidates import seam_candidates
from robomax_py.plan.graph import PROBE_STATES, Sequencer
from robomax_py.plan.sequence import HOME
from robomax_py.plan.thinning import representatives
from robomax_py.world.collision import CollisionWorld, SegmentCheck
from robomax_py.world.scene import build_scene

VELOCITY = np.array([2.0, 2.0, 2.5, 4.0, 4.0, 5.0])   # rad/s, a KR 125-like spread


def _gap(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.max(np.abs(q[a][:, None, :] - q[b][None, :, :]) / VELOCITY, axis=2)


@settings(max_examples=40, deadline=None)
@given(k=st.integers(1, 120), count=st.integers(1, 40), seed=st.integers(0, 2**16))
def test_representatives_spread_like_a_farthest_point_sample(k: int, count: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    q = rng.uniform(-3, 3, (k, 6))
    node = rng.uniform(1, 2, k)
    reps = representatives(q, node, VELOCITY, count)
    assert list(reps) == sorted(set(reps.tolist())) and len(reps) == min(k, count)
    assert int(np.argmin(node)) in reps
    if k > count:
        # Farthest-point sampling: no candidate is farther from the chosen ones than two chosen
        # ones are from each other (the covering radius is at most the separation).
        rest = np.setdiff1d(np.arange(k), reps)
        cover = np.max(np.min(_gap(q, rest, reps), axis=1))
        sep = _gap(q, reps, reps)
        np.fill_diagonal(sep, np.inf)
        assert cover <= np.min(sep) + 1e-12
    assert np.array_equal(reps, representatives(q, node, VELOCITY, count))      # deterministic


def test_duplicates_are_represented_once() -> None:
    q = np.repeat(np.array([[0.0] * 6, [1.0] * 6]), 5, axis=0)
    assert len(representatives(q, np.zeros(10), VELOCITY, 4)) == 2


class _CountingWorld:
    """Full segment checks always free, every single-state check blocked; counts both."""

    def __init__(self, world: CollisionWorld) -> None:
        self._world = world
        self.segments: list[tuple[bytes, bytes]] = []
        self.states = 0

    def check_segment(self, q0: np.ndarray, q1: np.ndarray, *args: Any, **kwargs: Any) -> SegmentCheck:
        self.segments.append((q0.tobytes(), q1.tobytes()))
        return SegmentCheck(free=True, checks=1, states=2, narrow_phase_tests=0, s_contact=None)

    def is_free(self, q: np.ndarray, t: float | None = None) -> bool:
        self.states += 1
        return False

    def are_free(self, qs: np.ndarray, t: float | None = None) -> np.ndarray:
        self.states += len(qs)
        return np.zeros(len(qs), dtype=bool)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._world, name)


@pytest.fixture(scope="module")
def reference(reference_cell_path: Path) -> tuple[Any, Any, CollisionWorld, list[Any]]:
    cell = load_cell(reference_cell_path)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots, _ = seam_candidates(cell, robot, world, 0)
    return cell, robot, world, spots


@pytest.mark.slow
def test_probe_checks_near_pairs_in_full_and_far_pairs_coarsely(reference: tuple[Any, Any, CollisionWorld, list[Any]]) -> None:
    cell, robot, world, spots = reference
    fake = _CountingWorld(world)
    k = 2
    seq = Sequencer(cell, robot, fake, None, spots, resolved_options(cell, PlanOptions(probe_neighbours=k)),  # type: ignore[arg-type]
                    np.random.default_rng(0))
    seq._probe_pairs()
    n = len(spots)
    xyz = np.array([s.xyz for s in cell.seams[0].spots])
    gap = np.linalg.norm(xyz[:, None] - xyz[None], axis=2)
    np.fill_diagonal(gap, np.inf)
    near = {(min(i, int(j)), max(i, int(j))) for i in range(n) for j in np.argsort(gap[i], kind="stable")[:k]}
    assert len(fake.segments) == len(near)                         # one full check per near pair
    far = (n + 1) * n // 2 - len(near)                              # home included
    assert fake.states == far                                       # each far probe stops at its first (blocked) state
    # Far pairs the coarse probe found blocked are detour-only; near pairs (free in full) are not,
    # and their free move is known.
    assert seq.detour_only == {(min(i, j), max(i, j)) for i in [HOME, *range(n)] for j in range(n)
                               if i < j or i == HOME} - near
    for i, j in near:
        a, b = seq.probe_pair(i, j)
        assert seq.straight[(i, j)][(a, b)] is True
    assert PROBE_STATES >= 3


def _via_costs_one_by_one(seq: Sequencer, i: int, j: int, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """The detour prices as they were computed before the legs were batched: two estimates per
    detour, its blocked (or, past MAX_BLOCKED_LEGS, its verified) legs marked, the least kept."""
    from robomax_py.plan.graph import MAX_BLOCKED_LEGS
    from robomax_py.plan.graph_knowledge import _UNUSABLE
    from robomax_py.timing import ptp_time_estimate

    out = np.full((len(rows), len(cols)), np.inf)
    pi, pj = seq._positions(i, rows), seq._positions(j, cols)
    bad = seq.legs_bad.get((i, j), set())
    sp = seq._detour_speed()
    for v, det in enumerate(seq.vias_for(i, j)):
        if det is _UNUSABLE:
            continue
        enter = ptp_time_estimate(seq.q(i)[rows], det.waypoints[0][None, :], seq.limits, sp)
        leave = ptp_time_estimate(det.waypoints[-1][None, :], seq.q(j)[cols], seq.limits, sp)
        via = enter[:, None] + seq._inner_time(v, det) + leave[None, :]
        if len(bad) >= MAX_BLOCKED_LEGS:
            verified = np.full_like(via, np.inf)
            for a, b, vv in seq.legs_ok.get((i, j), ()):
                if vv == v and pi[a] >= 0 and pj[b] >= 0:
                    verified[pi[a], pj[b]] = via[pi[a], pj[b]]
            via = verified
        else:
            for a, b, vv in bad:
                if vv == v and pi[a] >= 0 and pj[b] >= 0:
                    via[pi[a], pj[b]] = np.inf
        out = np.minimum(out, via)
    return out


@pytest.mark.slow
def test_detour_prices_batched_equal_one_by_one(reference: tuple[Any, Any, CollisionWorld, list[Any]]) -> None:
    from robomax_py.plan.graph import MAX_BLOCKED_LEGS
    from robomax_py.plan.roadmap import Detour

    cell, robot, world, spots = reference
    seq = Sequencer(cell, robot, world, None, spots, resolved_options(cell, PlanOptions()), np.random.default_rng(0))
    rng = np.random.default_rng(7)
    i, j = 0, 1
    # Detours between i and j both ways, leaving i, reaching j, reaching i (used reversed) and
    # between other spots (not usable from i to j).
    for di, dj in [(i, j), (j, i), (i, 2), (3, j), (2, i), (2, 3), (j, 4)]:
        seq.detours.append((di, dj, Detour(rng.uniform(-2.0, 2.0, (4, 6)), 1.0, 10)))
    rows, cols = np.arange(len(seq.q(i))), seq._rows(j)
    pi, pj = seq._positions(i, rows), seq._positions(j, cols)
    assert np.isfinite(_via_costs_one_by_one(seq, i, j, rows, cols)).all()
    free = _via_costs_one_by_one(seq, i, j, rows, cols)
    for count in (0, MAX_BLOCKED_LEGS - 1, MAX_BLOCKED_LEGS + 2):
        seq.legs_bad[(i, j)] = {(int(rng.integers(len(rows))), int(cols[rng.integers(len(cols))]), int(rng.integers(7)))
                                for _ in range(count)}
        if 0 < count < MAX_BLOCKED_LEGS:
            # Two of the bans on the detour a leg's least goes through, so that they change the price.
            bans = set(list(seq.legs_bad[(i, j)])[:count - 2])
            while len(bans) < count:
                a, b = int(rng.integers(len(rows))), int(cols[rng.integers(len(cols))])
                for v in range(7):
                    seq.legs_bad[(i, j)] = {(a, b, v)}
                    if not np.array_equal(_via_costs_one_by_one(seq, i, j, rows, cols), free):
                        bans.add((a, b, v))
                        break
            seq.legs_bad[(i, j)] = bans
        seq.legs_ok[(i, j)] = {(int(rng.integers(len(rows))), int(cols[rng.integers(len(cols))]), int(rng.integers(7)))
                               for _ in range(5)}
        got = seq._via_costs(i, j, seq.vias_for(i, j), rows, cols, pi, pj)
        assert np.array_equal(got, _via_costs_one_by_one(seq, i, j, rows, cols))     # bit for bit
