"""Interlock ordering on constructed coordination diagrams (no robots): the order chosen for the
makespan, not first come first served; the shared clock keeps every pair outside its zones;
interlocks that wait on each other are a deadlock."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from robomax_py.station.coordinate import (
    Interlock,
    PairMap,
    Schedule,
    Timeline,
    _first_clash,
    coordinate,
    own_time,
    simulate,
)

DT = 0.1


def _timeline(robot: str, end: float, points: list[float]) -> Timeline:
    return Timeline(robot, end, (0.0, *points), (*points, end))


def _crossing(a_zone: tuple[float, float], b_zone: tuple[float, float], end: float = 10.0) -> PairMap:
    """Robots a and b collide while a is in a_zone and b in b_zone (own times, s)."""
    t = np.arange(0.0, end + DT, DT)
    in_a = (t >= a_zone[0]) & (t <= a_zone[1])
    in_b = (t >= b_zone[0]) & (t <= b_zone[1])
    return PairMap("a", "b", DT, in_a[:, None] & in_b[None, :])


def test_picks_the_order_with_the_shorter_makespan() -> None:
    # b reaches the zone first (2.0 s) but stays long (to 8 s); a passes it quickly (2.5-3 s).
    # First come first served lets b go first and a waits ~6 s; a first costs b about 1 s.
    lines = [_timeline("a", 10.0, [1.0, 2.0, 3.5, 5.0, 7.0]), _timeline("b", 10.0, [1.5, 8.5, 9.0])]
    pair = _crossing((2.5, 3.0), (2.0, 8.0))
    best = coordinate(lines, [pair])
    fcfs = coordinate(lines, [pair], fcfs=True)
    assert not best.unresolved and not fcfs.unresolved
    assert [x.leader for x in best.interlocks] == ["a"]
    assert [x.leader for x in fcfs.interlocks] == ["b"]
    assert best.schedule.makespan < fcfs.schedule.makespan - 1.0
    for done in (best, fcfs):
        assert _first_clash([pair], done.schedule) is None      # the shared clock keeps them apart


def test_no_interlock_where_the_paths_never_meet_in_time() -> None:
    lines = [_timeline("a", 10.0, [2.0, 4.0]), _timeline("b", 10.0, [2.0, 4.0])]
    pair = _crossing((1.0, 2.0), (6.0, 7.0))          # a's zone time long before b's
    done = coordinate(lines, [pair])
    assert done.interlocks == () and done.schedule.makespan == pytest.approx(10.0)


def test_a_wait_is_as_long_as_the_leader_needs() -> None:
    lines = [_timeline("a", 10.0, [4.0]), _timeline("b", 6.0, [1.0])]
    lock = Interlock(("a", "b"), (0, 0), "a", "b", 4.0, 1.0, (2.0, 3.5), (1.5, 3.0))
    schedule = simulate(lines, [lock])
    assert schedule.waits["b"] == ((1.0, pytest.approx(3.0)),)
    assert schedule.ends["b"] == pytest.approx(9.0)
    assert schedule.makespan == pytest.approx(10.0)


def test_interlocks_waiting_on_each_other_are_a_deadlock() -> None:
    lines = [_timeline("a", 10.0, [2.0, 6.0]), _timeline("b", 10.0, [2.0, 6.0])]
    locks = [Interlock(("a", "b"), (1, 1), "a", "b", 6.0, 2.0, (3.0, 5.0), (3.0, 5.0)),
             Interlock(("a", "b"), (1, 1), "b", "a", 6.0, 2.0, (3.0, 5.0), (3.0, 5.0))]
    assert simulate(lines, locks).deadlock


def test_a_wait_implied_by_a_later_signal_is_dropped() -> None:
    lines = [_timeline("a", 10.0, [2.0, 4.0, 6.0]), _timeline("b", 10.0, [3.0])]
    # b would collide with a's segments 0 and 1 while it leaves home: both interlocks wait at home.
    t = np.arange(0.0, 10.0 + DT, DT)
    clash = ((t <= 3.9)[:, None] & ((t >= 0.5) & (t <= 1.0))[None, :])
    done = coordinate(lines, [PairMap("a", "b", DT, clash)])
    assert not done.unresolved
    assert len([x for x in done.interlocks if x.waiter == "b" and x.wait_at == 0.0]) <= 1
    assert _first_clash([PairMap("a", "b", DT, clash)], done.schedule) is None


def test_a_wait_already_held_long_enough_by_an_earlier_one_is_no_wait() -> None:
    """b waits at 1 s for a's signal at 6 s, and at 2 s for a's signal at 4 s: held at 1 s until a's
    6 s, b reaches its 2 s point at 7 s, after a's 4 s signal, and waits no more there (as the
    programs run: the signal is long set)."""
    lines = [_timeline("a", 10.0, [4.0, 6.0]), _timeline("b", 10.0, [1.0, 2.0])]

    def lock(signal_at: float, wait_at: float) -> Interlock:
        return Interlock(("a", "b"), (0, 0), "a", "b", signal_at, wait_at, (0.0, signal_at), (wait_at, wait_at + 1))

    schedule = simulate(lines, [lock(4.0, 2.0), lock(6.0, 1.0)])
    assert not schedule.deadlock
    assert len(schedule.waits["b"]) == 1                 # none at 2 s
    at, waited = schedule.waits["b"][0]
    assert at == 1.0 and waited == pytest.approx(5.0)
    assert schedule.ends["b"] == pytest.approx(15.0) and schedule.makespan == pytest.approx(15.0)


def _clashes_to_the_end(pair: PairMap, schedule: Schedule) -> int:
    """Samples of the shared clock, to the later robot's end, where the pair collides (checked here
    on its own, not by `_first_clash`)."""
    shared = np.arange(0.0, schedule.makespan + DT, DT / 2)
    i = np.clip(np.rint(own_time(schedule, pair.a, shared) / DT).astype(int), 0, pair.clash.shape[0] - 1)
    j = np.clip(np.rint(own_time(schedule, pair.b, shared) / DT).astype(int), 0, pair.clash.shape[1] - 1)
    return int(pair.clash[i, j].sum())


def test_a_robot_passes_while_the_other_rests_at_its_one_clear_point() -> None:
    """a's move from 4 to 5 s sweeps through b's path everywhere but around b's rest at 7 s (home
    included), as a KR 125-class arm's move across a UR10 on a generated two-robot station: a may
    pass only while b rests at 7 s. At b's 5-6 s segment the order "a first" waits less at that zone
    (b waits at 5 s, where it is itself in a's way), a dead end the greedy completion must take
    back, not a deadlock."""
    lines = [_timeline("a", 8.0, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]),
             _timeline("b", 10.0, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])]
    t = np.arange(0.0, 10.0 + DT, DT)
    in_a = (t > 4.05) & (t < 4.95)
    in_b = (t < 6.55) | (t > 7.45)
    pair = PairMap("a", "b", DT, in_a[:, None] & in_b[None, :])
    done = coordinate(lines, [pair])
    assert not done.unresolved
    assert _clashes_to_the_end(pair, done.schedule) == 0
    # a waits at 4 s for b to reach its 7 s rest; b waits there until a is through (5 s).
    assert {(x.waiter, x.wait_at, x.signal_at) for x in done.interlocks} == {("a", 4.0, 7.0), ("b", 7.0, 5.0)}


def test_a_robot_that_has_ended_stands_at_home_in_the_others_way() -> None:
    """b is home again at 5 s; a's move from 6 to 7 s sweeps through b's home posture: b must wait
    at its last weld until a is through, though b would end long before a moves there."""
    lines = [_timeline("a", 10.0, [2.0, 4.0, 6.0, 7.0, 8.0]), _timeline("b", 5.0, [1.0, 2.0, 3.0, 4.0])]
    t = np.arange(0.0, 10.0 + DT, DT)
    in_a = (t > 6.15) & (t < 6.85)
    at_home_b = (t < 0.45) | (t > 4.55)
    pair = PairMap("a", "b", DT, in_a[:, None] & at_home_b[None, :])
    done = coordinate(lines, [pair])
    assert not done.unresolved
    assert _clashes_to_the_end(pair, done.schedule) == 0
    assert [(x.waiter, x.wait_at, x.signal_at) for x in done.interlocks] == [("b", 4.0, 7.0)]


def test_a_home_in_the_way_is_named_only_where_the_diagram_says_so() -> None:
    """b standing at home (its first and last sample) is in a's way while a moves from s2 to s3;
    a at home is in nobody's way."""
    from robomax_py.station.coordinate import _homes_in_the_way

    lines = {name: dataclasses.replace(_timeline(name, 4.0, [1.0, 2.0, 3.0]), stops=("home", "s1", "s2", "s3", "home"))
             for name in ("a", "b")}
    t = np.arange(0.0, 4.0 + DT, DT)
    clash = np.zeros((len(t), len(t)), dtype=bool)
    clash[(t > 2.05) & (t < 2.95), 0] = True
    clash[(t > 2.05) & (t < 2.95), -1] = True
    clash[(t > 1.05) & (t < 1.95), 10] = True            # b moving: not at home, not said
    said = _homes_in_the_way(PairMap("a", "b", DT, clash), lines)
    assert said == "; at home, b is in a's way (s2 -> s3): a home elsewhere may untangle them"
    assert _homes_in_the_way(PairMap("a", "b", DT, np.zeros_like(clash)), lines) == ""


def test_a_deadlock_names_the_robots_and_the_waits_it_is_made_of() -> None:
    """a's move from 1 to 2 s sweeps through b wherever b is, at rest or moving, and b's move from 1
    to 2 s through a: whichever goes first, the other stands in its way. The message names both
    robots and each wait on its own clock, not only that there is a deadlock."""
    lines = [_timeline("a", 4.0, [1.0, 2.0, 3.0]), _timeline("b", 4.0, [1.0, 2.0, 3.0])]
    t = np.arange(0.0, 4.0 + DT, DT)
    moving = (t > 1.05) & (t < 1.95)
    pair = PairMap("a", "b", DT, moving[:, None] | moving[None, :])
    done = coordinate(lines, [pair])
    assert done.unresolved.startswith("the interlocks wait on each other (deadlock): ")
    assert "a and b move through each other's rest postures or paths in every order tried" in done.unresolved
    for lock in done.interlocks[-2:]:
        assert (f"{lock.waiter} waits at {lock.wait_at:.2f} s for {lock.leader} to finish "
                f"{lock.leader_span[0]:.2f}-{lock.leader_span[1]:.2f} s") in done.unresolved
    # With the spots the robots rest at known, each wait and each move is named by them too.
    named = [dataclasses.replace(line, stops=("home", "s1", "s2", "s3", "home")) for line in lines]
    done = coordinate(named, [pair])
    at = dict(zip((0.0, 1.0, 2.0, 3.0), ("home", "s1", "s2", "s3"), strict=True))
    # Each sweeps through the other standing at home too: said, with the move that does it.
    assert done.unresolved.endswith("; at home, a is in b's way (s1 -> s2); at home, b is in a's way (s1 -> s2): a "
                                    "home elsewhere may untangle them"), done.unresolved
    for lock in done.interlocks[-2:]:
        a, b = lock.leader_span
        assert (f"{lock.waiter} waits at {lock.wait_at:.2f} s (at {at[lock.wait_at]}) for {lock.leader} to finish "
                f"{a:.2f}-{b:.2f} s ({at[a]} -> {at[b]})") in done.unresolved, done.unresolved
