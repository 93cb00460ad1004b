"""The compiled loops of the two-step minimum-time profile (`frenet_profile`, numba).

The profile lives on arclength nodes s_i; between two nodes the tangential acceleration a is linear
in s (slope sigma_i = da/ds), so b = v^2 is quadratic: b_(i+1) = b_i + 2 a_i h_i + sigma_i h_i^2.
The paper's constraints (Benko Loknar et al., eqs. 2 and 7), with kappa' = d kappa / ds and
j_T = d^2 v / dt^2 - kappa^2 v^3 = v sigma - kappa^2 v^3, j_R = 3 kappa v a + kappa' v^3:

    b <= v_max^2,   (a / a_Tmax)^2 + (kappa b / a_Rmax)^2 <= 1,   (j_T / j_Tmax)^2 + (j_R / j_Rmax)^2 <= 1.

For a state (b, a) the jerk ellipse is an interval of sigma (`jerk_interval`); a step's sigma
must keep every constraint at both its nodes and halfway (`step_code`). `limits` is the array
(v_max, a_Tmax, a_Rmax, j_Tmax, j_Rmax).

Step 1 (`envelope`): forward and backward passes, implicit in each step, under the limit curve.

Step 2 (`sweep`): along the nodes, under an upper bound W on b (the step-1 profile lowered by
approaches, `frenet_profile`), the largest feasible slope at each node, and on the bound the
bound's own acceleration. Where the bound would be crossed (a corner of the step-1 profile where
the tangential acceleration drops, a stretch of it bending faster than the jerk allows), the
profile is repaired: from the latest node k (and the latest point theta within its step) from
which braking with the most negative tangential jerk the ellipse leaves gets past the failure,
the profile is that braking until it meets the bound with the bound's acceleration. Braking too
late crosses the bound, too early stalls or over-decelerates: the search gallops back from the
failure, bisects between the two, then bisects theta. Any other failure (the ellipses closed
whatever the slope) ends the sweep; the caller lowers the speed there.
"""

from __future__ import annotations

import math
from typing import Any

from robomax_py.jit import kernel

OK, FAIL_W, FAIL_A, FAIL_J, FAIL_STALL, LANDED = 0, 1, 2, 3, 4, 5
TOO_LATE, TOO_EARLY = 6, 7
_TOL = 1e-9            # relative slack of the checks against rounding
_BISECT = 30           # bisection steps for a step's slope
_ENVELOPE_MARGIN = 1e-3    # step 1 keeps this far inside the limits (relative)
_MARGIN = 1e-7         # the slope's fixed point is sought this far inside its interval (relative)


@kernel
def accel_cap(kappa: float, b: float, a_t: float, a_r: float) -> float:
    """The largest |a_T| the acceleration ellipse leaves at curvature kappa and b = v^2; -1 when the
    radial acceleration alone is past its limit."""
    r = kappa * b / a_r
    q = 1.0 - r * r
    if q < 0.0:
        return -1.0
    return a_t * math.sqrt(q)


@kernel
def jerk_interval(b: float, a: float, kappa: float, dk: float, j_t: float, j_r: float) -> tuple[float, float]:
    """The sigma = da/ds the jerk ellipse allows at state (b, a); (1, -1) when j_R alone is past it."""
    v = math.sqrt(max(b, 0.0))
    jr = 3.0 * kappa * v * a + dk * v * v * v
    q = 1.0 - (jr / j_r) ** 2
    if q < 0.0:
        return 1.0, -1.0
    if v < 1e-12:
        return -1e300, 1e300
    big_j = j_t * math.sqrt(q)
    c = kappa * kappa * v * v
    return c - big_j / v, c + big_j / v


@kernel
def _state_ok(b: float, a: float, sig: float, kappa: float, dk: float, limits: Any) -> int:
    """Whether state (b, a) with slope sig keeps v_max and both ellipses; else which it breaks."""
    if b > limits[0] * limits[0] * (1.0 + _TOL):
        return FAIL_W
    cap = accel_cap(kappa, b, limits[1], limits[2])
    if cap < 0.0 or abs(a) > cap * (1.0 + _TOL) + 1e-12:
        return FAIL_A
    lo, hi = jerk_interval(b, a, kappa, dk, limits[3], limits[4])
    slack = _TOL * (abs(sig) + 1.0)
    if sig < lo - slack or sig > hi + slack:
        return FAIL_J
    return OK


