"""A station's robot is planned with the candidates its reach found (`plan_cell(known=)`): the
same plan as when the planner finds them itself, on a spot of the crossing station, in its own
order and in another (an order change's)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.plan import PlanOptions, plan_cell
from robomax_py.spec_station import robot_view
from robomax_py.station.reach import robot_reach
from robomax_py.station.reorder import ordered_view

CROSSING = Path(__file__).parents[1] / "data" / "station" / "crossing.yaml"


def test_the_reach_candidates_plan_as_the_planner_own() -> None:
    station = load_station(CROSSING)
    robot = station.robots[0]
    model = load_cell_robot(robot.cell)
    reach = robot_reach(station, robot.name, model)
    spots = reach.keys[-2:]                       # the last two: a seam's spot index is not 0
    cell = robot_view(station, robot.name, spots)
    known = plan_cell(cell, model, known=reach.candidates)
    own = plan_cell(cell, model)
    assert own.status == known.status == "planned"
    assert own.trajectory is not None and known.trajectory is not None
    np.testing.assert_array_equal(known.trajectory.q, own.trajectory.q)
    assert [(s.seam, s.name) for s in known.spots] == [(s.seam, s.name) for s in own.spots]
    assert known.stats is not None and own.stats is not None
    assert known.stats.candidate_checks == 0 < own.stats.candidate_checks   # not found again


def test_the_reach_candidates_plan_a_given_order_as_the_planner_own() -> None:
    # An order change plans a robot's spots in another order (`reorder.ordered_view`: the seams cut
    # into runs, a seam's name in several runs); its candidates are the reach's, as for its own order.
    station = load_station(CROSSING)
    robot = station.robots[1]
    model = load_cell_robot(robot.cell)
    reach = robot_reach(station, robot.name, model)
    order = (reach.keys[1], reach.keys[0], *reach.keys[2:])     # r1, l1, r4: right_rail cut in two runs
    cell = ordered_view(robot.cell, order)
    assert [seam.name for seam in cell.seams] == ["right_rail", "left_rail", "right_rail"]
    options = PlanOptions(given_order=True)
    known = plan_cell(cell, model, options, known=reach.candidates)
    own = plan_cell(cell, model, options)
    assert own.status == known.status == "planned"
    assert own.trajectory is not None and known.trajectory is not None
    np.testing.assert_array_equal(known.trajectory.q, own.trajectory.q)
    assert [(s.seam, s.name) for s in known.spots] == [(s.seam, s.name) for s in own.spots] == list(order)
    assert known.stats is not None and own.stats is not None
    assert known.stats.candidate_checks == 0 < own.stats.candidate_checks
