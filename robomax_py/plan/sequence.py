"""Choosing the spot order and one candidate per spot so that the total cycle time is least.

This is a generalised travelling-salesman problem over a layered graph: spots are layers, candidate
configurations are nodes, and an edge costs the motion time between two nodes. For a fixed spot
order the best candidates follow exactly by dynamic programming (min-plus products along the
layers); the order itself is improved by local search (Or-opt, 2-opt and seam moves) whose moves
are screened with a spot-level lower bound before the exact DP judges them. `exact_tour` enumerates
every admissible order, for checking the search on small instances.

Nothing here knows geometry: costs come from an `EdgeCosts` callable, so the planner can make
blocked edges expensive, add detours, and ask again.
"""

from __future__ import annotations

import itertools
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray

HOME = -1  # the start/end configuration, a layer of one node
# Or-opt moves a run at most this many positions: spots of a seam lie along a line, far moves are
# rarely good and are still reachable through 2-opt and perturbations; keeps neighbourhoods O(n^2).
OR_OPT_WINDOW = 6
# Consecutive perturbations that found no unseen order before the search gives up.
MAX_STALE_KICKS = 50
# Neighbourhoods (all orders one move away) a search keeps for orders it may pass through again.
KEPT_NEIGHBOURHOODS = 16
# Up to this many admissible orders, `optimise` evaluates every one (exact).
EXACT_ORDERS = 720

# cost(i, j) -> (N_i, N_j) float: motion time from every candidate of spot i to every candidate of
# spot j (HOME has one candidate). Must be deterministic; the optimiser caches what it asks for.
EdgeCosts = Callable[[int, int], FloatArray]


@dataclass(frozen=True, slots=True)
class SeamBlock:
    """A seam's spots (global spot ids) in their given order; `ordered` fixes that order."""

    spots: tuple[int, ...]
    ordered: bool


@dataclass(frozen=True, slots=True)
class Tour:
    """A visiting order (global spot ids) and the chosen candidate index at each visited spot."""

    order: tuple[int, ...]
    choice: tuple[int, ...]
    cost: float                # s: sum of edge costs (home -> ... -> home) plus node costs


@dataclass(frozen=True, slots=True)
class SearchStats:
    dp_evaluations: int
    moves_screened: int
    improvements: int


class _Costs:
    """Caches edge-cost matrices (float64) and spot-level lower bounds."""

    def __init__(self, edge: EdgeCosts, node: Sequence[FloatArray]) -> None:
        self._edge = edge
        self.node = [np.asarray(c, dtype=float) for c in node]
        self._cache: dict[tuple[int, int], FloatArray] = {}
        self._bounds: dict[tuple[int, int], float] = {}
        self.node_min = [float(np.min(c)) for c in self.node]

    def __call__(self, i: int, j: int) -> FloatArray:
        key = (i, j)
        got = self._cache.get(key)
        if got is None:
            got = np.asarray(self._edge(i, j), dtype=float)
            self._cache[key] = got
        return got

    def lower_bound(self, i: int, j: int) -> float:
        got = self._bounds.get((i, j))
        if got is None:
            got = self._bounds[(i, j)] = float(np.min(self(i, j)))
        return got



class _BoundTable:
    """Spot-level lower bounds (min edge cost between two spots) for spots 0..S-1, index S standing
    for HOME, filled in as orders ask for them: a neighbourhood only joins spots of one seam and
    seam ends, so most of the S^2 pairs of a large cell are never needed (and each costs a matrix)."""

    def __init__(self, costs: _Costs, size: int) -> None:
        self.costs, self.size = costs, size
        self.table = np.full((size + 1, size + 1), np.nan)

    def _id(self, k: int) -> int:
        return HOME if k == self.size else k

    def of_orders(self, orders: np.ndarray) -> FloatArray:
        """Sum of the bounds along each of many same-length orders (rows; home at both ends).

        Node minima are the same for every permutation of the same spots, so they are left out: the
        result ranks orders correctly but is a bound only after adding them back.
        """
        arr = np.asarray(orders, dtype=np.int64)
        home = np.full((len(arr), 1), self.size)
        padded = np.concatenate([home, arr, home], axis=1)
        a, b = padded[:, :-1], padded[:, 1:]
        values = self.table[a, b]
        missing = np.isnan(values)
        if missing.any():
            for code in np.unique(a[missing] * (self.size + 1) + b[missing]).tolist():
                x, y = divmod(code, self.size + 1)
                self.table[x, y] = self.costs.lower_bound(self._id(x), self._id(y))
            values = self.table[a, b]
        total: FloatArray = values.sum(axis=1)
        return total