@kernel
def step_code(b: float, a: float, sig: float, h: float, i: int, geo: Any, w1: float, limits: Any) -> int:
    """Whether the step from node i with slope sig from state (b, a) keeps every constraint at its
    start, middle and end and ends under the bound w1; else which one it breaks first."""
    b1 = b + 2.0 * a * h + sig * h * h
    if b1 > w1 * (1.0 + _TOL) + 1e-15:
        return FAIL_W
    if b1 <= 0.0:
        return FAIL_STALL
    code = _state_ok(b1, a + sig * h, sig, geo[i + 1, 0], geo[i + 1, 2], limits)
    if code == OK:
        code = _state_ok(b + a * h + 0.25 * sig * h * h, a + 0.5 * sig * h, sig, geo[i, 3], geo[i, 4], limits)
    if code == OK:
        code = _state_ok(b, a, sig, geo[i, 0], geo[i, 1], limits)
    return FAIL_J if code == FAIL_A and b == 0.0 else code


@kernel
def _bounds_guess(b: float, a: float, sig: float, h: float, i: int, geo: Any, limits: Any) -> tuple[float, float]:
    """The sigma interval of the step's constraints evaluated at the states sig leads to, each end
    pulled in by _MARGIN of the interval so that the fixed point needs no exact convergence."""
    lo, hi = jerk_interval(b, a, geo[i, 0], geo[i, 1], limits[3], limits[4])
    for frac, kc, dc in ((1.0, 0, 2), (0.5, 3, 4)):
        x = frac * h
        bx = max(b + 2.0 * a * x + sig * x * x, 0.0)
        ax = a + sig * x
        row = i + 1 if frac == 1.0 else i
        lo1, hi1 = jerk_interval(bx, ax, geo[row, kc], geo[row, dc], limits[3], limits[4])
        cap = max(accel_cap(geo[row, kc], bx, limits[1], limits[2]), 0.0)
        lo, hi = max(lo, lo1, (-cap - a) / x), min(hi, hi1, (cap - a) / x)
    pull = _MARGIN * max(hi - lo, 0.0)
    return lo + pull, hi - pull


@kernel
def _iterate(b: float, a: float, h: float, i: int, geo: Any, lo: float, hi: float, limits: Any,
             low_end: bool) -> float:
    sig = lo if low_end else hi
    for _ in range(6):
        glo, ghi = _bounds_guess(b, a, sig, h, i, geo, limits)
        sig = min(max(lo, glo), hi) if low_end else max(min(hi, ghi), lo)
    return sig


@kernel
def choose(b: float, a: float, h: float, i: int, geo: Any, w1: float, cap_hi: float, limits: Any,
           brake: bool) -> tuple[int, float]:
    """The largest (brake False) or smallest (brake True) feasible slope of the step from node i,
    at most cap_hi; (failure code, 0) when none is."""
    lo, hi = jerk_interval(b, a, geo[i, 0], geo[i, 1], limits[3], limits[4])
    hi = min(hi, cap_hi, (w1 - b - 2.0 * a * h) / (h * h))
    if hi < lo:                                   # no slope keeps both the bound and the jerk
        code = step_code(b, a, lo, h, i, geo, w1, limits)
        return (code if code != OK else FAIL_W), 0.0
    end = _iterate(b, a, h, i, geo, lo, hi, limits, brake)
    code = step_code(b, a, end, h, i, geo, w1, limits)
    if code == OK:
        return OK, end
    # A feasible slope to bisect towards: the interval's other end, else its middle.
    other = _iterate(b, a, h, i, geo, lo, hi, limits, not brake)
    code_other = step_code(b, a, other, h, i, geo, w1, limits)
    if code_other != OK:
        mid = 0.5 * (end + other)
        if step_code(b, a, mid, h, i, geo, w1, limits) != OK:
            return (code_other if brake else code), 0.0
        other = mid
    bad, good = end, other
    for _ in range(_BISECT):
        mid = 0.5 * (bad + good)
        if step_code(b, a, mid, h, i, geo, w1, limits) == OK:
            good = mid
        else:
            bad = mid
    return OK, good


@kernel
def start_piece(a_t: float, j_t: float, h: float) -> tuple[float, float, float]:
    """From rest over the first step h: jerk j_t until a reaches a_t, then a_t; (b, a, time) at h."""
    t_a = a_t / j_t
    s_a = j_t * t_a**3 / 6.0
    if s_a >= h:
        t1 = (6.0 * h / j_t) ** (1.0 / 3.0)
        v1 = 0.5 * j_t * t1 * t1
        return v1 * v1, j_t * t1, t1
    v_a = 0.5 * j_t * t_a * t_a
    rest = h - s_a
    tau = (-v_a + math.sqrt(v_a * v_a + 2.0 * a_t * rest)) / a_t
    v1 = v_a + a_t * tau
    return v1 * v1, a_t, t_a + tau


