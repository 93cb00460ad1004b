"""Closed-form minimum times of rest-to-rest joint moves, vectorised for ranking many candidate pairs.

Both estimates come in two flavours:

* ``straight=True`` (default): the time of the straight joint-space line from q0 to q1 with every
  joint within its limits, which is exactly what `ptp_move` (rest to rest) executes. Along the line
  q = q0 + s (q1 - q0) the joint limits become scalar limits on s: V = min_j v_j / |dq_j| and alike
  for acceleration and jerk, so the time is the 1-D profile time with those limits.
* ``straight=False``: the largest of the joints' independent minimum times. This is a lower bound,
  and the duration a time-synchronised controller achieves (joints then follow differently shaped
  profiles, so the joint-space path is not the straight line). It differs from the straight-line
  time only when one joint limits the velocity and another the acceleration (or jerk).

Formulas are written in the ratios r_v = d / v, r_a = d / a, r_j = d / j (d = |q1 - q0| per joint)
so that joints that do not move (all ratios zero) need no special case.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.robot import JointLimits
from robomax_py.timing._common import ZERO_MOVE, scaled_limits
from robomax_py.timing._estimate_kernels import straight_times


def ptp_time_estimate(
    q0: FloatArray,
    q1: FloatArray,
    limits: JointLimits,
    speed: float = 1.0,
    *,
    accel: float = 1.0,
    straight: bool = True,
) -> FloatArray:
    """Minimum rest-to-rest time under velocity and acceleration limits (trapezoidal profiles).

    Parameters
    ----------
    q0, q1 : (..., n) float
        Start and goal configurations, rad (m for prismatic joints); broadcast against each other.
    limits : JointLimits
        velocity (n,) rad/s and acceleration (n,) rad/s^2 are used.
    speed, accel : float
        Overrides in (0, 1] scaling the velocity and the acceleration limits.
    straight : bool
        True: time of the straight joint-space line (what `ptp_move` and toppra on a line achieve);
        False: max over joints of the independent times (a lower bound).

    Returns
    -------
    (...) float
        Seconds; 0 where q0 == q1.
    """
    lim = _scaled(limits, speed, accel)
    q0 = np.asarray(q0, dtype=float)
    q1 = np.asarray(q1, dtype=float)
    if q0.ndim and q1.ndim and q0.size == q1.size == q0.shape[-1] == q1.shape[-1] <= len(lim.v):
        # One move (the sequencer asks thousands of these): Python floats do the same IEEE
        # operations as numpy's (subtraction, abs, division, comparison, sqrt correctly rounded),
        # without an array call per operation.
        t = _ptp_one(q0.ravel().tolist(), q1.ravel().tolist(), lim.v, lim.a, straight)
        return np.full((1,) * (max(q0.ndim, q1.ndim) - 1), t)
    if not straight:
        return _largest(_trapezoid_time(r_v, r_a) for r_v, r_a in _joint_ratios(q0, q1, lim.v, lim.a))
    n = q0.shape[-1] if q0.ndim else 0
    if 0 < n <= len(lim.v) and q1.ndim == q0.ndim and q1.shape[-1] == n:
        # The candidate matrices (k, 1, n) x (1, m, n) and paired rows (k, n), (k, n) in one
        # compiled pass (`_estimate_kernels`), the same floats.
        if q0.ndim == 3 and q0.shape[1] == 1 and q1.shape[0] == 1:
            matrix: FloatArray = straight_times(_columns(q0[:, 0]), _columns(q1[0]),
                                                lim.v_array[:n], lim.a_array[:n], ZERO_MOVE, True)
            return matrix
        if q0.ndim == 2 and q0.shape == q1.shape:
            paired: FloatArray = straight_times(_columns(q0), _columns(q1),
                                                lim.v_array[:n], lim.a_array[:n], ZERO_MOVE, False)[0]
            return paired
    # Any other broadcast, joint by joint into two running maxima, reusing buffers: a reduction over
    # a last axis of 6 and fresh temporaries cost numpy more than the arithmetic (measured on
    # 32 x 32 candidate matrices, before they were compiled: 31 us against 50 us allocating per
    # joint, and 100 us as one (N, M, 6) array). This is also the definition the compiled pass
    # follows.
    d = np.abs(q1[..., 0] - q0[..., 0])
    r_v, r_a = d / lim.v[0], d / lim.a[0]
    ratio = np.empty_like(d)
    for k in range(1, max(q0.shape[-1], q1.shape[-1])):
        np.subtract(q1[..., k], q0[..., k], out=d)
        np.abs(d, out=d)
        np.maximum(r_v, np.divide(d, lim.v[k], out=ratio), out=r_v)
        np.maximum(r_a, np.divide(d, lim.a[k], out=ratio), out=r_a)
    # Differences of at most ZERO_MOVE count as none (as the moves do). Such a joint's ratio is at
    # most ZERO_MOVE / (least limit) (division rounds monotonically), so a maximum above that bound
    # comes from a joint that moves and is the maximum with the others zeroed as well: only the
    # moves at or below it (configurations that coincide, NaN too) are computed again with the
    # zeroing, instead of three more passes per joint over the whole matrix.
    few = ~((r_v > lim.still_v) & (r_a > lim.still_a))
    if few.any():
        shape = np.broadcast_shapes(q0.shape, q1.shape)
        dd = np.abs(np.broadcast_to(q1, shape)[few] - np.broadcast_to(q0, shape)[few])
        dd = np.where(dd > ZERO_MOVE, dd, 0.0)
        r_v[few] = (dd / np.asarray(lim.v[:shape[-1]])).max(axis=-1)
        r_a[few] = (dd / np.asarray(lim.a[:shape[-1]])).max(axis=-1)
    # `_trapezoid_time` in place (r_a becomes r_a / r_v where cruising).
    cruise = r_a < r_v * r_v
    times: FloatArray = np.sqrt(r_a)
    times *= 2.0
    np.divide(r_a, r_v, out=r_a, where=cruise)
    np.add(r_v, r_a, out=times, where=cruise)
    return times


def _columns(q: FloatArray) -> FloatArray:
    """q (k, n) transposed to contiguous (n, k), as a read-only view: numba compiles a kernel once
    per array type, and a writable and a read-only argument are two (configurations come both ways:
    a roadmap's nodes and cached candidates are read-only), each about 0.25 s of a first plan."""
    columns = np.ascontiguousarray(q.T).view()
    columns.flags.writeable = False
    return columns


def polyline_time_estimate(waypoints: FloatArray, limits: JointLimits, speed: float = 1.0) -> float:
    """`ptp_time_estimate` summed along a joint-space polyline (k, n): each leg rest to rest, in
    the order travelled (the estimate every detour is ranked by)."""
    return float(np.sum(ptp_time_estimate(waypoints[:-1], waypoints[1:], limits, speed)))


def jerk_limited_time_estimate(
    q0: FloatArray,
    q1: FloatArray,
    limits: JointLimits,
    speed: float = 1.0,
    *,
    accel: float = 1.0,
    straight: bool = True,
) -> FloatArray:
    """Minimum rest-to-rest time under velocity, acceleration and jerk limits (double-S profiles).

    Parameters and return value as `ptp_time_estimate`; jerk (n,) rad/s^3 is used as well, scaled
    by `accel`. With ``straight=True`` this equals the duration of `ptp_move(q0, q1, ...)` to
    round-off (ruckig's 1-D profile is the time-optimal double-S).
    """
    lim = _scaled(limits, speed, accel)
    per_joint = _joint_ratios(np.asarray(q0, dtype=float), np.asarray(q1, dtype=float), lim.v, lim.a, lim.j)
    if straight:
        return _double_s_time(*(_largest(ratio) for ratio in zip(*per_joint)))
    return _largest(_double_s_time(r_v, r_a, r_j) for r_v, r_a, r_j in per_joint)


@dataclass(frozen=True, slots=True)
class _Scaled:
    """`scaled_limits` as Python floats per joint: velocity, acceleration, jerk (/s, /s^2, /s^3)."""

    v: tuple[float, ...]
    a: tuple[float, ...]
    j: tuple[float, ...]
    still_v: float        # ZERO_MOVE / min(v), s: no ratio d / v of a joint that does not move exceeds it
    still_a: float        # ZERO_MOVE / min(a), s^2
    v_array: FloatArray   # v and a as arrays, for the compiled matrices (never written)
    a_array: FloatArray


# (velocity, acceleration, jerk bytes, speed, accel) -> the scaled limits. A plan asks with the same
# few limits tens of thousands of times; keyed by value, so a changed limit is never served stale.
_SCALED: dict[tuple[bytes, bytes, bytes, float, float], _Scaled] = {}
_SCALED_MAX = 64


def _scaled(limits: JointLimits, speed: float, accel: float) -> _Scaled:
    """`scaled_limits(limits, speed, accel)` (which checks them), remembered."""
    key = tuple(np.asarray(x, dtype=float).tobytes() for x in (limits.velocity, limits.acceleration, limits.jerk))
    full = (key[0], key[1], key[2], speed, accel)
    got = _SCALED.get(full)
    if got is None:
        lim = scaled_limits(limits, speed, accel)
        if len(_SCALED) >= _SCALED_MAX:
            _SCALED.clear()
        v, a = tuple(lim.velocity.tolist()), tuple(lim.acceleration.tolist())
        got = _SCALED[full] = _Scaled(v, a, tuple(lim.jerk.tolist()), ZERO_MOVE / min(v), ZERO_MOVE / min(a),
                                      np.array(v), np.array(a))
    return got


def _ptp_one(q0: list[float], q1: list[float], v: tuple[float, ...], a: tuple[float, ...], straight: bool) -> float:
    """`ptp_time_estimate` of one move in Python floats: the array path's operations in its order."""
    r_v = r_a = t_max = 0.0                    # every ratio and time is >= +0.0, so 0.0 starts the max
    for x0, x1, v_k, a_k in zip(q0, q1, v, a):
        d = abs(x1 - x0)
        if not d > ZERO_MOVE:                  # as np.where(d > ZERO_MOVE, d, 0.0), NaN included
            d = 0.0
        rv_k, ra_k = d / v_k, d / a_k
        if straight:
            r_v = max(r_v, rv_k)
            r_a = max(r_a, ra_k)
        else:
            t_k = rv_k + ra_k / rv_k if ra_k < rv_k * rv_k else 2.0 * math.sqrt(ra_k)
            t_max = max(t_max, t_k)
    if straight:
        return r_v + r_a / r_v if r_a < r_v * r_v else 2.0 * math.sqrt(r_a)
    return t_max


def _joint_ratios(q0: FloatArray, q1: FloatArray, *limits: tuple[float, ...]) -> list[tuple[FloatArray, ...]]:
    """Per joint k: (d_k / limit_k for each limit), d_k = |q1 - q0| of joint k broadcast over the
    leading axes, differences of at most ZERO_MOVE counted as none (as the moves do)."""
    out = []
    for k in range(max(q0.shape[-1], q1.shape[-1])):
        d = np.abs(q1[..., k] - q0[..., k])
        d = np.where(d > ZERO_MOVE, d, 0.0)
        out.append(tuple(d / lim[k] for lim in limits))
    return out


def _largest(per_joint: Iterable[FloatArray]) -> FloatArray:
    """Element-wise largest over the joints' arrays (exact, like np.max over a joint axis)."""
    out: FloatArray | None = None
    for value in per_joint:
        out = value if out is None else np.maximum(out, value)
    assert out is not None
    return np.asarray(out, dtype=float)


def _trapezoid_time(r_v: FloatArray, r_a: FloatArray) -> FloatArray:
    """Rest-to-rest time over unit distance with V = 1/r_v, A = 1/r_a (s).

    Cruise phase exists iff V^2 / A <= 1, i.e. r_a <= r_v^2: T = 1/V + V/A = r_v + r_a / r_v;
    otherwise the triangle T = 2 sqrt(1/A) = 2 sqrt(r_a).
    """
    r_v = np.asarray(r_v, dtype=float)
    r_a = np.asarray(r_a, dtype=float)
    cruise = r_a < r_v * r_v
    safe_rv = np.where(cruise, r_v, 1.0)
    return np.where(cruise, r_v + r_a / safe_rv, 2.0 * np.sqrt(r_a))


def _double_s_time(r_v: FloatArray, r_a: FloatArray, r_j: FloatArray) -> FloatArray:
    """Rest-to-rest jerk-limited time over unit distance with V = 1/r_v, A = 1/r_a, J = 1/r_j (s).

    Cases (Biagiotti & Melchiorri, "Trajectory Planning for Automatic Machines and Robots", §3.4):
    time to reach V from rest Tv = V/A + A/J if V J >= A^2 else 2 sqrt(V/J); if the distance allows
    (V Tv <= 1) T = Tv + 1/V. Otherwise the peak velocity vp < V: with a constant-acceleration phase
    (1 >= 2 A^3 / J^2) vp solves vp^2/A + vp A/J = 1 and T = 2 (vp/A + A/J); without it
    T = 4 (1 / (2 J))^(1/3).
    """
    r_v, r_a, r_j = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (r_v, r_a, r_j)))
    moving = r_v > 0
    rv = np.where(moving, r_v, 1.0)
    ra = np.where(moving, r_a, 1.0)
    rj = np.where(moving, r_j, 1.0)
    reaches_a = ra * ra >= rv * rj                               # V J >= A^2
    t_v = np.where(reaches_a, ra / rv + rj / ra, 2.0 * np.sqrt(rj / rv))
    cruise = t_v <= rv                                           # V Tv <= 1
    # vp in units of 1/time: vp = (A/2) (-A/J + sqrt(A^2/J^2 + 4/A)), A = 1/ra, J = 1/rj.
    a_over_j = rj / ra
    vp = 2.0 / (np.sqrt(a_over_j * a_over_j + 4.0 * ra) + a_over_j)     # the root above, cancellation-free
    t_acc_phase = 2.0 * (vp * ra + a_over_j)
    t_no_acc_phase = 4.0 * np.cbrt(rj / 2.0)
    with_acc_phase = ra**3 >= 2.0 * rj * rj                      # 1 >= 2 A^3 / J^2
    t = np.where(cruise, t_v + rv, np.where(with_acc_phase, t_acc_phase, t_no_acc_phase))
    return np.where(moving, t, 0.0)
