"""The tour the repairs found known free (`plan.graph.Sequencer.run`, KNOWN_TOUR_MARGIN), on the small
two-spot cell. On four panels of 60 spots each round's best tour had one more unchecked move between
two panels' flanges found blocked, while the repair of that round's order found it a tour known free
about 1 % dearer: 80 rounds without a plan. Here a sequencer sees every round's best tour as left
open (a stand-in for the next blocked move), so that only the repairs' tours are known free."""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, graph, resolved_options
from robomax_py.plan.candidates import SpotCandidates, seam_candidates
from robomax_py.plan.graph import KNOWN_TOUR_MARGIN, LOOKAHEAD_FROM_ROUND, Sequencer
from robomax_py.plan.roadmap import Detour
from robomax_py.plan.sequence import HOME, Tour, choice_for_order
from robomax_py.spec import CellSpec
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene
from tests.conftest import _write_small_cell

Small = tuple[CellSpec, Any, CollisionWorld, list[SpotCandidates]]

ROUNDS = 12                 # more than LOOKAHEAD_FROM_ROUND: the rounds do not run out before it
COST_TOL_S = 1e-9           # estimated tour costs are sums of the same float estimates


class _NoRoadmap:
    def query(self, q0: np.ndarray, q1: np.ndarray) -> Detour | None:
        return None


class _BestTourLeftOpen(Sequencer):
    """Each round's best tour (the first one checked in a round) is reported with a leg left open;
    the repairs' tours are checked as usual. `dearer` scales the cost of the tours they find."""

    dearer = 1.0
    _round_seen = 0

    def _verify(self, tour: Tour) -> Any:
        checked = super()._verify(tour)
        if self.rounds != self._round_seen:
            self._round_seen = self.rounds
            return type(checked)(False, checked.transitions)
        return checked

    def _repair(self, order: tuple[int, ...]) -> Any:
        known = super()._repair(order)
        if known is None or self.dearer == 1.0:
            return known
        return type(known)(Tour(known.tour.order, known.tour.choice, known.tour.cost * self.dearer),
                           known.transitions)


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory) -> Small:
    cell = load_cell(_write_small_cell(tmp_path_factory.mktemp("known_tour"), "known_tour"))
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots, _ = seam_candidates(cell, robot, world, 0)
    return cell, robot, world, spots


def _sequencer(small: Small, rounds: int, order_candidates: int = 32) -> _BestTourLeftOpen:
    cell, robot, world, spots = small
    options = resolved_options(cell, PlanOptions(max_rounds=rounds, detours="roadmap",
                                                 order_candidates=order_candidates))
    return _BestTourLeftOpen(cell, robot, world, _NoRoadmap(), spots, options,  # type: ignore[arg-type]
                             np.random.default_rng(0))


def test_a_known_tour_within_the_margin_ends_the_rounds(small: Small) -> None:
    seq = _sequencer(small, ROUNDS)
    outcome = seq.run()
    assert outcome.status == "found", outcome.message
    assert seq.rounds == LOOKAHEAD_FROM_ROUND            # not before it, and not ROUNDS
    assert outcome.tour is not None and len(outcome.transitions) == len(outcome.tour.order) + 1
    # The repairs' tour, known free: its every leg is a move or detour found free.
    assert all(t.kind in ("move", "detour") for t in outcome.transitions)


def test_not_before_the_sixth_round(small: Small, monkeypatch: pytest.MonkeyPatch) -> None:
    """Cells that find their tour in fewer rounds plan as before: the rule waits for the round the
    look round starts from."""
    monkeypatch.setattr(graph, "LOOKAHEAD_FROM_ROUND", 9)
    seq = _sequencer(small, ROUNDS)
    assert seq.run().status == "found"
    assert seq.rounds == 9


def test_a_known_tour_dearer_than_the_margin_waits_for_the_last_round(small: Small) -> None:
    seq = _sequencer(small, ROUNDS)
    seq.dearer = 1.0 + 2 * KNOWN_TOUR_MARGIN
    outcome = seq.run()
    assert seq.rounds == ROUNDS
    assert outcome.status == "found", outcome.message   # out of rounds, the tour known free stands
    assert outcome.tour is not None


def test_without_a_known_tour_the_rounds_run_out(small: Small, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(graph, "REPAIRS_PER_ROUND", 0)
    seq = _sequencer(small, LOOKAHEAD_FROM_ROUND + 1)
    outcome = seq.run()
    assert outcome.status == "not_converged" and outcome.tour is None
    assert f"did not converge in {LOOKAHEAD_FROM_ROUND + 1} rounds" in outcome.message


def test_the_known_tour_is_shown_to_the_order_search(small: Small) -> None:
    """Two representatives per spot: the known tour's candidates the thinning left out join them,
    so that the search prices that tour's order at no more than the tour itself."""
    seq = _sequencer(small, ROUNDS, order_candidates=2)
    seq.run()
    order = (0, 1)
    # A tour of candidates the thinning left out (the last of each spot's others).
    choice = tuple(int(np.setdiff1d(np.arange(len(seq.q(i))), seq._rows(i))[-1]) for i in order)
    stops = [(HOME, 0), *zip(order, choice), (HOME, 0)]
    cost = sum(float(seq.full_cost(i, j)[a, b]) for (i, a), (j, b) in itertools.pairwise(stops))
    cost += sum(float(seq.node[i][c]) for i, c in zip(order, choice))
    seq._show_to_search(order, choice)
    for i, c in zip(order, choice):
        rows = seq._rows(i)
        assert c in rows and np.all(np.diff(rows) > 0)               # joined, ascending as before
        assert np.array_equal(seq.node_reps[i], seq.node[i][rows])
        assert seq.cost(i, 1 - i).shape[0] == len(rows)              # matrices made again
    _, searched = choice_for_order(order, seq.cost, seq.node_reps)
    assert searched <= cost + COST_TOL_S
