"""The seven-step quintic of Benko Loknar, Klančar and Blažič (eqs. 8-11) has the end poses, end
curvatures, curvature derivative at its start and tangent lengths it is built from, and curves
built so join as the paper joins them: curvature continuous, its derivative zero where a curve
starts."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from robomax_py.timing._common import TimingError
from robomax_py.timing.bezier_construct import (
    EndPose,
    construct,
    curvature,
    hodographs,
    straight,
)
from robomax_py.timing.quintic_chain import QuinticChain

# The construction is exact algebra: only rounding separates the built curve from its data.
EXACT = 1e-9

angles = st.floats(-math.pi, math.pi)
curvatures = st.floats(-1.5, 1.5)
lengths = st.floats(0.2, 2.0)


@settings(max_examples=60, deadline=None)
@given(st.floats(-5, 5), st.floats(-5, 5), angles, curvatures, st.floats(-5, 5), st.floats(-5, 5), angles,
       curvatures, lengths, lengths, st.floats(-2.0, 2.0))
def test_the_curve_has_the_ends_it_is_built_from(x0: float, y0: float, h0: float, k0: float, x5: float, y5: float,
                                                 h5: float, k5: float, d1: float, d5: float, dk0: float) -> None:
    assume(abs(math.sin(h5 - h0)) > 0.05)       # step 7's lines nearly parallel: P3 far away
    start, end = EndPose(x0, y0, h0, k0), EndPose(x5, y5, h5, k5)
    c = construct(start, end, d1, d5, dk0)
    np.testing.assert_allclose(c[0], start.point, atol=EXACT)
    np.testing.assert_allclose(c[5], end.point, atol=EXACT)
    assert abs(np.linalg.norm(c[1] - c[0]) - d1) < EXACT and abs(np.linalg.norm(c[5] - c[4]) - d5) < EXACT
    # eq. 8: P2 is d1/2 beyond P1 along the start heading
    assert abs(float(np.dot(c[2] - c[1], start.tangent)) - d1 / 2) < EXACT
    _, r1, _, _ = hodographs(c, np.array([0.0, 1.0]))
    headings = np.arctan2(r1[:, 1], r1[:, 0])
    for got, want in zip(headings, (h0, h5), strict=True):
        assert abs(math.remainder(float(got) - want, 2 * math.pi)) < EXACT
    kappa, dkappa_dlam, _ = curvature(c, np.array([0.0, 1.0]))
    scale = 1.0 + abs(k0) + abs(k5) + abs(dk0)
    assert abs(kappa[0] - k0) < EXACT * scale and abs(kappa[1] - k5) < EXACT * scale
    assert abs(dkappa_dlam[0] - dk0) < EXACT * scale * 10


def test_parallel_construction_lines_are_refused() -> None:
    with pytest.raises(TimingError, match="parallel"):
        construct(EndPose(0, 0, 0.0), EndPose(3, 1, 0.0), 0.5, 0.5)
    with pytest.raises(TimingError, match="tangent lengths"):
        construct(EndPose(0, 0, 0.0), EndPose(3, 1, 1.0), 0.0, 0.5)


def test_a_chain_built_the_papers_way_joins_with_continuous_curvature_and_flat_starts() -> None:
    """Straight, two curves meeting at a pose with curvature -0.7, straight: at every join the
    curvature agrees and its derivative is zero at the start of the curve after it."""
    meet = EndPose(0.5, 5.0, math.pi / 2, -0.7)
    chain = QuinticChain.of([straight([5.5, 3.5], [2.0, 3.5]),
                             construct(EndPose(2.0, 3.5, math.pi), meet, 0.6, 0.9),
                             construct(meet, EndPose(2.0, 6.5, 0.0), 0.5, 0.8),
                             straight([2.0, 6.5], [5.5, 6.5])])
    ends = [curvature(c, np.array([0.0, 1.0])) for c in chain.control]
    for left, right in itertools.pairwise(ends):
        assert abs(left[0][1] - right[0][0]) < EXACT
        assert abs(right[1][0]) < EXACT


def test_a_chain_whose_segments_do_not_meet_is_refused() -> None:
    with pytest.raises(TimingError, match="must start where"):
        QuinticChain.of([straight([0, 0], [1, 0]), straight([1, 1], [2, 1])])


def test_points_lie_at_their_arclength() -> None:
    """Points at arclengths s are that far along the curve: the polyline through many of them has
    the chain's length, and consecutive points are as far apart as their arclengths (to 1e-6 m)."""
    chain = QuinticChain.of([construct(EndPose(0, 0, 0.0), EndPose(2, 2, math.pi / 2, 0.3), 0.8, 0.8)])
    s = np.linspace(0.0, chain.length, 4001)
    p = chain.points(s)
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    assert abs(float(steps.sum()) - chain.length) < 1e-6
    np.testing.assert_allclose(steps, np.diff(s), rtol=1e-5)
