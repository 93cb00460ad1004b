"""Which robot welds which spot, for the makespan: a min-max multiple-TSP over estimated tour times
(after Spensieri et al., IEEE T-ASE 2016, who pose assignment and sequencing of a station as one
min-max problem). The lower bound every plan is measured against is `bound`'s.

The estimate: a robot's tour is home -> its spots -> home over the quickest of a few representative
configurations per spot (`reach.cost_matrix`), ordered by nearest neighbour and 2-opt, plus the weld
and approach lines of each spot. The search: regret insertion (the spot whose best and second best
robot differ most is placed first), then moves of spots between robots while the longest tour shortens,
or stays and the sum of all tours shortens. The real planner then sequences each robot's spots itself.
Also here: the side prior the assignment is given, and the nearest-robot baseline.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from robomax_py.spec_station import SpotKey, StationSpec
from robomax_py.station.reach import RobotReach, cost_matrix

MAX_LOCAL_ROUNDS = 400


@dataclass(frozen=True, slots=True)
class Assignment:
    """Spots per robot in estimated tour order; `estimate` the estimated tour time of each, s."""

    spots: Mapping[str, tuple[SpotKey, ...]]
    estimate: Mapping[str, float]

    @property
    def makespan_estimate(self) -> float:
        return max(self.estimate.values(), default=0.0)


class _Tours:
    """Each robot's estimated tour (node indices into its cost matrix, 0 = home) and its time."""

    def __init__(self, reaches: Sequence[RobotReach], penalty: Mapping[tuple[str, SpotKey], float]) -> None:
        self.reaches = list(reaches)
        self.cost = [cost_matrix(r) for r in reaches]
        self.service = [np.concatenate([[0.0], r.dwell + 2 * r.line_s]) for r in reaches]
        for k, r in enumerate(reaches):
            for i, key in enumerate(r.keys):
                self.service[k][i + 1] += penalty.get((r.robot, key), 0.0)
        self.node = [{key: i + 1 for i, key in enumerate(r.keys)} for r in reaches]
        self.tour: list[list[int]] = [[0, 0] for _ in reaches]

    def time(self, k: int, tour: Sequence[int] | None = None) -> float:
        t = np.asarray(self.tour[k] if tour is None else tour)
        return float(self.cost[k][t[:-1], t[1:]].sum() + self.service[k][t].sum())

    def insertion(self, k: int, node: int) -> tuple[float, int]:
        """The cheapest place to insert `node` in tour k: (added time, position)."""
        t = np.asarray(self.tour[k])
        c = self.cost[k]
        delta = c[t[:-1], node] + c[node, t[1:]] - c[t[:-1], t[1:]]
        j = int(np.argmin(delta))
        return float(delta[j] + self.service[k][node]), j + 1

    def removal(self, k: int, pos: int) -> float:
        t = self.tour[k]
        c = self.cost[k]
        a, s, b = t[pos - 1], t[pos], t[pos + 1]
        return float(c[a, s] + c[s, b] - c[a, b] + self.service[k][s])

    def two_opt(self, k: int) -> None:
        t = np.asarray(self.tour[k])
        c = self.cost[k]
        improved = True
        while improved and len(t) > 4:
            improved = False
            for i in range(1, len(t) - 2):
                a, b = t[i - 1], t[i]
                cd = t[i + 1:-1], t[i + 2:]
                gain = c[a, b] + c[cd[0], cd[1]] - c[a, cd[0]] - c[b, cd[1]]
                j = int(np.argmax(gain))
                if gain[j] > 1e-9:
                    j += i + 1
                    t[i:j + 1] = t[i:j + 1][::-1].copy()
                    improved = True
        self.tour[k] = [int(x) for x in t]


def assign(reaches: Sequence[RobotReach], spots: Sequence[SpotKey], groups: Sequence[Sequence[SpotKey]] = (),
           penalty: Mapping[tuple[str, SpotKey], float] | None = None) -> Assignment:
    """Min-max assignment of `spots` to the robots of `reaches` (each spot to a robot that reaches it).

    groups : spots that must go to one robot together (an ordered seam's), each a sequence of keys.
    penalty : extra seconds a spot costs a robot (a wait the coordination found there).
    """
    tours = _Tours(reaches, penalty or {})
    units = _units(spots, groups)
    able = [[k for k in range(len(reaches)) if all(key in tours.node[k] for key in unit)] for unit in units]
    left = set(range(len(units)))
    while left:                                   # regret insertion
        best: tuple[float, float, int, int] | None = None
        for u in left:
            # Per able robot: the makespan after inserting there, then the time it adds (so that a
            # spot whose insertion leaves the makespan alone goes where it costs least).
            costs = sorted((max(tours.time(k) + add, _others(tours, k)), add, k)
                           for add, k in ((_insert_cost(tours, k, units[u]), k) for k in able[u]))
            regret = costs[1][0] - costs[0][0] + costs[1][1] - costs[0][1] if len(costs) > 1 else np.inf
            cand = (regret, -costs[0][0], u, costs[0][2])
            if best is None or cand[:2] > best[:2]:
                best = cand
        assert best is not None
        _, _, u, k = best
        for key in units[u]:
            add_pos = tours.insertion(k, tours.node[k][key])[1]
            tours.tour[k].insert(add_pos, tours.node[k][key])
        left.discard(u)
    for k in range(len(reaches)):
        tours.two_opt(k)
    _local_search(tours, units, able)
    out: dict[str, tuple[SpotKey, ...]] = {}
    for k, r in enumerate(reaches):
        out[r.robot] = tuple(r.keys[i - 1] for i in tours.tour[k][1:-1])
    return Assignment(out, {r.robot: tours.time(k) for k, r in enumerate(reaches)})


