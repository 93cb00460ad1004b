"""The near scan of a short path (an approach line) by runs of neighbouring states: the pairs
`Prefilter.near_reach` leaves out, and those coal's distance at a run's centre proves free, are free
at every configuration of the run's box; so `check_path(near=True)` gives what the plain scan gives,
from fewer exact tests.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

REFERENCE_CELL = Path(__file__).resolve().parents[2] / "tests" / "data" / "reference" / "cabin_flange.yaml"


@pytest.fixture(scope="module")
def reference() -> tuple[CellSpec, RobotModel, CollisionWorld]:
    from robomax_py.io.cell import load_cell, load_cell_robot

    cell = load_cell(REFERENCE_CELL)
    robot = load_cell_robot(cell)
    return cell, robot, CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)


def _short_paths(world: CollisionWorld, robot: RobotModel, rng: np.random.Generator, n: int) -> list[np.ndarray]:
    """Short polylines (a few cm of motion) starting at free configurations a few mm from a contact
    (bisected between a free and a colliding sample) and at free uniform samples."""
    lo, hi = robot.limits.lower, robot.limits.upper
    exact = world.copy(prefilter=False)
    starts: list[np.ndarray] = []
    while len(starts) < n:
        a, b = rng.uniform(lo, hi, size=(2, robot.dof))
        fa, fb = exact.is_free(a), exact.is_free(b)
        if fa and fb:
            starts.append(a)
        elif fa != fb:
            for _ in range(12):
                mid = (a + b) / 2
                a, b = (mid, b) if exact.is_free(mid) == fa else (a, mid)
            starts.append(a if fa else b)
    return [np.clip(s + np.cumsum(rng.normal(0.0, 0.006, size=(4, robot.dof)), axis=0), lo, hi) for s in starts]


def test_pairs_left_out_of_a_run_are_free_in_its_box_and_reach_bounds_the_distance(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    """At random configurations of a path's joint-space box: every active pair `near_reach` leaves
    out is farther apart than its margin (coal's distance), and every pair it keeps is no nearer than
    its distance at the box's centre less its reach (to 1e-9 m). Both kinds occur."""
    _, robot, world = reference
    filt = world._s.prefilter
    assert filt is not None
    active = np.ones(world.n_pairs, dtype=bool)
    margin = world.pair_margins()
    every = np.arange(world.n_pairs)
    left_out = bounded = 0
    for path in _short_paths(world, robot, rng, 24):
        _, live, reach = filt.near_reach(path, active)
        assert not (live & ~active).any() and np.isinf(reach[~live]).all()
        lo, hi = path.min(axis=0), path.max(axis=0)
        centre = world.pair_distances((lo + hi) / 2, every)
        kept = np.flatnonzero(live & np.isfinite(reach))
        out = np.flatnonzero(active & ~live)
        left_out += len(out)
        bounded += len(kept)
        for q in rng.uniform(lo, hi, size=(6, robot.dof)):
            d = world.pair_distances(q, every)
            assert (d[out] > margin[out]).all(), "a pair left out is within its margin"
            assert (d[kept] >= centre[kept] - reach[kept] - 1e-9).all(), "a pair came nearer than its reach"
    assert left_out > 0 and bounded > 0


def test_near_scan_gives_the_plain_scans_verdicts_from_fewer_exact_tests(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    """check_path(near=True) of short paths near contacts and near nothing: the same verdict, states
    checked and contact fraction as the plain scan, every verdict exercised, and fewer of coal's
    exact pair tests in all (the runs' bounds and distance proofs leave pairs out)."""
    _, robot, world = reference
    mine_tests = theirs_tests = 0
    outcomes = set()
    for path in _short_paths(world, robot, rng, 40):
        mine, theirs = world.check_path(path, near=True), world.check_path(path)
        assert (mine.free, mine.checks, mine.states, mine.s_contact) == \
            (theirs.free, theirs.checks, theirs.states, theirs.s_contact)
        outcomes.add(mine.free)
        mine_tests += mine.narrow_phase_tests
        theirs_tests += theirs.narrow_phase_tests
    assert outcomes == {True, False}
    assert mine_tests < theirs_tests


def test_each_run_is_given_the_states_of_its_places(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A near scan's run r is bounded over `states[run == r]`, run = place // _NEAR_RUN, in the given
    order, for every r up to the largest: along the path, in a shuffled order, and with places that
    skip every other number (runs of half as many states)."""
    from robomax_py.world import collision_core

    _, robot, world = reference
    seen: list[np.ndarray] = []
    run_pairs = collision_core.CollisionWorldCore._run_pairs

    def spy(self: collision_core.CollisionWorldCore, states: np.ndarray,
            active: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        seen.append(states.copy())
        return run_pairs(self, states, active)

    monkeypatch.setattr(collision_core.CollisionWorldCore, "_run_pairs", spy)
    rng = np.random.default_rng(5)
    n = 3 * collision_core._NEAR_RUN + 5
    states = rng.uniform(robot.limits.lower, robot.limits.upper, size=(n, robot.dof))
    run_len = collision_core._NEAR_RUN
    gappy = 2 * np.arange(n)
    world._set_presence(None, None)
    for place in (None, rng.permutation(n), gappy[rng.permutation(n)]):
        seen.clear()
        world._scan(states, np.linspace(0.0, 1.0, n), n, near=True, place=place)
        run = (np.arange(n) if place is None else place) // run_len
        want = [states[run == r] for r in range(int(run.max()) + 1)]
        assert len(seen) == len(want)
        assert all(np.array_equal(got, w) for got, w in zip(seen, want))
    assert len(want) == -(-2 * n // run_len) and len(want[0]) == run_len // 2
