"""The detour searches of the sequencer (`plan.graph.Sequencer`): a lift over the obstacle, the
roadmap's or the local C-space map's path, the gun withdrawn off the flange, and what a pair with
no detour found is given instead (more straight checks, then the pair given up)."""

from __future__ import annotations

import itertools

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.cheapest_first import cheapest_first
from robomax_py.plan.cspace_detour import grid_detour
from robomax_py.plan.graph_knowledge import MAX_FAILED_DETOURS, SequencerKnowledge
from robomax_py.plan.program_frames import cell_program_frames
from robomax_py.plan.roadmap import Detour
from robomax_py.plan.rrt_detour import rrt_detour
from robomax_py.plan.sequence import (
    HOME,
)
from robomax_py.plan.tcp_detour import tcp_detour
from robomax_py.robot import fk_tcp
from robomax_py.robot.ik.turns import wrap_to_pi
from robomax_py.robot.solve import solve_all
from robomax_py.timing import (
    polyline_time_estimate,
    ptp_time_estimate,
)
from robomax_py.transforms import invert

LIFT_HEIGHTS_M = (0.08, 0.15, 0.25, 0.4)
# The ways a lift moves each end (`Sequencer._lift_detour`): world up, back along the approach line, both.
LIFT_KINDS = ("up", "back", "up_back")
# Withdrawing the gun off a flange (`Sequencer._withdrawn_detour`): directions perpendicular to the
# electrode axis, distances (m; spots lie ~20 mm from the edge the C wraps round, and its jaws
# reach a little past the electrodes), and exit pairs tried per detour.
WITHDRAW_DIRECTIONS = 8
WITHDRAW_M = (0.06, 0.12)
WITHDRAW_PAIRS = 6
# Stepping round a clamp on the flange's other side (`Sequencer._open_side_detour`): how far (m) the
# gun, once off the flange, moves along its electrode axis before it crosses. A toggle clamp's jaw
# stands a few centimetres proud of the flange and the C reaches past its tips: the shortest step
# that clears both is of the lift heights' order, tried in 5 cm steps (longer ones for deeper tools).
OPEN_SIDE_M = (0.1, 0.15, 0.2, 0.25, 0.3, 0.4)


def _distinct(path: FloatArray) -> FloatArray:
    """The polyline without repeated waypoints."""
    keep = [0] + [k for k in range(1, len(path)) if not np.allclose(path[k], path[k - 1])]
    return path[keep]



