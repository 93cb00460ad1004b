"""Shared pieces of the timing package: its error, named constants, limit scaling and sampling helpers."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import RobomaxError
from robomax_py.robot import JointLimits
from robomax_py.tolerances import DEFAULT as TOL

# Sample period of the segments this package builds (s). 4 ms is a common controller interpolation
# cycle (and the trajectory file example's in docs/cell-files.md); `resample` turns a trajectory into the file's <= 10 ms grid.
DEFAULT_DT_S = 0.004
# docs/cell-files.md, "The trajectory file": trajectory samples at most this far apart (s).
SPEC_MAX_DT_S = 0.010
# Relative slack for boundary velocities given by a caller (rounding of values read off another move).
BOUNDARY_VEL_RTOL = TOL.boundary_vel_rtol
# A joint value this far outside its limit (rad or m) still counts as inside: round-off only.
LIMIT_TOL = TOL.limit_tol
# Moves shorter than this (infinity norm over joints, rad or m) are treated as no motion.
ZERO_MOVE = 1e-12


class TimingError(RobomaxError):
    """A move cannot be timed as asked: bad arguments, infeasible boundary states, or a solver failure."""


class LinMoveError(TimingError):
    """A Cartesian straight line cannot be followed in the requested IK branch.

    `reason` is one of "unreachable", "discontinuous", "joint_limit", "start_mismatch"; `index` is
    the first failing sample of the line (0 = start) and `fraction` its position along the line (0..1).
    """

    def __init__(self, reason: str, index: int, fraction: float, detail: str) -> None:
        self.reason = reason
        self.index = index
        self.fraction = fraction
        self.detail = detail
        super().__init__(f"LIN move {reason} at {100.0 * fraction:.1f} % of the line (sample {index}): {detail}")

    def __reduce__(self) -> tuple[type, tuple[str, int, float, str]]:
        return type(self), (self.reason, self.index, self.fraction, self.detail)


@dataclass(frozen=True, slots=True, eq=False)
class KinematicLimits:
    """Per-joint magnitude limits after speed/acceleration overrides; each (n,) float, > 0.

    velocity : rad/s (m/s), acceleration : rad/s^2, jerk : rad/s^3.
    """

    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray


def scaled_limits(limits: JointLimits, speed: float, accel: float) -> KinematicLimits:
    """The limits a move may use: velocity x speed, acceleration x accel, jerk x accel.

    Parameters
    ----------
    speed : float
        Velocity override in (0, 1]: the fraction of every joint's velocity limit this move may use.
    accel : float
        Acceleration override in (0, 1]; scales acceleration and jerk alike, so the time to build up
        full acceleration (acceleration / jerk) stays that of the robot.
    """
    for name, value in (("speed", speed), ("accel", accel)):
        if not (np.isfinite(value) and 0.0 < value <= 1.0):
            raise TimingError(f"{name} override must be in (0, 1], got {value}")
    v = np.asarray(limits.velocity, dtype=float) * speed
    a = np.asarray(limits.acceleration, dtype=float) * accel
    j = np.asarray(limits.jerk, dtype=float) * accel
    if not (np.all(v > 0) and np.all(a > 0) and np.all(j > 0)):
        raise TimingError("joint velocity, acceleration and jerk limits must all be > 0")
    return KinematicLimits(velocity=v, acceleration=a, jerk=j)


def time_grid(duration: float, dt: float) -> FloatArray:
    """(k,) uniform sample times from 0 to duration inclusive, steps <= dt; [0.0] for a zero duration."""
    if not (np.isfinite(dt) and dt > 0):
        raise TimingError(f"sample period dt must be > 0 s, got {dt}")
    if duration <= 0.0:
        return np.zeros(1)
    steps = max(1, int(np.ceil(duration / dt - 1e-9)))
    t = np.linspace(0.0, duration, steps + 1)
    t[-1] = duration
    return t


def as_joint_vector(value: FloatArray | None, n: int, name: str) -> FloatArray:
    """A finite (n,) float copy; None -> zeros."""
    if value is None:
        return np.zeros(n)
    arr = np.array(value, dtype=float).reshape(-1)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise TimingError(f"{name} must be {n} finite values, got shape {np.shape(value)}")
    return arr


def check_within_limits(q: FloatArray, limits: JointLimits, what: str) -> None:
    """Raise TimingError if any row of q (k, n) leaves [lower, upper] by more than LIMIT_TOL."""
    lo = np.asarray(limits.lower) - LIMIT_TOL
    hi = np.asarray(limits.upper) + LIMIT_TOL
    bad = np.any((q < lo) | (q > hi), axis=-1)
    if np.any(bad):
        k = int(np.argmax(bad))
        raise TimingError(f"{what} leaves the joint position limits at sample {k}: q = {np.round(q[k], 6).tolist()}")
