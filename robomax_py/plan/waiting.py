"""Waiting for dynamic obstacles (a machine door present in time windows) to clear.

The planner plans the cell as if its dynamic obstacles were absent, then walks the timed program
in time order: where a junction (retract, move or detour, approach, and the weld after it) would
meet a dynamic obstacle inside one of its windows, the robot waits at rest where it is until that
window is over, and the program says so (`WAIT FOR <name>_clear`, or `<name>_open` for a
machine's door, when the obstacle is there when the wait begins, else `WAIT n SEC`). The time-aware
alternative (`timed_moves`) waits nearer the goal or goes round. A robot that would itself be hit while waiting, or a window
that never ends, makes the cell infeasible with a message naming the obstacle.

`WAIT FOR <name>_clear` holds for `clear_wait`: until the window's end rounded up to the
program's millisecond, plus one millisecond (windows include their end), so a rebuilt program
waits exactly as planned.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import RobomaxError
from robomax_py.spec import dynamic_signal
from robomax_py.timing import Segment
from robomax_py.world.collision import KIND_DYNAMIC, CollisionWorld

# Programs state times in milliseconds (TIME_DECIMALS = 3).
TIME_STEP_S = 0.001
# Windows in the way of one move, and junctions started later so a trapped robot is not, before the
# planner gives up.
MAX_WAITS = 50


@dataclass(frozen=True, slots=True)
class WaitPlan:
    """A wait before junction `index`: seconds, the obstacle, and whether it is written as WAIT FOR."""

    index: int
    seconds: float
    obstacle: str
    for_signal: bool
    door: bool = False               # the obstacle is a machine's door: the signal is <name>_open

    @property
    def signal(self) -> str:
        return signal_of(self.obstacle, self.door)


class WaitingError(RobomaxError):
    """The dynamic obstacles cannot be avoided by waiting; the message says which and when."""


class Trapped(WaitingError):
    """The robot, at rest where a move starts, would be hit by a dynamic obstacle while it waits:
    the move before should have ended elsewhere, or later (after `window_end`)."""

    def __init__(self, message: str, obstacle: str, window_end: float, door: bool) -> None:
        super().__init__(message)
        self.obstacle, self.window_end, self.door = obstacle, window_end, door

    def __reduce__(self) -> tuple[type, tuple[str, str, float, bool]]:
        return type(self), (str(self), self.obstacle, self.window_end, self.door)


def clear_wait(t: float, windows: Sequence[tuple[float, float]]) -> float:
    """Seconds `WAIT FOR <name>_clear` holds at time t: 0 when the obstacle is absent."""
    for w0, w1 in windows:
        if w0 <= t <= w1:
            return ceil_ms(w1 - t) + TIME_STEP_S
    return 0.0


def ceil_ms(seconds: float) -> float:
    return round(math.ceil(round(seconds / TIME_STEP_S, 6)) * TIME_STEP_S, 3)


signal_of = dynamic_signal


def wait_at_rest(world: CollisionWorld, block: Sequence[Segment], t: float,
                 windows: dict[str, tuple[tuple[float, float], ...]], index: int,
                 doors: frozenset[str] = frozenset(), moving: frozenset[str] = frozenset()) -> WaitPlan | None:
    """The shortest wait at rest before `block` (starting at t) that keeps it clear of the dynamic
    obstacles, None when it needs none; WaitingError when waiting cannot help.

    A moving object's `windows` are those of its spans (`world.moving`): the wait is lengthened span
    by span until the block is clear, and written as a time (no input says where it is)."""
    wait: WaitPlan | None = None
    q_rest = np.asarray(block[0].q[0], dtype=float)
    for _ in range(MAX_WAITS):
        seconds = wait.seconds if wait else 0.0
        caught = trapped(world, q_rest, t, seconds, windows, doors) if seconds > 0 else None
        if caught is not None:
            raise caught
        hit = first_dynamic_hit(world, block, t + seconds)
        if hit is None:
            return wait
        name, t_hit = hit
        # The first window to end (a moving object's spans overlap where they meet; what stands
        # still for good is among them): waiting longer is checked again.
        ends = [w1 for w0, w1 in windows[name] if w0 <= t_hit <= w1]
        if not ends or not math.isfinite(min(ends)):
            raise WaitingError(f"{name} is in the way at t = {t_hit:.3f} s and its window does not end")
        needed = ceil_ms(min(ends) - t) + TIME_STEP_S
        if needed <= seconds:
            raise WaitingError(f"{name} is in the way at t = {t_hit:.3f} s even after waiting {seconds:.3f} s")
        for_signal = name not in moving and clear_wait(t, windows[name]) == needed
        wait = WaitPlan(index, needed, name, for_signal, name in doors)
    raise WaitingError(f"more than {MAX_WAITS} windows in the way of one move")


def trapped(world: CollisionWorld, q_rest: FloatArray, t: float, seconds: float,
            windows: dict[str, tuple[tuple[float, float], ...]], doors: frozenset[str]) -> Trapped | None:
    """Whether the robot at rest at q_rest over [t, t + seconds] is hit by a dynamic obstacle
    (checked where each window that meets the span begins): the error saying which, and until
    when its window lasts; None when it is not."""
    # Where the rest begins, and wherever an obstacle appears during it (a moving object appears
    # in every span of its motion: `world.moving`).
    for t_in in [t, *world.window_starts(t, t + seconds)]:
        contact = world.first_contact(q_rest, t_in)
        if contact is not None and contact.kind_b == KIND_DYNAMIC:
            name = contact.body_b
            end = min((b for a, b in windows.get(name, ()) if a <= t_in <= b), default=t_in)
            return Trapped(f"the robot would be hit while waiting at rest ({contact.describe()}) "
                           f"at t = {t_in:.3f} s", name, end, name in doors)
    return None


def first_dynamic_hit(world: CollisionWorld, block: Sequence[Segment], t0: float) -> tuple[str, float] | None:
    """(obstacle name, time) of the block's first contact with a dynamic obstacle, or None."""
    if not block:
        return None
    q0s, q1s, t0s, t1s = _sampled_moves(block, t0)
    start = 0
    while start < len(q0s):
        blocked = world.first_blocked(q0s[start:], q1s[start:], t0s[start:], t1s[start:])
        if blocked.index is None or blocked.check is None:
            return None
        i, res = start + blocked.index, blocked.check
        qa, qb, ta, tb = q0s[i], q1s[i], float(t0s[i]), float(t1s[i])
        s = res.s_contact or 0.0
        tc = float(ta + s * (tb - ta))
        # At rest, the obstacle that hits may only appear later in the span: look when each does.
        for at in [tc, *(world.window_starts(ta, tb) if np.array_equal(qa, qb) else [])]:
            contact = world.first_contact(qa + s * (qb - qa), at)
            if contact is not None and contact.kind_b == KIND_DYNAMIC:
                return contact.body_b, at
        start = i + 1
    return None


def _sampled_moves(block: Sequence[Segment], t0: float) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(q0s, q1s, t0s, t1s): the block as straight moves between its samples, in time order (a weld
    or a wait: one move at rest over its whole time)."""
    parts = []
    t = t0
    for seg in block:
        times = t + np.asarray(seg.t)
        q = np.asarray(seg.q, dtype=float)
        if len(times) == 1 or seg.kind in ("weld", "wait"):
            parts.append((q[:1], q[:1], times[:1], times[-1:]))
        else:
            parts.append((q[:-1], q[1:], times[:-1], times[1:]))
        t += seg.duration
    q0s, q1s, t0s, t1s = (np.concatenate([p[n] for p in parts]) for n in range(4))
    return q0s, q1s, t0s, t1s
