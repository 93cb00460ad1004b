"""The minimum-time speed profile along a planar path under the constraint set of Benko Loknar,
Klančar and Blažič (eqs. 2a-2c: v <= v_max and ellipses of the tangential and normal acceleration
and of the tangential and normal jerk, eq. 7), in the paper's two steps (its section 2, after its
reference [4], which the paper leaves to that reference: this is our reading of it):

1. velocity and acceleration: the largest v(s) under v_max and the acceleration ellipse, by forward
   and backward passes from rest at both ends (`_frenet_kernels.envelope`). The limit curve also
   keeps the radial jerk at zero tangential acceleration within j_Rmax, and the passes the
   tangential acceleration inside what the radial jerk leaves (|3 kappa v a + kappa' v^3| <= j_Rmax);
2. jerk: that profile modified where the tangential jerk breaks the jerk ellipse, at points (the
   corners where the tangential acceleration jumps: leaving and reaching rest, reaching v_max,
   accelerating to braking, the bottlenecks) and over intervals (stretches bending faster than the
   jerk allows). The modified profile:
   - at each bottleneck of step 1 (a dip: `_critical_nodes`) and at the stop, an approach: a sweep
     along the path run backwards from that state (at the bottleneck's speed with no tangential
     acceleration; the start from rest), keeping the jerk ellipse, until it runs on the step-1
     profile again; these lower the step-1 profile to the bound W;
   - the forward sweep from rest under W (`_frenet_kernels.sweep`): the largest tangential
     acceleration the jerk leaves, repaired where it would cross W by braking with the largest
     tangential jerk the ellipse allows, as late as possible, until it meets W with W's
     acceleration (a constant-jerk transition: analytic on a straight line);
   - where the forward sweep finds the ellipses closed (its state there too fast for what follows),
     the speed there is lowered and approached like a bottleneck, and the sweep run again.

Between two nodes the tangential acceleration is linear in arclength; the first and last steps
are the jerk-limited start from rest (jerk j_Tmax until a_Tmax, then a_Tmax) and the same run
backwards. The sweeps keep a little inside the limits (APPROACH_MARGIN, SWEEP_MARGIN, and
`_frenet_kernels._ENVELOPE_MARGIN` for step 1) so that one can run along another.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import find_peaks

from robomax_py._typing import FloatArray, IntArray
from robomax_py.spec import TcpLimits, frozen_array
from robomax_py.timing._common import TimingError
from robomax_py.timing._frenet_kernels import (
    FAIL_W,
    LANDED,
    OK,
    envelope,
    start_piece,
    sweep,
)
from robomax_py.timing.quintic_chain import QuinticChain

DEFAULT_STEP_M = 0.01
# A state within this fraction of the bound is on it.
ON_BOUND = 1e-6
# The sweeps keep this far inside the limits (the approaches further than the forward sweep, which
# runs along them, and the step-1 profile further still: `_frenet_kernels._ENVELOPE_MARGIN`), so
# that a sweep following a curve made at the edge of the same limits has room for rounding.
APPROACH_MARGIN = 5e-4
SWEEP_MARGIN = 1e-4
# How close (relative) the forward sweep must come to the stop's first node.
END_MATCH = 1e-3
# A dip of the step-1 profile this deep (relative to its peak) is a bottleneck the approaches start at.
CRITICAL_DEPTH = 1e-3
# Where the forward sweep cannot go on, the speed there is lowered by LOWERING of b (doubled each
# time at the same node), at most MAX_LOWERINGS times in all.
LOWERING = 0.01
MAX_LOWERINGS = 40
# Where the sweep fails, it runs again inside the limits scaled so, on a finer grid.
RETRY_SCALES = (0.995, 0.98)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_FAILURES = {1: "the bound would be crossed", 2: "the acceleration ellipse closes", 3: "the jerk ellipse closes",
             4: "the speed falls to zero"}


@dataclass(frozen=True, slots=True, eq=False)
class FrenetProfile:
    """Speed along a path: nodes s (n+1,) m with b = v^2 (m^2/s^2), tangential acceleration a
    (m/s^2) and time t (s); sigma (n,) = da/ds on each step (1/s^2); `envelope` the step-1 b.
    The first step is the start from rest with jerk and acceleration `start` (m/s^3, m/s^2); the
    last one the same start, with `stop`, run backwards. `limit_scale` < 1: the profile was made
    inside the limits scaled so (`frenet_profile`)."""

    s: FloatArray
    b: FloatArray
    a: FloatArray
    sigma: FloatArray
    t: FloatArray
    envelope: FloatArray
    start: tuple[float, float]
    stop: tuple[float, float]
    limit_scale: float = 1.0

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    @property
    def v(self) -> FloatArray:
        return np.sqrt(np.maximum(self.b, 0.0))

    def at_time(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Arclength (m), speed (m/s) and tangential acceleration (m/s^2) at times t (k,)."""
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        n = len(self.sigma)
        step = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, n - 1)
        s, v, a = np.empty(len(t)), np.empty(len(t)), np.empty(len(t))
        first, last = step == 0, step == n - 1
        for sel, tau, sign, (jerk, accel) in ((first, t, 1.0, self.start), (last, self.duration - t, -1.0, self.stop)):
            ds, vv, aa = _start_motion(tau[sel], jerk, accel)
            s[sel] = ds if sign > 0 else self.s[-1] - ds
            v[sel], a[sel] = vv, sign * aa
        mid = ~(first | last)
        i = step[mid]
        x = _step_position(self.b[i], self.a[i], self.sigma[i], self.s[i + 1] - self.s[i], t[mid] - self.t[i])
        s[mid] = self.s[i] + x
        v[mid] = np.sqrt(np.maximum(self.b[i] + 2 * self.a[i] * x + self.sigma[i] * x * x, 0.0))
        a[mid] = self.a[i] + self.sigma[i] * x
        return s, v, a