def best_choice(order: Sequence[int], costs: _Costs) -> tuple[tuple[int, ...], float]:
    """Exact best candidate per spot for a fixed order, by DP over the layers.

    Ties are broken towards the lowest candidate index, so results are deterministic.
    """
    if not order:
        return (), float(costs(HOME, HOME)[0, 0])
    value = costs(HOME, order[0])[0] + costs.node[order[0]]
    back: list[np.ndarray] = []
    for prev, nxt in itertools.pairwise(order):
        total = value[:, None] + costs(prev, nxt)           # (N_prev, N_next)
        arg = np.argmin(total, axis=0)
        value = total[arg, np.arange(total.shape[1])] + costs.node[nxt]
        back.append(arg)
    final = value + costs(order[-1], HOME)[:, 0]
    last = int(np.argmin(final))
    best = float(final[last])
    choice = [last]
    for arg in reversed(back):
        choice.append(int(arg[choice[-1]]))
    return tuple(reversed(choice)), best


# A tour under construction: seams in visiting order, each (seam id, its spots in visiting order).
Blocks = list[tuple[int, tuple[int, ...]]]


class _PrefixCost:
    """The DP cost of orders near an anchor order (a descent's current one): the anchor's layer
    values are kept, so an order that first differs from it at position p is costed from layer p
    on. The arithmetic is `best_choice`'s (a column's min is the value at its argmin), so costs
    are the same bit for bit."""

    def __init__(self, costs: _Costs) -> None:
        self.costs = costs
        self.anchor: tuple[int, ...] = ()
        self.values: list[FloatArray] = []      # values[k]: best cost ending at each node of layer k

    def set_anchor(self, order: tuple[int, ...]) -> None:
        if order != self.anchor:
            self.anchor, self.values = order, []

    def _layer(self, order: tuple[int, ...], k: int, value: FloatArray | None) -> FloatArray:
        node = self.costs.node[order[k]]
        if k == 0:
            first: FloatArray = self.costs(HOME, order[0])[0] + node
            return first
        assert value is not None
        layer: FloatArray = np.min(value[:, None] + self.costs(order[k - 1], order[k]), axis=0) + node
        return layer

    def __call__(self, order: tuple[int, ...]) -> float:
        if not order:
            return float(self.costs(HOME, HOME)[0, 0])
        anchor = self.anchor
        p, n = 0, min(len(order), len(anchor))
        while p < n and order[p] == anchor[p]:
            p += 1
        while len(self.values) < p:
            k = len(self.values)
            self.values.append(self._layer(anchor, k, self.values[-1] if k else None))
        value = self.values[p - 1] if p else None
        for k in range(p, len(order)):
            value = self._layer(order, k, value)
        assert value is not None
        return float(np.min(value + self.costs(order[-1], HOME)[:, 0]))


def choice_for_order(order: Sequence[int], edge: EdgeCosts, node: Sequence[FloatArray]) -> tuple[tuple[int, ...], float]:
    """The exact best candidates for a fixed spot order (public form of `best_choice`)."""
    return best_choice(order, _Costs(edge, node))


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
        return self.origin[:b] + [(self.origin[b][0], tuple(int(s) for s in row))] + self.origin[b + 1:]

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
        out.extend(np.array([_flatten(w)], dtype=np.int64) for w in self.whole)
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


def _bound(order: tuple[int, ...], costs: _Costs) -> float:
    """Spot-level lower bound of an order's cost (min edge per pair, min node per spot)."""
    stops = (HOME, *order, HOME)
    edges = sum(costs.lower_bound(a, b) for a, b in itertools.pairwise(stops))
    return edges + sum(costs.node_min[s] for s in order)


