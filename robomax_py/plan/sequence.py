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

from robomax_py._typing import FloatArray, IntArray
from robomax_py.plan.min_plus import min_plus, min_plus_arg
from robomax_py.plan.sequence_moves import (
    OR_OPT_WINDOW,
    Blocks,
    _flatten,
    _Moves,
    _neighbours,
    _perturb,
)

__all__ = [
    "EXACT_ORDERS", "HOME", "KEPT_NEIGHBOURHOODS", "MAX_STALE_KICKS", "OR_OPT_WINDOW", "Blocks", "EdgeCosts",
    "SeamBlock", "SearchStats", "Tour", "admissible_orders", "best_choice", "choice_for_order", "dp_choice",
    "dp_layer", "exact_tour", "optimise", "order_count",
]

HOME = -1  # the start/end configuration, a layer of one node
# Consecutive perturbations that found no unseen order before the search gives up.
MAX_STALE_KICKS = 50
# Neighbourhoods (all orders one move away) a search keeps for orders it may pass through again.
KEPT_NEIGHBOURHOODS = 16
# Up to this many admissible orders, `optimise` evaluates every one (exact).
EXACT_ORDERS = 720
# Costs closer than this (s) are a tie: the search moves only for a larger gain, and of tied tours
# keeps the one it met first (rounding, which differs between CPUs, never decides).
TIE_S = 1e-9

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
        self.node = [_costs_of(c, "node") for c in node]
        self._cache: dict[tuple[int, int], FloatArray] = {}
        self._bounds: dict[tuple[int, int], float] = {}
        self.node_min = [float(np.min(c)) for c in self.node]

    def __call__(self, i: int, j: int) -> FloatArray:
        key = (i, j)
        got = self._cache.get(key)
        if got is None:
            got = self._cache[key] = _costs_of(self._edge(i, j), f"edge {i} -> {j}")
        return got

    def lower_bound(self, i: int, j: int) -> float:
        got = self._bounds.get((i, j))
        if got is None:
            got = self._bounds[(i, j)] = float(np.min(self(i, j)))
        return got



def _costs_of(costs: FloatArray, what: str) -> FloatArray:
    """Costs as the DP's compiled step takes them (float64, contiguous); NaN is refused, as the step
    would skip it where numpy's reduction carries it (`min_plus`)."""
    out = np.ascontiguousarray(costs, dtype=np.float64)
    if np.isnan(out).any():
        raise ValueError(f"{what} costs hold NaN")       # an internal contract, not user input
    return out


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
        # Flat indices into the table: one gather, not a two-index one (rows x spots per neighbourhood).
        codes = padded[:, :-1] * (self.size + 1) + padded[:, 1:]
        flat = self.table.reshape(-1)
        values = flat[codes]
        missing = np.isnan(values)
        if missing.any():
            for code in np.unique(codes[missing]).tolist():
                x, y = divmod(code, self.size + 1)
                self.table[x, y] = self.costs.lower_bound(self._id(x), self._id(y))
            values = flat[codes]
        total: FloatArray = values.sum(axis=1)
        return total


def best_choice(order: Sequence[int], costs: _Costs) -> tuple[tuple[int, ...], float]:
    """Exact best candidate per spot for a fixed order, by DP over the layers.

    Ties are broken towards the lowest candidate index, so results are deterministic.
    """
    if not order:
        return (), float(costs(HOME, HOME)[0, 0])
    value = costs(HOME, order[0])[0] + costs.node[order[0]]
    back: list[IntArray] = []
    for prev, nxt in itertools.pairwise(order):
        value, arg = dp_layer(value, costs(prev, nxt), costs.node[nxt])
        back.append(arg)
    return dp_choice(value + costs(order[-1], HOME)[:, 0], back)


def dp_layer(value: FloatArray, matrix: FloatArray, node: FloatArray) -> tuple[FloatArray, IntArray]:
    """One layer of `best_choice`'s DP: the best cost ending at each candidate of the next spot
    (value (N_prev,) of the last layer, matrix (N_prev, N_next) of the move, node (N_next,)) and, for
    each, the candidate of the last spot it comes from (the lowest index among equals)."""
    if not len(value):
        raise ValueError("a DP layer needs at least one candidate before it")
    out, arg = min_plus_arg(*(np.ascontiguousarray(a, dtype=np.float64) for a in (value, matrix, node)))
    return out, arg


def dp_choice(final: FloatArray, back: Sequence[IntArray]) -> tuple[tuple[int, ...], float]:
    """The choice and cost of `best_choice`'s DP from the costs of the tour ending at each candidate
    of the last spot (home included) and each layer's `dp_layer` argmins after the first."""
    last = int(np.argmin(final))
    choice = [last]
    for arg in reversed(back):
        choice.append(int(arg[choice[-1]]))
    return tuple(reversed(choice)), float(final[last])


def _layer(costs: _Costs, order: Sequence[int], k: int, value: FloatArray | None) -> FloatArray:
    """Layer k of `best_choice`'s DP values for `order` from layer k - 1's (`value`; None for k = 0),
    with `best_choice`'s arithmetic (a column's min is the value at its argmin): the same bits."""
    node = costs.node[order[k]]
    if k == 0:
        first: FloatArray = costs(HOME, order[0])[0] + node
        return first
    assert value is not None
    if not len(value):
        raise ValueError("a DP layer needs at least one candidate before it")
    layer: FloatArray = min_plus(value, costs(order[k - 1], order[k]), node)
    return layer


