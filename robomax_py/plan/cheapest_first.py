"""The entries of a cost matrix cheapest first, as `np.argsort(values, axis=None, kind="stable")`
orders them (ties by flat index), found a few at a time.

The sequencer walks a blocked spot pair's candidate pairs cheapest first and stops after a few
dozen checks (`straight_tries`); the whole sort of two spots' candidate pairs (a million entries
for two spots of a thousand candidates) cost more than the checks. `np.argpartition` picks the k
cheapest in linear time; only those are sorted, and the next k only when the walk gets past them.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from robomax_py._typing import FloatArray, IntArray

# Entries sorted at first; each further batch is this many times the last.
FIRST_BATCH = 64
GROWTH = 4


def cheapest_first(values: FloatArray, first: int = FIRST_BATCH) -> Iterator[int]:
    """Flat indices of `values` (no NaN) in `np.argsort(values, axis=None, kind="stable")`'s order."""
    flat = np.ravel(values)
    done, k = 0, max(1, first)
    while done < flat.size:
        batch = np.argsort(flat, kind="stable") if k >= flat.size else _smallest(flat, k)
        yield from batch[done:].tolist()
        done = len(batch)
        k *= GROWTH


def _smallest(flat: FloatArray, k: int) -> IntArray:
    """The first k of the stable order (0 < k < flat.size): every entry below the k-th least value,
    then the entries equal to it by index, as many as fill k."""
    bound = flat[np.argpartition(flat, k - 1)[k - 1]]
    below = np.flatnonzero(flat < bound)
    equal = np.flatnonzero(flat == bound)[:k - len(below)]
    picked = np.concatenate([below, equal])          # ascending index within each value
    return picked[np.argsort(flat[picked], kind="stable")]
