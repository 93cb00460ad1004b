"""The station replay (`verify_station`): two robots' programs crossing one zone, on one clock as
their controllers run them. Without interlocks the arms touch, at the time an exact check of the
poses says; with the interlock (r2 waits for r1's output, written in another dialect) the station is
clean and r2 waits exactly as long as r1 is away from home; each waiting for the other is a
deadlock naming both robots and signals; a wait for a signal no robot sets is named. The robots
stand off the origin (a riser and a yaw; 4.3 m away, turned 190 deg)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from station_case import HOME_DEG, members, station_cells

from robomax_py.export.rebuild import SignalEvent
from robomax_py.verify_station import StationReport, verify_station
from robomax_py.verify_station.replay import replay
from robomax_py.world.robot_pairs import robot_body, robots_contact
from robomax_py.world.scene import build_scene

# The replay's clock: holds are differences of rebuilt times (exact up to float sums).
CLOCK_TOL_S = 1e-9
# The rebuilt motion is sampled at most 10 ms apart: "away from home" measured on samples is that
# close to the program's own time.
SAMPLE_TOL_S = 0.010 + 1e-9
REST_TOL_RAD = 1e-9


@pytest.fixture(scope="module")
def cells(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    return station_cells(tmp_path_factory.mktemp("station"))


def _run(folder: Path, cells: dict[str, Any], plans: dict[str, Any]) -> StationReport:
    return verify_station(members(folder, cells, plans))


def test_without_interlocks_the_arms_touch_when_both_are_in_the_zone(tmp_path: Path, cells: dict[str, Any]) -> None:
    report = _run(tmp_path, cells, {"r1": ((), (), "srcl"), "r2": ((), (), "srcl")})
    assert not report.clean and not report.stuck
    (hit,) = report.collisions
    assert (hit.robot_a, hit.robot_b) == ("r1", "r2")
    r1, r2 = report.members
    assert r1.report.clean and r2.report.clean            # each alone is fine
    # Both weld at once; they touch from some time on the way in until some time on the way out.
    weld = next(a for a in r1.timeline if a.kind == "welding")
    assert 0.0 < hit.t_start < weld.t_start and weld.t_end < hit.t_end < report.makespan
    # At the reported start the poses touch and at the sample before they do not, by the exact check.
    bodies = {n: robot_body(n, r, build_scene(c, r)) for n, (c, r) in cells.items()}
    assert r1.motion is not None and r2.motion is not None
    before = r1.motion.t[np.searchsorted(r1.motion.t, hit.t_start) - 1]
    for t, touching in ((hit.t_start, True), (before, False)):
        qa, qb = r1.motion.at(np.array([t]))[0], r2.motion.at(np.array([t]))[0]
        assert (robots_contact(bodies["r1"], qa, bodies["r2"], qb) is not None) == touching, t


def test_the_interlock_makes_r2_wait_while_r1_is_in_the_zone(tmp_path: Path, cells: dict[str, Any]) -> None:
    report = _run(tmp_path, cells, {"r1": ((), ("r1_z1_clear",), "srcl"), "r2": (("r1_z1_clear",), (), "krl")})
    assert report.clean, (report.collisions, [m.report.violations for m in report.members])
    r1, r2 = report.members
    wait = r2.timeline[0]
    assert (wait.kind, wait.signal, wait.other, wait.t_start) == ("waiting", "r1_z1_clear", "r1", 0.0)
    assert r1.motion is not None and r1.end is not None and r2.end is not None
    away = np.flatnonzero(np.abs(r1.motion.q - np.radians(HOME_DEG)).max(axis=1) > REST_TOL_RAD)
    away_s = r1.motion.t[away[-1] + 1] - r1.motion.t[away[0] - 1]
    assert abs((wait.t_end - wait.t_start) - away_s) <= SAMPLE_TOL_S
    assert abs(wait.t_end - r1.end) <= CLOCK_TOL_S          # set as r1's program ends
    assert abs(report.makespan - r2.end) <= CLOCK_TOL_S and r2.end > r1.end
    assert report.idle_share("r2") == pytest.approx((wait.t_end - wait.t_start) / report.makespan, abs=1e-12)
    # r1 is done while r2 still works: idle then, as the station plan counts it.
    assert report.idle_share("r1") == pytest.approx((report.makespan - r1.end) / report.makespan, abs=1e-12)


def test_each_waiting_for_the_other_is_a_deadlock(tmp_path: Path, cells: dict[str, Any]) -> None:
    report = _run(tmp_path, cells, {"r1": (("r2_z1_clear",), ("r1_z1_clear",), "srcl"),
                                    "r2": (("r1_z1_clear",), ("r2_z1_clear",), "srcl")})
    assert report.deadlock and not report.clean
    assert {(s.robot, s.signal, s.setters) for s in report.stuck} == {("r1", "r2_z1_clear", ("r2",)),
                                                                      ("r2", "r1_z1_clear", ("r1",))}
    assert all(m.end is None and m.timeline[-1].forever for m in report.members)


def test_a_signal_no_robot_sets_is_named(tmp_path: Path, cells: dict[str, Any]) -> None:
    report = _run(tmp_path, cells, {"r1": (("r3_z9_clear",), (), "srcl"), "r2": ((), (), "srcl")})
    assert not report.deadlock and not report.clean
    assert [(s.robot, s.signal, s.setters) for s in report.stuck] == [("r1", "r3_z9_clear", ())]
    assert report.members[1].end == report.makespan > 0


def _ev(t: float, kind: str, signal: str, value: bool = True) -> SignalEvent:
    return SignalEvent(t, kind, signal, value)  # type: ignore[arg-type]


def test_replay_takes_a_setting_before_a_wait_at_the_same_instant() -> None:
    result = replay({"a": ([_ev(1.0, "wait", "s")], 2.0), "b": ([_ev(1.0, "set", "s")], 1.5)})
    assert result.holds["a"][0].seconds == 0.0 and result.ends == {"a": 2.0, "b": 1.5}


def test_replay_a_signal_turned_off_again_holds_a_later_wait() -> None:
    """Levels, not pulses: a robot that arrives after the signal went off again waits for the next on."""
    b_events = [_ev(1.0, "set", "s"), _ev(2.0, "set", "s", False), _ev(5.0, "set", "s")]
    result = replay({"a": ([_ev(3.0, "wait", "s")], 4.0), "b": (b_events, 6.0)})
    (hold,) = result.holds["a"]
    assert (hold.t_local, hold.seconds, hold.setter) == (3.0, 2.0, "b")
    assert abs(result.ends["a"] - 6.0) <= CLOCK_TOL_S and not result.stuck


def test_the_gantt_chart_holds_each_robots_timeline(tmp_path: Path, cells: dict[str, Any]) -> None:
    from robomax_py.app.station_chart import render_station_png, station_chart

    report = _run(tmp_path, cells, {"r1": ((), ("r1_z1_clear",), "srcl"), "r2": (("r1_z1_clear",), (), "srcl")})
    chart = station_chart("duo", report)
    shares = [f"{100 * report.idle_share(n):.0f} %" for n in ("r1", "r2")]
    assert chart.rows == (f"r1 (idle {shares[0]})", f"r2 (idle {shares[1]})")
    for row, member in enumerate(report.members):
        bars = [b for b in chart.bars if b.row == row]
        assert [(b.kind, b.start) for b in bars] == [(a.kind, a.t_start) for a in member.timeline]
    assert [b.label for b in chart.bars if b.kind == "waiting"] == ["r1_z1_clear of r1"]
    assert render_station_png(chart).startswith(b"\x89PNG")


@st.composite
def _programs(draw: st.DrawFn) -> dict[str, tuple[list[SignalEvent], float]]:
    """Up to three robots, each a few settings and waits of two signals at increasing times, no two
    events of the station at one time (at one instant the replay's order is its own rule, tested
    above)."""
    out = {}
    pool = draw(st.lists(st.integers(0, 1000), min_size=12, max_size=12, unique=True))
    for k, name in enumerate(("a", "b", "c")[:draw(st.integers(1, 3))]):
        times = sorted(t / 100.0 for t in pool[4 * k:4 * k + draw(st.integers(0, 4))])
        events = [_ev(t, draw(st.sampled_from(["set", "wait"])), draw(st.sampled_from(["s", "u"])), draw(st.booleans()))
                  for t in times]
        events = [dataclasses.replace(e, value=True) if e.kind == "wait" else e for e in events]
        out[name] = (events, max([0.0, *times]) + draw(st.floats(0.0, 2.0, allow_nan=False)))
    return out


@settings(max_examples=100, deadline=None)
@given(_programs())
def test_replay_never_passes_a_wait_before_its_signal_is_on(programs: dict[str, Any]) -> None:
    """Replayed again by brute force from the holds: every wait passes at a moment when the signal,
    as the settings (shifted by their own robot's holds) leave it, is on; a robot is held exactly
    until a setting turns it on; the robots left are those whose wait nobody turns on later."""
    result = replay(programs)
    settings_at: list[tuple[float, int, str, bool]] = []
    for k, (name, (events, _)) in enumerate(programs.items()):
        stuck = next((x for x in result.stuck if x.robot == name), None)
        held_at = None if stuck is None else stuck.t - sum(h.seconds for h in result.holds[name])
        done = len(events) if held_at is None else sum(e.t < held_at for e in events)
        for i, e in enumerate(events[:done]):
            if e.kind == "set":
                settings_at.append((e.t + result.offset(name, e.t), k * 100 + i, e.signal, e.value))

    def level(signal: str, t: float) -> bool:
        state = False
        for when, _, s, value in sorted(settings_at):
            if s == signal and when <= t + CLOCK_TOL_S:
                state = value
        return state

    for name, holds in result.holds.items():
        assert all(h.seconds >= 0 for h in holds)
        for h in holds:
            released = h.t_local + result.offset(name, h.t_local)
            assert level(h.signal, released), (name, h)
        if name in result.ends:
            assert abs(result.ends[name] - programs[name][1] - sum(h.seconds for h in holds)) <= CLOCK_TOL_S
    for s in result.stuck:
        assert not level(s.signal, max([s.t, *(t for t, *_ in settings_at)]))
