"""Timing: estimates, ruckig and toppra moves, trajectories, corner blends, Cartesian lines."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from robomax_py.robot import JointLimits, RobotModel
from robomax_py.timing import (
    SPEC_MAX_DT_S,
    GeometricPath,
    LinMoveError,
    Segment,
    TimingError,
    blend_corner,
    blend_join,
    blended_polyline_path,
    concatenate,
    dwell,
    evaluate,
    jerk_limited_time_estimate,
    line_path,
    path_move,
    polyline_distance,
    ptp_move,
    ptp_time_estimate,
    resample,
    spline_path,
    time_path,
)
from robomax_py.timing.blend import blend_chain

# Finite-difference limit checks allow this fraction over a limit (toppra enforces its constraints
# at grid points only; ruckig's samples are exact and use far less).
LIMIT_SLACK = 0.01
# ruckig's rest-to-rest duration vs the closed-form double-S (both exact): relative.
DOUBLE_S_RTOL = 1e-9
# toppra on a straight line vs the closed-form trapezoid: relative (measured ~1e-5: grid rounding).
TRAPEZOID_RTOL = 1e-4
# Moves start and end exactly at their targets: rad.
ENDPOINT_TOL_RAD = 1e-9
# Rest at the ends: rad/s.
REST_TOL = 1e-9
# A straight joint-space move stays on its line: rad.
LINE_TOL_RAD = 1e-9
# SPEC §5: the TCP within 0.1 mm of the straight line: m.
TCP_LINE_TOL_M = 1e-4
# TCP orientation error along a line: rad.
TCP_ROT_TOL_RAD = 1e-4
# Relative slack on the TCP speed measured by finite differences of FK positions.
TCP_SPEED_SLACK = 0.01
# Hermite interpolation of a 10 ms resampling vs the 4 ms original: rad.
RESAMPLE_TOL_RAD = 1e-6
# Times computed by sums of sample steps: s.
TIME_TOL_S = 1e-9
# Curvature of the blend at its joins with the (straight) legs: 1/rad (relative to 1/radius).
JOIN_CURVATURE_RTOL = 1e-6
# Blend curve within its radius of the corner: relative round-off.
RADIUS_RTOL = 1e-9
# Curvature is continuous: change between neighbouring samples (step h) at most this x h x max |dk/ds|.
CURVATURE_STEP_FACTOR = 2.0

N = 6


def _limits() -> JointLimits:
    """Industrial-arm-like limits: rad, rad/s, rad/s^2, rad/s^3 (hypothesis tests cannot take fixtures)."""
    return JointLimits(
        lower=np.full(N, -6.0),
        upper=np.full(N, 6.0),
        velocity=np.array([2.0, 2.0, 2.5, 3.0, 3.0, 3.5]),
        acceleration=np.array([5.0, 5.0, 6.0, 8.0, 8.0, 10.0]),
        jerk=np.array([50.0, 50.0, 60.0, 80.0, 80.0, 100.0]),
    )


def assert_within_limits(seg: Segment, limits: JointLimits, *, speed: float = 1.0, jerk: bool) -> None:
    """Samples and finite differences of q, qd (and qdd) within the limits plus LIMIT_SLACK."""
    dt = np.diff(seg.t)[:, None]
    v_max = limits.velocity * speed * (1 + LIMIT_SLACK)
    a_max = limits.acceleration * (1 + LIMIT_SLACK)
    assert np.all(np.abs(seg.qd) <= v_max)
    assert np.all(np.abs(seg.qdd) <= a_max)
    if len(seg.t) < 2:
        return
    assert np.all(np.abs(np.diff(seg.q, axis=0) / dt) <= v_max)
    assert np.all(np.abs(np.diff(seg.qd, axis=0) / dt) <= a_max)
    if jerk:
        assert np.all(np.abs(np.diff(seg.qdd, axis=0) / dt) <= limits.jerk * (1 + LIMIT_SLACK))
    assert np.all(seg.q >= limits.lower - LINE_TOL_RAD) and np.all(seg.q <= limits.upper + LINE_TOL_RAD)


joint_vectors = st.lists(st.floats(-2.5, 2.5), min_size=N, max_size=N).map(np.array)


# --- estimates ---------------------------------------------------------------------------------


@pytest.mark.parametrize("distance", [0.05, 0.5, 0.8, 3.0])   # triangle and trapezoid profiles
@pytest.mark.parametrize("joint", [0, 5])
def test_toppra_single_joint_matches_analytic_trapezoid(limits: JointLimits, distance: float, joint: int) -> None:
    q0 = np.zeros(N)
    q1 = q0.copy()
    q1[joint] = distance
    seg = time_path(line_path(q0, q1), limits)
    v, a = limits.velocity[joint], limits.acceleration[joint]
    want = distance / v + v / a if distance >= v * v / a else 2.0 * np.sqrt(distance / a)
    assert_allclose(seg.duration, want, rtol=TRAPEZOID_RTOL)
    assert_allclose(float(ptp_time_estimate(q0, q1, limits)), want, rtol=1e-12)


@settings(max_examples=40, deadline=None)
@given(q0=joint_vectors, q1=joint_vectors, speed=st.floats(0.1, 1.0))
def test_ruckig_straight_ptp_matches_double_s(q0: np.ndarray, q1: np.ndarray, speed: float) -> None:
    limits = _limits()
    seg = ptp_move(q0, q1, limits, speed)
    want = float(jerk_limited_time_estimate(q0, q1, limits, speed))
    assert_allclose(seg.duration, want, rtol=DOUBLE_S_RTOL, atol=TIME_TOL_S)


@pytest.mark.parametrize("distance", [0.001, 0.05, 0.4, 3.0])
def test_single_joint_double_s_closed_form(limits: JointLimits, distance: float) -> None:
    """ruckig's single-joint time equals the textbook double-S (Biagiotti & Melchiorri §3.4)."""
    q0, q1 = np.zeros(N), np.zeros(N)
    q1[2] = distance
    v, a, j = limits.velocity[2], limits.acceleration[2], limits.jerk[2]
    t_v = v / a + a / j if v * j >= a * a else 2 * np.sqrt(v / j)
    if distance >= v * t_v:
        want = t_v + distance / v
    elif distance >= 2 * a**3 / j**2:
        vp = a / 2 * (-a / j + np.sqrt((a / j) ** 2 + 4 * distance / a))
        want = 2 * (vp / a + a / j)
    else:
        want = 4 * (distance / (2 * j)) ** (1 / 3)
    assert_allclose(ptp_move(q0, q1, limits).duration, want, rtol=DOUBLE_S_RTOL)
    assert_allclose(float(jerk_limited_time_estimate(q0, q1, limits, straight=False)), want, rtol=1e-12)


