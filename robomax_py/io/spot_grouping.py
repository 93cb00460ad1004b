"""Seams from a spot list's geometry, when the list has no group column (docs/spot-lists.md, "Seams").

A seam is a chain of spots along a line or a gentle curve on one face of the part. Joining every
spot to its nearest neighbours is not enough: two rows a few centimetres apart, or the two arms of
an L, would become one seam, and the chain would zig-zag between them. So a chain only grows to a
spot that continues its course:

1. **Links.** Two spots may be linked when their normals are within SAME_FACE_DEG (one face), one
   is among the other's NEIGHBOURS nearest spots, and they lie within GAP_FACTOR times the list's
   spacing of each other. The spacing is the median shorter step of the tightest straight triples
   below (the median nearest-neighbour distance when there are none), so that two rows closer
   together than their spots' pitch do not shrink it.
2. **Straight triples.** A spot with a neighbour on each side such that the two steps turn by at
   most MAX_TURN_DEG and differ in length by at most SPACING_RATIO is the middle of a straight
   triple; its tightest one (the shortest two steps, their length counted up to double as the
   turn nears MAX_TURN_DEG) joins it to its neighbours along its row. A link's
   support is the number of its two spots whose tightest straight triple it is part of: 2 along a
   row, 0 across two parallel rows (no third spot continues a rung).
3. **Chains.** Links are taken best first: those of support 2 (both spots' rows agree), then by
   support, the straightest first (a link that would start a new chain counting as bent by half
   the largest turn more, so that a chain already started is extended first), then the shortest.
   A link is kept when neither spot already has two, it closes no loop, and at each spot that
   already has a link the chain turns by at most MAX_TURN_DEG with steps differing by at most
   SPACING_RATIO. So every seam turns gently at each spot: a corner, a zig-zag or a jump to a
   parallel row starts a new seam.

Seams are named seam1, seam2, ... by their first spot in the list; a seam's spots are in chain
order, starting from the end that comes first in the list.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.tolerances import DEFAULT as TOL

# One face: neighbouring spots of a seam have normals within this angle (deg).
SAME_FACE_DEG = 10.0
# A link is at most this many times the list's spacing long: a seam does not jump a gap (a hole,
# a bracket) several pitches wide.
GAP_FACTOR = 3.0
# Each spot's links are looked for among its nearest spots: enough for two or three rows of
# neighbours on either side, few enough that a list of 2,000 spots is grouped in a fraction of a second.
NEIGHBOURS = 12
MAX_TURN_DEG = TOL.seam_turn_deg
SPACING_RATIO = TOL.seam_spacing_ratio
# Shorter than this (m) two spots are at one place, and their step has no direction.
SAME_PLACE_M = 1e-9


@dataclass(frozen=True, slots=True)
class SpotGroup:
    """A seam formed from a spot list: its name and its spots (indices into the list), in order."""

    name: str
    members: tuple[int, ...]


def geometric_groups(xyz: FloatArray, normals: FloatArray, max_turn_deg: float = MAX_TURN_DEG,
                     spacing_ratio: float = SPACING_RATIO) -> list[SpotGroup]:
    """The list's spots grouped into seams by the rule of the module docstring.

    Parameters
    ----------
    xyz : (n, 3) float
        The spots, m (any frame).
    normals : (n, 3) float
        Their unit normals, in the same frame.
    max_turn_deg, spacing_ratio : float
        The largest turn (deg) of a seam at a spot, and the largest ratio of the two steps there.
    """
    xyz = np.asarray(xyz, dtype=float)
    normals = np.asarray(normals, dtype=float)
    count = len(xyz)
    if count == 1:
        return [SpotGroup("seam1", (0,))]
    from scipy.spatial import cKDTree

    cos_turn = math.cos(math.radians(max_turn_deg))
    cos_face = math.cos(math.radians(SAME_FACE_DEG))
    k = min(NEIGHBOURS, count - 1)
    distance, index = cKDTree(xyz).query(xyz, k=k + 1)
    near, near_d = index[:, 1:], distance[:, 1:]                 # (n, k): a spot's nearest, itself left out
    face = np.einsum("ij,ikj->ik", normals, normals[near]) >= cos_face
    a, b, lu, lv, cos, straight = _straight_triples(xyz, near, face, cos_turn, spacing_ratio)
    # Each spot's tightest straight triple: its nearest neighbours on either side, in line. Its
    # length counts double at the largest turn allowed, so that of two triples of about the same
    # length the straighter one wins (a row, over a spot of the next row a few degrees off its line).
    bend = np.arccos(np.clip(cos, -1.0, 1.0)) / max(math.radians(max_turn_deg), 1e-9)
    total = np.where(straight, (lu + lv) * (1.0 + bend**2), np.inf)
    best = np.argmin(total, axis=1) if total.shape[1] else np.zeros(count, dtype=int)
    middle = np.flatnonzero(total.min(axis=1, initial=np.inf) < np.inf)
    j_a, j_b = a[middle, best[middle]], b[middle, best[middle]]
    near_step = np.minimum(lu[middle, best[middle]], lv[middle, best[middle]])
    far_step = np.maximum(lu[middle, best[middle]], lv[middle, best[middle]])
    spacing = float(np.median(near_step if len(middle) else near_d[:, 0]))
    gap = max(GAP_FACTOR * spacing, 1e-6)
    # A link's support, and the largest bend of the triples giving it.
    support: dict[tuple[int, int], tuple[int, float]] = {}
    for i, ja, jb, far, turned in zip(middle, j_a, j_b, far_step, bend[middle, best[middle]], strict=True):
        if far > gap:
            continue
        for j in (ja, jb):
            key = (int(min(i, j)), int(max(i, j)))
            count_so_far, worst = support.get(key, (0, 0.0))
            support[key] = (count_so_far + 1, max(worst, float(turned)))
    links: dict[tuple[int, int], Link] = {}
    for i, j in zip(*np.nonzero(face & (near_d <= gap)), strict=True):
        ends = (min(int(i), int(near[i, j])), max(int(i), int(near[i, j])))
        given, turned = support.get(ends, (0, 0.0))
        links[ends] = Link(ends[0], ends[1], given, turned, float(near_d[i, j]))
    return _named(_chains(xyz, list(links.values()), cos_turn, spacing_ratio), count)


def _straight_triples(xyz: FloatArray, near: np.ndarray, face: np.ndarray, cos_turn: float,
                      spacing_ratio: float) -> tuple[np.ndarray, np.ndarray, FloatArray, FloatArray, FloatArray,
                                                     np.ndarray]:
    """Every pair (a, b) of each spot's nearest (n, P each): the steps' lengths a -> spot (lu) and
    spot -> b (lv), m, the cosine of the turn between them, and whether a -> spot -> b is a straight
    triple on the spot's face."""
    p, q = np.triu_indices(near.shape[1], 1)
    a, b = near[:, p], near[:, q]
    u = xyz[:, None, :] - xyz[a]
    v = xyz[b] - xyz[:, None, :]
    lu, lv = np.linalg.norm(u, axis=2), np.linalg.norm(v, axis=2)
    ok = (lu > SAME_PLACE_M) & (lv > SAME_PLACE_M) & face[:, p] & face[:, q]
    with np.errstate(divide="ignore", invalid="ignore"):
        cos = np.einsum("ijk,ijk->ij", u, v) / (lu * lv)
        ratio = np.maximum(lu, lv) / np.minimum(lu, lv)
    straight = ok & (cos >= cos_turn) & (ratio <= spacing_ratio)
    return a, b, lu, lv, np.where(ok, cos, -1.0), straight


