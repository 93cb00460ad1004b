"""The programs of a station on one clock, as their controllers run them: each advances through its
own motion (rebuilt alone, `export.rebuild`, its signal events at rest); a wait for a signal holds
the robot until the signal is on. Pure: events and durations in, holds and outcomes out.

Signals are levels, all off at the start (`preset`: on from the start, such as a clamp's input that
no robot drives). Time advances from event to event: the next event of a robot that is not held
is taken in time order, settings before waits at the same instant (a wait then sees the setting),
robots in the order given on a tie. When a signal goes on, every robot held on it moves on at that
instant. When no robot can move, each one still held waits forever: for a signal that a held robot
would set later (a deadlock: the robots wait for one another) or for one that no robot sets any more.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from robomax_py.export.rebuild import SignalEvent


@dataclass(frozen=True, slots=True)
class Hold:
    """A robot held at rest from `t_local` of its own motion (s) for `seconds`, waiting for `signal`,
    which `setter` set (the robot whose program set it; "" for none)."""

    t_local: float
    seconds: float
    signal: str
    setter: str


@dataclass(frozen=True, slots=True)
class Stuck:
    """A robot that waits forever from `t` (s, station clock) for `signal`: `setters` are the held
    robots that would set it later (a deadlock), empty when no robot sets it any more."""

    robot: str
    signal: str
    t: float
    setters: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class Replay:
    """holds : per robot, its holds in time order.
    ends : per robot, when its program ends on the station clock (s); robots that wait forever
        have none.
    stuck : the robots that wait forever.
    makespan : the last end (s); of the robots that end."""

    holds: Mapping[str, tuple[Hold, ...]]
    ends: Mapping[str, float]
    stuck: tuple[Stuck, ...]
    makespan: float

    @property
    def deadlock(self) -> bool:
        """Whether robots wait for one another (not merely for a signal no one sets)."""
        return any(s.setters for s in self.stuck)

    def offset(self, robot: str, t_local: float) -> float:
        """How much later than its own motion the robot is at t_local (s): its holds up to then."""
        return sum(h.seconds for h in self.holds[robot] if h.t_local <= t_local)


@dataclass(slots=True)
class _Run:
    name: str
    events: Sequence[SignalEvent]
    duration: float
    index: int = 0
    offset: float = 0.0
    held_since: float | None = None
    done: bool = False

    def next_time(self) -> float:
        t = self.events[self.index].t if self.index < len(self.events) else self.duration
        return t + self.offset


def replay(programs: Mapping[str, tuple[Sequence[SignalEvent], float]], preset: frozenset[str] = frozenset()) -> Replay:
    """Replay the programs (robot name -> (its signal events in program order, its duration alone, s))."""
    runs = [_Run(name, events, duration) for name, (events, duration) in programs.items()]
    level = dict.fromkeys(preset, True)
    setter: dict[str, str] = {}
    holds: dict[str, list[Hold]] = {r.name: [] for r in runs}
    ends: dict[str, float] = {}
    while True:
        movable = [r for r in runs if not r.done and r.held_since is None]
        if not movable:
            break

        def order(r: _Run) -> tuple[float, int, int]:
            is_wait = r.index < len(r.events) and r.events[r.index].kind == "wait"
            return (r.next_time(), int(is_wait), runs.index(r))

        run = min(movable, key=order)
        now = run.next_time()
        if run.index >= len(run.events):
            run.done = True
            ends[run.name] = now
            continue
        event = run.events[run.index]
        run.index += 1
        if event.kind == "set":
            level[event.signal] = event.value
            if event.value:
                setter[event.signal] = run.name
                for other in runs:
                    waiting = other.held_since is not None and other.events[other.index].signal == event.signal
                    if waiting and other.held_since is not None:
                        wait = other.events[other.index]
                        holds[other.name].append(Hold(wait.t, now - other.held_since, event.signal, run.name))
                        other.offset += now - other.held_since
                        other.held_since = None
                        other.index += 1
        elif not level.get(event.signal, False):
            run.index -= 1                       # the wait is still to pass
            run.held_since = now
        else:
            holds[run.name].append(Hold(event.t, 0.0, event.signal, setter.get(event.signal, "")))
    stuck = tuple(_stuck(r, runs) for r in runs if r.held_since is not None)
    return Replay({k: tuple(v) for k, v in holds.items()}, ends, stuck, max(ends.values(), default=0.0))


def _stuck(run: _Run, runs: list[_Run]) -> Stuck:
    """Who would set the signal the held robot waits for: held robots whose later events set it on."""
    signal = run.events[run.index].signal
    setters = tuple(r.name for r in runs if r.held_since is not None and r is not run and
                    any(e.kind == "set" and e.value and e.signal == signal for e in r.events[r.index:]))
    assert run.held_since is not None
    return Stuck(run.name, signal, run.held_since, setters)