def _units(spots: Sequence[SpotKey], groups: Sequence[Sequence[SpotKey]]) -> list[tuple[SpotKey, ...]]:
    grouped = {key for g in groups for key in g}
    return [tuple(g) for g in groups] + [(key,) for key in spots if key not in grouped]


def _insert_cost(tours: _Tours, k: int, unit: Sequence[SpotKey]) -> float:
    return sum(tours.insertion(k, tours.node[k][key])[0] for key in unit)


def _others(tours: _Tours, k: int) -> float:
    return max((tours.time(j) for j in range(len(tours.tour)) if j != k), default=0.0)


def _local_search(tours: _Tours, units: list[tuple[SpotKey, ...]], able: list[list[int]]) -> None:
    """Move units between robots while that lowers the longest tour, or keeps it and lowers the sum
    of all tours (the min-max objective alone leaves every robot but the longest-running free to take
    anything, and its tie-breaks then send robots across each other)."""
    unit_of = {key: u for u, unit in enumerate(units) for key in unit}
    n = len(tours.tour)
    for _ in range(MAX_LOCAL_ROUNDS):
        times = [tours.time(k) for k in range(n)]
        now = (max(times), sum(times))
        best: tuple[tuple[float, float], int, int, int] | None = None
        for src in range(n):
            keys = [tours.reaches[src].keys[i - 1] for i in tours.tour[src][1:-1]]
            for u in dict.fromkeys(unit_of[key] for key in keys):
                nodes = [tours.node[src][key] for key in units[u]]
                t_rest = tours.time(src, [x for x in tours.tour[src] if x not in nodes])
                for k in able[u]:
                    if k == src:
                        continue
                    new = list(times)
                    new[src], new[k] = t_rest, times[k] + _insert_cost(tours, k, units[u])
                    score = (max(new), sum(new))
                    better = score[0] < now[0] - 1e-6 or (score[0] <= now[0] + 1e-9 and score[1] < now[1] - 1e-6)
                    if better and (best is None or score < best[0]):
                        best = (score, u, src, k)
        if best is None:
            return
        _, u, src, k = best
        nodes = [tours.node[src][key] for key in units[u]]
        tours.tour[src] = [x for x in tours.tour[src] if x not in nodes]
        for key in units[u]:
            tours.tour[k].insert(tours.insertion(k, tours.node[k][key])[1], tours.node[k][key])
        tours.two_opt(src)
        tours.two_opt(k)


def side_prior(station: StationSpec, reaches: Sequence[RobotReach],
               side_prior_s_per_m: float) -> dict[tuple[str, SpotKey], float]:
    """`side_prior_s_per_m` s per metre a robot's base is farther from a spot than the nearest base of a
    robot that reaches it."""
    xyz = {(seam.name, s.name): np.asarray(s.xyz) for seam in station.robots[0].cell.seams for s in seam.spots}
    base = {r.name: np.asarray(r.cell.T_world_base)[:3, 3] for r in station.robots}
    out: dict[tuple[str, SpotKey], float] = {}
    for key, p in xyz.items():
        d = {r.robot: float(np.linalg.norm(p[:2] - base[r.robot][:2])) for r in reaches if key in r.index()}
        nearest = min(d.values(), default=0.0)
        for robot, dist in d.items():
            out[(robot, key)] = side_prior_s_per_m * (dist - nearest)
    return out


def nearest(station: StationSpec, reaches: Sequence[RobotReach], keys: Sequence[SpotKey],
             groups: Sequence[Sequence[SpotKey]]) -> Assignment:
    """The baseline: each spot to the robot whose base is nearest among those that reach it."""
    xyz = {(seam.name, s.name): np.asarray(s.xyz) for seam in station.robots[0].cell.seams for s in seam.spots}
    base = {r.name: np.asarray(r.cell.T_world_base)[:3, 3] for r in station.robots}
    able = {r.robot: set(r.keys) for r in reaches}
    out: dict[str, list[SpotKey]] = {r.robot: [] for r in reaches}
    group_of = {k: tuple(g) for g in groups for k in g}
    done: set[SpotKey] = set()
    for k in keys:
        if k in done:
            continue
        unit = group_of.get(k, (k,))
        robots = [r for r in able if all(u in able[r] for u in unit)] or [r for r in able if k in able[r]]
        r = min(robots, key=lambda name: float(np.linalg.norm(xyz[k] - base[name])))
        out[r] += list(unit)
        done.update(unit)
    return Assignment({r: tuple(v) for r, v in out.items()}, {r: 0.0 for r in out})