def test_estimates_are_vectorised(limits: JointLimits, rng: np.random.Generator) -> None:
    q0 = rng.uniform(-2, 2, size=(3, 4, N))
    q1 = rng.uniform(-2, 2, size=(4, N))                      # broadcasts
    for fn in (ptp_time_estimate, jerk_limited_time_estimate):
        got = fn(q0, q1, limits)
        assert got.shape == (3, 4)
        for i, j in np.ndindex(3, 4):
            assert_allclose(got[i, j], fn(q0[i, j], q1[j], limits), rtol=1e-14)
        lower = fn(q0, q1, limits, straight=False)
        assert np.all(lower <= got * (1 + 1e-12))                # per-joint max is a lower bound
        assert_allclose(fn(q1, q1, limits), 0.0, atol=0.0)
        assert_allclose(fn(q0, q1, limits, 0.5), fn(q0, q1, dataclasses.replace(limits, velocity=limits.velocity * 0.5)))


def test_estimates_equal_the_whole_array_formula_bit_for_bit(limits: JointLimits, rng: np.random.Generator) -> None:
    # The estimates reduce joint by joint; the formula over the (..., n) array must give the same
    # floats (rankings and tie-breaks of the sequencer depend on them). Equal and near-equal
    # configurations included (differences at and below ZERO_MOVE count as none).
    from robomax_py.timing._common import ZERO_MOVE, scaled_limits
    from robomax_py.timing.estimate import _double_s_time, _trapezoid_time

    q0 = rng.uniform(-2, 2, size=(7, 1, N))
    q1 = rng.uniform(-2, 2, size=(1, 5, N))
    q1[0, 0] = q0[0, 0]
    q1[0, 1] = q0[1, 0] + ZERO_MOVE / 2
    for speed in (1.0, 0.3):
        lim = scaled_limits(limits, speed, 1.0)
        d = np.abs(q1 - q0)
        d = np.where(d > ZERO_MOVE, d, 0.0)
        r_v, r_a, r_j = d / lim.velocity, d / lim.acceleration, d / lim.jerk
        assert np.array_equal(ptp_time_estimate(q0, q1, limits, speed),
                              _trapezoid_time(r_v.max(axis=-1), r_a.max(axis=-1)))
        assert np.array_equal(ptp_time_estimate(q0, q1, limits, speed, straight=False),
                              _trapezoid_time(r_v, r_a).max(axis=-1))
        assert np.array_equal(jerk_limited_time_estimate(q0, q1, limits, speed),
                              _double_s_time(r_v.max(axis=-1), r_a.max(axis=-1), r_j.max(axis=-1)))
        assert np.array_equal(jerk_limited_time_estimate(q0, q1, limits, speed, straight=False),
                              _double_s_time(r_v, r_a, r_j).max(axis=-1))


