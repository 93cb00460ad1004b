"""Sampled motion: a `Segment` is one timed move or dwell, a `Trajectory` many of them end to end.

Both hold samples (t, q, qd, qdd), not solver objects, so they pickle to worker processes and stay
immutable. Segments are sampled densely (`DEFAULT_DT_S`); `resample` produces the trajectory file's
grid (docs/cell-files.md, "The trajectory file": strictly increasing t, at most 10 ms apart) with every phase boundary on a sample, so a
spot's arrive and leave times are exact sample times.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.spec import frozen_array
from robomax_py.timing._common import (
    DEFAULT_DT_S,
    SPEC_MAX_DT_S,
    TimingError,
    as_joint_vector,
    time_grid,
)
from robomax_py.tolerances import DEFAULT as TOL

# What a segment does. "move": PTP between configurations; "detour": a move through detour
# waypoints; "approach"/"retract": LIN along the electrode axis; "weld": dwell at a spot;
# "wait": any other dwell; "blend": a fly-by corner timed on its own.
SEGMENT_KINDS = frozenset({"move", "detour", "approach", "retract", "weld", "wait", "blend"})

# Segments joined by `concatenate` must meet within these (rad or m, and per second).
JOIN_POS_TOL = TOL.join_pos_tol
JOIN_VEL_TOL = TOL.join_vel_tol


@dataclass(frozen=True, slots=True, eq=False)
class Segment:
    """One timed piece of motion, starting at its own t = 0.

    t : (k,) float, s
        Sample times, t[0] == 0, strictly increasing; k == 1 for a zero-duration segment.
    q : (k, n) float, rad (m for prismatic joints)
    qd : (k, n) float, rad/s
    qdd : (k, n) float, rad/s^2
    kind : str
        One of SEGMENT_KINDS.
    label : str
        Free text carried into the trajectory's phases, e.g. the spot name of a "weld".
    """

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    kind: str = "move"
    label: str = ""

    def __post_init__(self) -> None:
        t, q, qd, qdd = _checked_samples(self.t, self.q, self.qd, self.qdd)
        if abs(t[0]) > 0.0:
            raise TimingError(f"a segment starts at t = 0, got t[0] = {t[0]}")
        if self.kind not in SEGMENT_KINDS:
            raise TimingError(f"segment kind must be one of {sorted(SEGMENT_KINDS)}, got {self.kind!r}")
        for name, value in (("t", t), ("q", q), ("qd", qd), ("qdd", qdd)):
            object.__setattr__(self, name, frozen_array(value))

    @property
    def duration(self) -> float:
        """Seconds from the first to the last sample."""
        return float(self.t[-1])

    @property
    def dof(self) -> int:
        return int(self.q.shape[1])

    @property
    def q_start(self) -> FloatArray:
        """(n,) first configuration."""
        return np.asarray(self.q[0], dtype=float)

    @property
    def q_end(self) -> FloatArray:
        """(n,) last configuration."""
        return np.asarray(self.q[-1], dtype=float)


@dataclass(frozen=True, slots=True)
class Phase:
    """Where one segment lies in a trajectory.

    t_start, t_end : s, on the trajectory's clock; both are sample times of the trajectory.
    i_start, i_end : indices of those samples in the trajectory's t.
    """

    kind: str
    label: str
    t_start: float
    t_end: float
    i_start: int
    i_end: int

    @property
    def duration(self) -> float:
        return self.t_end - self.t_start


@dataclass(frozen=True, slots=True, eq=False)
class Trajectory:
    """Segments end to end on one clock.

    t : (k,) float, s, strictly increasing (starts at the t_start given to `concatenate`, default 0).
    q, qd, qdd : (k, n) float, rad, rad/s, rad/s^2.
    phases : one Phase per segment, in order. For a spot welded in a segment of kind "weld" labelled
        with the spot's name, that phase's t_start and t_end are its t_arrive and t_leave.
    """

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    phases: tuple[Phase, ...]

    def __post_init__(self) -> None:
        t, q, qd, qdd = _checked_samples(self.t, self.q, self.qd, self.qdd)
        for name, value in (("t", t), ("q", q), ("qd", qd), ("qdd", qdd)):
            object.__setattr__(self, name, frozen_array(value))
        for p in self.phases:
            if not (0 <= p.i_start <= p.i_end < len(t)):
                raise TimingError(f"phase {p.kind} {p.label!r}: sample indices {p.i_start}..{p.i_end} outside 0..{len(t) - 1}")

    @property
    def duration(self) -> float:
        """Seconds from the first to the last sample (the trajectory file's cycle_time)."""
        return float(self.t[-1] - self.t[0])

    @property
    def dof(self) -> int:
        return int(self.q.shape[1])

    def phases_of(self, kind: str | None = None, label: str | None = None) -> tuple[Phase, ...]:
        """The phases matching kind and/or label (None matches anything), in time order."""
        return tuple(
            p for p in self.phases if (kind is None or p.kind == kind) and (label is None or p.label == label)
        )


@dataclass(frozen=True, slots=True, eq=False)
class JointStates:
    """Joint states at given times: t (k,) s; q, qd, qdd (k, n) rad, rad/s, rad/s^2."""

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray


def dwell(q: FloatArray, duration: float, *, kind: str = "weld", label: str = "", dt: float = DEFAULT_DT_S) -> Segment:
    """Standing still at q for exactly `duration` seconds.

    Parameters
    ----------
    q : (n,) float
        Configuration, rad.
    duration : float
        Seconds, >= 0; the segment's last sample is at exactly this time.
    dt : float
        Sample period, s.
    """
    if not (np.isfinite(duration) and duration >= 0.0):
        raise TimingError(f"dwell duration must be >= 0 s, got {duration}")
    q = as_joint_vector(q, int(np.size(q)), "dwell configuration")
    t = time_grid(float(duration), dt)
    zeros = np.zeros((len(t), len(q)))
    return Segment(t=t, q=np.broadcast_to(q, zeros.shape).copy(), qd=zeros, qdd=zeros.copy(), kind=kind, label=label)


def concatenate(
    segments: Sequence[Segment],
    *,
    t_start: float = 0.0,
    pos_tol: float = JOIN_POS_TOL,
    vel_tol: float = JOIN_VEL_TOL,
) -> Trajectory:
    """Join segments end to end; each must start where (and as fast as) the previous one ends.

    The first sample of every segment after the first coincides with the previous segment's last
    sample and is dropped (the previous one's state is kept), so t stays strictly increasing.

    Raises
    ------
    TimingError
        If the list is empty, degrees of freedom differ, or a join is off by more than pos_tol in
        position (rad) or vel_tol in velocity (rad/s).
    """
    if not segments:
        raise TimingError("cannot concatenate an empty list of segments")
    n = segments[0].dof
    ts: list[FloatArray] = [segments[0].t + t_start]
    qs, qds, qdds = [segments[0].q], [segments[0].qd], [segments[0].qdd]
    phases = [Phase(segments[0].kind, segments[0].label, t_start, t_start + segments[0].duration, 0, len(segments[0].t) - 1)]
    offset = t_start + segments[0].duration
    count = len(segments[0].t)
    for i, seg in enumerate(segments[1:], start=1):
        if seg.dof != n:
            raise TimingError(f"segment {i} has {seg.dof} joints, segment 0 has {n}")
        prev = segments[i - 1]
        dq = float(np.max(np.abs(seg.q[0] - prev.q[-1])))
        dv = float(np.max(np.abs(seg.qd[0] - prev.qd[-1])))
        if dq > pos_tol or dv > vel_tol:
            raise TimingError(
                f"segment {i} ({seg.kind} {seg.label!r}) does not continue segment {i - 1} ({prev.kind} "
                f"{prev.label!r}): position off by {dq:.3g} (tol {pos_tol:g}), velocity off by {dv:.3g} (tol {vel_tol:g})"
            )
        i_start = count - 1
        if len(seg.t) > 1:
            ts.append(seg.t[1:] + offset)
            qs.append(seg.q[1:])
            qds.append(seg.qd[1:])
            qdds.append(seg.qdd[1:])
            count += len(seg.t) - 1
        phases.append(Phase(seg.kind, seg.label, offset, offset + seg.duration, i_start, count - 1))
        offset += seg.duration
    t = np.concatenate(ts)
    # Keep phase times identical to their samples' times (offset sums can differ in the last bit).
    phases = [
        Phase(p.kind, p.label, float(t[p.i_start]), float(t[p.i_end]), p.i_start, p.i_end) for p in phases
    ]
    return Trajectory(t=t, q=np.concatenate(qs), qd=np.concatenate(qds), qdd=np.concatenate(qdds), phases=tuple(phases))


def as_segment(traj: Trajectory, kind: str = "move", label: str = "") -> Segment:
    """A trajectory as one segment of the given kind (its clock shifted to start at 0)."""
    return Segment(t=traj.t - traj.t[0], q=traj.q, qd=traj.qd, qdd=traj.qdd, kind=kind, label=label)


def evaluate(traj: Trajectory | Segment, t: FloatArray) -> JointStates:
    """Joint states at arbitrary times inside [t[0], t[-1]], interpolated between samples.

    q is a cubic Hermite interpolant of (q, qd), qd one of (qd, qdd), qdd is linear: exact at the
    samples and accurate to O(dt^4 q'''') between them for the smooth pieces of a move.

    Parameters
    ----------
    t : (m,) float
        Query times, s, on the clock of `traj`; clipped into its time range.
    """
    tq = np.clip(np.asarray(t, dtype=float).reshape(-1), traj.t[0], traj.t[-1])
    if len(traj.t) == 1:
        rep = np.ones((len(tq), 1))
        return JointStates(t=tq, q=rep * traj.q[0], qd=rep * traj.qd[0], qdd=rep * traj.qdd[0])
    i = np.clip(np.searchsorted(traj.t, tq, side="right") - 1, 0, len(traj.t) - 2)
    h = (traj.t[i + 1] - traj.t[i])[:, None]
    u = ((tq - traj.t[i])[:, None]) / h
    q = _hermite(traj.q[i], traj.qd[i], traj.q[i + 1], traj.qd[i + 1], h, u)
    qd = _hermite(traj.qd[i], traj.qdd[i], traj.qd[i + 1], traj.qdd[i + 1], h, u)
    qdd = (1.0 - u) * traj.qdd[i] + u * traj.qdd[i + 1]
    return JointStates(t=tq, q=q, qd=qd, qdd=qdd)


def resample(traj: Trajectory, max_dt: float = SPEC_MAX_DT_S) -> Trajectory:
    """The trajectory on a grid at most max_dt apart, with every phase boundary a sample.

    Each phase is divided evenly into the fewest steps of at most max_dt, so t is strictly
    increasing, no step exceeds max_dt, and phases keep their exact start and end times.
    """
    if not (np.isfinite(max_dt) and max_dt > 0):
        raise TimingError(f"max_dt must be > 0 s, got {max_dt}")
    bounds = np.unique(np.array([traj.t[0], traj.t[-1], *(p.t_start for p in traj.phases), *(p.t_end for p in traj.phases)]))
    pieces = [bounds[:1]]
    for a, b in itertools.pairwise(bounds):
        steps = max(1, int(np.ceil((b - a) / (max_dt * (1.0 - 1e-9)))))
        piece = np.linspace(a, b, steps + 1)[1:]
        piece[-1] = b
        pieces.append(piece)
    t_new = np.concatenate(pieces)
    states = evaluate(traj, t_new)
    index = {float(v): k for k, v in enumerate(t_new)}
    phases = tuple(
        Phase(p.kind, p.label, p.t_start, p.t_end, index[float(p.t_start)], index[float(p.t_end)]) for p in traj.phases
    )
    # Phase boundaries are samples of `traj` too, where `evaluate` returns the stored state exactly.
    return Trajectory(t=t_new, q=states.q, qd=states.qd, qdd=states.qdd, phases=phases)


def _hermite(p0: FloatArray, m0: FloatArray, p1: FloatArray, m1: FloatArray, h: FloatArray, u: FloatArray) -> FloatArray:
    u2 = u * u
    u3 = u2 * u
    return (
        (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * h * m0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * h * m1
    )


def _checked_samples(
    t: FloatArray, q: FloatArray, qd: FloatArray, qdd: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    t = np.asarray(t, dtype=float)
    q, qd, qdd = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
    if t.ndim != 1 or len(t) < 1:
        raise TimingError(f"t must be a non-empty 1-D array, got shape {t.shape}")
    for name, arr in (("q", q), ("qd", qd), ("qdd", qdd)):
        if arr.ndim != 2 or arr.shape[0] != len(t):
            raise TimingError(f"{name} must have shape ({len(t)}, n), got {arr.shape}")
        if arr.shape != q.shape:
            raise TimingError(f"{name} has shape {arr.shape}, q has {q.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(q)) and np.all(np.isfinite(qd)) and np.all(np.isfinite(qdd))):
        raise TimingError("samples must be finite")
    if np.any(np.diff(t) <= 0):
        raise TimingError("sample times must be strictly increasing")
    return t, q, qd, qdd
