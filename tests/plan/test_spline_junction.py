"""The spline junction's rule for the lines the dialects without spline motion write
(`plan.spline_junction.line_flybys`)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.plan.spline_junction import line_flybys


@st.composite
def points(draw: st.DrawFn) -> np.ndarray:
    n = draw(st.integers(3, 8))
    steps = draw(st.lists(st.tuples(*[st.floats(-0.2, 0.2)] * 3), min_size=n - 1, max_size=n - 1))
    return np.cumsum(np.vstack([np.zeros(3), np.array(steps)]), axis=0)


@settings(max_examples=60, deadline=None)
@given(points())
def test_line_blends_never_overlap_and_the_spot_stops(pts: np.ndarray) -> None:
    r = line_flybys(pts[1:], pts[0])
    chords = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assert r[-1] == 0.0 and np.all(r >= 0.0)
    # The blend at the end of chord j and the one at its start (the end of chord j - 1) share it.
    assert np.all(r[1:] + r[:-1] <= chords[1:] + 1e-12)
    assert np.all(r[:-1] <= 0.5 * chords[:-1])