# --- ruckig PTP ----------------------------------------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(q0=joint_vectors, q1=joint_vectors, speed=st.floats(0.2, 1.0), accel=st.floats(0.3, 1.0))
def test_ptp_move_respects_limits_and_is_synchronised(q0: np.ndarray, q1: np.ndarray, speed: float, accel: float) -> None:
    limits = _limits()
    seg = ptp_move(q0, q1, limits, speed, accel=accel)
    scaled = dataclasses.replace(limits, acceleration=limits.acceleration * accel, jerk=limits.jerk * accel)
    assert_within_limits(seg, scaled, speed=speed, jerk=True)
    assert_allclose(seg.q[0], q0, atol=ENDPOINT_TOL_RAD)
    assert_allclose(seg.q[-1], q1, atol=ENDPOINT_TOL_RAD)
    assert_allclose(seg.qd[[0, -1]], 0.0, atol=REST_TOL)
    # Synchronised on the straight line: every sample is q0 + f (q1 - q0) with one f for all joints.
    delta = q1 - q0
    if np.linalg.norm(delta) > 0:
        f = (seg.q - q0) @ delta / (delta @ delta)
        assert_allclose(seg.q, q0 + f[:, None] * delta, atol=LINE_TOL_RAD)
        assert np.all(np.diff(f) >= -LINE_TOL_RAD)               # monotone: all joints arrive together
        assert np.all(f[:-1] < 1.0)                               # nobody is there before the end


def test_ptp_move_passes_through_with_velocities(limits: JointLimits) -> None:
    q0 = np.array([0.0, 0.5, -0.3, 0.0, 1.0, 0.0])
    q1 = np.array([1.0, -0.2, 0.4, 1.5, 0.5, -1.0])
    v0 = np.array([0.5, 0.0, 0.2, -0.3, 0.0, 0.1])
    v1 = np.array([0.0, -0.4, 0.3, 0.5, -0.2, 0.0])
    seg = ptp_move(q0, q1, limits, v0=v0, v1=v1)
    assert_within_limits(seg, limits, jerk=True)
    assert_allclose(seg.q[[0, -1]], [q0, q1], atol=ENDPOINT_TOL_RAD)
    assert_allclose(seg.qd[[0, -1]], [v0, v1], atol=REST_TOL)
    # The segment that follows, starting at v1, joins it.
    nxt = ptp_move(q1, np.zeros(N), limits, v0=v1)
    assert concatenate([seg, nxt]).duration == pytest.approx(seg.duration + nxt.duration, abs=TIME_TOL_S)


def test_ptp_move_rejects_too_fast_boundary_velocity(limits: JointLimits) -> None:
    with pytest.raises(TimingError, match="exceeds"):
        ptp_move(np.zeros(N), np.ones(N), limits, 0.5, v0=np.full(N, 1.5))


def test_zero_ptp_move_is_one_sample(limits: JointLimits) -> None:
    seg = ptp_move(np.ones(N), np.ones(N), limits)
    assert seg.duration == 0.0 and len(seg.t) == 1


# --- trajectories --------------------------------------------------------------------------------


@pytest.mark.parametrize("duration", [0.0, 0.004, 0.5, 0.5013])
def test_dwell_is_exact(duration: float) -> None:
    q = np.linspace(-1, 1, N)
    seg = dwell(q, duration, label="s1")
    assert seg.duration == duration
    assert_allclose(seg.q, np.broadcast_to(q, seg.q.shape), atol=0.0)
    assert_allclose(seg.qd, 0.0, atol=0.0)
    assert seg.kind == "weld" and seg.label == "s1"


def _program(limits: JointLimits) -> list[Segment]:
    home = np.zeros(N)
    above = np.array([0.8, -0.4, 0.6, 0.2, 0.9, -0.3])
    spot = above + 0.02
    return [
        ptp_move(home, above, limits),
        ptp_move(above, spot, limits, 0.3, kind="approach", label="s1"),
        dwell(spot, 0.5, label="s1"),
        ptp_move(spot, above, limits, 0.3, kind="retract", label="s1"),
        ptp_move(above, home, limits),
    ]


