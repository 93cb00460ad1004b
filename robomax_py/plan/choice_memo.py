"""The exact candidate choice of one spot order (`sequence.best_choice`), remembered layer by layer
between calls, so that the sequencer's repeated choices for (nearly) the same order cost only the
layers whose costs changed.

The sequencer chooses the candidates of one order again and again: after every blocked move a round
re-chooses them for the same order (`Sequencer._repair`, up to 40 times a round), the next round's
order shares most of its prefix with the last, and the sequencer of the file's order re-chooses one
fixed order every round. Each choice is a DP over every layer (N spots of C candidates, N C^2
additions), while what was learnt between two calls changes the cost matrices of a few spot pairs
only. A layer is recomputed only where its spot pair, its cost matrix (the same object: the
sequencer's matrices are cached and replaced, never changed in place) or the values entering it
differ from the last call; a recomputed layer whose values come out bit for bit as before lets the
layers after it be reused again. The arithmetic is `best_choice`'s, so choices and costs are the
same bit for bit.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray, IntArray
from robomax_py.plan.sequence import (
    HOME,
    EdgeCosts,
    choice_for_order,
    dp_choice,
    dp_layer,
)


@dataclass(frozen=True, slots=True, eq=False)
class _Layer:
    prev: int               # the stop before (HOME for the first layer)
    spot: int
    # The cost matrix prev -> spot the layer was computed with, compared by identity; held weakly,
    # so that the memo keeps no matrix alive that the sequencer has dropped (one that is gone
    # cannot be the one asked with).
    matrix: weakref.ref[FloatArray]
    value: FloatArray       # (C_spot,) best cost of the tour so far ending at each candidate of spot
    arg: IntArray | None    # (C_spot,) the best candidate of prev for each of spot's (None: first layer)


def _same_bits(a: FloatArray, b: FloatArray) -> bool:
    return a.shape == b.shape and a.tobytes() == b.tobytes()


class ChoiceMemo:
    """`choice_for_order(order, edge, node)` for a fixed `edge` and `node`, reusing the layers of the
    last call that nothing changed (see the module docstring). `layers_computed` counts the layers
    actually computed (the rest were reused)."""

    def __init__(self, edge: EdgeCosts, node: Sequence[FloatArray]) -> None:
        self._edge = edge
        self._node = [np.asarray(c, dtype=float) for c in node]
        self._layers: list[_Layer] = []
        self.layers_computed = 0

    def __call__(self, order: Sequence[int]) -> tuple[tuple[int, ...], float]:
        if not order:
            return choice_for_order(order, self._edge, self._node)
        layers: list[_Layer] = []
        value: FloatArray | None = None
        inputs_same = True          # the values entering this layer are those of the last call's
        for k, spot in enumerate(order):
            prev = HOME if k == 0 else order[k - 1]
            matrix = np.asarray(self._edge(prev, spot), dtype=float)
            old = self._layers[k] if k < len(self._layers) else None
            if (old is not None and inputs_same and old.prev == prev and old.spot == spot
                    and old.matrix() is matrix):
                layers.append(old)
                value = old.value
                continue
            arg: IntArray | None = None
            if value is None:
                value = matrix[0] + self._node[spot]
            else:
                value, arg = dp_layer(value, matrix, self._node[spot])     # `best_choice`'s step
            self.layers_computed += 1
            assert value is not None
            layers.append(_Layer(prev, spot, weakref.ref(matrix), value, arg))
            inputs_same = old is not None and old.spot == spot and _same_bits(value, old.value)
        self._layers = layers
        assert value is not None
        final = value + np.asarray(self._edge(order[-1], HOME), dtype=float)[:, 0]
        back: list[IntArray] = []
        for layer in layers[1:]:
            assert layer.arg is not None         # every layer after the first comes from one
            back.append(layer.arg)
        return dp_choice(final, back)

