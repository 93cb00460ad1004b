"""The station's lower bound (`station.bound`) on constructed robots (no planning): every leg bound
below the time of a real rest-to-rest move, every tour bound below a tour timed move by move, and
the min-max partition equal to the brute-force optimum of small instances."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.robot import JointLimits
from robomax_py.station.bound import SpotWork, _leg, _partition, lower_bound, spot_work
from robomax_py.station.reach import REPRESENTATIVES, RobotReach
from robomax_py.timing import ptp_time_estimate

N = 3
VELOCITY = np.array([1.5, 2.0, 3.0])
ACCELERATION = np.array([3.0, 5.0, 8.0])
LIMITS = JointLimits(lower=np.full(N, -10.0), upper=np.full(N, 10.0), velocity=VELOCITY, acceleration=ACCELERATION,
                     jerk=np.full(N, 100.0))
# The bound takes the limits 0.1 % higher (a solver's slack), so it stays below the exact times here;
# this only absorbs float rounding, s.
TIME_TOL_S = 1e-9
DWELL = 0.4


def _reach(rng: np.random.Generator, spots: int, per_spot: int, name: str = "r") -> RobotReach:
    """A robot whose spots each have `per_spot` candidate weld configurations (the approach point
    the weld configuration itself: lines of no length)."""
    qs = [rng.uniform(-2, 2, size=(per_spot, N)) for _ in range(spots)]
    return RobotReach(name, tuple(("s", f"p{i}") for i in range(spots)), (),
                      np.repeat(np.stack([q[:1] for q in qs]), REPRESENTATIVES, axis=1),
                      np.stack([q.min(axis=0) for q in qs]), np.stack([q.max(axis=0) for q in qs]),
                      np.zeros(N), VELOCITY, ACCELERATION, np.full(spots, DWELL), 0.0, {}, tuple(qs), tuple(qs))


@settings(max_examples=30, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10_000))
def test_a_leg_is_never_longer_than_a_real_move(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(-3, 3, size=(4, N)), rng.uniform(-3, 3, size=(5, N))
    bound = _leg(a, a, b, b, VELOCITY, ACCELERATION, 0.0, 0.0)
    moves = ptp_time_estimate(a[:, None, :], b[None, :, :], LIMITS)       # the straight rest-to-rest move
    assert bound <= float(moves.min()) + TIME_TOL_S
    # The compiled search passes pairs over early; it finds what every pair's joints' times give.
    each_joint = ptp_time_estimate(a[:, None, :], b[None, :, :], LIMITS, straight=False)
    approach = rng.uniform(-3, 3, size=(4, N))
    between = (np.abs(approach[:, None, :] - b[None, :, :]) / VELOCITY).max(axis=-1) + 0.03
    assert abs(_leg(a, approach, b, b, VELOCITY, ACCELERATION, 0.01, 0.02)
               - float(np.maximum(each_joint, between).min())) <= TIME_TOL_S
    # The lines' near halves are at least the lines' time, however short the move between them.
    assert _leg(a, a, b, b, VELOCITY, ACCELERATION, 0.05, 0.07) >= 0.12 - 1e-12


@settings(max_examples=25, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10_000), spots=st.integers(1, 5))
def test_a_tour_is_never_shorter_than_its_bound(seed: int, spots: int) -> None:
    """Any tour (any order, any candidate per spot), timed rest to rest at each spot and home, takes
    at least `tour_bound` of its spots."""
    rng = np.random.default_rng(seed)
    reach = _reach(rng, spots, 3)
    work = spot_work(reach, 0.0)
    order = [int(i) for i in rng.permutation(spots)[: rng.integers(1, spots + 1)]]
    picks = [reach.weld_q[i][rng.integers(3)] for i in order]
    path = np.array([reach.home, *picks, reach.home])
    cycle = float(ptp_time_estimate(path[:-1], path[1:], LIMITS).sum()) + DWELL * len(order)
    assert work.tour_bound([reach.keys[i] for i in order]) <= cycle + TIME_TOL_S


def _brute_force(works: list[SpotWork], spots: list[tuple[str, str]]) -> float:
    index = [{k: i for i, k in enumerate(w.keys)} for w in works]
    best = np.inf
    for owners in itertools.product(range(len(works)), repeat=len(spots)):
        if any(key not in index[r] for r, key in zip(owners, spots, strict=True)):
            continue
        longest = max(w.tour_bound([k for r, k in zip(owners, spots, strict=True) if r == j])
                      for j, w in enumerate(works))
        best = min(best, longest)
    return float(best)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10_000), robots=st.integers(1, 3), spots=st.integers(1, 6))
def test_the_partition_is_the_min_max_optimum(seed: int, robots: int, spots: int) -> None:
    """The partition's mixed-integer program finds the least longest tour that brute force finds
    (each tour its spots' work and home legs, at least its longest round trip), within HiGHS's
    default relative gap (1e-4)."""
    rng = np.random.default_rng(seed)
    keys = [("s", f"p{i}") for i in range(spots)]
    works = []
    for r in range(robots):
        mine = [k for k in keys if r == 0 or rng.random() < 0.7]     # robot 0 reaches every spot
        works.append(SpotWork(f"r{r}", tuple(mine), rng.uniform(0.5, 2.0, len(mine)),
                              rng.uniform(1.0, 4.0, len(mine)), float(rng.uniform(0.2, 1.0))))
    index = [{k: i for i, k in enumerate(w.keys)} for w in works]
    optimum = _brute_force(works, keys)
    got = _partition(works, index, keys, ())
    assert optimum * (1 - 2e-4) <= got <= optimum + 1e-9
    bound = lower_bound(works, keys)
    assert bound.value <= optimum + 1e-9 and bound.partition >= bound.shared * (1 - 2e-4)


def test_an_ordered_seam_goes_to_one_robot() -> None:
    """Two robots, two spots of one ordered seam: sharing them would halve the longest tour, the
    seam going whole to one robot does not."""
    keys = [("seam", "a"), ("seam", "b")]
    works = [SpotWork(r, tuple(keys), np.array([1.0, 1.0]), np.array([1.5, 1.5]), 0.0) for r in ("r1", "r2")]
    index = [{k: i for i, k in enumerate(w.keys)} for w in works]
    assert abs(_partition(works, index, keys, ()) - 1.5) < 1e-4
    assert abs(_partition(works, index, keys, [keys]) - 2.0) < 1e-4