def test_concatenate_and_resample(limits: JointLimits) -> None:
    segs = _program(limits)
    traj = concatenate(segs)
    assert traj.duration == pytest.approx(sum(s.duration for s in segs), abs=TIME_TOL_S)
    (weld,) = traj.phases_of("weld", "s1")
    assert weld.duration == pytest.approx(0.5, abs=TIME_TOL_S)
    held = traj.q[weld.i_start : weld.i_end + 1]
    assert_allclose(held, np.broadcast_to(segs[2].q[0], held.shape), atol=0.0)

    out = resample(traj)
    steps = np.diff(out.t)
    assert np.all(steps > 0) and np.all(steps <= SPEC_MAX_DT_S)
    assert out.t[0] == traj.t[0] and out.t[-1] == traj.t[-1]
    for p_old, p_new in zip(traj.phases, out.phases):
        assert (p_new.t_start, p_new.t_end) == (p_old.t_start, p_old.t_end)
        assert out.t[p_new.i_start] == p_new.t_start and out.t[p_new.i_end] == p_new.t_end
        assert_allclose(out.q[p_new.i_start], traj.q[p_old.i_start], atol=0.0)
    (weld_new,) = out.phases_of("weld")
    assert_allclose(out.qd[weld_new.i_start : weld_new.i_end + 1], 0.0, atol=0.0)
    # Interpolating the 10 ms samples (cubic Hermite) reproduces the dense original.
    back = evaluate(out, traj.t)
    assert_allclose(back.q, traj.q, atol=RESAMPLE_TOL_RAD)


def test_concatenate_rejects_a_gap(limits: JointLimits) -> None:
    a = ptp_move(np.zeros(N), np.ones(N), limits)
    b = dwell(np.ones(N) + 1e-3, 0.1)
    with pytest.raises(TimingError, match="does not continue"):
        concatenate([a, b])


def test_segment_checks_its_samples() -> None:
    t = np.array([0.0, 0.1, 0.1])
    z = np.zeros((3, N))
    with pytest.raises(TimingError, match="strictly increasing"):
        Segment(t=t, q=z, qd=z, qdd=z)
    with pytest.raises(TimingError, match="kind"):
        Segment(t=np.array([0.0, 0.1, 0.2]), q=z, qd=z, qdd=z, kind="fly")


# --- corner blends -------------------------------------------------------------------------------


def _curvature(path: GeometricPath, s: np.ndarray) -> np.ndarray:
    d1, d2 = path(s, 1), path(s, 2)
    n1 = np.linalg.norm(d1, axis=-1)
    cross = np.sqrt(np.maximum(n1**2 * np.sum(d2 * d2, axis=-1) - np.sum(d1 * d2, axis=-1) ** 2, 0.0))
    return np.asarray(cross / n1**3, dtype=float)


@settings(max_examples=50, deadline=None)
@given(
    a=st.lists(st.floats(-2, 2), min_size=3, max_size=3).map(np.array),
    c=st.lists(st.floats(-2, 2), min_size=3, max_size=3).map(np.array),
    b=st.lists(st.floats(-2, 2), min_size=3, max_size=3).map(np.array),
    radius=st.floats(0.01, 1.0),
)
@example(a=np.array([0.09375, 0.0, 0.0]), c=np.zeros(3), b=np.array([-1.0, 0.0, 0.0]), radius=1.0)   # straight through
def test_blend_corner_is_g2_and_within_radius(a: np.ndarray, c: np.ndarray, b: np.ndarray, radius: float) -> None:
    len_in, len_out = np.linalg.norm(c - a), np.linalg.norm(b - c)
    if min(len_in, len_out) < 0.05:
        return
    d_in, d_out = (c - a) / len_in, (b - c) / len_out
    if np.arccos(np.clip(d_in @ d_out, -1, 1)) > np.deg2rad(170):
        return
    corner = blend_corner(a, c, b, radius)
    path = corner.path
    h = corner.param_length
    # Joins: on the legs, unit tangent along them, zero curvature like the straight legs.
    assert_allclose(path(0.0), c - corner.radius * d_in, atol=1e-12)
    assert_allclose(path(h), c + corner.radius * d_out, atol=1e-12)
    assert_allclose(path(0.0, 1), d_in, atol=1e-12)
    assert_allclose(path(h, 1), d_out, atol=1e-12)
    assert _curvature(path, np.array([0.0, h])).max() <= JOIN_CURVATURE_RTOL / corner.radius
    # Curvature continuous inside: neighbouring samples differ by O(step).
    s = np.linspace(0, h, 2001)
    k = _curvature(path, s)
    dk = np.abs(np.diff(k))
    # Plus round-off: on a straight-through corner the curvature is 0 and its samples are noise of
    # the join check's size (JOIN_CURVATURE_RTOL / radius), not a jump.
    assert dk.max() <= CURVATURE_STEP_FACTOR * (s[1] - s[0]) * np.max(np.abs(np.gradient(k, s))) \
        + JOIN_CURVATURE_RTOL / corner.radius
    # Within the radius of the corner.
    assert np.max(np.linalg.norm(path(s) - c, axis=1)) <= corner.radius * (1 + RADIUS_RTOL)


