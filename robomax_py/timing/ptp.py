"""Jerk-limited state-to-state moves with ruckig (offline, no intermediate waypoints).

ruckig's community build computes trajectories *through* intermediate waypoints by calling a cloud
service; an offline tool must not, so every call here is state to state: `Ruckig(dof)` without a
control cycle, `calculate(input, trajectory)`, no `intermediate_positions`.

Straight lines. A rest-to-rest move (or one whose boundary velocities point along the move) is
computed as a 1-D profile of the distance s along the straight joint-space line q0 + s e, with the
joint limits turned into limits on s (V = min_j v_j / |e_j|, alike for acceleration and jerk). The
joints are then exactly proportional at every instant: all start and finish together and the path
is the straight line that a collision checker interpolates. ruckig's own phase synchronisation aims
at the same but tests collinearity to machine epsilon and silently falls back to time
synchronisation, whose joint-space path bows away from the line.

Other boundary velocities (passing through a waypoint in another direction) use all joints with
time synchronisation: every joint ends together, but the path is a curve; its samples are the
segment's q.

Note: ruckig's community build accepts `min_position`/`max_position` but does not enforce them, so
joint position limits are checked on the samples here instead.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.robot import JointLimits
from robomax_py.timing._common import (
    BOUNDARY_VEL_RTOL,
    DEFAULT_DT_S,
    ZERO_MOVE,
    KinematicLimits,
    TimingError,
    as_joint_vector,
    check_within_limits,
    scaled_limits,
    time_grid,
)
from robomax_py.timing.trajectory import Segment
from robomax_py.tolerances import DEFAULT as TOL

# Boundary velocities whose component across the move is below this fraction of their size count
# as pointing along the move (the move is then an exact straight line).
COLLINEAR_RTOL = TOL.collinear_rtol


@dataclass(frozen=True, slots=True, eq=False)
class _Samples:
    """t (k,) s; q, qd, qdd (k, n)."""

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray


def ptp_move(
    q0: FloatArray,
    q1: FloatArray,
    limits: JointLimits,
    speed: float = 1.0,
    v0: FloatArray | None = None,
    v1: FloatArray | None = None,
    *,
    accel: float = 1.0,
    kind: str = "move",
    label: str = "",
    dt: float = DEFAULT_DT_S,
) -> Segment:
    """Time-optimal jerk-limited point-to-point move, all joints synchronised.

    Parameters
    ----------
    q0, q1 : (n,) float
        Start and goal configurations, rad (m for prismatic joints).
    limits : JointLimits
        velocity, acceleration, jerk (n,) and the position limits the samples are checked against.
    speed : float
        Velocity override in (0, 1]: the move uses speed x the velocity limits (a per-move speed
        or a global override). Acceleration and jerk are not scaled by it, so a slow move still
        reaches its (lower) top speed quickly, as on a robot controller.
    v0, v1 : (n,) float, optional
        Joint velocities at start and end, rad/s (None: at rest). Non-zero values let a move pass
        through q0 or q1; each joint must be within speed x its velocity limit there.
    accel : float
        Acceleration override in (0, 1], scaling the acceleration and jerk limits.
    dt : float
        Sample period, s.

    Returns
    -------
    Segment
        Samples every <= dt from t = 0 to the duration; the first and last samples are exactly
        (q0, v0, 0) and (q1, v1, 0). With v0 and v1 zero or along q1 - q0 the joint-space path is the
        straight segment q0 -> q1 (time: `jerk_limited_time_estimate`); otherwise a curve.

    Raises
    ------
    TimingError
        Boundary velocity above its limit, ruckig failure, or the move leaving the joint limits
        (possible only with non-zero boundary velocities).
    """
    lim = scaled_limits(limits, speed, accel)
    q0 = np.asarray(q0, dtype=float).reshape(-1)
    n = len(q0)
    q0 = as_joint_vector(q0, n, "q0")
    q1 = as_joint_vector(q1, n, "q1")
    v0 = as_joint_vector(v0, n, "v0")
    v1 = as_joint_vector(v1, n, "v1")
    for name, v in (("v0", v0), ("v1", v1)):
        _check_velocity(v, lim.velocity, name)
    samples = _straight_or_curved(q0, v0, q1, v1, lim, dt)
    check_within_limits(samples.q, limits, "ptp move")
    return Segment(t=samples.t, q=samples.q, qd=samples.qd, qdd=samples.qdd, kind=kind, label=label)


def line_speed_limits(direction: FloatArray, lim: KinematicLimits) -> tuple[float, float, float]:
    """Limits on the speed, acceleration and jerk of s along q = q0 + s e, e a unit (n,) direction.

    Returns (V, A, J) in rad/s, rad/s^2, rad/s^3 of Euclidean joint-space distance.
    """
    e = np.abs(np.asarray(direction, dtype=float))
    moving = e > 0
    if not np.any(moving):
        raise TimingError("a line needs a non-zero direction")
    return (
        float(np.min(lim.velocity[moving] / e[moving])),
        float(np.min(lim.acceleration[moving] / e[moving])),
        float(np.min(lim.jerk[moving] / e[moving])),
    )


def line_samples(
    q0: FloatArray, q1: FloatArray, lim: KinematicLimits, sd0: float, sd1: float, dt: float
) -> _Samples:
    """Jerk-limited motion along the straight line q0 -> q1 with path speeds sd0, sd1 at its ends.

    sd0, sd1 : rad/s of Euclidean joint-space distance along the line (>= 0 moves towards q1).
    The samples lie exactly on the line through q0 and q1; with non-zero end speeds that are too
    high for the length, ruckig overshoots along the line and comes back (callers check).
    """
    delta = q1 - q0
    length = float(np.linalg.norm(delta))
    if length <= ZERO_MOVE:
        if abs(sd0) > 0 or abs(sd1) > 0:
            raise TimingError("a zero-length line cannot be passed at non-zero speed")
        return _Samples(t=np.zeros(1), q=q0[None, :].copy(), qd=np.zeros((1, len(q0))), qdd=np.zeros((1, len(q0))))
    e = delta / length
    v_max, a_max, j_max = line_speed_limits(e, lim)
    sd0 = float(np.clip(sd0, -v_max, v_max))
    sd1 = float(np.clip(sd1, -v_max, v_max))
    traj = _ruckig(
        [0.0], [sd0], [length], [sd1], np.array([v_max]), np.array([a_max]), np.array([j_max]), "straight move"
    )
    t = time_grid(traj.duration, dt)
    s, sd, sdd = _sample(traj, t, 1)
    q = q0 + s * e
    qd = sd * e
    qdd = sdd * e
    q[0], q[-1] = q0, q1
    qd[0], qd[-1] = sd0 * e, sd1 * e
    qdd[0], qdd[-1] = 0.0, 0.0
    return _Samples(t=t, q=q, qd=qd, qdd=qdd)


def state_samples(
    q0: FloatArray, v0: FloatArray, q1: FloatArray, v1: FloatArray, lim: KinematicLimits, dt: float
) -> _Samples:
    """Time-synchronised jerk-limited move between two states (zero acceleration at both ends).

    q0, q1 : (n,) rad; v0, v1 : (n,) rad/s. The joint-space path is in general a curve.
    """
    n = len(q0)
    traj = _ruckig(q0, v0, q1, v1, lim.velocity, lim.acceleration, lim.jerk, "state-to-state move")
    t = time_grid(traj.duration, dt)
    q, qd, qdd = _sample(traj, t, n)
    q[0], q[-1] = q0, q1
    qd[0], qd[-1] = v0, v1
    qdd[0], qdd[-1] = 0.0, 0.0
    return _Samples(t=t, q=q, qd=qd, qdd=qdd)


def _straight_or_curved(
    q0: FloatArray, v0: FloatArray, q1: FloatArray, v1: FloatArray, lim: KinematicLimits, dt: float
) -> _Samples:
    delta = q1 - q0
    length = float(np.linalg.norm(delta))
    if length > ZERO_MOVE:
        e = delta / length
        sd0, sd1 = float(v0 @ e), float(v1 @ e)
        along = all(
            float(np.linalg.norm(v - sd * e)) <= COLLINEAR_RTOL * float(np.linalg.norm(v)) for v, sd in ((v0, sd0), (v1, sd1))
        )
        if along:
            return line_samples(q0, q1, lim, sd0, sd1, dt)
    elif not np.any(v0) and not np.any(v1):
        n = len(q0)
        return _Samples(t=np.zeros(1), q=q0[None, :].copy(), qd=np.zeros((1, n)), qdd=np.zeros((1, n)))
    return state_samples(q0, v0, q1, v1, lim, dt)


def _check_velocity(v: FloatArray, v_max: FloatArray, name: str) -> None:
    over = np.abs(v) > v_max * (1.0 + BOUNDARY_VEL_RTOL)
    if np.any(over):
        j = int(np.argmax(over))
        raise TimingError(f"{name}[{j}] = {v[j]:.6g} exceeds the (overridden) velocity limit {v_max[j]:.6g}")


def _ruckig(
    p0: Any, v0: Any, p1: Any, v1: Any, v_max: FloatArray, a_max: FloatArray, j_max: FloatArray, what: str
) -> Any:
    """A ruckig Trajectory from (p0, v0, 0) to (p1, v1, 0); offline, state to state only."""
    from ruckig import InputParameter, Result, Ruckig, Synchronization, Trajectory

    n = len(v_max)
    inp = InputParameter(n)
    inp.current_position = [float(x) for x in p0]
    inp.current_velocity = [float(x) for x in v0]
    inp.current_acceleration = [0.0] * n
    inp.target_position = [float(x) for x in p1]
    inp.target_velocity = [float(x) for x in v1]
    inp.target_acceleration = [0.0] * n
    inp.max_velocity = [float(x) for x in v_max]
    inp.max_acceleration = [float(x) for x in a_max]
    inp.max_jerk = [float(x) for x in j_max]
    inp.synchronization = Synchronization.Time
    traj = Trajectory(n)
    result = Ruckig(n).calculate(inp, traj)
    if result not in (Result.Working, Result.Finished):
        raise TimingError(f"ruckig cannot compute the {what}: {result}")
    return traj


def _sample(traj: Any, t: FloatArray, n: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(k, n) position, velocity, acceleration of a ruckig trajectory at times t (k,)."""
    out = np.empty((3, len(t), n))
    for k, tk in enumerate(t):
        p, v, a = traj.at_time(float(tk))
        out[0, k], out[1, k], out[2, k] = p, v, a
    return out[0], out[1], out[2]
