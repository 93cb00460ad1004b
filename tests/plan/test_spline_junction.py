"""The spline junction's rule for the lines the dialects without spline motion write
(`plan.spline_junction.line_flybys`)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.plan.junction import Junction
from robomax_py.plan.spline_junction import SplineVariant, choose, line_flybys
from robomax_py.plan.spline_moves import SplineMoves
from robomax_py.timing.trajectory import Segment


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


def _resting(seconds: float) -> Segment:
    """A segment of `seconds` s at rest (only its duration matters to the choice)."""
    t = np.array([0.0, seconds])
    q = np.zeros((2, 6))
    return Segment(t, q, q.copy(), q.copy())


@pytest.mark.parametrize(("spline", "lines", "native", "chosen"), [
    (0.50, 0.70, True, "spline"),      # KUKA runs the spline block itself: its time counts
    (0.50, 0.70, False, "flyby"),      # the others run its lines, slower than the fly-by (0.60 s)
    (0.50, 0.55, False, "spline"),     # ... kept where the lines beat the fly-by too
    (0.50, None, False, "flyby"),      # lines that could not be timed are not written
    (0.65, 0.55, True, "flyby"),       # the spline itself slower
])
def test_a_spline_is_chosen_only_where_the_controllers_own_program_gains(
        spline: float, lines: float | None, native: bool, chosen: str) -> None:
    junction = Junction([_resting(0.60)], 0.0, 0.0, 0)
    moves = SplineMoves(np.zeros((0, 4, 4)), np.zeros(0), np.zeros((0, 6)), (), 0.0, lines)
    variant = SplineVariant([_resting(spline)], moves, 0)
    _, choice = choose(junction, variant, native=native)
    assert choice.chosen == chosen
    assert choice.flyby_time == pytest.approx(0.60, abs=1e-12)