# A blend's radius comes back as asked to this fraction: the cut is bisected to neighbouring floats.
CUT_RTOL = 1e-9


def test_a_chain_blends_at_the_radius_asked_wherever_the_grid_falls() -> None:
    """A corner between two straight moves, the first one just over twice the radius long: the
    radius is reached within the move's half, between its last grid step and the half. The blend
    is the radius asked for every length, not the half (up to one grid step, radius / 16, wider)
    for the lengths whose grid steps leave that stretch empty."""
    radius = 0.05
    used = []
    for length in np.linspace(2.0 * radius, 2.0 * radius * (1.0 + 1.5 / 16.0), 301):
        first = line_path(np.zeros(3), np.array([length, 0.0, 0.0]))
        second = line_path(np.array([length, 0.0, 0.0]), np.array([length, 1.0, 0.0]))
        used.append(float(blend_chain([first, second], [radius]).radii[0]))
    assert_allclose(used, radius, rtol=CUT_RTOL)


def test_blended_polyline_is_c2_at_every_join() -> None:
    w = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.5], [0, 1.5, 0.5], [0, 1.5, 0.5], [0.2, 0.0, 0.0]], dtype=float)
    path, radii = blended_polyline_path(w, 0.3)
    assert radii[0] == 0 and radii[-1] == 0 and np.all(radii[1:-1] > 0)
    inner = path.breaks[1:-1]
    eps = 1e-7
    for order in (0, 1, 2):
        assert_allclose(path(inner - eps, order), path(inner + eps, order), atol=1e-5)
    # Within each radius of the polyline.
    q = path.sample(0.001)
    assert polyline_distance(q, w[[0, 1, 2, 3, 5]]).max() <= 0.3           # the repeated waypoint dropped


def test_blend_join_matches_value_slope_and_curvature() -> None:
    first = line_path(np.zeros(3), np.array([1.0, 0.0, 0.0]))
    s = np.linspace(0, 1, 21)
    curve = np.stack([1.0 + s, np.sin(2 * s), 0.3 * s**2], axis=1)        # starts where `first` ends
    second = spline_path(s, curve)
    joined = blend_join(first, second, 0.2)
    assert_allclose(joined.start, first.start, atol=1e-12)
    assert_allclose(joined.end, second.end, atol=1e-12)
    inner = joined.breaks[1:-1]
    eps = 1e-7
    for order in (0, 1, 2):
        assert_allclose(joined(inner - eps, order), joined(inner + eps, order), atol=1e-4)
    seg = time_path(joined, _limits_3())
    assert seg.duration > 0 and np.all(np.abs(seg.qd[[0, -1]]) <= REST_TOL)


@pytest.fixture(scope="module")
def limits() -> JointLimits:
    return _limits()


def _limits_3() -> JointLimits:
    lim = _limits()
    return JointLimits(*(np.asarray(getattr(lim, f.name))[:3] for f in dataclasses.fields(lim)))


# --- toppra paths and path moves -----------------------------------------------------------------


def test_time_path_respects_limits_and_path_speed(limits: JointLimits) -> None:
    w = np.array([np.zeros(N), [1.0, 0.5, 0.0, 0.5, 0.2, 0.0], [1.0, -0.5, 0.3, 2.0, 0.1, -1.0]])
    path, _ = blended_polyline_path(w, 0.3)
    seg = time_path(path, limits, 0.8, accel=0.5)
    assert_within_limits(seg, dataclasses.replace(limits, acceleration=limits.acceleration * 0.5), speed=0.8, jerk=False)
    assert_allclose(seg.q[[0, -1]], w[[0, -1]], atol=ENDPOINT_TOL_RAD)
    cap = 0.4                       # rad/s along a line parameterised by arc length: |qd| = ds/dt
    line = line_path(w[0], w[2])
    slow = time_path(line, limits, path_speed_limit=lambda s: np.full(np.shape(s), cap))
    assert np.linalg.norm(slow.qd, axis=1).max() <= cap * (1 + LIMIT_SLACK)
    assert slow.duration >= np.linalg.norm(w[2] - w[0]) / cap


