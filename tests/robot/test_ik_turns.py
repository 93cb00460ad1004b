"""Turn variants (q + 2 pi k inside the joint limits) and joint-limit filtering."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from robomax_py.robot.ik.turns import (
    LIMIT_SLACK,
    expand,
    filter_limits,
    turn_shifts,
    variant_of,
    wrap_to_pi,
)

DEG = np.pi / 180.0
KR_LOWER = np.array([-170, -190, -120, -350, -125, -350]) * DEG
KR_UPPER = np.array([170, 45, 156, 350, 125, 350]) * DEG


@pytest.mark.parametrize(
    ("lower_deg", "upper_deg", "shifts_deg"),
    [
        (-170, 170, [0]),
        (-350, 350, [0, -360, 360]),
        (-10, 350, [0, 360]),
        (-360, 360, [0, -360, 360]),
        (-180, 180, [0]),                       # exactly one turn: -180 and 180 are one solution
        (-540, 540, [0, -360, 360]),
        (-541, 541, [0, -360, 360, -720, 720]),
        (200, 300, [360]),                      # no overlap with (-180, 180]
    ],
)
def test_shifts_per_joint(lower_deg: float, upper_deg: float, shifts_deg: list[float]) -> None:
    variants = turn_shifts(np.array([lower_deg * DEG]), np.array([upper_deg * DEG]))
    assert_allclose(variants.shifts[:, 0] / DEG, shifts_deg, atol=1e-9)


def test_shift_table_order_and_count() -> None:
    variants = turn_shifts(KR_LOWER, KR_UPPER)
    assert variants.count == 2 * 3 * 3                        # A2 reaches -190, A4 and A6 +-350
    assert np.all(variants.shifts[0] == 0)
    # C order, last joint fastest, per joint 0, -2 pi, +2 pi.
    assert_allclose(variants.shifts[1] / (2 * np.pi), [0, 0, 0, 0, 0, -1])
    assert_allclose(variants.shifts[3] / (2 * np.pi), [0, 0, 0, -1, 0, 0])
    assert_allclose(variants.shifts[9] / (2 * np.pi), [0, -1, 0, 0, 0, 0])
    prismatic = turn_shifts(np.array([-10.0, -7.0]), np.array([10.0, 7.0]), revolute=np.array([False, True]))
    assert_allclose(prismatic.shifts[:, 0], 0.0)
    assert prismatic.count == 3


def test_expand_350_degree_joint_gets_both_turns() -> None:
    """A4 at +-350 deg: 100 deg also appears as -260 deg; 179 deg as -181 deg; 539 deg is out."""
    variants = turn_shifts(KR_LOWER, KR_UPPER)
    q = np.zeros((2, 6))
    q[0, 3] = 100 * DEG
    q[1, 3] = 179 * DEG
    q[:, 1] = -30 * DEG
    out, valid = expand(q, np.array([True, True]), variants)
    V = variants.count
    assert out.shape == (2 * V, 6) and valid.shape == (2 * V,)
    for b, want in ((0, [100, -260]), (1, [179, -181])):
        cols = np.flatnonzero(valid[b * V : (b + 1) * V]) + b * V
        got = sorted(np.round(out[cols, 3] / DEG, 9))
        assert sorted(set(got)) == sorted(want)
        assert_allclose(out[cols, 5], 0.0)     # A6 = 0: +-360 deg lies outside +-350 deg
    assert np.all(np.isnan(out[~valid]))


def test_expand_filters_limits_and_keeps_invalid_branches_invalid() -> None:
    variants = turn_shifts(KR_LOWER, KR_UPPER)
    q = np.array([[175 * DEG, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [np.nan] * 6])
    _out, valid = expand(q, np.array([True, True, False]), variants)
    V = variants.count
    assert not valid[:V].any()                 # A1 at 175 deg is beyond 170 and has no other turn
    assert valid[V : 2 * V].sum() == 1         # all zero: +-360 deg is outside every limit
    assert valid[V]                            # ... and the unshifted variant comes first
    assert not valid[2 * V :].any()


def test_expand_batch_axes_and_clamp() -> None:
    lower, upper = np.array([-1.0, -2.0]), np.array([1.0, 2.0])
    variants = turn_shifts(lower, upper)
    q = np.zeros((3, 4, 5, 2))
    q[..., 0] = 1.0 + LIMIT_SLACK / 2             # on the limit up to round-off: kept, clamped
    valid = np.ones((3, 4, 5), dtype=bool)
    out, ok = expand(q, valid, variants)
    assert out.shape == (3, 4, 5 * variants.count, 2)
    assert ok.all() and np.all(out[..., 0] == 1.0)


def test_filter_limits() -> None:
    q = np.array([[0.0, 0.0], [2.0, 0.0], [np.nan, 0.0]])
    valid = filter_limits(q, np.array([True, True, True]), np.array([-1.0, -1.0]), np.array([1.0, 1.0]))
    assert valid.tolist() == [True, False, False]


def test_wrap_to_pi_half_open_interval() -> None:
    x = np.array([np.pi, -np.pi, 3 * np.pi, -3 * np.pi, np.nextafter(np.pi, 4), 0.5, -7.0, 2 * np.pi - 1e-17])
    w = wrap_to_pi(x)
    assert np.all((w > -np.pi) & (w <= np.pi))
    assert_allclose(np.exp(1j * w), np.exp(1j * x), atol=1e-12)
    assert w[0] == np.pi and w[1] == np.pi


# Solutions as solvers return them: wrapped angles, exact limit values, signed zeros, NaN rows.
_ANGLE = st.one_of(st.floats(-np.pi, np.pi, allow_nan=False), st.sampled_from([-0.0, 0.0, np.pi, -np.pi + 1e-13]),
                   st.sampled_from([float(v) for v in (*KR_LOWER, *KR_UPPER)]), st.just(float("nan")))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.lists(_ANGLE, min_size=6, max_size=6), min_size=1, max_size=8),
       st.lists(st.booleans(), min_size=8, max_size=8), st.sampled_from(["kr", "ur", "one_sided"]), st.data())
def test_variant_of_is_the_expanded_column_bit_for_bit(rows: list[list[float]], valid: list[bool], arm: str,
                                                       data: st.DataObject) -> None:
    """A chosen variant of each solution is exactly expand's column for it: the same values (bit for
    bit: -0.0 and clamping included), the same NaN rows, the same validity."""
    lower, upper = {"kr": (KR_LOWER, KR_UPPER), "ur": (np.full(6, -2 * np.pi), np.full(6, 2 * np.pi)),
                    "one_sided": (np.array([-10, -190, -120, -10, -125, -350]) * DEG,
                                  np.array([350, 45, 156, 350, 125, 10]) * DEG)}[arm]
    variants = turn_shifts(lower, upper)
    q = np.array(rows)                                                       # (B, 6)
    ok = np.array(valid[:len(rows)]) & ~np.isnan(q).any(axis=1)
    v = np.array(data.draw(st.lists(st.integers(0, variants.count - 1), min_size=len(rows), max_size=len(rows))))
    table_q, table_valid = expand(q[None], ok[None], variants)              # (1, B * V, 6)
    columns = np.arange(len(rows)) * variants.count + v
    got_q, got_valid = variant_of(q, ok, variants, v)
    np.testing.assert_array_equal(got_valid, table_valid[0, columns])
    assert got_q.tobytes() == table_q[0, columns].tobytes()