@kernel
def accel_band(kappa: float, dk: float, b: float, limits: Any) -> tuple[float, float]:
    """The tangential accelerations the acceleration ellipse and the radial jerk alone allow at
    speed^2 b: |a| <= the ellipse's cap and |3 kappa v a + kappa' v^3| <= j_Rmax."""
    cap = accel_cap(kappa, b, limits[1], limits[2])
    if cap < 0.0:
        return 1.0, -1.0
    lo, hi = -cap, cap
    v = math.sqrt(max(b, 0.0))
    c = 3.0 * kappa * v
    if abs(c) > 1e-12:
        e1 = (-limits[4] - dk * v * v * v) / c
        e2 = (limits[4] - dk * v * v * v) / c
        lo, hi = max(lo, min(e1, e2)), min(hi, max(e1, e2))
    return lo, hi


@kernel
def envelope(h: Any, geo: Any, limits: Any, out: Any) -> None:
    """Step 1: the largest b = v^2 under v_max and the acceleration ellipse, by forward and backward
    passes from rest at both ends under the limit curve, written to out (n+1,). Both the limit
    curve and the passes also keep the radial jerk (eq. 7) alone within j_Rmax: at zero tangential
    acceleration |kappa'| v^3 <= j_Rmax, and the tangential acceleration inside what
    |3 kappa v a + kappa' v^3| <= j_Rmax leaves (step 2 then only has the tangential jerk to fit).
    Every limit here is taken _ENVELOPE_MARGIN inside the real one, so that step 2, which checks
    the real ones at each step's ends and middle, can run along this profile."""
    n = len(h)
    inner = limits * (1.0 - _ENVELOPE_MARGIN)
    v2 = inner[0] * inner[0]
    kappa = geo[:, 0]
    for i in range(n + 1):
        cap = v2
        if abs(kappa[i]) > 0.0:
            cap = min(cap, inner[2] / abs(kappa[i]))
        dk = max(abs(geo[i, 1]), abs(geo[i, 2]))
        if dk > 0.0:
            cap = min(cap, (inner[4] / dk) ** (2.0 / 3.0))
        out[i] = cap
    out[0] = 0.0
    out[n] = 0.0
    for i in range(n):                       # forward: the largest acceleration
        out[i + 1] = min(out[i + 1], _trapezoid(out[i], h[i], kappa[i], geo[i, 1], kappa[i + 1], geo[i + 1, 2],
                                                inner, 1.0))
    for i in range(n - 1, -1, -1):           # backward: the largest deceleration
        out[i] = min(out[i], _trapezoid(out[i + 1], h[i], kappa[i + 1], geo[i + 1, 2], kappa[i], geo[i, 1],
                                        inner, -1.0))


@kernel
def _trapezoid(b0: float, h: float, k0: float, dk0: float, k1: float, dk1: float, limits: Any, sign: float) -> float:
    """One step of a step-1 pass, implicit: the b1 = b0 + h (A0 + A1) with A the largest
    acceleration (sign 1, forward) or deceleration (sign -1, backward; dk is then the derivative
    along the pass, so its sign flips with the direction) at each end, found by bisection (the
    right side falls as b1 grows). The explicit step would zigzag along the limit curve, where
    the acceleration left goes to zero like a square root."""
    def best(kappa: float, dk: float, b: float) -> float:
        lo, hi = accel_band(kappa, dk, b, limits)
        return hi if sign > 0 else -lo

    a0 = best(k0, dk0, b0)
    lo, hi = max(b0 - 2.0 * h * limits[1], 0.0), b0 + 2.0 * h * limits[1]
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if mid - b0 - h * (a0 + best(k1, dk1, mid)) > 0.0:
            hi = mid
        else:
            lo = mid
    return float(max(lo, 0.0))


_THETA_BISECT = 20
# A repair has met the bound once its acceleration is within this (m/s^2) of the bound's or below.
_LANDING_A = 1e-6
# Within this fraction of the bound the sweep merges onto it instead of meeting it at full slope.
_NEAR = 1e-3
_MERGE_STEPS = 4.0
# A sweep has left its bound once this far below it (relative); it hands over where it runs on it
# again, to within _HANDOVER_GAP (relative) and its acceleration to within _HANDOVER_A (m/s^2).
_LEFT = 1e-4
_HANDOVER_GAP = 1e-6
_HANDOVER_A = 1e-4


