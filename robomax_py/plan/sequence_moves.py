"""The moves of the order search of `plan.sequence`: a tour under construction as seam blocks, every
order one move away (Or-opt and 2-opt within free seams, seam swaps, seam-level 2-opt) and the
random kick a stalled search restarts from."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

# Or-opt moves a run at most this many positions: spots of a seam lie along a line, far moves are
# rarely good and are still reachable through 2-opt and perturbations; keeps neighbourhoods O(n^2).
OR_OPT_WINDOW = 6

# A tour under construction: seams in visiting order, each (seam id, its spots in visiting order).
Blocks = list[tuple[int, tuple[int, ...]]]


def _flatten(blocks: Blocks) -> tuple[int, ...]:
    return tuple(s for _, block in blocks for s in block)


class _Moves:
    """The orders one move away from `origin`, kept compactly: for a move within seam b the new
    order of that seam's spots (a row of `local[b]`), else the whole new blocks (seam moves). Flat
    orders and blocks are built on demand: a descent looks at a few of its thousands of moves."""

    def __init__(self, origin: Blocks) -> None:
        self.origin = origin
        self.parts: list[tuple[int, np.ndarray]] = []      # (block index, (M_b, n_b) new block orders)
        self.whole: list[Blocks] = []                       # seam moves, after every block move
        self.n_local = 0

    def __len__(self) -> int:
        return self.n_local + len(self.whole)

    def _locate(self, k: int) -> tuple[int, np.ndarray] | Blocks:
        if k >= self.n_local:
            return self.whole[k - self.n_local]
        for b, rows in self.parts:
            if k < len(rows):
                return b, rows[k]
            k -= len(rows)
        raise IndexError(k)  # pragma: no cover

    def blocks(self, k: int) -> Blocks:
        where = self._locate(k)
        if isinstance(where, list):
            return where
        b, row = where
        return self.origin[:b] + [(self.origin[b][0], tuple(row.tolist()))] + self.origin[b + 1:]

    def flat(self, k: int) -> tuple[int, ...]:
        return _flatten(self.blocks(k))

    def rows(self) -> np.ndarray:
        """(len, S) every move's flat order, in move order (for the bounds; not kept)."""
        flats = [block for _, block in self.origin]
        out = []
        for b, rows in self.parts:
            prefix = np.array([s for f in flats[:b] for s in f], dtype=np.int64)
            suffix = np.array([s for f in flats[b + 1:] for s in f], dtype=np.int64)
            out.append(np.concatenate([np.broadcast_to(prefix, (len(rows), len(prefix))), rows,
                                       np.broadcast_to(suffix, (len(rows), len(suffix)))], axis=1))
        if self.whole:
            # Seam moves rearrange whole blocks: each row joined from the blocks' arrays (made once
            # per block order), not flattened spot by spot (seams^2 moves of N spots each).
            arrays: dict[tuple[int, ...], np.ndarray] = {}

            def array(block: tuple[int, ...]) -> np.ndarray:
                got = arrays.get(block)
                if got is None:
                    got = arrays[block] = np.asarray(block, dtype=np.int64)
                return got

            out.append(np.stack([np.concatenate([array(block) for _, block in w]) for w in self.whole]))
        return np.concatenate(out) if out else np.zeros((0, 0), dtype=np.int64)


_MOVE_TABLES: dict[int, np.ndarray] = {}


def _move_table(n: int) -> np.ndarray:
    """(M, n) the new positions of every distinct move within a free seam of n spots: 2-opt
    (reverse positions i..j-1), then Or-opt (a run of 1-3 spots moved at most OR_OPT_WINDOW places,
    both ways round); each new order once, first occurrence first; the unchanged order is no move.
    The same for every seam of n spots, so made once per n."""
    got = _MOVE_TABLES.get(n)
    if got is not None:
        return got
    pos = tuple(range(n))
    made: list[tuple[int, ...]] = []
    for i in range(n):
        for j in range(i + 2, n + 1):
            made.append(pos[:i] + pos[i:j][::-1] + pos[j:])
    for length in (1, 2, 3):
        for i in range(n - length + 1):
            run = pos[i:i + length]
            rest = pos[:i] + pos[i + length:]
            for k in range(max(0, i - OR_OPT_WINDOW), min(len(rest), i + OR_OPT_WINDOW) + 1):
                if k == i:
                    continue
                for piece in (run, run[::-1]) if length > 1 else (run,):
                    made.append(rest[:k] + piece + rest[k:])
    fresh = [new for new in dict.fromkeys(made) if new != pos]
    table = np.array(fresh, dtype=np.int64).reshape(len(fresh), n)
    _MOVE_TABLES[n] = table
    return table


def _neighbours(blocks: Blocks, ordered: Sequence[bool]) -> _Moves:
    """Every order one move away: within free seams Or-opt (1-3 spots, moved at most
    OR_OPT_WINDOW places) and 2-opt; seam swaps; seam-level 2-opt."""
    out = _Moves(blocks)
    for b, (seam, block) in enumerate(blocks):
        if ordered[seam] or len(block) < 2:
            continue
        rows = np.asarray(block, dtype=np.int64)[_move_table(len(block))]
        out.parts.append((b, rows))
        out.n_local += len(rows)
    for a, c in itertools.combinations(range(len(blocks)), 2):  # seam order
        swapped = list(blocks)
        swapped[a], swapped[c] = swapped[c], swapped[a]
        out.whole.append(swapped)
    # 2-opt at the seam level: a run of seams visited backwards, each free seam in it reversed
    # (rows of seams are then welded as a serpentine, which pairwise swaps reach only one by one).
    for a, c in itertools.combinations(range(len(blocks)), 2):
        run = [(seam, spots if ordered[seam] else spots[::-1]) for seam, spots in reversed(blocks[a:c + 1])]
        out.whole.append(blocks[:a] + run + blocks[c + 1:])
    return out


def _perturb(blocks: Blocks, ordered: Sequence[bool], rng: np.random.Generator) -> Blocks:
    """A random kick: move a random run of a free seam elsewhere, reversed; or swap two seams."""
    out = list(blocks)
    free = [b for b, (seam, spots) in enumerate(out) if not ordered[seam] and len(spots) >= 3]
    if free and (len(out) < 2 or rng.random() < 0.8):
        b = free[int(rng.integers(len(free)))]
        seam, block = out[b]
        n = len(block)
        i = int(rng.integers(n))
        j = int(rng.integers(i + 1, n + 1))
        run, rest = block[i:j][::-1], block[:i] + block[j:]
        k = int(rng.integers(len(rest) + 1))
        out[b] = (seam, rest[:k] + run + rest[k:])
    elif len(out) >= 2:
        a, c = rng.choice(len(out), size=2, replace=False)
        out[a], out[c] = out[c], out[a]
    return out
