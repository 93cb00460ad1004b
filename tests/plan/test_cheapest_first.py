"""The cheapest-first walk against numpy's stable sort of the whole matrix (its definition):
the same indices in the same order, over ties, infinities and every batch size."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.plan.cheapest_first import cheapest_first


@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), rows=st.integers(1, 30), cols=st.integers(1, 30),
       levels=st.sampled_from([0, 2, 5]), first=st.integers(1, 70), take=st.integers(0, 1000))
def test_the_walk_is_the_stable_sort(seed: int, rows: int, cols: int, levels: int, first: int, take: int) -> None:
    rng = np.random.default_rng(seed)
    values = rng.uniform(0, 5, (rows, cols))
    if levels:                                   # few distinct values: long runs of ties
        values = np.round(values * levels / 5)
    values[rng.random((rows, cols)) < 0.2] = np.inf     # moves known impossible
    want = np.argsort(values, axis=None, kind="stable")
    got = list(itertools.islice(cheapest_first(values, first), take))
    assert got == want[:take].tolist()
    assert list(cheapest_first(values, first)) == want.tolist()


def test_an_empty_matrix_walks_nothing() -> None:
    assert list(cheapest_first(np.zeros((0, 3)))) == []
