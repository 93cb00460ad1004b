"""Another spot order instead of waiting (`station.reorder`), without planning: the cell a given
order is planned in, the candidates the interlocks suggest, and the search that keeps a change only
when the makespan shortens."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.io.station import load_station
from robomax_py.spec_station import SpotKey
from robomax_py.station.coordinate import Interlock, Timeline, simulate
from robomax_py.station.reorder import (
    MIN_GAIN_SHARE,
    ORDER_CANDIDATES,
    ORDER_ROUNDS,
    OrderChange,
    candidates,
    improve_orders,
    most_gain,
    ordered_view,
)

TWO = Path(__file__).parents[1] / "data" / "station" / "two_robots.yaml"


def test_the_ordered_view_lists_the_spots_in_the_order_given() -> None:
    cell = load_station(TWO).robot("r1").cell
    order = [("right_rail", "r1"), ("front_rail", "f4"), ("front_rail", "f1"), ("left_rail", "l1")]
    view = ordered_view(cell, order)
    assert [(seam.name, s.name) for seam in view.seams for s in seam.spots] == order
    # Runs of one seam keep that seam's settings; consecutive spots of one seam stay one run.
    assert [seam.name for seam in view.seams] == ["right_rail", "front_rail", "left_rail"]
    by_name = {seam.name: seam for seam in cell.seams}
    for seam in view.seams:
        whole = by_name[seam.name]
        assert (seam.ordered, seam.alpha_max, seam.beta_max, seam.gamma_range, seam.grid) == \
            (whole.ordered, whole.alpha_max, whole.beta_max, whole.gamma_range, whole.grid)


def _keys(*names: str) -> tuple[SpotKey, ...]:
    return tuple(("s", n) for n in names)


def _lock(leader: str, waiter: str, leader_segment: int, waiter_segment: int) -> Interlock:
    """An interlock between a and b (the pair's order) of the given segments; the times do not matter here."""
    zone = (leader_segment, waiter_segment) if leader == "a" else (waiter_segment, leader_segment)
    return Interlock(("a", "b"), zone, leader, waiter, 5.0, 1.0, (3.0, 5.0), (1.0, 2.0))


ORDER = {"a": _keys("a1", "a2", "a3"), "b": _keys("b1", "b2", "b3")}


def test_no_candidate_unless_the_robot_that_ends_last_waits() -> None:
    # b waits 2 s but a still ends last: no order of b can shorten the makespan.
    ends = {"a": 12.0, "b": 11.0}
    waits = {"a": (), "b": ((1.0, 2.0),)}
    assert candidates(ORDER, ends, waits, [_lock("a", "b", 2, 0)], ()) == []


def test_the_waiters_zone_spot_moves_and_the_leader_leaves_sooner() -> None:
    # b ends last after waiting at its start for a's third segment (a2 -> a3): b's first segment
    # goes to b1, a's to a3.
    ends = {"a": 10.0, "b": 14.0}
    waits = {"a": (), "b": ((1.0, 5.0),)}
    got = candidates(ORDER, ends, waits, [_lock("a", "b", 2, 0)], ())
    assert [(c.robot, c.order) for c in got] == [
        ("b", _keys("b2", "b3", "b1")),            # b's zone spot last
        ("b", _keys("b3", "b2", "b1")),            # b's tour reversed
        ("a", _keys("a3", "a1", "a2")),            # a's zone spot first: a leaves the zone sooner
    ]                                              # (b1 first: b's order already)
    assert all(c.why for c in got)


def test_an_ordered_seam_keeps_its_order() -> None:
    ends = {"a": 10.0, "b": 14.0}
    waits = {"a": (), "b": ((1.0, 5.0),)}
    got = candidates(ORDER, ends, waits, [_lock("a", "b", 2, 0)], [_keys("b1", "b2")])
    assert all(c.order.index(("s", "b1")) < c.order.index(("s", "b2")) for c in got if c.robot == "b")
    assert [c.robot for c in got] == ["a"]


@dataclasses.dataclass(frozen=True)
class _Station:
    """A stand-in for a station plan: the robots' orders and a makespan made up from them."""

    orders: dict[str, tuple[SpotKey, ...]]

    @property
    def makespan(self) -> float:
        # Made-up rule: b's tour is quickest when b3 comes first, and a's reversal helps a bit more.
        t = 14.0 - (3.0 if self.orders["b"][0] == ("s", "b3") else 0.0)
        return t - (0.5 if self.orders["a"] == _keys("a3", "a2", "a1") else 0.0)


def _propose(plan: _Station) -> list[OrderChange]:
    return [OrderChange("b", plan.orders["b"][::-1], "b reversed"), OrderChange("a", plan.orders["a"][::-1], "a reversed"),
            OrderChange("b", plan.orders["b"][1:] + plan.orders["b"][:1], "b rotated"),
            OrderChange("a", plan.orders["a"][1:] + plan.orders["a"][:1], "a rotated")]


def test_the_search_keeps_only_changes_that_shorten_the_makespan() -> None:
    planned: list[frozenset[tuple[str, tuple[SpotKey, ...]]]] = []

    def trial(plan: _Station, change: OrderChange) -> _Station | None:
        planned.append(frozenset({**plan.orders, change.robot: change.order}.items()))
        if change.why == "b rotated":
            return None                               # that order does not plan
        return _Station({**plan.orders, change.robot: change.order})

    start = _Station(dict(ORDER))
    got = improve_orders(start, lambda p: p.makespan, lambda p: p.orders, _propose, trial)
    assert got.best.makespan == pytest.approx(10.5)
    assert [c.why for c in got.kept] == ["b reversed", "a reversed"]
    assert got.tried == len(planned) <= ORDER_ROUNDS * ORDER_CANDIDATES and got.skipped == 0
    # No station is planned twice, nor the one started from (b reversed twice is b's first order).
    assert len(set(planned)) == len(planned) and frozenset(ORDER.items()) not in planned


def test_the_search_stops_where_nothing_is_shorter() -> None:
    start = _Station({"a": _keys("a3", "a2", "a1"), "b": _keys("b3", "b2", "b1")})
    got = improve_orders(start, lambda p: p.makespan, lambda p: p.orders,
                         _propose, lambda p, c: _Station({**p.orders, c.robot: c.order}))
    assert got.best is start and got.kept == () and got.tried == ORDER_CANDIDATES


def test_the_most_gain_is_bounded_by_the_other_robots_own_cycles() -> None:
    # b ends last (14 s) after waiting 5 s for a; c's own cycle is 12 s.
    own = {"a": 10.0, "b": 9.0, "c": 12.0}
    # b re-ordered: a and c keep their plans, c ends at 12 s at the soonest.
    assert most_gain(14.0, own, "b", floor=6.0) == pytest.approx(2.0)
    # ... or at b's own cycle, when b's new order cannot be quicker than 13 s.
    assert most_gain(14.0, own, "b", floor=13.0) == pytest.approx(1.0)
    # The leader a re-ordered: b keeps its 9 s, c its 12 s.
    assert most_gain(14.0, own, "a", floor=6.0) == pytest.approx(2.0)
    # Nothing to gain where another robot's own cycle is the makespan.
    assert most_gain(12.0, own, "b", floor=0.0) == 0.0


@given(st.lists(st.floats(1.0, 20.0), min_size=2, max_size=4),
       st.lists(st.tuples(st.integers(0, 3), st.integers(0, 3), st.floats(0.0, 1.0), st.floats(0.0, 1.0)), max_size=6),
       st.floats(0.5, 20.0), st.integers(0, 3))
@settings(max_examples=60, deadline=None)
def test_no_new_order_and_interlocks_beat_the_most_gain(ends: list[float], locks: list[tuple[int, int, float, float]],
                                                      new_end: float, moved: int) -> None:
    """Whatever interlocks a coordination sets, the station re-planned with one robot's new own cycle
    (at least `floor`) ends no sooner than the makespan less the most gain."""
    names = [f"r{i}" for i in range(len(ends))]
    robot = names[moved % len(names)]

    def lines(cycle: dict[str, float]) -> list[Timeline]:
        return [Timeline(r, cycle[r], (0.0, cycle[r] / 2), (cycle[r] / 2, cycle[r])) for r in names]

    def interlocks(cycle: dict[str, float]) -> list[Interlock]:
        out = []
        for i, j, at, sig in locks:
            a, b = names[i % len(names)], names[j % len(names)]
            if a != b:
                out.append(Interlock((a, b), (0, 0), a, b, sig * cycle[a], at * cycle[b], (0.0, cycle[a]),
                                     (0.0, cycle[b])))
        return out

    own = dict(zip(names, ends, strict=True))
    before = simulate(lines(own), interlocks(own))
    if before.deadlock:
        return
    floor = min(new_end, own[robot])
    after_own = {**own, robot: new_end}
    after = simulate(lines(after_own), interlocks(after_own))
    assert after.deadlock or after.makespan >= before.makespan - most_gain(before.makespan, own, robot, floor) - 1e-9


def _recording(planned: list[str]) -> Callable[[_Station, OrderChange], _Station | None]:
    """A trial that plans every change (the station in the changed order) and records its name."""
    def trial(plan: _Station, change: OrderChange) -> _Station | None:
        planned.append(change.why)
        return _Station({**plan.orders, change.robot: change.order})

    return trial


def test_a_change_that_cannot_gain_enough_is_not_planned() -> None:
    # The makespan is 14 s; a change of b could gain at most 0.02 s (0.14 %), of a 3 s.
    planned: list[str] = []

    trial = _recording(planned)
    def gain(plan: _Station, change: OrderChange) -> float:
        return 0.02 if change.robot == "b" else 3.0

    start = _Station(dict(ORDER))
    assert 0.02 < MIN_GAIN_SHARE * start.makespan < 3.0
    got = improve_orders(start, lambda p: p.makespan, lambda p: p.orders, _propose, trial, gain)
    assert "b reversed" not in planned and "b rotated" not in planned
    assert planned[0] == "a reversed"
    assert [c.why for c in got.kept] == ["a reversed"] and got.tried == len(planned) and got.skipped >= 2
    # No change could gain anything: nothing is planned.
    planned.clear()
    got = improve_orders(start, lambda p: p.makespan, lambda p: p.orders, _propose, trial, lambda p, c: 0.0)
    assert planned == [] and got.best is start and got.tried == 0 and got.skipped == len(_propose(start))


def test_a_round_stops_once_no_change_left_can_end_sooner() -> None:
    # b reversed ends at 11 s; a's changes could reach 11 s at best (gain 3 s): not planned.
    planned: list[str] = []

    trial = _recording(planned)
    def gain(plan: _Station, change: OrderChange) -> float:
        return 4.0 if change.robot == "b" else plan.makespan - 11.0

    got = improve_orders(_Station(dict(ORDER)), lambda p: p.makespan, lambda p: p.orders, _propose, trial, gain)
    assert planned[:2] == ["b reversed", "b rotated"]     # the most gain first
    assert "a reversed" not in planned                    # third in the round, and a's gain left is 0 after
    assert got.kept[0].why == "b reversed"


def test_among_equal_gains_the_least_tour_growth_is_planned_first() -> None:
    # Both changes of b could reach 11 s at best (the others' own cycles bound them alike); b rotated
    # comes first but its tour is estimated 2 s longer, b reversed keeps its legs and reaches 11 s:
    # it is planned first and b rotated is then not planned.
    planned: list[str] = []

    def propose(plan: _Station) -> list[OrderChange]:
        b = plan.orders["b"]
        return [OrderChange("b", b[1:] + b[:1], "b rotated"), OrderChange("b", b[::-1], "b reversed")]

    trial = _recording(planned)
    def growth(plan: _Station, change: OrderChange) -> float:
        return 2.0 if change.why == "b rotated" else 0.0

    start = _Station(dict(ORDER))
    got = improve_orders(start, lambda p: p.makespan, lambda p: p.orders, propose, trial,
                         lambda p, c: p.makespan - 11.0, growth)
    assert planned == ["b reversed"] and got.tried == 1
    assert got.best.makespan == pytest.approx(11.0) and [c.why for c in got.kept] == ["b reversed"]
    # Equal growth: `propose`'s order, and b rotated (14 s) leaves b reversed to be planned too.
    planned.clear()
    improve_orders(start, lambda p: p.makespan, lambda p: p.orders, propose, trial, lambda p, c: p.makespan - 11.0,
                   lambda p, c: 0.0)
    assert planned == ["b rotated", "b reversed"]
