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

The continuation's cell: the cell with the events applied (`io.replan_events`), the actions done
by the stop removed, every window moved to the continuation's clock (which starts at the stop:
windows are seconds from the original program's start), and the stop configuration as `start`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import RobomaxError
from robomax_py.program import as_written_joints
from robomax_py.robot import JointLimits
from robomax_py.spec import CellSpec, MachineSpec, ObjectSpec

__all__ = ["Action", "ReplanInputError", "Stop", "StopHow", "continuation_cell", "shifted_windows", "stop_at"]

# Samples of the slowing-down motion (s): as the trajectory file's (at most 10 ms apart).
STOP_SAMPLE_S = 0.004
# At least this many samples, so the last step's mean speed is at most 3 / 64^2 (0.07 %) of the
# path's speed there: the sampled motion ends at rest, as the profile does.
STOP_MIN_SAMPLES = 65
# Slowing-down times tried (s): from 20 ms, each 1.25 times the last, up to 20 s.
STOP_LADDER_S = tuple(0.02 * 1.25 ** k for k in range(32))
# Two samples closer than this (rad, every joint) are the robot at rest.
REST_TOL_RAD = 1e-9
# Acceleration is measured by second differences over this step (s): the program's own samples
# are linear in joint space, so a step of one sample would measure their corners, not the motion.
ACCEL_STEP_S = 0.02

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
    t, q_motion : (k,), (k, n): the motion from t_request to t_stop (program clock), for checks.
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
    """The program's own samples over [t0, t1], both ends included."""
    inner = t[(t > t0) & (t < t1)]
    ts = np.concatenate([[t0], inner, [t1]]) if t1 > t0 else np.array([t0])
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
    """The path from T slowed to rest over D s: sample times (from T), configurations, end tau."""
    u = np.linspace(0.0, D, max(STOP_MIN_SAMPLES, math.ceil(D / STOP_SAMPLE_S) + 1))
    x = u / D
    tau = T + D * (x - x ** 3 + 0.5 * x ** 4)
    return T + u, _at(t, q, tau), T + 0.5 * D


def _within_limits(ts: FloatArray, qs: FloatArray, limits: JointLimits) -> bool:
    dt = np.diff(ts)
    v = np.abs(np.diff(qs, axis=0)) / dt[:, None]
    if np.any(v > limits.velocity[None, :] * (1.0 + 1e-6)):
        return False
    step = max(1, round(ACCEL_STEP_S / float(dt[0])))
    if len(qs) <= 2 * step:
        return True
    h = float(ts[step] - ts[0])
    a = np.abs(qs[2 * step:] - 2.0 * qs[step:-step] + qs[:-2 * step]) / h ** 2
    return bool(np.all(a <= limits.acceleration[None, :] * (1.0 + 1e-6)))


def stop_at(t: FloatArray, q: FloatArray, actions: Sequence[Action], T: float, limits: JointLimits) -> Stop:
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
        if _within_limits(ts, qs, limits):
            return Stop(T, float(ts[-1]), tau, qs[-1], "slowed", ts, qs, done_by(T))
    if rest is None:
        raise ReplanInputError(f"the robot cannot stop on its path after t = {T:g} s within its limits")
    arriving = next((a for a in actions if abs(a.t_arrive - rest) <= 1e-6), None)
    if arriving is not None:
        return follow(arriving.t_leave, "action")      # at the station: its action is the next statement
    return follow(rest, "program stop")


def shifted_windows(windows: tuple[tuple[float, float], ...], t0: float) -> tuple[tuple[float, float], ...]:
    """Windows (s from program start) in a clock starting at t0: those over before t0 dropped, one
    in progress at t0 starting at 0."""
    return tuple((max(0.0, a - t0), b - t0) for a, b in windows if b - t0 >= 0.0)


def continuation_cell(cell: CellSpec, stop: Stop, name: str) -> CellSpec:
    """The cell the rest of the work is planned in (see the module's docstring); `cell` has the
    events applied already. ReplanInputError when nothing is left to do."""
    done = {(a.seam, a.name) for a in stop.done}
    seams = []
    for seam in cell.seams:
        left = tuple(s for s in seam.spots if (seam.name, s.name) not in done)
        if left:
            seams.append(replace(seam, spots=left))
    if not seams:
        raise ReplanInputError(f"nothing left to do after the stop at t = {stop.t_stop:.3f} s: every "
                               f"{'station' if cell.tending else 'spot'} is done")
    dynamic: list[ObjectSpec] = []
    for d in cell.dynamic:
        if d.present is None:
            dynamic.append(d)
            continue
        moved = shifted_windows(d.present, stop.t_stop)
        if moved:
            dynamic.append(replace(d, present=moved))
    machines = tuple(MachineSpec(m.name, m.door, shifted_windows(m.windows, stop.t_stop)) for m in cell.machines)
    return replace(cell, name=name, seams=tuple(seams), dynamic=tuple(dynamic), machines=machines,
                   start=as_written_joints(stop.q))
