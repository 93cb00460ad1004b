"""Coordinating timed robots by interlocks, with the least waiting.

Each pair of robots has a coordination diagram: robot a's own time on one axis, b's on the other,
and the cells where the two collide (`bodies.clash_map`). A robot's program is cut into segments at
the points where it rests and may wait or signal (home, each weld done, home again). An interlock
orders two segments that collide: the waiting robot may not start its segment (it waits at its
start, at rest) until the leading robot has finished its own (it signals there). The two segments'
box in the diagram is then never entered, whatever else delays either robot; a robot resting at a
segment's start is in that segment, so a rest posture in the other's way is ordered too.

Which segments need an interlock depends on the waits already set, so collisions are resolved one
at a time, the earliest on the shared clock first. Per collision both orders are tried, each followed
by a greedy completion of the rest (the order with the shorter makespan at every later zone, the
other order tried where that one ends in a deadlock or a collision no order resolves); the order
whose completed makespan is shorter is kept: a rollout, not first come first served (which
`fcfs=True` gives, the baseline). A cycle of interlocks (a deadlock) rules an order out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import BoolArray, FloatArray

# Zones resolved per station at most (each resolution adds one interlock); beyond it the plan fails.
MAX_INTERLOCKS = 400
# Orders taken back per greedy completion at most, where the shorter order at a zone led to a
# deadlock: a robot whose move sweeps through the other's path at every rest point but one (a
# generated two-robot station: a KR 125-class arm's move across the UR10's home) can pass only while
# the other rests there, which the greedy order, shorter at the zone itself, gives up a zone earlier.
MAX_BACKTRACKS = 64
TIME_EPS = 1e-9


@dataclass(frozen=True, slots=True)
class Timeline:
    """One robot's own clock: where its program may wait (at rest: home at 0, each weld done) and
    where it may signal (each weld done, home at the end), seconds from its start."""

    robot: str
    end: float
    wait_points: tuple[float, ...]
    signal_points: tuple[float, ...]
    # What the robot rests at at each of its points (`_segments`: home, each spot, home), for
    # messages; () where not known.
    stops: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True, eq=False)
class PairMap:
    """The coordination diagram of robots a and b sampled every `dt` s of their own clocks:
    `clash[i, j]` where a at i * dt and b at j * dt come too close."""

    a: str
    b: str
    dt: float
    clash: BoolArray          # (ka, kb)


@dataclass(frozen=True, slots=True)
class Interlock:
    """`waiter` waits at its own time `wait_at` until `leader` reaches its own time `signal_at`
    (where it sets the signal). `pair`, `zone`: the diagram and the two program segments (between
    rest points) it orders; their time spans on each robot's own clock, s."""

    pair: tuple[str, str]
    zone: tuple[int, int]     # the program segments of pair[0] and pair[1] it orders
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
    (a signal is set on arriving at its point, before any wait there), as the programs run.

    Each wait point's wait is computed again from the others until none changes: a wait depends
    only on the waiter's earlier waits and the leader's waits before its signal, so without a
    deadlock this settles within one sweep per wait point; a wait made shorter by an earlier one
    (the robot already held there long enough) is made shorter, not kept. With a deadlock the waits
    grow every sweep."""
    waits: dict[str, dict[float, float]] = {t.robot: {} for t in timelines}
    ends = {t.robot: t.end for t in timelines}
    points: dict[tuple[str, float], list[Interlock]] = {}
    for lock in interlocks:
        points.setdefault((lock.waiter, lock.wait_at), []).append(lock)

    def arrive(robot: str, own: float) -> float:
        return own + sum(w for at, w in waits[robot].items() if at < own - TIME_EPS)

    for _ in range(len(points) + 2):
        changed = False
        for (waiter, at), locks in points.items():
            reach = arrive(waiter, at)
            need = max(0.0, *(arrive(lock.leader, lock.signal_at) - reach for lock in locks))
            if abs(need - waits[waiter].get(at, 0.0)) > TIME_EPS:
                waits[waiter][at] = need
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


def _first_clash(pairs: Sequence[PairMap], schedule: Schedule) -> tuple[PairMap, float, float, float] | None:
    """The earliest collision on the shared clock under `schedule`: (diagram, a's own time, b's own
    time, shared time)."""
    best: tuple[PairMap, float, float, float] | None = None
    for p in pairs:
        # To the later end: a robot that has ended stands at home, where the other may still reach it
        # (an imported FANUC M-710iC parked on its riser, swept by a KR 125-class arm going home).
        stop = max(schedule.ends[p.a], schedule.ends[p.b])
        shared = np.arange(0.0, stop + p.dt, p.dt / 2)
        ta, tb = own_time(schedule, p.a, shared), own_time(schedule, p.b, shared)
        i = np.clip(np.rint(ta / p.dt).astype(int), 0, p.clash.shape[0] - 1)
        j = np.clip(np.rint(tb / p.dt).astype(int), 0, p.clash.shape[1] - 1)
        hit = np.flatnonzero(p.clash[i, j])
        if len(hit) and (best is None or shared[hit[0]] < best[3]):
            k = hit[0]
            best = (p, float(ta[k]), float(tb[k]), float(shared[k]))
    return best


def _segments(line: Timeline) -> list[float]:
    """The robot's program points where it is at rest and may wait or signal: home, each weld done,
    home again; segment s runs from point s to point s + 1."""
    return sorted({0.0, *line.wait_points, *line.signal_points, line.end})


def _segment(points: list[float], own: float) -> int:
    """The segment a robot at its own time `own` is in; at a point, the one that starts there (the
    robot rests there before it moves on)."""
    return max(0, min(len(points) - 2, int(np.searchsorted(points, own + TIME_EPS, side="right")) - 1))


def _option(p: PairMap, at: tuple[float, float], leader_is_a: bool, timelines: Mapping[str, Timeline],
            locks: Sequence[Interlock] = ()) -> Interlock | None:
    """The interlock that orders the two program segments the robots collide in: the waiter may not
    start its segment until the leader has finished its own. Where that interlock is already set
    (the waiter, resting where it waits, is itself in the leader's way), the waiter waits a segment
    earlier. None for a robot that never moves, or one with no earlier segment."""
    leader, waiter = (p.a, p.b) if leader_is_a else (p.b, p.a)
    own_l, own_w = at if leader_is_a else at[::-1]
    lp, wp = _segments(timelines[leader]), _segments(timelines[waiter])
    if len(lp) < 2 or len(wp) < 2:
        return None
    k, m = _segment(lp, own_l), _segment(wp, own_w)
    while m >= 0:
        lock = Interlock((p.a, p.b), (k, m) if leader_is_a else (m, k), leader, waiter, lp[k + 1], wp[m],
                         (lp[k], lp[k + 1]), (wp[m], wp[m + 1]))
        if lock not in locks:
            return lock
        m -= 1
    return None


def _entry(schedule: Schedule, robot: str, own: float) -> float:
    return own + sum(w for at, w in schedule.waits[robot] if at < own - TIME_EPS)


def coordinate(timelines: Sequence[Timeline], pairs: Sequence[PairMap], fcfs: bool = False,
               lookahead: bool = True) -> Coordination:
    """Interlocks that keep every pair of robots apart on the shared clock, orders chosen for the
    makespan (`fcfs`: the robot first at its zone goes first; `lookahead=False`: the order better
    for the makespan of this zone alone)."""
    by_name = {t.robot: t for t in timelines}

    def run(locks: list[Interlock], mode: str, backtrack: bool) -> Coordination:
        # The greedy completion's zones where another order is left to try: (interlocks before, orders).
        untried: list[tuple[list[Interlock], list[Interlock]]] = []
        backtracks = 0
        failed: Coordination | None = None
        while True:
            schedule = simulate(timelines, locks)
            if schedule.deadlock:
                stuck = Coordination(tuple(locks), schedule, _deadlock_text(locks, by_name, pairs))
            elif (hit := _first_clash(pairs, schedule)) is None:
                return Coordination(tuple(locks), schedule)
            elif len(locks) >= MAX_INTERLOCKS:
                return Coordination(tuple(locks), schedule, f"more than {MAX_INTERLOCKS} interlocks needed")
            else:
                p, ta, tb, t = hit
                options = [o for o in (_option(p, (ta, tb), True, by_name, locks),
                                       _option(p, (ta, tb), False, by_name, locks)) if o is not None]
                if not options:
                    stuck = Coordination(tuple(locks), schedule, f"{p.a} and {p.b} collide at {t:.2f} s on the "
                                         f"shared clock ({p.a} at {ta:.2f} s, {p.b} at {tb:.2f} s of their own) "
                                         "whichever goes first")
                elif mode == "fcfs":
                    # First come first served, passing over an order that would deadlock.
                    live = [o for o in options if not simulate(timelines, [*locks, o]).deadlock] or options
                    locks = [*locks, min(live, key=lambda o: _entry(schedule, o.leader, o.leader_span[0]))]
                    continue
                elif mode == "greedy":
                    ranked = sorted(options, key=lambda o: simulate(timelines, [*locks, o]).makespan)
                    untried.append((locks, ranked[1:]))
                    locks = [*locks, ranked[0]]
                    continue
                else:
                    done = [run([*locks, o], "greedy", backtrack) for o in options]
                    k = min(range(len(done)), key=lambda k: (bool(done[k].unresolved), done[k].schedule.makespan))
                    locks = [*locks, options[k]]
                    continue
            # Stuck: the greedy completion takes back its latest order with another left to try; the
            # first way it got stuck is the answer when none completes.
            failed = failed or stuck
            while untried and not untried[-1][1]:
                untried.pop()
            if mode != "greedy" or not backtrack or not untried or backtracks >= MAX_BACKTRACKS:
                return failed
            backtracks += 1
            before, others = untried[-1]
            locks = [*before, others.pop(0)]

    mode = "fcfs" if fcfs else ("lookahead" if lookahead else "greedy")
    done = run([], mode, False)
    if done.unresolved and mode != "fcfs":
        # Taking orders back only where the completions without it got stuck: a rollout's estimate
        # changes with it, and with it the orders chosen at later zones (the crossing test station
        # ended at 12.58 s, not 11.00 s, with it on from the start).
        again = run([], mode, True)
        if not again.unresolved:
            done = again
    return Coordination(_without_implied(done.interlocks), done.schedule, done.unresolved)


def _deadlock_text(locks: Sequence[Interlock], timelines: dict[str, Timeline], pairs: Sequence[PairMap]) -> str:
    """What a deadlock is made of: the interlocks of the robots the last one orders, on each robot's
    own clock (the segment the leader must finish, the point the waiter waits at), each named by
    the spots it lies between where the timelines know them: a person finds "w6 -> home" in the
    cell, not 12.82 s. Where a robot standing at home is in the other's way, that is said too:
    no order of the two tours gets past it, and a home elsewhere may."""
    last = locks[-1]
    pair = {last.leader, last.waiter}
    held = [x for x in locks if {x.leader, x.waiter} == pair]
    said = "; ".join(f"{x.waiter} waits at {x.wait_at:.2f} s{_at(timelines[x.waiter], x.wait_at)} for {x.leader} "
                     f"to finish {x.leader_span[0]:.2f}-{x.leader_span[1]:.2f} s{_move(timelines[x.leader], x.leader_span)}"
                     for x in held[-4:])
    diagram = next((p for p in pairs if (p.a, p.b) == last.pair), None)
    homes = "" if diagram is None else _homes_in_the_way(diagram, timelines)
    return (f"the interlocks wait on each other (deadlock): {said} (each on its own clock); {last.pair[0]} and "
            f"{last.pair[1]} move through each other's rest postures or paths in every order tried{homes}")


def _homes_in_the_way(p: PairMap, timelines: dict[str, Timeline]) -> str:
    """'; at home, a is in b's way (home -> s1, ...)' for each robot of the pair whose home posture
    (its first and last sample) the other's moves pass through (the first three named), or ''."""
    said = []
    for still, mover, at_home in ((p.a, p.b, p.clash[0, :] | p.clash[-1, :]),
                                  (p.b, p.a, p.clash[:, 0] | p.clash[:, -1])):
        line = timelines[mover]
        points = _segments(line)
        hit = sorted({_segment(points, k * p.dt) for k in np.flatnonzero(at_home)})
        if not hit:
            continue
        names = [_move_name(line, k) or f"{points[k]:.2f}-{points[k + 1]:.2f} s" for k in hit[:3]]
        more = f" and {len(hit) - 3} more" if len(hit) > 3 else ""
        said.append(f"at home, {still} is in {mover}'s way ({', '.join(names)}{more})")
    return "" if not said else "; " + "; ".join(said) + ": a home elsewhere may untangle them"


def _stop(line: Timeline, own: float) -> int | None:
    """The index of the robot's rest point at its own time `own`, None where its stops are not known."""
    points = _segments(line)
    if len(line.stops) != len(points):
        return None
    k = _segment(points, own)
    return k if abs(points[k] - own) <= TIME_EPS else None


def _at(line: Timeline, own: float) -> str:
    k = _stop(line, own)
    return "" if k is None else f" (at {line.stops[k]})"


def _move(line: Timeline, span: tuple[float, float]) -> str:
    k = _stop(line, span[0])
    name = None if k is None else _move_name(line, k)
    return "" if name is None else f" ({name})"


def _move_name(line: Timeline, k: int) -> str | None:
    """'s1 -> s2' of the robot's segment k, None where its stops are not known."""
    known = len(line.stops) == len(_segments(line)) and k + 1 < len(line.stops)
    return f"{line.stops[k]} -> {line.stops[k + 1]}" if known else None


def _without_implied(locks: Sequence[Interlock]) -> tuple[Interlock, ...]:
    """The interlocks without those another implies: a wait at the same point for the same leader's
    later signal (the leader signals in program order, so the earlier one has been given too)."""
    def implied(x: Interlock) -> bool:
        return any(y is not x and (y.leader, y.waiter, y.wait_at) == (x.leader, x.waiter, x.wait_at)
                   and (y.signal_at > x.signal_at or (y.signal_at == x.signal_at and locks.index(y) < locks.index(x)))
                   for y in locks)
    return tuple(x for x in locks if not implied(x))