@kernel
def _slope(i: int, b: float, a: float, h: Any, geo: Any, w: Any, aw: Any, limits: Any, delta: float) -> tuple[int, float]:
    """The sweep's slope at node i: the largest feasible one; on or just under the bound, the
    bound's own acceleration (plus what closes the gap smoothly) where feasible."""
    gap = w[i] - b
    if gap <= _NEAR * w[i] + 1e-15:
        # Close the gap over about _MERGE_STEPS steps at the bound's acceleration plus a little.
        target = aw[i + 1] + max(gap, 0.0) / (2.0 * _MERGE_STEPS * h[i])
        code, sig = choose(b, a, h[i], i, geo, w[i + 1], (target - a) / h[i], limits, False)
        if code == OK:
            return code, sig
    return choose(b, a, h[i], i, geo, w[i + 1], 1e300, limits, False)


@kernel
def _greedy(i: int, b: float, a: float, h: Any, geo: Any, w: Any, aw: Any, limits: Any, delta: float) -> tuple[int, float]:
    """`_slope`, except that meeting the bound much faster than it rises is a crossing (FAIL_W),
    repaired by a braking that lands on it with its acceleration rather than a kink the next steps
    would ring on."""
    code, sig = _slope(i, b, a, h, geo, w, aw, limits, delta)
    if code == OK and w[i] - b > delta * w[i] + 1e-15:
        b1 = b + 2.0 * a * h[i] + sig * h[i] * h[i]
        a1 = a + sig * h[i]
        # What the next step can take off the acceleration again without ringing: a quarter of
        # the jerk's reach over a step.
        spare = 0.25 * limits[3] * h[i] / math.sqrt(max(b1, 1e-12))
        if w[i + 1] - b1 <= delta * w[i + 1] + 1e-15 and a1 > aw[i + 1] + spare:
            return FAIL_W, sig
    return code, sig


@kernel
def _braking_outcome(b: float, a: float, h: float, i: int, geo: Any, limits: Any) -> int:
    """Why no braking step is feasible from (b, a): TOO_EARLY when the hardest braking the jerk
    allows stops the robot or decelerates past the acceleration ellipse (braking began too soon);
    otherwise (the bound, the ellipse's cap from above, the radial jerk) TOO_LATE."""
    lo = max(jerk_interval(b, a, geo[i, 0], geo[i, 1], limits[3], limits[4])[0], -1e6)
    b1 = b + 2.0 * a * h + lo * h * h
    if b1 <= 0.0:
        return TOO_EARLY
    cap = accel_cap(geo[i + 1, 0], b1, limits[1], limits[2])
    if cap >= 0.0 and a + lo * h < -cap and b + 2.0 * a * h - cap * h * h > 0.0:
        return TOO_EARLY
    return TOO_LATE


@kernel
def _maneuver(k: int, theta: float, f: int, typ: int, h: Any, geo: Any, w: Any, aw: Any, limits: Any,
              delta: float, b: Any, a: Any, i_end: int, tb: Any, ta: Any, ts: Any) -> tuple[int, int]:
    """Braking from node k (its step blended theta of the way from the sweep's slope to the
    braking one) into tb, ta, ts: (OK, the node where it ends past f) or (TOO_LATE or TOO_EARLY,
    the node where it failed)."""
    cg, sg = _slope(k, b[k], a[k], h, geo, w, aw, limits, delta)
    cb, sb = choose(b[k], a[k], h[k], k, geo, w[k + 1], 1e300, limits, True)
    if cb != OK:
        return _braking_outcome(b[k], a[k], h[k], k, geo, limits), k
    sig = sb if cg != OK else (1.0 - theta) * sg + theta * sb
    if step_code(b[k], a[k], sig, h[k], k, geo, w[k + 1], limits) != OK:
        return TOO_LATE, k
    tb[k], ta[k] = b[k], a[k]
    m = k
    while True:
        ts[m] = sig
        tb[m + 1] = tb[m] + 2.0 * ta[m] * h[m] + sig * h[m] * h[m]
        ta[m + 1] = ta[m] + sig * h[m]
        m += 1
        if typ == FAIL_W:
            if m >= f + 1 and ta[m] <= aw[m] + _LANDING_A:
                return OK, m
        elif m >= f + 2:
            return OK, m
        if m >= i_end:
            return TOO_LATE, m
        code, sig = choose(tb[m], ta[m], h[m], m, geo, w[m + 1], 1e300, limits, True)
        if code != OK:
            return _braking_outcome(tb[m], ta[m], h[m], m, geo, limits), m