WAYPOINTS = np.array([
    np.zeros(N),
    [1.0, 0.5, 0.0, 0.5, 0.2, 0.0],
    [1.0, -0.5, 0.3, 2.0, 0.1, -1.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.5],
])


def test_path_move_stop_follows_the_polyline_exactly(limits: JointLimits) -> None:
    move = path_move(WAYPOINTS, limits, mode="stop")
    assert move.deviation <= LINE_TOL_RAD
    assert_within_limits(move.segment, limits, jerk=True)
    assert polyline_distance(move.segment.q, WAYPOINTS).max() <= LINE_TOL_RAD
    for w in WAYPOINTS:                                             # at rest at every waypoint
        k = int(np.argmin(np.linalg.norm(move.segment.q - w, axis=1)))
        assert_allclose(move.segment.q[k], w, atol=ENDPOINT_TOL_RAD)
        assert_allclose(move.segment.qd[k], 0.0, atol=REST_TOL)
    legs = sum(float(jerk_limited_time_estimate(a, b, limits)) for a, b in itertools.pairwise(WAYPOINTS))
    assert move.segment.duration == pytest.approx(legs, abs=1e-6)


@pytest.mark.parametrize("radius", [0.05, 0.2, 0.5])
def test_path_move_blend_stays_near_the_polyline_and_saves_time(limits: JointLimits, radius: float) -> None:
    move = path_move(WAYPOINTS, limits, mode="blend", blend_radius=radius)
    sharp = path_move(WAYPOINTS, limits, mode="blend", blend_radius=0.0)
    assert move.deviation <= radius and sharp.deviation <= LINE_TOL_RAD
    assert move.segment.duration < sharp.segment.duration
    assert_within_limits(move.segment, limits, jerk=False)
    assert polyline_distance(move.segment.q, WAYPOINTS).max() <= radius
    gaps = np.linalg.norm(np.diff(move.path, axis=0), axis=1)
    assert gaps.max() <= 0.005 + 1e-12
    assert_allclose(move.path[[0, -1]], WAYPOINTS[[0, -1]], atol=ENDPOINT_TOL_RAD)


@settings(max_examples=12, deadline=None)
@given(
    w=st.lists(joint_vectors, min_size=3, max_size=4).map(np.array),
    radius=st.floats(0.0, 0.6),
    mode=st.sampled_from(["blend", "jerk"]),
)
def test_path_moves_respect_limits_and_radius(w: np.ndarray, radius: float, mode: str) -> None:
    limits = _limits()
    if np.min(np.linalg.norm(np.diff(w, axis=0), axis=1)) < 1e-3:
        return
    move = path_move(w, limits, mode=mode, blend_radius=radius)  # type: ignore[arg-type]
    assert_within_limits(move.segment, limits, jerk=mode == "jerk")
    assert move.deviation <= radius + LINE_TOL_RAD
    assert_allclose(move.segment.q[[0, -1]], w[[0, -1]], atol=ENDPOINT_TOL_RAD)
    assert_allclose(move.segment.qd[[0, -1]], 0.0, atol=REST_TOL)


def test_path_move_stops_at_a_reversal(limits: JointLimits) -> None:
    a, b = np.zeros(N), np.full(N, 0.5)
    w = np.array([a, b, a + 0.1])                                   # turns back by ~180 deg
    move = path_move(w, limits, mode="blend", blend_radius=0.2)
    assert move.radii[1] == 0.0
    k = int(np.argmin(np.linalg.norm(move.segment.q - b, axis=1)))
    assert_allclose(move.segment.q[k], b, atol=ENDPOINT_TOL_RAD)
    assert_allclose(move.segment.qd[k], 0.0, atol=REST_TOL)