def _start_motion(tau: FloatArray, jerk: float, accel: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Distance, speed and acceleration tau (k,) s after leaving rest (jerk, then constant accel)."""
    t_a = accel / jerk
    ramp = tau <= t_a
    tr = np.minimum(tau, t_a)
    s = jerk * tr**3 / 6.0
    v = 0.5 * jerk * tr**2
    a = jerk * tr
    rest = np.where(ramp, 0.0, tau - t_a)
    return s + v * rest + 0.5 * accel * rest**2, v + accel * rest, np.where(ramp, a, accel)


def _step_time(b: FloatArray, a: FloatArray, sig: FloatArray, x: FloatArray) -> FloatArray:
    """Time (k,) to cover x (k,) from the start of steps with b, a, sigma: the integral of
    1/sqrt(b + 2 a u + sigma u^2) over [0, x] (8-point Gauss; b stays away from 0 inside the path)."""
    u = 0.5 * x[:, None] * (1.0 + _GL_X[None, :])
    q = b[:, None] + 2.0 * a[:, None] * u + sig[:, None] * u * u
    return np.asarray(0.5 * x * (_GL_W[None, :] / np.sqrt(np.maximum(q, 1e-300))).sum(axis=1), dtype=float)


def _step_position(b: FloatArray, a: FloatArray, sig: FloatArray, h: FloatArray, tau: FloatArray) -> FloatArray:
    """The x in [0, h] a step reaches tau after its start (Newton on the step's time integral)."""
    x = np.clip(tau * np.sqrt(np.maximum(b, 1e-300)), 0.0, h)
    for _ in range(8):
        q = np.maximum(b + 2.0 * a * x + sig * x * x, 1e-300)
        x = np.clip(x - (_step_time(b, a, sig, x) - tau) * np.sqrt(q), 0.0, h)
    return np.asarray(x, dtype=float)


def _node_slopes(s: FloatArray, b: FloatArray) -> FloatArray:
    """Tangential acceleration a = (db/ds)/2 at nodes, by central differences (one-sided at the ends)."""
    return np.asarray(0.5 * np.gradient(b, s), dtype=float)


def _mirrored(geo: FloatArray) -> FloatArray:
    """The kernels' table of the path run backwards: curvature changes sign (the turn is the other
    way), its derivative in the new arclength does not; leaving and arriving swap."""
    out = np.zeros_like(geo)
    out[:, 0] = -geo[::-1, 0]
    out[:, 1] = geo[::-1, 2]
    out[:, 2] = geo[::-1, 1]
    out[:-1, 3] = -geo[-2::-1, 3]
    out[:-1, 4] = geo[-2::-1, 4]
    return out


def _critical_nodes(upper: FloatArray) -> IntArray:
    """Interior nodes where the step-1 profile has a local minimum at least CRITICAL_DEPTH of its
    largest value below the higher ground on both sides (scipy's prominence): the path's
    bottlenecks. Shallower dips the forward sweep passes by itself."""
    found, _ = find_peaks(-np.asarray(upper), prominence=CRITICAL_DEPTH * float(np.max(upper)))
    return np.asarray(found[(found > 0) & (found < len(upper) - 1)], dtype=np.int64)


def _approaches(h: FloatArray, geo: FloatArray, upper: FloatArray, a_upper: FloatArray, lim: FloatArray,
                extra: list[tuple[int, float]]) -> tuple[FloatArray, FloatArray]:
    """The bound the forward sweep runs under: the step-1 profile, lowered by the jerk-limited
    approaches to its bottlenecks, to the stop and to the lowered speeds `extra` (node, b). Each
    approach is a sweep along the mirrored path from the bottleneck or lowered speed (with no
    tangential acceleration) or from the stop (the start from rest run backwards), until it runs on
    the step-1 profile again."""
    n = len(h)
    m_h, m_geo = h[::-1].copy(), _mirrored(geo)
    m_bound, m_a = upper[::-1].copy(), -a_upper[::-1]
    bound, a_bound = upper.copy(), a_upper.copy()
    scratch = (np.empty(n + 1), np.empty(n + 1), np.empty(n + 1))
    inner = lim * (1.0 - APPROACH_MARGIN)
    starts = [(0, *start_piece(float(inner[1]), float(inner[3]), float(h[-1]))[:2])]
    starts += [(n - int(c), float(upper[c]), 0.0) for c in _critical_nodes(upper)]
    starts += [(n - node, b_node, 0.0) for node, b_node in extra]
    for i0, b0, a0 in starts:
        rb, ra, rsig = np.zeros(n + 1), np.zeros(n + 1), np.zeros(n)
        first = i0 + 1 if i0 == 0 else i0
        rb[first], ra[first] = b0, a0
        code, last = sweep(m_h, m_geo, m_bound.copy(), m_a, inner, rb, ra, rsig, first, n, True, ON_BOUND, *scratch)
        if code not in (OK, LANDED):
            last -= 1                         # valid up to the node before the one that failed
        if last <= i0:
            continue
        fwd = np.arange(n - last, n - i0 + 1)
        rev = n - fwd
        lower = rb[rev] < bound[fwd]
        bound[fwd[lower]] = rb[rev][lower]
        a_bound[fwd[lower]] = -ra[rev][lower]
    return bound, a_bound


def frenet_profile(chain: QuinticChain, limits: TcpLimits, step: float = DEFAULT_STEP_M) -> FrenetProfile:
    """The two-step minimum-time profile along `chain`, from rest to rest, under the paper's
    constraints with `limits` (v_max, a_Tmax, a_Rmax, j_Tmax, j_Rmax: `TcpLimits` fields v, a_T,
    a_R, j_T, j_R). Nodes at most `step` m apart, closer where the curvature changes fast
    (`QuinticChain.nodes`).

    Where the sweep finds no repair (a failure it cannot back out of: a sharp rise of the
    curvature's derivative right after a bottleneck, a near-corner), it is run again inside the
    limits scaled by each of RETRY_SCALES on a grid twice as fine each time; `limit_scale` says
    which run it is. Every run keeps the real limits."""
    failure = TimingError("no profile")
    for k, scale in enumerate((1.0, *RETRY_SCALES)):
        try:
            return _profile(chain, limits, step / 2**k, scale)
        except TimingError as err:
            failure = err
    raise failure


def _profile(chain: QuinticChain, limits: TcpLimits, step: float, scale: float) -> FrenetProfile:
    s, geo = chain.geometry(step)
    h = np.diff(s)
    n = len(h)
    if n < 4:
        raise TimingError("a path needs at least four nodes for a profile")
    real = np.array([limits.v, limits.a_T, limits.a_R, limits.j_T, limits.j_R], dtype=float)
    if not np.all(np.isfinite(real) & (real > 0)):
        raise TimingError(f"every limit must be finite and > 0, got {real}")
    lim = real * scale
    upper = np.empty(n + 1)
    envelope(h, geo, lim, upper)
    a_upper = _node_slopes(s, upper)
    forward = lim * (1.0 - SWEEP_MARGIN)
    start = (float(forward[3]), float(forward[1]))
    stop = (float(lim[3] * (1.0 - APPROACH_MARGIN)), float(lim[1] * (1.0 - APPROACH_MARGIN)))
    if not start_piece(start[1], start[0], float(min(h[0], h[-1])))[0] < min(upper[1], upper[-2]):
        raise TimingError("the first step is longer than the path allows; use a finer step")
    # Where the forward sweep finds the ellipses closed whatever it does (its state there came too
    # fast for what follows: a curvature rising sharply, the radial jerk taking the whole jerk
    # ellipse), the speed allowed there is lowered and approached like a bottleneck; again, lower
    # each time, until the sweep gets through.
    extra: list[tuple[int, float]] = []
    scratch = (np.empty(n + 1), np.empty(n + 1), np.empty(n + 1))
    for _ in range(MAX_LOWERINGS + 1):
        bound, a_bound = _approaches(h, geo, upper, a_upper, lim, extra)
        b, a, sig = np.zeros(n + 1), np.zeros(n + 1), np.zeros(n)
        b[1], a[1] = start_piece(start[1], start[0], float(h[0]))[:2]
        code, where = sweep(h, geo, bound, a_bound, forward, b, a, sig, 1, n - 1, False, ON_BOUND, *scratch)
        if code == OK or code == FAIL_W or where <= 1:
            break
        lowered = [e for e in extra if e[0] == where]
        cut = LOWERING * 2 ** len(lowered)
        extra.append((where, min(b[where], bound[where]) * (1.0 - cut)))
    if code != OK:
        raise TimingError(f"no jerk-limited profile: at s = {s[where]:.3f} m {_FAILURES.get(code, 'no repair found')}")
    b_stop, a_stop = start_piece(stop[1], stop[0], float(h[-1]))[:2]
    if abs(b[n - 1] - b_stop) > END_MATCH * b_stop or abs(a[n - 1] + a_stop) > END_MATCH * a_stop:
        raise TimingError("the profile does not end on the stop from the end")
    # The sweep ran along the stop's approach to within rounding: its last node is the stop's.
    b[n - 1], a[n - 1] = b_stop, -a_stop
    b[n], a[n] = 0.0, 0.0
    t_steps = np.empty(n)
    t_steps[0] = start_piece(start[1], start[0], float(h[0]))[2]
    t_steps[-1] = start_piece(stop[1], stop[0], float(h[-1]))[2]
    t_steps[1:-1] = _step_time(b[1:n - 1], a[1:n - 1], sig[1:n - 1], h[1:n - 1])
    return FrenetProfile(frozen_array(s), frozen_array(b), frozen_array(a), frozen_array(sig),
                         frozen_array(np.concatenate([[0.0], np.cumsum(t_steps)])), frozen_array(upper), start, stop,
                         scale)


def time_of(chain: QuinticChain, limits: TcpLimits, step: float = DEFAULT_STEP_M) -> float:
    """The travel time of `frenet_profile`, or +inf where no profile exists (for optimisers)."""
    try:
        return frenet_profile(chain, limits, step).duration
    except TimingError:
        return math.inf
