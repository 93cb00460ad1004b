"""Coordinating timed robots by interlocks, with the least waiting.

Each pair of robots has a coordination diagram: robot a's own time on one axis, b's on the other,
and the cells where the two collide (`bodies.clash_map`); each connected region of collisions is
a shared zone, its extent on a's axis the time a spends in it, on b's the time b does. An
interlock orders one zone: the waiting robot stops at a point of its program before it would enter
(a weld done, or home) until the leading robot signals that it has left (at the first weld done, or
home reached, after the zone); the two can then never be in the zone together, whatever else
delays either (the diagram's path keeps outside the zone's box).

Which zones need an interlock depends on the waits already set, so zones are resolved one at a
time, earliest collision on the shared clock first. Per zone both orders are tried, each followed
by a greedy completion of the rest (the order with the shorter makespan at every later zone); the
order whose completed makespan is shorter is kept: a rollout, not first come first served (which
`fcfs=True` gives, the baseline). A cycle of interlocks (a deadlock) rules an order out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from robomax_py._typing import BoolArray, FloatArray, IntArray

# Zones resolved per station at most (each resolution adds one interlock); beyond it the plan fails.
MAX_INTERLOCKS = 400
TIME_EPS = 1e-9


@dataclass(frozen=True, slots=True)
class Timeline:
    """One robot's own clock: where its program may wait (at rest: home at 0, each weld done) and
    where it may signal (each weld done, home at the end), seconds from its start."""

    robot: str
    end: float
    wait_points: tuple[float, ...]
    signal_points: tuple[float, ...]


@dataclass(frozen=True, slots=True, eq=False)
class PairMap:
    """The coordination diagram of robots a and b sampled every `dt` s of their own clocks."""

    a: str
    b: str
    dt: float
    clash: BoolArray          # (ka, kb)
    labels: IntArray = field(init=False)
    boxes: tuple[tuple[int, int, int, int], ...] = field(init=False)   # per zone: i0, i1, j0, j1 (ends included)

    def __post_init__(self) -> None:
        labels, n = ndimage.label(self.clash, structure=np.ones((3, 3), dtype=int))
        boxes = tuple((s[0].start, s[0].stop - 1, s[1].start, s[1].stop - 1) for s in ndimage.find_objects(labels))
        object.__setattr__(self, "labels", labels)
        object.__setattr__(self, "boxes", boxes[:n])


@dataclass(frozen=True, slots=True)
class Interlock:
    """`waiter` waits at its own time `wait_at` until `leader` reaches its own time `signal_at`
    (where it sets the signal). `pair`, `zone`: the diagram and region it orders; the zone's time
    spans on each robot's own clock, s."""

    pair: tuple[str, str]
    zone: int
    leader: str
    waiter: str
    signal_at: float
    wait_at: float
    leader_span: tuple[float, float]
    waiter_span: tuple[float, float]


@dataclass(frozen=True, slots=True)
class Schedule:
    """The shared clock: per robot its waits (own time of the wait point, seconds waited), its end,
    the makespan; `deadlock` when the interlocks wait on each other in a cycle (then inf)."""

    waits: Mapping[str, tuple[tuple[float, float], ...]]
    ends: Mapping[str, float]
    makespan: float
    deadlock: bool = False

    def waited(self, robot: str) -> float:
        return sum(w for _, w in self.waits[robot])


@dataclass(frozen=True, slots=True)
class Coordination:
    interlocks: tuple[Interlock, ...]
    schedule: Schedule
    unresolved: str = ""      # why a collision could not be ordered ("" when none is left)


def simulate(timelines: Sequence[Timeline], interlocks: Sequence[Interlock]) -> Schedule:
    """The shared clock under the interlocks: each wait as long as its leader's signal requires
    (a signal is set on arriving at its point, before any wait there), found as the least fixed point."""
    waits: dict[str, dict[float, float]] = {t.robot: {} for t in timelines}
    ends = {t.robot: t.end for t in timelines}

    def arrive(robot: str, own: float) -> float:
        return own + sum(w for at, w in waits[robot].items() if at < own - TIME_EPS)

    for _ in range(len(interlocks) + 2):
        changed = False
        for lock in interlocks:
            need = max(0.0, arrive(lock.leader, lock.signal_at) - arrive(lock.waiter, lock.wait_at))
            if need > waits[lock.waiter].get(lock.wait_at, 0.0) + TIME_EPS:
                waits[lock.waiter][lock.wait_at] = need
                changed = True
        if not changed:
            finish = {r: ends[r] + sum(waits[r].values()) for r in ends}
            return Schedule({r: tuple(sorted((a, w) for a, w in waits[r].items() if w > TIME_EPS)) for r in ends},
                            finish, max(finish.values(), default=0.0))
    return Schedule({r: () for r in ends}, {r: math.inf for r in ends}, math.inf, deadlock=True)