@kernel
def _repair_node(f: int, typ: int, i0: int, h: Any, geo: Any, w: Any, aw: Any, limits: Any, delta: float, b: Any,
                 a: Any, i_end: int, tb: Any, ta: Any, ts: Any) -> int:
    """The latest node from which braking gets past the failure at f, or -1. Braking too late
    crosses the bound; too early it stalls or overdoes the deceleration, so the feasible nodes
    form a window: gallop back while too late, then bisect between too early and too late."""
    out, _ = _maneuver(f, 1.0, f, typ, h, geo, w, aw, limits, delta, b, a, i_end, tb, ta, ts)
    if out == OK:
        return f
    if out == TOO_EARLY:
        return -1
    late, early, ok, d = f, -1, -1, 1
    while ok < 0:
        k = max(i0, f - d)
        out, _ = _maneuver(k, 1.0, f, typ, h, geo, w, aw, limits, delta, b, a, i_end, tb, ta, ts)
        if out == OK:
            ok = k
        elif out == TOO_LATE:
            late = k
            if k == i0:
                return -1
            d *= 2
        else:
            early = k
            while late - early > 1 and ok < 0:
                mid = (late + early) // 2
                out, _ = _maneuver(mid, 1.0, f, typ, h, geo, w, aw, limits, delta, b, a, i_end, tb, ta, ts)
                if out == OK:
                    ok = mid
                elif out == TOO_LATE:
                    late = mid
                else:
                    early = mid
            if ok < 0:
                return -1
    while late - ok > 1:                       # the latest node that still works
        mid = (late + ok) // 2
        out, _ = _maneuver(mid, 1.0, f, typ, h, geo, w, aw, limits, delta, b, a, i_end, tb, ta, ts)
        if out == OK:
            ok = mid
        else:
            late = mid
    return ok


@kernel
def sweep(h: Any, geo: Any, w: Any, aw: Any, limits: Any, b: Any, a: Any, sig: Any,
          i0: int, i_end: int, stop_on_landing: bool, delta: float, tb: Any, ta: Any, ts: Any) -> tuple[int, int]:
    """Fill b, a (nodes) and sig (steps) from node i0 (its state given) to node i_end. Returns
    (OK, i_end); (LANDED, m) when stop_on_landing and, after leaving the bound, the sweep runs on
    it again at m; or (a failure code, node) when no repair was found."""
    i = i0
    left = False
    while i < i_end:
        code, s = _greedy(i, b[i], a[i], h, geo, w, aw, limits, delta)
        if code == OK:
            sig[i] = s
            b[i + 1] = b[i] + 2.0 * a[i] * h[i] + s * h[i] * h[i]
            a[i + 1] = a[i] + s * h[i]
            i += 1
            # Handed over only where the sweep, having left the bound, runs on it again with its
            # acceleration, so that the other sweep can go on from the bound there without a kink.
            gap = w[i] - b[i]
            if gap > _LEFT * w[i]:
                left = True
            elif stop_on_landing and left and gap <= _HANDOVER_GAP * w[i] + 1e-15 and abs(a[i] - aw[i]) <= _HANDOVER_A:
                return LANDED, i
            continue
        f, typ = i, code
        if typ != FAIL_W:
            return typ, f                    # the caller lowers the speed here (`frenet_profile`)
        k_ok = _repair_node(f, typ, i0, h, geo, w, aw, limits, delta, b, a, i_end, tb, ta, ts)
        if k_ok < 0:
            return typ, f
        lo, hi = 0.0, 1.0
        for _ in range(_THETA_BISECT):
            mid_t = 0.5 * (lo + hi)
            out, m = _maneuver(k_ok, mid_t, f, typ, h, geo, w, aw, limits, delta, b, a, i_end, tb, ta, ts)
            if out == OK:
                hi = mid_t
            else:
                lo = mid_t
        out, m = _maneuver(k_ok, hi, f, typ, h, geo, w, aw, limits, delta, b, a, i_end, tb, ta, ts)
        for j in range(k_ok, m):
            sig[j] = ts[j]
            b[j + 1] = tb[j + 1]
            a[j + 1] = ta[j + 1]
        i = m
        left = True
    return OK, i