@pytest.mark.parametrize("radius", [0.05, 0.2, 0.5])
def test_path_move_jerk_flyby(limits: JointLimits, radius: float) -> None:
    move = path_move(WAYPOINTS, limits, mode="jerk", blend_radius=radius)
    stop = path_move(WAYPOINTS, limits, mode="stop")
    assert_within_limits(move.segment, limits, jerk=True)
    assert move.deviation <= radius
    assert move.segment.duration <= stop.segment.duration + TIME_TOL_S
    for k, w in enumerate(WAYPOINTS):                              # off the polyline only near corners
        if move.radii[k] > 0:
            near = np.linalg.norm(move.path - w, axis=1) <= move.radii[k] * (1 + RADIUS_RTOL)
            assert np.any(near)
    far = np.all(np.linalg.norm(move.path[:, None] - WAYPOINTS[None], axis=2) > radius + 1e-9, axis=1)
    assert polyline_distance(move.path[far], WAYPOINTS).max(initial=0.0) <= 1e-6
    assert_allclose(move.segment.qd[[0, -1]], 0.0, atol=REST_TOL)
    if radius == 0.5:
        assert move.segment.duration < 0.95 * stop.segment.duration


# --- Cartesian lines on a UR10 -------------------------------------------------------------------


@pytest.fixture(scope="module")
def ur10() -> RobotModel:
    from robomax_py.io.ik_params import params_from_mapping
    from robomax_py.io.robot import package_share_dirs, urdf_package_dirs
    from robomax_py.robot import load_robot, mount_tool
    from robomax_py.spec import RobotSpec
    from robomax_py.transforms import pose_matrix

    shares = [d / "example-robot-data/robots/ur_description/urdf/ur10_robot.urdf" for d in package_share_dirs()]
    urdf = next((p for p in shares if p.is_file()), None)
    if urdf is None:
        pytest.skip("example-robot-data's ur10_robot.urdf is not installed")
    params = params_from_mapping(
        "ur", {"d1": 0.1273, "a2": -0.612, "a3": -0.5723, "d4": 0.163941, "d5": 0.1157, "d6": 0.0922, "base_rpy": [0, 0, 180]}
    )
    spec = RobotSpec(
        name="ur10", source=urdf, urdf=urdf, flange="tool0", ik_solver="ur", ik_params=params, acceleration=None, jerk=None,
        package_dirs=urdf_package_dirs(urdf, urdf),
    )
    return mount_tool(load_robot(spec), pose_matrix([0.0, 0.0, 0.2], [0.0, 0.0, 0.0]))


Q_UR = np.array([0.3, -1.2, 1.5, -1.9, -1.5, 0.4])


def _branch_of(robot: RobotModel, q: np.ndarray) -> int:
    from robomax_py.robot import fk_tcp
    from robomax_py.robot.solve import solve_all

    table = solve_all(robot, fk_tcp(robot, q)[None])
    err = np.where(table.valid[0], np.max(np.abs(table.q[0] - q), axis=1), np.inf)
    return int(np.argmin(err))


@pytest.mark.parametrize("offset", [[0.0, 0.0, -0.03], [0.25, -0.1, 0.15]])
def test_lin_move_keeps_the_tcp_on_the_line(ur10: RobotModel, offset: list[float]) -> None:
    from robomax_py.robot import fk_tcp
    from robomax_py.timing import lin_move

    T0 = fk_tcp(ur10, Q_UR)
    T1 = T0.copy()
    T1[:3, 3] += np.asarray(offset)
    tcp_speed = 0.25
    seg = lin_move(ur10, T0, T1, _branch_of(ur10, Q_UR), ur10.limits, tcp_speed, q_start=Q_UR, label="s1")
    assert_allclose(seg.q[0], Q_UR, atol=ENDPOINT_TOL_RAD)
    assert_allclose(seg.qd[[0, -1]], 0.0, atol=REST_TOL)
    assert_within_limits(seg, ur10.limits, jerk=False)
    T = fk_tcp(ur10, seg.q)
    p = T[:, :3, 3]
    d = T1[:3, 3] - T0[:3, 3]
    e = d / np.linalg.norm(d)
    along = (p - T0[:3, 3]) @ e
    off_line = np.linalg.norm(p - T0[:3, 3] - along[:, None] * e, axis=1)
    assert off_line.max() <= TCP_LINE_TOL_M
    assert along.min() >= -TCP_LINE_TOL_M and along.max() <= np.linalg.norm(d) + TCP_LINE_TOL_M
    assert_allclose(p[-1], T1[:3, 3], atol=TCP_LINE_TOL_M)
    assert_allclose(T[:, :3, :3], np.broadcast_to(T0[:3, :3], T[:, :3, :3].shape), atol=1e-6)   # no rotation asked
    tcp_v = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(seg.t)
    assert tcp_v.max() <= tcp_speed * (1 + TCP_SPEED_SLACK)