class SequencerDetours(SequencerKnowledge):
    """Detours searched for blocked moves (the base of `Sequencer`)."""

    def _lift_detour(self, i: int, a: int, j: int, b: int) -> Detour | None:
        """Up, across, down: the TCP moved away by h at both ends in the same IK branch, for clamps.

        The cheapest kind of detour an operator would teach, tried for rising h before the roadmap:
        first straight up; then backed off along each spot's approach line (away from the part,
        where the clamps of the row above block the way up on a stacked flange); then both at once.
        """
        qa, qb = self.q(i)[a], self.q(j)[b]
        checks = 0
        ends_at = [(qa, i, a), (qb, j, b)]
        for kind in LIFT_KINDS:
            for h in LIFT_HEIGHTS_M:
                ends = []
                for q, idx, col in ends_at:
                    if idx == HOME:
                        ends.append(q)
                        continue
                    lifted = self._lifted(idx, col, kind, h)
                    if lifted is None:
                        break
                    ends.append(lifted)
                if len(ends) < 2 or not self.limits.contains(np.array(ends)).all():
                    continue
                path = np.array([qa, ends[0], ends[1], qb])
                free, used = self._path_free(i, path)
                checks += used
                if free:
                    wp = _distinct(path)
                    return Detour(wp, polyline_time_estimate(wp, self.limits), checks)
        self.checks += checks
        return None

    def _lifted(self, idx: int, col: int, kind: str, h: float) -> FloatArray | None:
        """Spot idx's candidate col with its TCP moved h (m) `kind` of away (`_lift_detour`), in the
        candidate's IK column, wrapped towards it; None where that column has no solution. Cached:
        a candidate ends the lifts of every pair it is in, each asking the same inverse kinematics
        (most of a clamped cell's lift searches, which mostly fail)."""
        key = (idx, col, kind, h)
        if key in self._lift_cache:
            return self._lift_cache[key]
        q = self.q(idx)[col]
        T = fk_tcp(self.robot, q)
        T[:3, 3] += h * self._away(idx, col, kind)
        table = solve_all(self.robot, T[None], q_hint=q)
        column = int(self.spots[idx].column[col])
        out = q + wrap_to_pi(table.q[0, column] - q) if table.valid[0, column] else None
        self._lift_cache[key] = out
        return out

    def _tcp_detour(self, i: int, a: int, j: int, b: int) -> Detour | None:
        """Straight TCP lines between two spots' candidates (`plan.tcp_detour`): the single line,
        else through via points lifted as `_lift_detour` lifts its ends (up, back along the
        approach lines, both), for rising heights. Not from or to home: home is a joint posture."""
        if HOME in (i, j):
            return None
        self.tcp_detour_searches += 1
        aways = [(self._away(i, a, kind), self._away(j, b, kind)) for kind in LIFT_KINDS]
        options = self.options
        found = tcp_detour(self.robot, self.world_from(i), self.limits, self.q(i)[a], self.q(j)[b], aways,
                           LIFT_HEIGHTS_M, cell_program_frames(self.cell).written, options.speed,
                           options.detour_tcp_speed * options.speed)
        if found.detour is None:
            self.checks += found.checks
            return None
        self.tcp_detours_found += 1
        return found.detour

    def _up(self) -> FloatArray:
        """World up in the robot base frame."""
        up: FloatArray = invert(np.asarray(self.cell.T_world_base))[:3, :3] @ np.array([0.0, 0.0, 1.0])
        return up

    def _path_free(self, i: int, path: FloatArray) -> tuple[bool, int]:
        """Whether every leg of a joint polyline leaving stop i is free (stops at the first blocked
        one), and the collision checks spent."""
        checks = 0
        for p0, p1 in itertools.pairwise(path):
            if np.allclose(p0, p1):
                continue
            res = self.world_from(i).check_segment(p0, p1)
            checks += res.checks
            if not res.free:
                return False, checks
        return True, checks

    def _moved(self, idx: int, col: int, q: FloatArray, offsets: FloatArray) -> FloatArray:
        """(k, n) configurations of spot idx's candidate col with its TCP (at q) moved by each of
        `offsets` (k, 3), base frame, in the candidate's IK column, wrapped towards q; NaN rows
        where that column has no solution within the limits."""
        T = np.repeat(fk_tcp(self.robot, q)[None], len(offsets), axis=0)
        T[:, :3, 3] += offsets
        table = solve_all(self.robot, T, q_hint=q)
        column = int(self.spots[idx].column[col])
        out = q[None, :] + wrap_to_pi(table.q[:, column] - q[None, :])
        out[~table.valid[:, column]] = np.nan
        out[~self.limits.contains(out)] = np.nan
        return out

    def _exits(self, idx: int, col: int) -> list[FloatArray]:
        """Where the gun can leave spot idx's approach point (candidate col) by a free straight
        move that takes it off the flange: the TCP moved perpendicular to the electrode axis in
        WITHDRAW_DIRECTIONS directions by each of WITHDRAW_M (the sheet leaves the C through its
        mouth only one way; which depends on the tool and the candidate's spin, so every direction
        is tried), nearest first. Cached per candidate: a spot's candidate joins many pairs."""
        key = (idx, col)
        got = self._exit_cache.get(key)
        if got is not None:
            return got
        if idx == HOME:
            self._exit_cache[key] = [self.home[0]]
            return self._exit_cache[key]
        q = self.q(idx)[col]
        R = fk_tcp(self.robot, q)[:3, :3]
        angles = 2 * np.pi * np.arange(WITHDRAW_DIRECTIONS) / WITHDRAW_DIRECTIONS
        dirs = np.cos(angles)[:, None] * R[:, 0][None, :] + np.sin(angles)[:, None] * R[:, 1][None, :]
        offsets = np.concatenate([w * dirs for w in WITHDRAW_M])
        moved = self._moved(idx, col, q, offsets)
        out: list[FloatArray] = []
        for row in moved:
            if np.isnan(row).any():
                continue
            res = self.world_from(idx).check_segment(q, row)
            self.checks += res.checks
            if res.free:
                out.append(row)
        self._exit_cache[key] = out
        return out

    def _exit_pairs(self, i: int, a: int, j: int, b: int) -> tuple[FloatArray, FloatArray, list[tuple[int, int]]] | None:
        """Both ends' exits off the flange (`_exits`) and at most WITHDRAW_PAIRS (start exit, goal
        exit) index pairs, fastest first by the rest-to-rest estimate leave + across + arrive;
        None where either end has no exit."""
        qa, qb = self.q(i)[a], self.q(j)[b]
        starts, goals = self._exits(i, a), self._exits(j, b)
        if not starts or not goals:
            return None
        sa, sb = np.array(starts), np.array(goals)
        sp = 1.0 if self.options.speed is None else self.options.speed
        leave = np.asarray(ptp_time_estimate(qa[None, :], sa, self.limits, sp))
        across = np.asarray(ptp_time_estimate(sa[:, None, :], sb[None, :, :], self.limits, sp))
        arrive = np.asarray(ptp_time_estimate(sb, qb[None, :], self.limits, sp))
        est = leave[:, None] + across + arrive[None, :]
        ranked = np.argsort(est, axis=None, kind="stable")[:WITHDRAW_PAIRS]
        return sa, sb, [(int(x), int(y)) for x, y in (np.unravel_index(int(flat), est.shape) for flat in ranked)]

    def _raised(self, idx: int, col: int, e: int, h: float) -> FloatArray:
        """Exit e of spot idx's candidate col (`_exits`) with the TCP raised by h (world up), as
        `_moved` gives it (NaN where the column has none). Cached: the withdrawn detours of every pair
        a candidate ends asked the same inverse kinematics again (a third of a clamped bracket's
        failed detour searches)."""
        key = (idx, col, e, h)
        got = self._raised_cache.get(key)
        if got is None:
            got = self._raised_cache[key] = self._moved(idx, col, self._exits(idx, col)[e], (h * self._up())[None])[0]
        return got

    def _withdrawn_detour(self, i: int, a: int, j: int, b: int) -> Detour | None:
        """Off the flange, (up,) across, (down,) onto the flange: each end leaves its approach point
        perpendicular to the electrode axis (`_exits`), then the straight move between the two exits,
        else both exits raised by h (world up) for rising h. This is how the gun is turned over a
        flange between two faces of a part: the C slid off one edge, turned clear of the part, slid
        onto the other edge. At most WITHDRAW_PAIRS exit pairs are tried, fastest first."""
        qa, qb = self.q(i)[a], self.q(j)[b]
        exits = self._exit_pairs(i, a, j, b)
        if exits is None:
            return None
        sa, sb, pairs = exits
        checks = 0
        for heights in ((0.0,), LIFT_HEIGHTS_M):
            for x, y in pairs:
                ea, eb = sa[x], sb[y]
                for h in heights:
                    if h == 0.0:
                        path = np.array([qa, ea, eb, qb])
                    else:
                        ra = ea if i == HOME else self._raised(i, a, x, h)
                        rb = eb if j == HOME else self._raised(j, b, y, h)
                        if np.isnan(ra).any() or np.isnan(rb).any():
                            continue
                        path = np.array([qa, ea, ra, rb, eb, qb])
                    free, used = self._path_free(i, path)
                    checks += used
                    if free:
                        wp = _distinct(path)
                        return Detour(wp, polyline_time_estimate(wp, self.limits), checks)
        self.checks += checks
        return None

    def _open_side_detour(self, i: int, a: int, j: int, b: int) -> Detour | None:
        """Off the flange, out to the side of the part opposite the approach, across, back in.

        A clamp that grips the flange edge blocks the straight move along the row; the lift over it
        is blocked too where another clamp stands above (stacked rows of flange: lifting the gun
        lifts the forearm into the clamp of the row above), and the lift's "back" runs along the
        approach line, the side the clamps' arms and posts may occupy. A programmer slides the C off
        the edge (`_exits`), steps it along the electrode axis to the other side of the flange, in
        front of the clamp's jaw, moves across there and comes back the same way. The step goes
        against the approach line (-TCP z at each end; +z is the lift's "back"), for rising distances
        of OPEN_SIDE_M, through at most WITHDRAW_PAIRS exit pairs, fastest first. Not from or to
        home: home is a joint posture, not on a flange."""
        if HOME in (i, j):
            return None
        qa, qb = self.q(i)[a], self.q(j)[b]
        exits = self._exit_pairs(i, a, j, b)
        if exits is None:
            return None
        sa, sb, pairs = exits
        steps = -np.array(OPEN_SIDE_M)[:, None]            # against the approach line, rising
        sides: dict[tuple[int, int], FloatArray] = {}     # (end, exit) -> (k, n) stepped configurations
        legs: dict[tuple[int, ...], bool] = {}            # a leg's verdict, for the exit pairs sharing it
        checks = 0

        def free(key: tuple[int, ...], p0: FloatArray, p1: FloatArray) -> bool:
            nonlocal checks
            if key not in legs:
                res = self.world_from(i).check_segment(p0, p1)
                checks += res.checks
                legs[key] = res.free
            return legs[key]

        for x, y in pairs:
            ea, eb = sa[x], sb[y]
            for end, e, idx, col in ((0, x, i, a), (1, y, j, b)):
                if (end, e) not in sides:
                    q_exit = (sa if end == 0 else sb)[e]
                    sides[(end, e)] = self._moved(idx, col, q_exit, steps * fk_tcp(self.robot, q_exit)[:3, 2][None, :])
            for k, (ra, rb) in enumerate(zip(sides[(0, x)], sides[(1, y)], strict=True)):
                if np.isnan(ra).any() or np.isnan(rb).any():
                    continue
                # Cheapest verdicts first: the short legs each end shares with other exit pairs.
                if (free((0, x), qa, ea) and free((1, y), eb, qb) and free((0, x, k), ea, ra)
                        and free((1, y, k), rb, eb) and free((2, x, y, k), ra, rb)):
                    wp = _distinct(np.array([qa, ea, ra, rb, eb, qb]))
                    return Detour(wp, polyline_time_estimate(wp, self.limits), checks)
        self.checks += checks
        return None

    def _faster(self, first: Detour | None, second: Detour | None) -> Detour | None:
        """The detour of the lower time estimate (the second where equal); the other's checks are
        counted as spent (a detour taken carries its own)."""
        if first is None or second is None:
            return first or second
        best, other = (first, second) if first.time_estimate < second.time_estimate else (second, first)
        self.checks += other.checks
        return best

    def _searched_detour(self, i: int, qa: FloatArray, qb: FloatArray) -> Detour | None:
        """The roadmap's detour, the local C-space map's, the faster of both, or the learned C-space
        map's (`planner.detours`)."""
        kind = self.options.detours                   # resolved from the cell (`resolved_options`)
        if kind not in ("roadmap", "cspace", "both", "learned"):
            raise ValueError(f"planner.detours must be roadmap, cspace, both or learned, got {kind!r}")
        if kind == "learned":
            if self.learned is None:
                raise ValueError("planner.detours: learned needs the plan's learned map (LearnedDetours.build)")
            det, spent = self.learned.query(self.world_from(i), qa, qb)
            if det is None:
                self.checks += spent           # a found detour's checks are counted with it
            return det
        on_roadmap = self.roadmap_from(i).query(qa, qb) if kind in ("roadmap", "both") else None
        on_map: Detour | None = None
        if kind in ("cspace", "both"):
            on_map, spent = grid_detour(self.world_from(i), self.limits, qa, qb)
            if on_map is None:
                self.checks += spent           # a found detour's checks are counted with it
        return self._faster(on_map, on_roadmap)  # the roadmap's where both estimate the same

    def _away(self, idx: int, col: int, kind: str) -> FloatArray:
        """The direction (base frame) a lift of `kind` (LIFT_KINDS) moves spot idx's candidate col:
        world up, back along its approach line, or halfway between."""
        up = self._up()
        if kind == "up":
            return up
        back = self._back_direction(idx, col)
        return back if kind == "back" else (up + back) / np.sqrt(2.0)

    def _back_direction(self, idx: int, col: int) -> FloatArray:
        """Unit vector (base frame) from the spot to its approach point: away from the part."""
        c = self.spots[idx]
        d = fk_tcp(self.robot, c.q_app[col])[:3, 3] - fk_tcp(self.robot, c.q_spot[col])[:3, 3]
        norm = float(np.linalg.norm(d))
        return d / norm if norm > 0 else np.zeros(3)

    def _new_detour(self, i: int, a: int, j: int, b: int, last_resort: bool = False) -> None:
        # Lift first: on clamp cells it is found in ~1,000 checks; the roadmap is the general fallback.
        # Where neither finds a way, the gun's C may still hold the sheet at both approach points
        # (moves between two faces of a part): off the flange first (`_withdrawn_detour`).
        # The learned map is the method under study: every detour is its own, nothing else is tried.
        learned_only = self.options.detours == "learned"
        if learned_only:
            det = self._searched_detour(i, self.q(i)[a], self.q(j)[b])
        else:
            # `planner.detour_moves: lin`: straight TCP lines first (paper 003's detours), joint-space
            # detours only where none is found.
            det = self._tcp_detour(i, a, j, b) if self.options.detour_moves == "lin" else None
            det = det or self._lift_detour(i, a, j, b)
            if det is None:
                # Where the lift is blocked, the open side is found cheaply where the roadmap often
                # finds nothing (a clamp with another above it), but where the roadmap finds a way
                # it may be the faster one: both are asked and the faster estimate taken, so where
                # the roadmap's detours are the faster a cell plans as it did.
                det = self._faster(self._open_side_detour(i, a, j, b),
                                   self._searched_detour(i, self.q(i)[a], self.q(j)[b]))
            det = det or self._withdrawn_detour(i, a, j, b)
        if det is None and last_resort and not learned_only:
            # A tour with no other way on (`_open_dead_end`): trees grown between the two ends find
            # narrow ways out that the shared roadmap samples too thinly (a few CPU seconds at most).
            det, spent = rrt_detour(self.world_from(i), self.limits, self.q(i)[a], self.q(j)[b], self.rng)
            if det is None:
                self.checks += spent
        if det is None:
            # No way found for this exact pair: make sure the optimiser stops choosing it.
            self.no_way.setdefault((i, j), set()).add((a, b))
            self.no_way.setdefault((j, i), set()).add((b, a))
            pair = (min(i, j), max(i, j))
            self.failed_detours[pair] += 1
            if self.failed_detours[pair] >= MAX_FAILED_DETOURS:
                # Two spots with hundreds of candidates each would otherwise cost a round per
                # banned candidate pair: the spots are taken to be unconnected except through
                # detours known at their ends.
                self.unconnected.add(pair)
            self._forget(i, j)
            if (min(i, j), max(i, j)) in self.detour_only:
                self._retry_straight(i, j)
            return
        self.checks += det.checks
        self.detours.append((i, j, det))
        # Every pair sharing an end spot with this detour may now use it (`vias_for`).
        for table in (self._matrices, self._full):
            for key in [key for key in table if not {i, j}.isdisjoint(key)]:
                del table[key]
        self._record_leg(i, a, j, b, len(self.detours) - 1, True)   # its ends are this pair's configurations

    def _retry_straight(self, i: int, j: int) -> bool:
        """A detour-only spot pair without a detour: check up to `straight_tries` straight moves between
        candidate pairs not yet checked, cheapest first; a free one lifts the detour-only mark.

        The pair may have been marked detour-only after a single blocked probe (`_probe_pairs`) while
        other candidate pairs of the same two spots move freely (a clamp beside one orientation only).
        """
        est = self.estimate(i, j)
        known = self.straight.get((i, j), {})
        banned = self.no_way.get((i, j), set())
        tried = 0
        for flat in cheapest_first(est):
            if tried >= self.options.straight_tries:
                break
            a, b = (int(x) for x in np.unravel_index(int(flat), est.shape))
            if (a, b) in known or (a, b) in banned or not np.isfinite(est[a, b]):
                continue
            tried += 1
            if self._try_straight(i, a, j, b):
                self._forget(i, j)
                return True
        return False
