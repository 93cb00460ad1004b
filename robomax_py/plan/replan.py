"""Replanning while a program runs (`robomax replan`): where the robot can stop, and the cell the
rest of the work is planned in.

The stop rule. At the replanning time T the robot follows the program's own path, never another:
- in a weld or gripper action, it completes it (the stop is the action's end);
- at rest (waiting, at home), it stops where it is, at T;
- moving, it slows down along the planned path to rest: the program's time runs slower and slower,
  tau' = r(u) = 1 - 3 (u/D)^2 + 2 (u/D)^3 for u in [0, D] (a smoothstep, so its speed and
  acceleration both reach zero at the end), with the shortest D of a ladder whose motion keeps every
  joint's velocity and acceleration limits; it then stands at the path point of program time
  T + D/2. Where the program itself comes to rest on its path sooner (an exact stop at a station,
  a wait), it follows the program to there; arriving at a station it also does the station's action,
  which is the next statement.
Slowing along the path keeps the robot on the motion that was planned and checked (a controller's
path-maintaining stop); continuing to the next exact stop instead can run much further (a tending
program flies by its corners from one station to the next, often through a door), and a door
opening late closes across exactly that path.

The continuation's cell (`io.cell_continuation`): the cell with the events applied
(`io.replan_events`), the actions done by the stop removed, every window moved to the
continuation's clock (which starts at the stop: windows are seconds from the original program's
start), and the stop configuration as `start`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import RobomaxError
from robomax_py.robot import JointLimits
from robomax_py.world.motion import rate_violations

__all__ = ["Action", "ReplanInputError", "Stop", "StopHow", "stop_at"]

# The slowing-down motion's pieces are split no finer than the program's sample step, at most this (s).
STOP_SAMPLE_S = 0.010
# The slowing's last piece is halved this many times towards its end: the last step's mean speed
# is then a small fraction (about 3 / 4^(8+1)) of the path's speed there: the samples end at rest,
# as the profile does.
END_HALVINGS = 8
# Slowing-down times tried (s): from 20 ms, each 1.25 times the last, up to 20 s.
STOP_LADDER_S = tuple(0.02 * 1.25 ** k for k in range(32))
# Two samples closer than this (rad, every joint) are the robot at rest.
REST_TOL_RAD = 1e-9

StopHow = Literal["at rest", "action", "slowed", "program stop"]


class ReplanInputError(RobomaxError):
    """The replanning time or program does not allow a continuation (after the program's end,
    nothing left to do)."""


@dataclass(frozen=True, slots=True)
class Action:
    """A weld or gripper action of the program: `seam/name` at rest over [t_arrive, t_leave] (s)."""

    seam: str
    name: str
    t_arrive: float
    t_leave: float

    @property
    def label(self) -> str:
        return f"{self.seam}/{self.name}"


@dataclass(frozen=True, slots=True, eq=False)
class Stop:
    """Where the robot comes to rest after replanning was asked for at `t_request`.

    t_stop : s, program clock: when it is at rest at q (the continuation starts then).
    t_path : s, the program time of the path point it stands on (t_stop when it follows the program).
    q : (n,) rad, the stop configuration, a point of the program's path.
    t, q_motion : (k,), (k, n): the motion to t_stop (program clock), for checks: from t_request, or
        when slowing down from the program's sample at or before it.
    done : the actions completed by t_stop, in program order.
    """

    t_request: float
    t_stop: float
    t_path: float
    q: FloatArray
    how: StopHow
    t: FloatArray
    q_motion: FloatArray
    done: tuple[Action, ...]


def _at(t: FloatArray, q: FloatArray, when: float | FloatArray) -> FloatArray:
    """q at `when` (s), linear between samples (scalar -> (n,), (k,) -> (k, n))."""
    w = np.atleast_1d(np.asarray(when, dtype=float))
    out = np.stack([np.interp(w, t, q[:, j]) for j in range(q.shape[1])], axis=1)
    return out[0] if np.ndim(when) == 0 else out


def _followed(t: FloatArray, q: FloatArray, t0: float, t1: float) -> tuple[FloatArray, FloatArray]:
    """The program's own samples over [t0, t1], from its sample at or before t0 (a sample at t0
    itself would cut a piece short and make the program's next corner measure sharper than it is)
    to t1 included."""
    i = max(int(np.searchsorted(t, t0, side="right")) - 1, 0)
    inner = t[(t >= t[i]) & (t < t1)]
    ts = np.concatenate([inner, [t1]]) if t1 > t[i] else np.array([t1])
    return ts, _at(t, q, ts)


def _resting_from(t: FloatArray, q: FloatArray, at: float) -> float | None:
    """The first time >= `at` at which the program is at rest (two equal samples), None if never."""
    still = np.max(np.abs(np.diff(q, axis=0)), axis=1) <= REST_TOL_RAD
    i0 = int(np.searchsorted(t, at, side="right")) - 1
    for i in range(max(i0, 0), len(t) - 1):
        if still[i]:
            return max(float(t[i]), at)
    return None


def _slowed(t: FloatArray, q: FloatArray, T: float, D: float) -> tuple[FloatArray, FloatArray, float]:
    """The path from T slowed to rest over D s: sample times (from T), configurations, end tau.

    Every sample of the program inside the span is a sample here too (where the slowed clock
    reaches it), so the motion bends only where the program's does; a piece between two of them
    that the slowing stretches is split into pieces no shorter than the program's own sample step
    (a shorter piece beside a corner makes the corner measure sharper than it is); the last piece's
    last quarter is halved END_HALVINGS times towards the end, where the speed goes to zero."""
    fine = np.linspace(0.0, 1.0, 20_001)
    tau_fine = fine - fine ** 3 + 0.5 * fine ** 4            # (tau - T) / D, increasing from 0 to 1/2
    end = T + 0.5 * D
    h = float(np.clip(np.median(np.diff(t)), 0.001, STOP_SAMPLE_S))
    corners = t[(t > T) & (t < end)]
    knots_x = np.concatenate([[0.0], np.interp((corners - T) / D, tau_fine, fine), [1.0]])
    knots_tau = np.concatenate([[T], corners, [end]])
    xs: list[float] = []
    taus: list[float] = []
    for k in range(len(knots_x) - 1):
        x0, x1 = float(knots_x[k]), float(knots_x[k + 1])
        if x1 - x0 <= 1e-12:
            continue
        n = max(1, math.floor(D * (x1 - x0) / h))
        inner = x0 + (x1 - x0) * np.arange(1, n) / n
        if k == len(knots_x) - 2:
            last = float(inner[-1]) if len(inner) else x0
            inner = np.concatenate([inner, 1.0 - 0.25 * (1.0 - last) * 0.5 ** np.arange(END_HALVINGS)])
        xs += [x0, *inner.tolist()]
        taus += [float(knots_tau[k]), *(T + D * (inner - inner ** 3 + 0.5 * inner ** 4)).tolist()]
    xs.append(1.0)
    taus.append(end)
    return T + D * np.array(xs), _at(t, q, np.array(taus)), end


def _within_limits(ts: FloatArray, qs: FloatArray, limits: JointLimits, names: tuple[str, ...]) -> bool:
    """Velocity and acceleration within the limits, measured as `verify` measures them."""
    return not rate_violations(limits, names, ts, qs)


def stop_at(t: FloatArray, q: FloatArray, actions: Sequence[Action], T: float, limits: JointLimits,
            names: tuple[str, ...] = ()) -> Stop:
    """Where and when the robot stops after replanning is asked for at T (s, program clock), by
    the rule of this module. t (k,), q (k, n): the program's motion, linear between samples.
    ReplanInputError when T is not inside the program."""
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    if not math.isfinite(T) or T < float(t[0]) or T >= float(t[-1]):
        raise ReplanInputError(f"--at {T:g} s is not inside the program, which runs from {t[0]:g} s to {t[-1]:.3f} s")

    def done_by(t_stop: float) -> tuple[Action, ...]:
        return tuple(a for a in actions if a.t_leave <= t_stop + 1e-9)

    def follow(t_stop: float, how: StopHow) -> Stop:
        ts, qs = _followed(t, q, T, t_stop)
        return Stop(T, t_stop, t_stop, qs[-1], how, ts, qs, done_by(t_stop))

    busy = next((a for a in actions if a.t_arrive - 1e-9 <= T < a.t_leave), None)
    if busy is not None:
        return follow(busy.t_leave, "action")
    rest = _resting_from(t, q, T)
    if rest is not None and rest <= T + 1e-12:
        return follow(T, "at rest")
    for D in STOP_LADDER_S:
        if rest is not None and T + 0.5 * D >= rest:
            break                            # the program itself is at rest sooner
        ts, qs, tau = _slowed(t, q, T, D)
        # From the program's own sample at or before T (the motion up to T is the program's): a
        # sample at T itself would cut the program's piece short and make its next corner measure
        # sharper than it is.
        i = int(np.searchsorted(t, T, side="right")) - 1
        if t[i] < T - 1e-12 and len(ts) > 2:
            ts, qs = np.concatenate([t[i:i + 1], ts[1:]]), np.vstack([q[i:i + 1], qs[1:]])
        if _within_limits(ts, qs, limits, names or tuple(f"joint {j + 1}" for j in range(q.shape[1]))):
            return Stop(T, float(ts[-1]), tau, qs[-1], "slowed", ts, qs, done_by(T))
    if rest is None:
        raise ReplanInputError(f"the robot cannot stop on its path after t = {T:g} s within its limits")
    arriving = next((a for a in actions if abs(a.t_arrive - rest) <= 1e-6), None)
    if arriving is not None:
        return follow(arriving.t_leave, "action")      # at the station: its action is the next statement
    return follow(rest, "program stop")
