"""The move-time estimates give exactly the floats of their defining formula.

The sequencer ranks candidate pairs and breaks ties by these estimates, so a faster evaluation
(Python floats for one move, reused buffers for matrices) must not change a single bit: the
reference below is the formula of `robomax_py.timing.estimate`'s docstring over whole (..., n)
arrays, written independently of the module.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from robomax_py.robot import JointLimits
from robomax_py.timing import (
    TimingError,
    jerk_limited_time_estimate,
    polyline_time_estimate,
    ptp_time_estimate,
)
from robomax_py.timing._common import ZERO_MOVE
from robomax_py.timing.estimate import _double_s_time

# (q0 shape, q1 shape) for n joints: single moves in every spelling, paired rows, and the
# broadcast candidate matrices the sequencer ranks.
SHAPES: dict[str, Callable[[int, int, int], tuple[tuple[int, ...], tuple[int, ...]]]] = {
    "single": lambda k, m, n: ((n,), (n,)),
    "single_row": lambda k, m, n: ((1, n), (1, n)),
    "row_vs_single": lambda k, m, n: ((1, 1, n), (n,)),
    "rows": lambda k, m, n: ((k, n), (k, n)),
    "row_to_many": lambda k, m, n: ((1, n), (m, n)),
    "matrix": lambda k, m, n: ((k, 1, n), (1, m, n)),
    "column": lambda k, m, n: ((k, 1, n), (1, 1, n)),
}


def _reference_ratios(q0: np.ndarray, q1: np.ndarray, lim: JointLimits, speed: float,
                      accel: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d = np.abs(q1 - q0)
    d = np.where(d > ZERO_MOVE, d, 0.0)
    return d / (lim.velocity * speed), d / (lim.acceleration * accel), d / (lim.jerk * accel)


def _reference_trapezoid(r_v: np.ndarray, r_a: np.ndarray) -> np.ndarray:
    # Cruise iff r_a < r_v^2: T = r_v + r_a / r_v, else the triangle 2 sqrt(r_a).
    with np.errstate(divide="ignore", invalid="ignore"):
        out: np.ndarray = np.where(r_a < r_v * r_v, r_v + r_a / r_v, 2.0 * np.sqrt(r_a))
    return out


@st.composite
def cases(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, JointLimits, float, float]:
    n = draw(st.integers(1, 7))
    kind = draw(st.sampled_from(sorted(SHAPES)))
    s0, s1 = SHAPES[kind](draw(st.integers(1, 9)), draw(st.integers(1, 9)), n)
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    q0 = rng.uniform(-3.0, 3.0, size=s0)
    q1 = rng.uniform(-3.0, 3.0, size=s1)
    # Some joints do not move, some by at most ZERO_MOVE (counted as none), some just above it.
    base = np.broadcast_to(q0, np.broadcast_shapes(s0, s1))[tuple(slice(0, x) for x in s1)]
    pick = rng.integers(0, 5, size=s1)
    tiny = rng.choice([0.0, ZERO_MOVE / 2, -ZERO_MOVE, ZERO_MOVE * 1.5], size=s1)
    q1 = np.where(pick == 0, base, np.where(pick == 1, base + tiny, q1))
    limits = JointLimits(lower=-np.full(n, 4.0), upper=np.full(n, 4.0), velocity=rng.uniform(0.05, 10.0, n),
                         acceleration=rng.uniform(0.1, 60.0, n), jerk=rng.uniform(1.0, 900.0, n))
    speed = draw(st.sampled_from([1.0, 0.5, 0.1]) | st.floats(0.01, 1.0))
    accel = draw(st.sampled_from([1.0, 0.3]) | st.floats(0.01, 1.0))
    return q0, q1, limits, speed, accel


def _near_still_matrix() -> tuple[np.ndarray, np.ndarray, JointLimits, float, float]:
    # Candidate matrix with coinciding pairs, a pair apart by at most ZERO_MOVE in every joint,
    # and one where a slow joint's sub-ZERO_MOVE difference would outweigh a fast joint's move.
    rng = np.random.default_rng(3)
    q0 = rng.uniform(-2.0, 2.0, size=(4, 1, 3))
    q1 = rng.uniform(-2.0, 2.0, size=(1, 5, 3))
    q1[0, 0] = q0[0, 0]
    q1[0, 1] = q0[1, 0] + np.array([ZERO_MOVE / 2, -ZERO_MOVE, 0.0])
    q1[0, 2] = q0[2, 0] + np.array([ZERO_MOVE / 2, 1.5 * ZERO_MOVE, 0.0])
    limits = JointLimits(lower=-np.full(3, 4.0), upper=np.full(3, 4.0), velocity=np.array([0.05, 10.0, 2.0]),
                         acceleration=np.array([0.1, 50.0, 9.0]), jerk=np.full(3, 100.0))
    return q0, q1, limits, 1.0, 1.0


@settings(max_examples=300, deadline=None)
@given(case=cases())
@example(case=(np.zeros(6), np.zeros(6), JointLimits(-np.ones(6), np.ones(6), np.ones(6), np.ones(6), np.ones(6)),
               1.0, 1.0))
@example(case=_near_still_matrix())
def test_estimates_equal_the_formula_bit_for_bit(case: tuple[np.ndarray, np.ndarray, JointLimits, float, float]) -> None:
    q0, q1, limits, speed, accel = case
    r_v, r_a, r_j = _reference_ratios(q0, q1, limits, speed, accel)
    want = {True: _reference_trapezoid(r_v.max(axis=-1), r_a.max(axis=-1)),
            False: _reference_trapezoid(r_v, r_a).max(axis=-1)}
    want_jerk = {True: _double_s_time(r_v.max(axis=-1), r_a.max(axis=-1), r_j.max(axis=-1)),
                 False: _double_s_time(r_v, r_a, r_j).max(axis=-1)}
    for straight in (True, False):
        got = ptp_time_estimate(q0, q1, limits, speed, accel=accel, straight=straight)
        assert isinstance(got, np.ndarray) and got.dtype == np.float64
        assert got.shape == want[straight].shape
        assert np.array_equal(got, want[straight])
        got_jerk = jerk_limited_time_estimate(q0, q1, limits, speed, accel=accel, straight=straight)
        assert np.array_equal(got_jerk, want_jerk[straight])
    if q0.ndim == q1.ndim == 2 and len(q0) > 1:
        assert polyline_time_estimate(q0, limits, speed) == float(np.sum(_reference_trapezoid(
            *(r.max(axis=-1) for r in _reference_ratios(q0[:-1], q0[1:], limits, speed, 1.0)[:2]))))


def test_changed_limits_are_not_served_from_before() -> None:
    # The scaled limits are remembered by value: the same object with other numbers, or other
    # overrides, give the other time.
    limits = JointLimits(-np.ones(2), np.ones(2), np.array([1.0, 2.0]), np.array([4.0, 4.0]), np.ones(2) * 50)
    q0, q1 = np.zeros(2), np.array([0.5, 0.0])
    first = float(ptp_time_estimate(q0, q1, limits))
    limits.velocity[0] = 0.5
    assert float(ptp_time_estimate(q0, q1, limits)) > first
    assert float(ptp_time_estimate(q0, q1, limits, 0.5)) > float(ptp_time_estimate(q0, q1, limits))
    with pytest.raises(TimingError):
        ptp_time_estimate(q0, q1, limits, 0.0)


def test_the_compiled_estimate_is_compiled_once_for_writable_and_read_only_configurations() -> None:
    """Candidates and roadmap nodes come read-only, other configurations writable: numba compiles
    a kernel per array type, so the estimate hands its kernel one type (read-only views) and the
    first plan compiles it once (about 0.25 s each)."""
    from robomax_py.timing._estimate_kernels import straight_times

    limits = JointLimits(lower=np.full(6, -3.0), upper=np.full(6, 3.0), velocity=np.full(6, 2.0),
                         acceleration=np.full(6, 8.0), jerk=np.full(6, 80.0))
    rng = np.random.default_rng(3)
    many = rng.uniform(-1, 1, (5, 6))
    # One configuration against many: its transpose is contiguous already, and was passed as it came.
    one = rng.uniform(-1, 1, (1, 6))
    one.flags.writeable = False
    ptp_time_estimate(many, many[::-1], limits)
    ptp_time_estimate(many[:, None, :], many[None, :, :], limits)
    ptp_time_estimate(one[:, None, :], many[None, :, :], limits)
    ptp_time_estimate(many[:, None, :], one[None, :, :], limits)
    assert len(straight_times.signatures) == 1