def optimise(
    blocks: Sequence[SeamBlock],
    edge: EdgeCosts,
    node: Sequence[FloatArray],
    rng: np.random.Generator | None = None,
    max_evaluations: int = 600,
    screen: int = 12,
    exact_limit: int = EXACT_ORDERS,
    starts: Sequence[tuple[int, ...]] = (),
) -> tuple[Tour, SearchStats]:
    """Best tour: exact when few orders are admissible, else construction + iterated local search.

    With at most `exact_limit` admissible orders every one is evaluated by DP (exact). Otherwise the
    search starts from the given order, the given order with free seams reversed, and a
    candidate-aware cheapest-insertion construction; each start is improved by local search
    (neighbours tried in order of their spot-level lower bound, the first improvement taken; after
    the `screen` most promising, only those whose bound beats the current cost),
    then the best tour is perturbed (a random segment of a free seam reversed and moved) and
    improved again until `max_evaluations` DP evaluations are spent. Deterministic for a given rng.
    `starts` adds admissible orders to start from (e.g. the previous best, when costs changed).
    """
    rng = rng if rng is not None else np.random.default_rng(0)
    costs = _Costs(edge, node)
    if order_count(blocks) <= exact_limit:
        tour = _exact(blocks, costs)
        n = order_count(blocks)
        return tour, SearchStats(dp_evaluations=n, moves_screened=n, improvements=0)

    ordered = [b.ordered for b in blocks]   # by seam id (= index in `blocks`)
    all_spots = sorted(s for b in blocks for s in b.spots)
    if all_spots != list(range(len(all_spots))):
        raise ValueError("spot ids must be 0..S-1")  # an internal contract, not user input
    bounds_of = _BoundTable(costs, len(all_spots))
    node_total = sum(costs.node_min)
    counter = {"evaluations": 0, "screened": 0, "improvements": 0}
    seen: dict[tuple[int, ...], float] = {}

    prefix = _PrefixCost(costs)

    def evaluate(flat: tuple[int, ...]) -> float:
        if flat not in seen:
            counter["evaluations"] += 1
            seen[flat] = prefix(flat)
        return seen[flat]

    # Descents from different starts and kicks pass through the same orders again and again; the
    # most recent neighbourhoods are kept (each holds thousands of whole orders on a large cell).
    screened: OrderedDict[tuple[tuple[int, tuple[int, ...]], ...], tuple[_Moves, FloatArray, list[int]]] = OrderedDict()

    def neighbours(current: Blocks) -> tuple[_Moves, FloatArray, list[int]]:
        """The moves from `current`, their bounds and their ranking (cached per order)."""
        key = tuple(current)
        got = screened.get(key)
        if got is None:
            options = _neighbours(current, ordered)
            bounds = bounds_of.of_orders(options.rows()) + node_total if len(options) else np.zeros(0)
            got = screened[key] = (options, bounds, np.argsort(bounds, kind="stable").tolist())
            if len(screened) > KEPT_NEIGHBOURHOODS:
                screened.popitem(last=False)
        else:
            screened.move_to_end(key)
        return got

    def descend(start: Blocks) -> tuple[Blocks, float]:
        current, current_cost = start, evaluate(_flatten(start))
        while counter["evaluations"] < max_evaluations:
            options, bounds, ranked = neighbours(current)
            if not options:
                break
            prefix.set_anchor(_flatten(current))      # its neighbours share prefixes with it
            counter["screened"] += len(options)
            improved = False
            for rank, idx in enumerate(ranked):
                # Past the `screen` most promising moves, a neighbour whose lower bound does not
                # beat the current cost cannot improve it (and nor can any later one).
                if counter["evaluations"] >= max_evaluations or (
                    rank >= screen and bounds[idx] >= current_cost - 1e-9
                ):
                    break
                value = evaluate(options.flat(idx))
                if value < current_cost - 1e-9:
                    current, current_cost, improved = options.blocks(idx), value, True
                    counter["improvements"] += 1
                    break
            if not improved:
                break
        return current, current_cost

    initial: list[Blocks] = [
        *(_as_blocks(order, blocks) for order in starts),
        [(i, b.spots) for i, b in enumerate(blocks)],
        [(i, b.spots if b.ordered else b.spots[::-1]) for i, b in enumerate(blocks)],
        _insertion_start(blocks, costs),
    ]
    best, best_cost = min((descend(s) for s in initial), key=lambda pair: pair[1])
    can_kick = len(blocks) > 1 or any(not b.ordered and len(b.spots) >= 3 for b in blocks)
    # Kicks that only revisit known orders spend no budget; they grow stronger, and are capped so
    # the search always ends.
    stale = kicks = 0
    while (counter["evaluations"] < max_evaluations and can_kick and stale < MAX_STALE_KICKS
           and kicks < 3 * max_evaluations):
        kicks += 1
        before = counter["evaluations"]
        kicked = best
        for _ in range(1 + stale // 5):
            kicked = _perturb(kicked, ordered, rng)
        cand, cand_cost = descend(kicked)
        stale = stale + 1 if counter["evaluations"] == before else 0
        if cand_cost < best_cost - 1e-9:
            best, best_cost = cand, cand_cost
    flat = _flatten(best)
    choice, cost = best_choice(flat, costs)
    stats = SearchStats(counter["evaluations"], counter["screened"], counter["improvements"])
    return Tour(flat, choice, cost), stats


def _as_blocks(order: tuple[int, ...], blocks: Sequence[SeamBlock]) -> Blocks:
    """A flat admissible order back into seam blocks (seams in order of first appearance)."""
    seam_of = {spot: b for b, block in enumerate(blocks) for spot in block.spots}
    out: Blocks = []
    for spot in order:
        if not out or out[-1][0] != seam_of[spot]:
            out.append((seam_of[spot], ()))
        out[-1] = (out[-1][0], (*out[-1][1], spot))
    return out


def _insertion_start(blocks: Sequence[SeamBlock], costs: _Costs) -> Blocks:
    """Cheapest insertion, spot by spot, judged by the spot-level bound (no DP: it is a start)."""
    out: Blocks = []
    for seam, block in enumerate(blocks):
        if block.ordered or len(block.spots) <= 2:
            out.append((seam, block.spots))
            continue
        tour: list[int] = [block.spots[0]]
        for spot in block.spots[1:]:
            options = [tuple(tour[:k] + [spot] + tour[k:]) for k in range(len(tour) + 1)]
            best = min(options, key=lambda o: _bound(_flatten([*out, (seam, o)]), costs))
            tour = list(best)
        out.append((seam, tuple(tour)))
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


def order_count(blocks: Sequence[SeamBlock]) -> int:
    """How many orders the constraints admit (capped a little above 10^9)."""
    count = 1
    for i, b in enumerate(blocks, start=1):
        count *= i * (1 if b.ordered else _factorial(len(b.spots)))
    return count


def _factorial(n: int) -> int:
    out = 1
    for k in range(2, n + 1):
        out *= k
        if out > 10**9:
            return out
    return out


def admissible_orders(blocks: Sequence[SeamBlock]) -> list[tuple[int, ...]]:
    """Every order the constraints allow: seams contiguous, ordered seams in their given order."""
    per_block = [
        [b.spots] if b.ordered else list(itertools.permutations(b.spots)) for b in blocks
    ]
    orders: list[tuple[int, ...]] = []
    for seam_order in itertools.permutations(range(len(blocks))):
        for inner in itertools.product(*(per_block[b] for b in seam_order)):
            orders.append(tuple(s for part in inner for s in part))
    return orders


def exact_tour(blocks: Sequence[SeamBlock], edge: EdgeCosts, node: Sequence[FloatArray]) -> Tour:
    """The optimum by enumerating admissible orders (each with exact DP). Small instances only."""
    return _exact(blocks, _Costs(edge, node))


def _exact(blocks: Sequence[SeamBlock], costs: _Costs) -> Tour:
    best: Tour | None = None
    for order in admissible_orders(blocks):
        choice, cost = best_choice(order, costs)
        if best is None or cost < best.cost - 1e-12:
            best = Tour(order, choice, cost)
    assert best is not None  # admissible_orders always yields at least one order
    return best
