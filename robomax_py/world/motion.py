"""Sampled motion against the robot's limits and the world: the one check the planner runs on its
own trajectory before anything is written and `robomax verify` runs on a program's rebuilt motion."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray, IntArray
from robomax_py.robot import JointLimits, RobotModel
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.world.collision import CollisionWorld

# Finite differences of 10 ms samples: velocity is exact for the linear interpolation the trajectory file
# prescribes; acceleration from second differences of a jerk-limited profile overshoots the
# sampled peak slightly, hence the larger slack.
VELOCITY_RTOL = TOL.velocity_rtol
ACCELERATION_RTOL = TOL.acceleration_rtol
MAX_REPORTED_COLLISIONS = 20        # collision intervals reported at most
MIN_CLEARANCE_SUBSTEPS = 10


@dataclass(frozen=True, slots=True)
class Violation:
    t: float | None
    kind: str                # collision | joint_limit | velocity | acceleration | spot | dwell | order | home | format
    #                          (.srcl also: lin | config | flyby | frame | signal | timing)
    detail: str
    line: int | None = None  # the program line whose statement commands the motion then
    t_end: float | None = None  # the end of the interval it lasts (s); None: an instant


@dataclass(frozen=True, slots=True)
class MotionCheck:
    """What `check_motion` found: violations (empty when clean) and collision checks spent."""

    violations: tuple[Violation, ...]
    checks: int

    @property
    def clean(self) -> bool:
        return not self.violations


def check_motion(
    world: CollisionWorld, robot: RobotModel, t: FloatArray, q: FloatArray,
    max_collisions: int = MAX_REPORTED_COLLISIONS, stop_at_first: bool = False,
    velocity_rtol: float = VELOCITY_RTOL,
) -> MotionCheck:
    """Limits and swept collisions of sampled motion, linear in joint space between samples.

    Parameters
    ----------
    t : (k,) float, s, strictly increasing
    q : (k, n) float, rad

    velocity_rtol : relative slack on the velocity limits (the planner's own check is tighter).

    Returns
    -------
    MotionCheck
        The violations, one per interval: a run of consecutive samples (or swept steps) breaking
        the same limit of the same joint, or colliding with the same pair, is one violation from
        its first to its last time (`t`, `t_end`) with its worst value; at most `max_collisions`
        collision intervals. With `stop_at_first`, at most one violation and no collision check
        once a limit is broken.
    """
    lim = robot.limits
    out: list[Violation] = []
    below = q < lim.lower - 1e-9
    above = q > lim.upper + 1e-9
    for j, i0, i1 in _runs(below | above):
        worst = i0 + int(np.argmax(np.maximum(lim.lower[j] - q[i0:i1 + 1, j], q[i0:i1 + 1, j] - lim.upper[j])))
        out.append(Violation(float(t[i0]), "joint_limit", f"{robot.joint_names[j]} = {math.degrees(q[worst, j]):.3f} deg "
                                                          f"(limits {math.degrees(lim.lower[j]):.3f} .. {math.degrees(lim.upper[j]):.3f})",
                             t_end=_end(t, i0, i1)))
    out.extend(rate_violations(lim, robot.joint_names, t, q, velocity_rtol))
    out.sort(key=lambda x: (x.t if x.t is not None else -1.0))
    if stop_at_first and out:
        return MotionCheck(tuple(out[:1]), 0)
    checks = 0
    limit = 1 if stop_at_first else max_collisions
    collisions: list[Violation] = []
    rest_end = _rest_ends(q)
    skip_to, checks = _free_prefix(world, t, q, rest_end)
    for i in range(len(t) - 1):
        if i < skip_to:
            continue
        j = int(rest_end[i])
        if j > i + 1:
            # A rest (a long weld or wait): one configuration among the obstacles present at any
            # time of it, checked once; sample by sample only where that finds a collision.
            res = world.check_segment(q[i], q[i], float(t[i]), float(t[j]))
            checks += res.checks
            if res.free:
                skip_to = j
                continue
        res = world.check_segment(q[i], q[i + 1], float(t[i]), float(t[i + 1]))
        checks += res.checks
        if res.free:
            continue
        s_hit = res.s_contact or 0.0
        tc = float(t[i] + s_hit * (t[i + 1] - t[i]))
        contact = world.first_contact(q[i] + s_hit * (q[i + 1] - q[i]), tc)
        detail = contact.describe() if contact else "collision"
        last = collisions[-1] if collisions else None
        if last is not None and last.detail == detail and last.t_end is not None and last.t_end >= float(t[i]) - 1e-9:
            collisions[-1] = Violation(last.t, "collision", detail, t_end=float(t[i + 1]))
            continue
        if len(collisions) >= limit:
            break
        collisions.append(Violation(tc, "collision", detail, t_end=float(t[i + 1])))
        if stop_at_first:
            break
    out.extend(collisions)
    return MotionCheck(tuple(out), checks)


def _free_prefix(world: CollisionWorld, t: FloatArray, q: FloatArray, rest_end: IntArray) -> tuple[int, int]:
    """(the sample the loop of `check_motion` must start from, the checks it would have spent
    before it): its moves up to the first blocked one, checked in one call (`first_blocked`, the
    same answers and checks as its `check_segment`s one by one). From there on the loop checks as
    it always does."""
    starts, q0s, q1s, t0s, t1s = [], [], [], [], []
    i = 0
    while i < len(t) - 1:
        j = int(rest_end[i])
        nxt = max(i + 1, j)                      # a rest is one move at rest over all its time
        starts.append(i)
        q0s.append(q[i])
        q1s.append(q[i] if j > i + 1 else q[i + 1])
        t0s.append(t[i])
        t1s.append(t[nxt])
        i = nxt
    if not starts:
        return 0, 0
    found = world.first_blocked(np.array(q0s), np.array(q1s), np.array(t0s), np.array(t1s))
    return (len(t) if found.index is None else starts[found.index]), found.free_checks


def _rest_ends(q: FloatArray) -> IntArray:
    """For each sample i, the last sample j >= i of the rest it starts: samples i..j all within
    REST_Q_TOL_RAD of sample i (j = i where the robot moves on)."""
    n = len(q)
    out = np.arange(n)
    if n < 2:
        return out
    still = np.abs(np.diff(q, axis=0)).max(axis=1) <= REST_Q_TOL_RAD
    for i in range(n - 2, -1, -1):
        if still[i] and float(np.abs(q[int(out[i + 1])] - q[i]).max()) <= REST_Q_TOL_RAD:
            out[i] = out[i + 1]
    return out


def rate_violations(lim: JointLimits, names: tuple[str, ...], t: FloatArray, q: FloatArray,
                    velocity_rtol: float = VELOCITY_RTOL) -> list[Violation]:
    """Joint velocity and acceleration over their limits (finite differences of the samples), one
    violation per run of samples breaking the same limit of the same joint, with its peak."""
    out: list[Violation] = []
    dt = np.diff(t)
    v = np.diff(q, axis=0) / dt[:, None]
    for j, i0, i1 in _runs(np.abs(v) > lim.velocity * (1 + velocity_rtol)):
        peak = float(np.abs(v[i0:i1 + 1, j]).max())
        out.append(Violation(float(t[i0]), "velocity", f"{names[j]} up to {peak:.3f} rad/s > {lim.velocity[j]:.3f}",
                             t_end=float(t[i1 + 1])))
    a = np.diff(v, axis=0) / ((dt[:-1] + dt[1:]) / 2)[:, None]
    for j, i0, i1 in _runs(np.abs(a) > lim.acceleration * (1 + ACCELERATION_RTOL)):
        peak = float(np.abs(a[i0:i1 + 1, j]).max())
        out.append(Violation(float(t[i0 + 1]), "acceleration", f"{names[j]} up to {peak:.3f} rad/s^2 > "
                                                               f"{lim.acceleration[j]:.3f}", t_end=float(t[i1 + 1])))
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int, int]]:
    """(column, first row, last row) of every run of True down the columns of a (k, n) mask."""
    out: list[tuple[int, int, int]] = []
    for j in range(mask.shape[1]):
        rows = np.flatnonzero(mask[:, j])
        if not len(rows):
            continue
        breaks = np.flatnonzero(np.diff(rows) > 1)
        starts = np.concatenate([[rows[0]], rows[breaks + 1]])
        ends = np.concatenate([rows[breaks], [rows[-1]]])
        out.extend((j, int(a), int(b)) for a, b in zip(starts, ends))
    return out


def _end(t: FloatArray, i0: int, i1: int) -> float | None:
    return float(t[i1]) if i1 > i0 else None


@dataclass(frozen=True, slots=True)
class Clearance:
    """The smallest distance (m) between the robot or tool and anything it must not touch, the time
    it is reached (s) and between which bodies."""

    distance_m: float
    t: float
    between: str


# Samples of a rest this close to each other (rad) are one configuration: interpolating a rest
# moves no point farther than the lever arms (a few m) times this.
REST_Q_TOL_RAD = 1e-12

# `_closest_sample` screens the pairs due at a sample with the pre-filter's bounds when there are at
# least this many (one exact distance costs about as much as the screen).
SCREEN_MIN_PAIRS = 2


def min_clearance(world: CollisionWorld, t: FloatArray, q: FloatArray) -> Clearance | None:
    """The smallest distance over the samples of a motion, refined on the steps either side of
    the closest sample (10 sub-steps each); None when no pair is checked."""
    best_i, best = _closest_sample(world, q, t if world.has_dynamic else None)
    if not math.isfinite(best):
        return None
    best_t, best_q = float(t[best_i]), q[best_i]
    # Sub-steps either side of the closest sample: a pair is computed only where its distance at
    # that sample, less the most the motion since could take off it (`_closest_sample`'s bound),
    # is below the best so far, so the answer is the minimum over every pair, as `closest` gives.
    lever, factor = world.lever_arms, world.pair_approach_factors()
    at_best = world.pair_distances(q[best_i], np.arange(world.n_pairs))
    for k in (best_i - 1, best_i):
        if 0 <= k < len(t) - 1:
            for s in np.linspace(0.0, 1.0, MIN_CLEARANCE_SUBSTEPS + 1)[1:-1]:
                qs = q[k] + s * (q[k + 1] - q[k])
                ts = float(t[k] + s * (t[k + 1] - t[k]))
                wanted = at_best - factor * (np.abs(qs - q[best_i]) @ lever) < best
                if world.has_dynamic:
                    wanted &= world.active_pairs(ts)
                due = np.flatnonzero(wanted)
                if len(due):
                    d = float(np.min(world.pair_distances(qs, due)))
                    if d < best:
                        best, best_t, best_q = d, ts, qs
    pair = world.closest(best_q, best_t).pair
    between = f"{pair.body_a} and {pair.body_b}" if pair is not None else "?"
    return Clearance(float(best), best_t, between)


def _closest_sample(world: CollisionWorld, q: FloatArray, t: FloatArray | None = None) -> tuple[int, float]:
    """The first sample of the least distance over every enabled pair, and that distance.

    A pair is computed again only where the motion since it was last computed could have brought
    it below the best so far: no point moves farther than `sweep_length`, so a pair's distance
    shrinks by at most its approach factor times the sweep (1 against a static obstacle, 2 between
    two moving bodies). The answer is the minimum over every pair and sample, exactly as computing
    them all; the closest few pairs are computed at most samples, the rest rarely. Of the pairs
    due, those the pre-filter's bounding volumes put farther apart than the best so far are not
    computed either (`CollisionWorld.pairs_within`): about a tenth of the distances on the
    reference cell's plan.

    With `t` (a scene whose obstacles come and go), only the pairs counting at each sample's time
    are candidates there: a dynamic obstacle stands still while present, so the bound holds for
    its pairs across its absences too (their distances are geometry, not time).
    """
    n_pairs = world.n_pairs
    if n_pairs == 0 or len(q) == 0:
        return 0, math.inf
    lever = world.lever_arms
    factor = world.pair_approach_factors()
    everything = np.arange(n_pairs)
    last = world.pair_distances(q[0], everything)              # distance of each pair where last computed
    where = np.repeat(np.asarray(q[:1], dtype=float), n_pairs, axis=0)
    counts = world.active_pairs(float(t[0])) if t is not None else np.ones(n_pairs, dtype=bool)
    best_i, best = 0, float(np.min(last[counts])) if counts.any() else math.inf
    screen, screened = None, math.inf           # the pre-filter with margin `screened` (>= best)
    for i in range(1, len(q)):
        bound = last - factor * (np.abs(q[i] - where) @ lever)
        wanted = bound < best
        if t is not None:
            wanted &= world.active_pairs(float(t[i]))
        due = np.flatnonzero(wanted)
        if len(due) >= SCREEN_MIN_PAIRS and 0.0 < best < math.inf:
            # Of those, the pairs whose bounding volumes are farther apart than the best so far
            # are farther apart too and cannot lower it: not computed (their `last` stays where it
            # was, still a true distance). The screen is made again whenever the best falls (one
            # made for a larger distance would screen fewer pairs, never a wrong one); none once
            # two pieces touch or overlap (the bounds say nothing of how deep).
            if screened > best:
                screen, screened = world.distance_screen(best), best
            if screen is not None:
                due = world.pairs_within(q[i], wanted, screen)
        if not len(due):
            continue
        d = world.pair_distances(q[i], due)
        last[due] = d
        where[due] = q[i]
        low = float(np.min(d))
        if low < best:
            best_i, best = i, low
    return best_i, best