def _shared_prefix(a: tuple[int, ...], b: tuple[int, ...]) -> int:
    """How many leading spots two orders share."""
    p, n = 0, min(len(a), len(b))
    while p < n and a[p] == b[p]:
        p += 1
    return p


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
        """Cost from `order` on; the layers of the prefix it shares with the last anchor are kept (a
        layer depends on the order up to its spot only)."""
        del self.values[_shared_prefix(order, self.anchor):]
        self.anchor = order

    def __call__(self, order: tuple[int, ...]) -> float:
        if not order:
            return float(self.costs(HOME, HOME)[0, 0])
        anchor = self.anchor
        p = _shared_prefix(order, anchor)
        while len(self.values) < p:
            k = len(self.values)
            self.values.append(_layer(self.costs, anchor, k, self.values[-1] if k else None))
        value = self.values[p - 1] if p else None
        for k in range(p, len(order)):
            value = _layer(self.costs, order, k, value)
        assert value is not None
        return float(np.min(value + self.costs(order[-1], HOME)[:, 0]))


def choice_for_order(order: Sequence[int], edge: EdgeCosts, node: Sequence[FloatArray]) -> tuple[tuple[int, ...], float]:
    """The exact best candidates for a fixed spot order (public form of `best_choice`)."""
    return best_choice(order, _Costs(edge, node))


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
                    rank >= screen and bounds[idx] >= current_cost - TIE_S
                ):
                    break
                value = evaluate(options.flat(idx))
                if value < current_cost - TIE_S:
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
    # Among the results within the search's tolerance of the best, the file's order's, then its
    # reverse's, then the others' in the order above: a tour and its reverse over symmetric legs sum
    # the same times in another order, and which one is a few ulps shorter follows the CPU's
    # rounding; the tolerance makes the choice the same everywhere. The file's order goes before
    # the earlier rounds' tours (`starts`), which follow their own rounds' costs and so the CPU as
    # well: on cells/cabin_flange.yaml one CPU's second round found the reverse shorter, and the
    # third, which priced both the same, kept it. (The descents still run in the order above: which
    # one spends the evaluation budget first changes the tours found.)
    descents = [descend(s) for s in initial]
    lowest = min(cost for _, cost in descents)
    first = len(starts)
    preferred = [*descents[first:first + 2], *descents[:first], *descents[first + 2:]]
    best, best_cost = next(pair for pair in preferred if pair[1] <= lowest + TIE_S)
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
        if cand_cost < best_cost - TIE_S:
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
    """Cheapest insertion, spot by spot, judged by the spot-level bound (no DP: it is a start).

    Each option is judged by `_bound` of the whole order so far; the terms of the seams already
    placed are the same for every option and are kept, not looked up again (an option's bound
    took N look-ups, N^2 per start): the same terms summed in the same order, the same bound."""
    out: Blocks = []
    edges: list[float] = []         # `_bound`'s edge terms along (HOME, *placed seams)
    nodes: list[float] = []         # its node terms of the placed spots
    last = HOME

    def bound(option: tuple[int, ...]) -> float:
        stops = (last, *option, HOME)
        tail = [costs.lower_bound(a, b) for a, b in itertools.pairwise(stops)]
        return sum(edges + tail) + sum(nodes + [costs.node_min[s] for s in option])

    for seam, block in enumerate(blocks):
        if block.ordered or len(block.spots) <= 2:
            placed = block.spots
        else:
            tour: list[int] = [block.spots[0]]
            for spot in block.spots[1:]:
                options = [tuple(tour[:k] + [spot] + tour[k:]) for k in range(len(tour) + 1)]
                best: tuple[int, ...] = min(options, key=bound)
                tour = list(best)
            placed = tuple(tour)
        out.append((seam, placed))
        edges.extend(costs.lower_bound(a, b) for a, b in itertools.pairwise((last, *placed)))
        nodes.extend(costs.node_min[s] for s in placed)
        last = placed[-1] if placed else last
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
    """Every admissible order's `best_choice` cost, in `admissible_orders`' order, the first of tied
    least kept. Consecutive orders mostly share a prefix (the enumeration varies the last spots
    fastest): each order is `_PrefixCost`'s anchor in turn, so the DP's layers over the prefix it
    shares with the previous order are kept, not computed again, and only the winner's candidates
    are traced back (on an 8-spot cell of three free seams with hundreds of candidates per spot,
    576 orders, the layers of every order one by one were 88 % of the plan's CPU)."""
    prefix = _PrefixCost(costs)
    best_order: tuple[int, ...] | None = None
    best_cost = np.inf
    for order in admissible_orders(blocks):
        prefix.set_anchor(order)
        cost = prefix(order)
        if best_order is None or cost < best_cost - TIE_S:
            best_order, best_cost = order, cost
    assert best_order is not None  # admissible_orders always yields at least one order
    choice, cost = best_choice(best_order, costs)
    return Tour(best_order, choice, cost)
