"""The exact DP of one order with its layers kept between calls (`plan.choice_memo.ChoiceMemo`): the
same choices and costs bit for bit as `choice_for_order`, recomputing only the layers whose costs
changed."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.plan.choice_memo import ChoiceMemo
from robomax_py.plan.sequence import HOME, choice_for_order


class _Matrices:
    """Cost matrices cached per spot pair and replaced (never changed in place) when a pair's costs
    change, as the sequencer's are."""

    def __init__(self, rng: np.random.Generator, sizes: list[int]) -> None:
        self.rng, self.sizes = rng, sizes
        self.table: dict[tuple[int, int], np.ndarray] = {}

    def _size(self, i: int) -> int:
        return 1 if i == HOME else self.sizes[i]

    def __call__(self, i: int, j: int) -> np.ndarray:
        got = self.table.get((i, j))
        if got is None:
            got = self.table[(i, j)] = self.rng.uniform(0.1, 1.0, size=(self._size(i), self._size(j)))
        return got

    def block(self, i: int, j: int) -> None:
        """A new matrix for the pair: its cheapest entry blocked (inf), as a blocked move makes it."""
        m = self(i, j).copy()
        m[np.unravel_index(int(np.argmin(m)), m.shape)] = np.inf
        self.table[(i, j)] = m


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(2, 9), steps=st.integers(1, 6))
def test_memo_matches_the_plain_dp_bit_for_bit(seed: int, n: int, steps: int) -> None:
    rng = np.random.default_rng(seed)
    edge = _Matrices(rng, [int(rng.integers(1, 5)) for _ in range(n)])
    node = [rng.uniform(0.5, 0.6, size=edge.sizes[i]) for i in range(n)]
    memo = ChoiceMemo(edge, node)
    order = tuple(int(s) for s in rng.permutation(n))
    for _ in range(steps):
        assert memo(order) == choice_for_order(order, edge, node)       # exact: tuples and float
        if rng.random() < 0.5:
            stops = (HOME, *order, HOME)
            k = int(rng.integers(len(stops) - 1))
            edge.block(stops[k], stops[k + 1])
        else:
            a, b = sorted(int(x) for x in rng.choice(n, size=2, replace=False))
            order = order[:a] + order[a:b + 1][::-1] + order[b + 1:]


def test_only_the_layers_after_a_changed_matrix_are_computed() -> None:
    rng = np.random.default_rng(3)
    n = 12
    edge = _Matrices(rng, [4] * n)
    node = [np.full(4, 0.5) for _ in range(n)]
    memo = ChoiceMemo(edge, node)
    order = tuple(range(n))
    memo(order)
    assert memo.layers_computed == n
    memo(order)                                   # nothing changed: nothing computed again
    assert memo.layers_computed == n
    edge.block(order[-2], order[-1])              # the last move's costs changed
    assert memo(order) == choice_for_order(order, edge, node)
    assert memo.layers_computed == n + 1
    edge.block(HOME, order[0])                    # the first: every layer after it may change
    assert memo(order) == choice_for_order(order, edge, node)
    assert n + 2 <= memo.layers_computed <= 2 * n + 1