def test_lin_move_slerps_the_orientation(ur10: RobotModel) -> None:
    """Position and orientation move together: the rotation matches the slerp at the position's fraction."""
    from scipy.spatial.transform import Rotation

    from robomax_py.robot import fk_tcp
    from robomax_py.timing import lin_move
    from robomax_py.transforms import rotation_angle

    T0 = fk_tcp(ur10, Q_UR)
    T1 = T0.copy()
    T1[:3, 3] += [0.05, 0.02, -0.04]
    T1[:3, :3] = T0[:3, :3] @ Rotation.from_rotvec([0.2, -0.1, 0.4]).as_matrix()
    omega = 0.5                                                       # rad/s
    seg = lin_move(ur10, T0, T1, _branch_of(ur10, Q_UR), ur10.limits, 1.0, tcp_angular_speed=omega, q_start=Q_UR)
    T = fk_tcp(ur10, seg.q)
    d = T1[:3, 3] - T0[:3, 3]
    u = (T[:, :3, 3] - T0[:3, 3]) @ d / (d @ d)
    rotvec = Rotation.from_matrix(T0[:3, :3].T @ T1[:3, :3]).as_rotvec()
    R_want = T0[:3, :3] @ Rotation.from_rotvec(u[:, None] * rotvec).as_matrix()
    assert rotation_angle(T[:, :3, :3], R_want).max() <= TCP_ROT_TOL_RAD
    assert rotation_angle(T[-1, :3, :3], T1[:3, :3]) <= TCP_ROT_TOL_RAD
    angles = rotation_angle(T[:-1, :3, :3], T[1:, :3, :3]) / np.diff(seg.t)
    assert angles.max() <= omega * (1 + TCP_SPEED_SLACK)


def test_lin_move_reports_leaving_the_branch(ur10: RobotModel) -> None:
    """A branch column that jumps (here: faked beyond 40 % of the line) is found by bisection."""
    from robomax_py.robot import fk_tcp
    from robomax_py.robot.solve import solve_all
    from robomax_py.timing import lin_path

    k = _branch_of(ur10, Q_UR)
    T0 = fk_tcp(ur10, Q_UR)
    T1 = T0.copy()
    T1[:3, 3] += [0.0, 0.0, -0.05]
    z_jump = T0[2, 3] - 0.02

    def jumping_ik(robot: RobotModel, T: np.ndarray) -> object:
        table = solve_all(robot, T)
        q = np.array(table.q)
        valid = np.zeros_like(table.valid)
        valid[..., k] = table.valid[..., k]
        q[..., k, 0] += np.where(T[..., 2, 3] < z_jump, 0.5, 0.0)
        return dataclasses.replace(table, q=q, valid=valid)

    result = lin_path(ur10, T0, T1, k, ik=jumping_ik)
    assert not result.ok and result.reason == "discontinuous"
    assert result.fraction == pytest.approx(0.4, abs=1e-3)
    with pytest.raises(LinMoveError, match="discontinuous"):
        from robomax_py.timing import lin_move

        lin_move(ur10, T0, T1, k, ur10.limits, 0.1, ik=jumping_ik)


def test_lin_path_reports_unreachable(ur10: RobotModel) -> None:
    from robomax_py.robot import fk_tcp
    from robomax_py.timing import lin_path

    T0 = fk_tcp(ur10, Q_UR)
    T1 = T0.copy()
    T1[:3, 3] += [1.0, 0.0, 0.0]                 # leaves the branch's reach after ~0.37 m
    result = lin_path(ur10, T0, T1, _branch_of(ur10, Q_UR))
    assert not result.ok and result.reason == "unreachable"
    assert 0.0 < result.fraction < 1.0


def test_time_path_phases_cuts_the_same_motion(limits: JointLimits) -> None:
    from robomax_py.timing.topp import time_path_phases

    w = np.array([[0.0] * N, [0.5] * N, [0.5, 1.0] + [0.3] * (N - 2)])
    path, _ = blended_polyline_path(w, 0.2)
    whole = time_path(path, limits)
    cuts = np.array([0.0, 0.3 * path.length, 0.3 * path.length, 0.8 * path.length, path.length])
    parts = time_path_phases(path, limits, cuts, [("move", "a"), ("move", "empty"), ("detour", "b"), ("move", "c")])
    assert [p.kind for p in parts] == ["move", "move", "detour", "move"]
    assert parts[1].duration == 0.0
    joined = concatenate(parts)                      # raises if any join is off in position or speed
    assert_allclose(joined.duration, whole.duration, rtol=1e-12)
    assert_allclose(joined.q[-1], w[-1], atol=1e-12)
    assert [p.label for p in joined.phases] == ["a", "empty", "b", "c"]
