"""The DP's compiled step against numpy's two passes (the definition): the same values to the bit
and the first index of the least, over ties and unreachable (inf) candidates; the (min, +) matrix
product against numpy's broadcast sums and their least."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.plan.min_plus import min_plus, min_plus_arg, min_plus_product
from robomax_py.plan.sequence import _Costs, best_choice


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 40), m=st.integers(1, 40), coarse=st.booleans())
def test_the_step_is_numpys_to_the_bit(seed: int, n: int, m: int, coarse: bool) -> None:
    rng = np.random.default_rng(seed)
    value, matrix, node = rng.uniform(0, 5, n), rng.uniform(0, 5, (n, m)), rng.uniform(0, 1, m)
    if coarse:                                  # few distinct values: ties down most columns
        value, matrix = np.round(value), np.round(matrix)
    matrix[rng.random((n, m)) < 0.2] = np.inf   # blocked moves
    value[rng.random(n) < 0.1] = np.inf         # candidates no tour reaches
    total = value[:, None] + matrix
    want = np.min(total, axis=0) + node
    out, arg = min_plus_arg(value, matrix, node)
    assert out.tobytes() == want.tobytes()
    assert min_plus(value, matrix, node).tobytes() == want.tobytes()
    np.testing.assert_array_equal(arg, np.argmin(total, axis=0))


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 30), p=st.integers(1, 12), m=st.integers(0, 30),
       coarse=st.booleans())
def test_the_product_is_numpys_to_the_bit(seed: int, n: int, p: int, m: int, coarse: bool) -> None:
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(0, 5, (n, p)), rng.uniform(0, 5, (p, m))
    if coarse:
        a, b = np.round(a), np.round(b)
    a[rng.random((n, p)) < 0.2] = np.inf        # legs no move can take
    b[rng.random((p, m)) < 0.2] = np.inf
    want = np.min(a[:, :, None] + b[None, :, :], axis=1)
    assert min_plus_product(a, b).tobytes() == want.tobytes()


def test_nan_costs_are_refused_before_the_dp() -> None:
    def edge(i: int, j: int) -> np.ndarray:
        return np.array([[np.nan, 1.0]])

    with pytest.raises(ValueError, match="NaN"):
        best_choice((0,), _Costs(edge, [np.zeros(2)]))
