"""The sequencer's look round the moves a round left open (`plan.graph_lookahead`), on a clamped
cell that needs many rounds: four seams of a 60-spot row with a toggle clamp every 8 spots (a copy
of `tests/bench/scale_cells.py`'s `clamped` family at 60 spots, seed 0, in tests/data). Without the
look round, each late round's search leans on one more unchecked move from a spot next to a clamp
to a neighbour of the spot it was found blocked towards; with it, those moves are checked after the
round that left the first one open. Compared on the round count the sequencer reports, and on the
estimated cost of the tour it returns, which must not be longer."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, graph, resolved_options
from robomax_py.plan.candidates import SpotCandidates, seam_candidates
from robomax_py.plan.graph import Sequencer
from robomax_py.plan.roadmap import Roadmap
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

CELL = Path(__file__).resolve().parents[1] / "data" / "clamped_rows_60.yaml"
COST_TOL_S = 1e-9       # estimated tour costs are sums of the same float estimates


def _sequence(monkeypatch: pytest.MonkeyPatch, cell: CellSpec, robot: RobotModel, world: CollisionWorld,
              spots: list[SpotCandidates], from_round: int) -> tuple[int, float]:
    options = resolved_options(cell, PlanOptions())
    # As `plan_cell` makes them: the roadmap draws from the generator the sequencer then uses.
    rng = np.random.default_rng(cell.planner.seed)
    anchors = np.vstack([cell.home[None, :], *[c.q_app for c in spots]])
    roadmap = Roadmap(world, robot.limits, anchors, rng, options.roadmap_nodes, options.roadmap_k, seeds=anchors)
    monkeypatch.setattr(graph, "LOOKAHEAD_FROM_ROUND", from_round)
    seq = Sequencer(cell, robot, world, roadmap, spots, options, rng)
    outcome = seq.run()
    assert outcome.status == "found", outcome.message
    assert outcome.tour is not None
    return seq.rounds, outcome.tour.cost


@pytest.mark.slow
def test_look_round_cuts_rounds_without_a_longer_tour(monkeypatch: pytest.MonkeyPatch) -> None:
    cell = load_cell(CELL)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots: list[SpotCandidates] = []
    for s in range(len(cell.seams)):
        spots.extend(seam_candidates(cell, robot, world, s)[0])      # candidates do not depend on it
    from_round = graph.LOOKAHEAD_FROM_ROUND
    rounds_before, cost_before = _sequence(monkeypatch, cell, robot, world, spots, 10**6)   # never: as it was
    rounds_now, cost_now = _sequence(monkeypatch, cell, robot, world, spots, from_round)
    assert rounds_before > from_round                              # the cell does reach the look round
    assert rounds_now < rounds_before
    assert cost_now <= cost_before + COST_TOL_S
