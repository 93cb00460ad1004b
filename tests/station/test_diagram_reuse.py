"""A station's pair diagrams are made once per pair of robot plans: a re-assignment round that keeps
two robots' plans takes their diagram as made, and makes again only the pairs with a new plan (robots
resting at home here, so that nothing needs planning)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.station import pipeline
from robomax_py.station.bodies import clash_map, robot_body
from robomax_py.station.pipeline import RobotPlan, _diagrams, _Made
from robomax_py.world.scene import build_scene

STATION = Path(__file__).parents[1] / "data" / "station" / "two_robots.yaml"


def test_a_pair_of_unchanged_plans_keeps_its_diagram(monkeypatch: pytest.MonkeyPatch) -> None:
    station = load_station(STATION)
    first, second = station.robots
    models = {r.name: load_cell_robot(r.cell) for r in station.robots}
    bodies = {r.name: robot_body(r.name, models[r.name], build_scene(r.cell, models[r.name])) for r in station.robots}
    # A third robot: the first one's arm and place under another name (its diagrams are made alike).
    bodies["r3"] = dataclasses.replace(bodies[first.name], name="r3")
    made: list[tuple[str, str]] = []
    real = clash_map

    def counted(a, pa, b, pb, *args, **kwargs):  # type: ignore[no-untyped-def]
        made.append((a.name, b.name))
        return real(a, pa, b, pb, *args, **kwargs)

    monkeypatch.setattr(pipeline, "clash_map", counted)
    plans = [RobotPlan(first.name, first.cell, models[first.name], None),
             RobotPlan(second.name, second.cell, models[second.name], None),
             RobotPlan("r3", first.cell, models[first.name], None)]
    cache = _Made()
    pairs, margin = _diagrams(plans, bodies, cache, 0.005, 0.04)
    assert len(made) == 3 and [(p.a, p.b) for p in pairs] == [("r1", "r2"), ("r1", "r3"), ("r2", "r3")]
    assert margin == pytest.approx(0.005)             # robots at rest: the clearance alone
    again, _ = _diagrams(plans, bodies, cache, 0.005, 0.04)
    assert len(made) == 3 and all(x is y for x, y in zip(again, pairs, strict=True))
    # The second robot planned again (a new plan, the same motion): only its two pairs are made again.
    plans[1] = RobotPlan(second.name, second.cell, models[second.name], None)
    third, _ = _diagrams(plans, bodies, cache, 0.005, 0.04)
    assert made[3:] == [(first.name, second.name), (second.name, "r3")]
    assert third[1] is pairs[1] and third[0] is not pairs[0]
    assert (third[0].clash == pairs[0].clash).all()