@dataclass(frozen=True, slots=True)
class Link:
    """Two spots a seam may join (i < j): how many of them have it in their tightest straight
    triple (0-2), the larger bend of those triples (a fraction of the largest turn), its length (m)."""

    i: int
    j: int
    support: int
    bend: float
    length: float


# The order links are taken in: first those both their spots' rows agree on (support 2); then by
# support, and within it the straightest first, a link that starts a new chain counting as bent by
# START_BEND more than its triple: a chain already started is extended (a long row's last spot
# joins its row, not a line of three across the rows), unless the extension bends by over half the
# largest turn more than a row of its own would.
START_BEND = 0.5


def _chains(xyz: FloatArray, links: list[Link], cos_turn: float, spacing_ratio: float) -> list[list[int]]:
    """The links kept under the chain rule, best first (see START_BEND), as chains of spot indices.

    A link's rank changes as chains grow (from starting a chain to extending one), so the links at a
    spot are ranked again, and entered in the heap again, when it takes a link; an entry whose rank
    is no longer the link's is passed over. A spot takes at most two links, so each link is entered
    at most five times."""
    count = len(xyz)
    linked: list[list[int]] = [[] for _ in range(count)]
    parent = list(range(count))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    def continues(at: int, to: int) -> bool:
        """Whether a step at -> to continues the chain that reaches `at` (if one does)."""
        if not linked[at]:
            return True
        u = xyz[at] - xyz[linked[at][0]]
        v = xyz[to] - xyz[at]
        lu, lv = float(np.linalg.norm(u)), float(np.linalg.norm(v))
        if min(lu, lv) <= SAME_PLACE_M:
            return False
        return float(u @ v) >= cos_turn * lu * lv and max(lu, lv) <= spacing_ratio * min(lu, lv)

    def rank(link: Link) -> tuple[bool, int, float, float, int, int]:
        starts = not linked[link.i] and not linked[link.j]
        return link.support != 2, -link.support, link.bend + START_BEND * starts, link.length, link.i, link.j

    touching: list[list[int]] = [[] for _ in range(count)]
    for k, link in enumerate(links):
        touching[link.i].append(k)
        touching[link.j].append(k)
    heap = [(rank(link), k) for k, link in enumerate(links)]
    heapq.heapify(heap)
    while heap:
        ranked, k = heapq.heappop(heap)
        link = links[k]
        i, j = link.i, link.j
        if len(linked[i]) >= 2 or len(linked[j]) >= 2 or root(i) == root(j):
            continue                                 # never again: a spot keeps its links, a loop stays one
        if rank(link) != ranked:
            continue                                 # ranked again when a chain reached it (below)
        if not (continues(i, j) and continues(j, i)):
            continue
        linked[i].append(j)
        linked[j].append(i)
        parent[root(j)] = root(i)
        for other in (*touching[i], *touching[j]):   # links at i or j now extend a chain
            heapq.heappush(heap, (rank(links[other]), other))
    chains, seen = [], [False] * count
    for start in range(count):
        if seen[start] or len(linked[start]) == 2:
            continue                                 # a chain is walked from its end with the lower index
        chain, previous, at = [start], -1, start
        seen[start] = True
        while True:
            following = [n for n in linked[at] if n != previous]
            if not following:
                break
            previous, at = at, following[0]
            seen[at] = True
            chain.append(at)
        chains.append(chain)
    return chains


def _named(chains: list[list[int]], count: int) -> list[SpotGroup]:
    """seam1..n, numbered by each chain's first spot in the list."""
    ordered = sorted(chains, key=min)
    assert sum(len(c) for c in ordered) == count     # no loops are kept, so every spot is on one chain
    return [SpotGroup(f"seam{k + 1}", tuple(c)) for k, c in enumerate(ordered)]
