"""A robot's motion on the station clock: its own motion (rebuilt alone) with the replay's holds put
in, as joint samples (to pose the robots together) and as a timeline of what it does (moving,
welding, waiting for which signal of which robot)."""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise
from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.timing import Trajectory
from robomax_py.verify_station.replay import Hold

ActivityKind = Literal["moving", "welding", "waiting"]


@dataclass(frozen=True, slots=True)
class Activity:
    """What a robot does during [t_start, t_end] (s, station clock): moving, welding (or a gripper
    action) or waiting: for `signal` of robot `other` ("" when the signal is no robot's, or a
    wait of its own program: a dwell, a dynamic obstacle); `forever` when it is never set."""

    t_start: float
    t_end: float
    kind: ActivityKind
    signal: str = ""
    other: str = ""
    forever: bool = False


@dataclass(frozen=True, slots=True)
class StationMotion:
    """A robot's joint values on the station clock: t (k,) s, strictly increasing; q (k, n) rad."""

    t: FloatArray
    q: FloatArray

    def at(self, t: FloatArray) -> FloatArray:
        """q at the times t (m,), linear between samples, held before the first and after the last."""
        t = np.asarray(t, dtype=float)
        return np.stack([np.interp(t, self.t, self.q[:, j]) for j in range(self.q.shape[1])], axis=1)


def station_motion(traj: Trajectory, holds: tuple[Hold, ...], stuck_at: float | None) -> StationMotion:
    """The motion with each hold put in at its local time; a robot stuck at local time `stuck_at`
    stops there (and stays)."""
    t, q = np.asarray(traj.t, dtype=float), np.asarray(traj.q, dtype=float)
    if stuck_at is not None:
        keep = t < stuck_at - 1e-12
        q_stop = _q_at(t, q, stuck_at)
        t, q = np.append(t[keep], stuck_at), np.vstack([q[keep], q_stop])
    pieces_t, pieces_q = [], []
    offset, start = 0.0, 0
    for h in sorted(holds, key=lambda h: h.t_local):
        if h.seconds <= 0:
            continue
        cut = int(np.searchsorted(t, h.t_local, side="right"))
        pieces_t.append(t[start:cut] + offset)
        pieces_q.append(q[start:cut])
        q_h = _q_at(t, q, h.t_local)
        pieces_t.append(np.array([h.t_local + offset, h.t_local + offset + h.seconds]))
        pieces_q.append(np.vstack([q_h, q_h]))
        offset += h.seconds
        start = cut
    pieces_t.append(t[start:] + offset)
    pieces_q.append(q[start:])
    t_all, q_all = np.concatenate(pieces_t), np.vstack(pieces_q)
    # Equal times where a hold meets a sample: keep the later (the same pose either way).
    keep = np.append(np.diff(t_all) > 1e-12, True)
    return StationMotion(t_all[keep], q_all[keep])


def _q_at(t: FloatArray, q: FloatArray, at: float) -> FloatArray:
    return np.array([np.interp(at, t, q[:, j]) for j in range(q.shape[1])])


def timeline(traj: Trajectory, holds: tuple[Hold, ...], stuck_at: float | None = None, stuck_signal: str = "",
             until: float = 0.0) -> tuple[Activity, ...]:
    """The robot's activities on the station clock: its motion's phases (a weld phase welding, a
    wait phase waiting, any other moving), shifted by the holds before them, and the holds; a robot
    stuck at local time `stuck_at` waits for `stuck_signal` from then until `until`."""
    local: list[tuple[float, float, ActivityKind, str]] = []
    for p in traj.phases:
        if p.t_end <= p.t_start:
            continue
        kind: ActivityKind = "welding" if p.kind == "weld" else ("waiting" if p.kind == "wait" else "moving")
        local.append((float(p.t_start), float(p.t_end), kind, ""))
    cuts = sorted({h.t_local for h in holds if h.seconds > 0} | ({stuck_at} if stuck_at is not None else set()))
    out: list[Activity] = []
    for a, b, kind, _ in local:
        if stuck_at is not None and a >= stuck_at:
            break
        b = min(b, stuck_at) if stuck_at is not None else b
        edges = [a, *(c for c in cuts if a < c < b), b]
        for lo, hi in pairwise(edges):
            shift = sum(h.seconds for h in holds if h.t_local <= lo + 1e-12)
            out.append(Activity(lo + shift, hi + shift, kind))
    for h in holds:
        if h.seconds > 0:
            before = sum(o.seconds for o in holds if o.t_local < h.t_local - 1e-12)
            out.append(Activity(h.t_local + before, h.t_local + before + h.seconds, "waiting", h.signal, h.setter))
    if stuck_at is not None:
        start = stuck_at + sum(h.seconds for h in holds)
        out.append(Activity(start, max(until, start), "waiting", stuck_signal, "", forever=True))
    return _merged(sorted(out, key=lambda x: (x.t_start, x.t_end)))


def _merged(items: list[Activity]) -> tuple[Activity, ...]:
    """Neighbours of the same kind and signal joined into one."""
    out: list[Activity] = []
    for a in items:
        last = out[-1] if out else None
        if last is not None and (last.kind, last.signal, last.other, last.forever) == (a.kind, a.signal, a.other,
                                                                                         a.forever) \
                and abs(last.t_end - a.t_start) <= 1e-9:
            out[-1] = Activity(last.t_start, a.t_end, a.kind, a.signal, a.other, a.forever)
        else:
            out.append(a)
    return tuple(out)