def own_time(schedule: Schedule, robot: str, shared: FloatArray) -> FloatArray:
    """A robot's own time at each shared time (it stands still while it waits)."""
    actual, own = [0.0], [0.0]
    shift = 0.0
    for at, w in schedule.waits[robot]:
        actual += [at + shift, at + shift + w]
        own += [at, at]
        shift += w
    end_own = schedule.ends[robot] - shift
    actual.append(schedule.ends[robot])
    own.append(end_own)
    out: FloatArray = np.interp(shared, actual, own)
    return out


def _first_clash(pairs: Sequence[PairMap], schedule: Schedule) -> tuple[PairMap, int, float] | None:
    """The earliest collision on the shared clock under `schedule`: (diagram, zone index, shared time)."""
    best: tuple[PairMap, int, float] | None = None
    for p in pairs:
        stop = min(schedule.ends[p.a], schedule.ends[p.b])
        shared = np.arange(0.0, stop + p.dt, p.dt / 2)
        i = np.clip(np.rint(own_time(schedule, p.a, shared) / p.dt).astype(int), 0, p.clash.shape[0] - 1)
        j = np.clip(np.rint(own_time(schedule, p.b, shared) / p.dt).astype(int), 0, p.clash.shape[1] - 1)
        hit = np.flatnonzero(p.clash[i, j])
        if len(hit) and (best is None or shared[hit[0]] < best[2]):
            k = hit[0]
            best = (p, int(p.labels[i[k], j[k]]) - 1, float(shared[k]))
    return best


def _option(p: PairMap, zone: int, leader_is_a: bool, timelines: Mapping[str, Timeline]) -> Interlock | None:
    """The interlock letting one robot through a zone first; None when the other has no point to wait
    at before it (the zone starts where it starts)."""
    i0, i1, j0, j1 = p.boxes[zone]
    a_span, b_span = ((i0 - 1) * p.dt, (i1 + 1) * p.dt), ((j0 - 1) * p.dt, (j1 + 1) * p.dt)
    leader, waiter = (p.a, p.b) if leader_is_a else (p.b, p.a)
    lspan, wspan = (a_span, b_span) if leader_is_a else (b_span, a_span)
    lt, wt = timelines[leader], timelines[waiter]
    signal = next((s for s in lt.signal_points if s >= lspan[1] - TIME_EPS), lt.end)
    wait = [w for w in wt.wait_points if w <= wspan[0] + TIME_EPS]
    if not wait or wspan[0] < 0:
        return None
    return Interlock((p.a, p.b), zone, leader, waiter, signal, wait[-1], lspan, wspan)


def _entry(schedule: Schedule, robot: str, own: float) -> float:
    return own + sum(w for at, w in schedule.waits[robot] if at < own - TIME_EPS)


def coordinate(timelines: Sequence[Timeline], pairs: Sequence[PairMap], fcfs: bool = False,
               lookahead: bool = True) -> Coordination:
    """Interlocks that keep every pair of robots apart on the shared clock, orders chosen for the
    makespan (`fcfs`: the robot first at its zone goes first; `lookahead=False`: the order better
    for the makespan of this zone alone)."""
    by_name = {t.robot: t for t in timelines}

    def run(locks: list[Interlock], mode: str) -> Coordination:
        while True:
            schedule = simulate(timelines, locks)
            if schedule.deadlock:
                return Coordination(tuple(locks), schedule, "the interlocks wait on each other (deadlock)")
            hit = _first_clash(pairs, schedule)
            if hit is None:
                return Coordination(tuple(locks), schedule)
            if len(locks) >= MAX_INTERLOCKS:
                return Coordination(tuple(locks), schedule, f"more than {MAX_INTERLOCKS} interlocks needed")
            p, zone, t = hit
            options = [o for o in (_option(p, zone, True, by_name), _option(p, zone, False, by_name)) if o is not None]
            if any(o in locks for o in options):
                return Coordination(tuple(locks), schedule, f"{p.a} and {p.b} collide at {t:.2f} s on the shared "
                                    "clock although the zone is interlocked")
            if not options:
                return Coordination(tuple(locks), schedule, f"{p.a} and {p.b} collide at {t:.2f} s where neither "
                                    "can wait before the zone (at their start)")
            if mode == "fcfs":
                # First come first served, passing over an order that would deadlock.
                live = [o for o in options if not simulate(timelines, [*locks, o]).deadlock] or options
                choice = min(live, key=lambda o: _entry(schedule, o.leader, o.leader_span[0]))
            elif mode == "greedy":
                choice = min(options, key=lambda o: simulate(timelines, [*locks, o]).makespan)
            else:
                done = [run([*locks, o], "greedy") for o in options]
                k = min(range(len(done)), key=lambda k: (bool(done[k].unresolved), done[k].schedule.makespan))
                choice = options[k]
            locks = [*locks, choice]

    return run([], "fcfs" if fcfs else ("lookahead" if lookahead else "greedy"))
