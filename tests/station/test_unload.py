"""Spots moved away from the robot whose own cycle is the makespan (`station.unload`): the moves the
estimate proposes, without planning, and one small station whose assignment leaves one robot the
bottleneck with no wait, planned."""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from pathlib import Path

import pytest

from robomax_py.io.cell import load_cell_robot
from robomax_py.io.station import load_station
from robomax_py.spec_station import SpotKey
from robomax_py.station import pipeline
from robomax_py.station.assign import Assignment
from robomax_py.station.unload import MAX_MOVES, UNLOAD_TRIALS, bottleneck, unloads

TWO = Path(__file__).parents[1] / "data" / "station" / "two_robots.yaml"

# Spots on a line, x in m; robot a stands at 0, b at 10. A tour costs 1 s per metre travelled from
# its base and back, and 1 s per spot.
X = {f"s{i}": float(i) for i in range(11)}
BASE = {"a": 0.0, "b": 10.0}


def _key(name: str) -> SpotKey:
    return ("line", name)


def _tour(robot: str, order: tuple[SpotKey, ...]) -> float:
    xs = [BASE[robot], *(X[k[1]] for k in order), BASE[robot]]
    return sum(abs(q - p) for p, q in itertools.pairwise(xs)) + len(order)


def _orders(a: list[str], b: list[str]) -> dict[str, tuple[SpotKey, ...]]:
    return {"a": tuple(map(_key, a)), "b": tuple(map(_key, b))}


EVERYONE: Mapping[SpotKey, tuple[str, ...]] = {_key(n): ("a", "b") for n in X}


def test_the_bottleneck_is_the_robot_that_ends_last_at_its_own_cycle() -> None:
    assert bottleneck({"a": 12.0, "b": 9.0}, {"a": 12.0, "b": 9.0}) == "a"
    # b ends last because it waited: interlocks are part of the makespan, not b's own cycle alone.
    assert bottleneck({"a": 12.0, "b": 9.0}, {"a": 12.0, "b": 13.0}) is None
    assert bottleneck({}, {}) is None


def test_the_far_spots_go_to_the_other_robot_while_the_longest_cycle_shortens() -> None:
    orders = _orders([f"s{i}" for i in range(1, 9)], ["s9"])
    own = {r: _tour(r, o) for r, o in orders.items()}
    got = unloads(orders, own, "a", EVERYONE, _tour)
    assert 1 <= len(got) <= UNLOAD_TRIALS
    assert [u.predicted for u in got] == sorted(u.predicted for u in got)
    best = got[0]
    assert best.predicted < own["a"]
    # The spots given are a's farthest, now b's; every spot still welded once.
    given = set(orders["a"]) - set(best.orders["a"])
    assert given and given == set(best.orders["b"]) - set(orders["b"])
    assert min(X[k[1]] for k in given) > max(X[k[1]] for k in best.orders["a"])
    # The prediction is each robot's own cycle plus its tour's change (its own cycle is the estimate
    # here, so the scale is 1).
    assert best.predicted == pytest.approx(max(_tour(r, o) for r, o in {**orders, **best.orders}.items()))
    assert "a gives" in best.why["a"] and "b takes" in best.why["b"]


def test_the_estimates_overrun_scales_the_prediction() -> None:
    # a's planned cycle is twice its estimate: a spot it gives saves twice its estimated time.
    orders = _orders(["s1", "s2", "s8"], ["s9"])
    own = {"a": 2 * _tour("a", orders["a"]), "b": _tour("b", orders["b"])}
    got = unloads(orders, own, "a", EVERYONE, _tour)
    moved = [u for u in got if u.orders["a"] == tuple(map(_key, ["s1", "s2"]))]
    assert moved
    assert moved[0].predicted == pytest.approx(max(2 * _tour("a", moved[0].orders["a"]),
                                                   _tour("b", moved[0].orders["b"])))


def test_no_move_where_none_shortens_the_longest_cycle() -> None:
    orders = _orders(["s1", "s2"], ["s8", "s9"])
    own = {r: _tour(r, o) for r, o in orders.items()}
    assert unloads(orders, own, "a", EVERYONE, _tour) == []


def test_a_spot_goes_only_to_a_robot_that_reaches_it_and_a_fixed_spot_stays() -> None:
    orders = _orders([f"s{i}" for i in range(1, 9)], ["s9"])
    own = {r: _tour(r, o) for r, o in orders.items()}
    able = {**EVERYONE, _key("s8"): ("a",)}
    for u in unloads(orders, own, "a", able, _tour, fixed=frozenset({_key("s7")})):
        assert _key("s8") in u.orders["a"] and _key("s7") in u.orders["a"]
        assert len(set(orders["a"]) - set(u.orders["a"])) <= MAX_MOVES


@pytest.mark.slow
def test_a_bottleneck_robot_with_no_wait_gives_spots_to_the_other(monkeypatch: pytest.MonkeyPatch) -> None:
    """Two robots, r1 given every spot but the one only r2 may weld: r1's own cycle is the makespan
    and nobody waits, so the re-assignment with the waits as costs has nothing to charge. The full
    method moves spots r2 reaches to r2 and keeps the first trial that ends sooner on the shared
    clock, interlocks included."""
    station = load_station(TWO)
    models = {r.name: load_cell_robot(r.cell) for r in station.robots}
    only_r2 = ("right_rail", "r4")
    lopsided = Assignment({"r1": tuple(s.key for s in station.spots if s.key != only_r2), "r2": (only_r2,)},
                          {"r1": 1.0, "r2": 1.0})
    monkeypatch.setattr(pipeline, "assign", lambda *args, **kwargs: lopsided)
    given = pipeline.plan_station(station, models, pipeline.StationOptions(method="minmax"))
    assert given.status == "planned" and given.coordination is not None
    r1 = next(p for p in given.robots if p.robot == "r1")
    assert given.makespan == pytest.approx(r1.own_cycle, abs=1e-9)      # the pattern: r1 alone decides
    plan = pipeline.plan_station(station, models, pipeline.StationOptions(method="full"))
    assert plan.status == "planned" and plan.coordination is not None
    assert plan.makespan < given.makespan - 1e-3
    assert plan.makespan >= max(p.own_cycle for p in plan.robots) - 1e-9
    welded = {p.robot: [(s.seam, s.name) for s in (p.result.spots if p.result else ())] for p in plan.robots}
    assert sorted(k for spots in welded.values() for k in spots) == sorted(s.key for s in station.spots)
    assert len(welded["r2"]) > 1
    # The kept changes name the moves and are the robots' planned orders.
    changes = {c.robot: c for c in plan.order_changes}
    assert "r1 gives" in changes["r1"].why and "r2 takes" in changes["r2"].why
    for robot, c in changes.items():
        assert list(c.order) == welded[robot]
