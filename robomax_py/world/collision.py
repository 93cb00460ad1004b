"""Collision and clearance queries for joint configurations of a robot carrying its tool in a scene.

`CollisionWorld` is built once from (robot, scene, clearance) and answers, for q in rad (robot joint
order) and an optional time t in s: is_free, first_contact, distance, are_free (batch) and
segment_free (a straight joint-space move, subdivided by a bound on how far any point moves).

Geometry (one Pinocchio GeometryModel)
--------------------------------------
Robot link pieces (coal convex hulls from `robot.load_robot`), tool body and tips pieces (fixed to
the flange frame), static obstacles and dynamic obstacles (fixed to the base frame, posed by
`scene.build_scene`). Checked pairs are the *enabled* pairs of the allowed-collision matrix below.

Allowed-collision matrix: see `world.acm`, which builds the checked pairs and proves the rest apart.

Margins
-------
Robot/tool vs obstacle pairs use `clearance` as coal's `security_margin`: a configuration closer than
`clearance` to an obstacle counts as colliding. Self pairs use margin 0 (touching counts). coal's GJK
decides the boundary to ~1e-9 m (tested at +-0.1 mm).

coal caveat
-----------
Every pair request has `enable_contact` on: without it coal 3.0.3 misses some overlaps of convex
pieces (see `configure_requests`); the tests compare with `coal.collide` at coal's defaults.

Dynamic obstacles
-----------------
An obstacle with `present` windows exists at time t iff start <= t <= end for one window. With
t=None it counts as present (unknown time: conservative). In `segment_free` with t0/t1, checked state
k (time t_k) includes every dynamic obstacle present at any time in [t_(k-1), t_(k+1)] (its
neighbours' times, clipped to [t0, t1]): the robot stays within `max_step` of state k or k+1 during
[t_k, t_(k+1)], so an obstacle appearing between checked states is not missed, and a robot dwelling
at one q (q0 == q1, t0 < t1) is checked against everything present during the dwell.

Broad phase
-----------
With `broad_phase=True` and `prefilter=True` (the defaults) a configuration first goes through
`world.prefilter` (enclosing spheres, then oriented boxes, of every piece, forward kinematics and
all pair bounds in one compiled loop over a batch of configurations); only the pairs it cannot clear
go to coal, one exact pair test each, in pair order, stopping at the first collision. A cleared
pair is provably farther apart than its margin, so every verdict is coal's; a colliding
configuration's contact is still named by the manager below, so reports name the same pair as
before. Swept checks filter their states in growing blocks in coarse-to-fine order, so a blocked
move still stops after a few states. On the reference cell this is 2-4x the configurations per CPU
second of the manager alone (`tests/bench/bench_collision.py`). Without the filter (or for a chain
it does not model, see `world.prefilter`) queries run Pinocchio's BroadPhaseManager over coal's
NaiveCollisionManager: world-space AABBs of every piece, inflated by half the pair margin on each
side, are tested pairwise and only overlapping enabled pairs go to the narrow phase (GJK/BVH), with
early exit at the first collision. Everything runs in C++ per query (FK, placements, AABBs, narrow
phase); no Python loop over pairs. AABBs inflated by the margin contain every point within the
margin, so skipping AABB-separated pairs cannot change an answer (tests compare with coal.collide on
every enabled pair). Every piece gets a computed local AABB (Pinocchio's manager silently ignores a
piece whose local AABB has no volume; `scene` pads perfectly flat meshes for that reason). With
`broad_phase=False` every enabled pair goes to the narrow phase in a fixed order (tool and distal
links vs obstacles first), still with early exit. The naive manager (all AABB pairs, ~40 pieces) was
the fastest coal manager on the reference cell: per CPU second Naive 61k, SSaP 54k,
DynamicAABBTree 36k, SaP 10k configurations, all with identical answers.

Thread safety
-------------
A CollisionWorld owns its Pinocchio Data / GeometryData / broad-phase scratch and is NOT thread-safe.
Use `copy()` to get one per thread or worker: it shares the read-only geometry, pairs and ACM and
makes fresh scratch (no re-sampling).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.robot import RobotModel
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.world.acm import (
    KIND_DYNAMIC,
    KIND_LINK,
    KIND_OBJECT,
    KIND_TOOL_BODY,
    KIND_TOOL_TIPS,
    AllowedCollisions,
    CollisionOptions,
    DisabledPair,
    SharedGeometry,
    acm_samples,
    build_shared,
    configure_requests,
)
from robomax_py.world.bounds import support_points
from robomax_py.world.scene import Scene, SceneObject


@dataclass(frozen=True, slots=True)
class Contact:
    """Two bodies in contact (or the closest pair): names for rejection reasons.

    Bodies are named by kind: a robot link (URDF link name), "tool_body", "tool_tips", or an obstacle
    (its cell name; kind "object" or "dynamic"). `piece_*` names the collision piece. When one body
    is an obstacle it is body_b; between robot/tool bodies, body_a comes first in geometry order
    (robot link pieces in URDF order, then the tool).
    """

    body_a: str
    kind_a: str
    body_b: str
    kind_b: str
    piece_a: str
    piece_b: str

    def describe(self) -> str:
        """'tool_body vs cabin_panel'."""
        return f"{self.body_a} vs {self.body_b}"


@dataclass(frozen=True, slots=True)
class Proximity:
    """The closest enabled pair: distance in m (<= 0 when touching; penetration is approximate)."""

    distance: float
    pair: Contact | None              # None when no pair is enabled


@dataclass(frozen=True, slots=True)
class ConfigCheck:
    """One configuration check: the answer, one colliding pair, and the narrow-phase work done."""

    free: bool
    contact: Contact | None
    narrow_phase_tests: int           # pairs handed to GJK/BVH (after the broad phase, if any)

    def __bool__(self) -> bool:
        return self.free


@dataclass(frozen=True, slots=True)
class SegmentCheck:
    """One swept-segment check.

    free : whether every state of the subdivided segment is collision-free.
    checks : configurations checked (stops at the first colliding one).
    states : configurations the segment was subdivided into, both ends included.
    narrow_phase_tests : pairs handed to the narrow phase over all checked states.
    s_contact : fraction in [0, 1] along the segment of the colliding state found, or None.
    """

    free: bool
    checks: int
    states: int
    narrow_phase_tests: int
    s_contact: float | None

    def __bool__(self) -> bool:
        return self.free


class CollisionWorld:
    """Collision queries for one robot + tool in one scene (see the module docstring).

    Parameters
    ----------
    robot : RobotModel
        Kinematics and link collision pieces.
    scene : Scene
        Obstacles in the robot base frame and the tool pieces in the flange frame.
    clearance : float
        m, safety margin to obstacles (`process.clearance`).
    options : CollisionOptions
        Broad phase on/off and ACM sampling settings.

    Not thread-safe: owns Pinocchio scratch. `copy()` gives an independent world cheaply.
    """

    __slots__ = ("_active", "_active_before", "_allowed", "_callback", "_data", "_gdata", "_manager", "_pf", "_present", "_s")

    def __init__(
        self, robot: RobotModel, scene: Scene, clearance: float = 0.0, options: CollisionOptions = CollisionOptions()
    ) -> None:
        if not (math.isfinite(clearance) and clearance >= 0):
            raise ValueError(f"clearance must be a finite number >= 0 m, got {clearance}")
        if options.acm_samples < 1:
            raise ValueError("options.acm_samples must be >= 1")
        self._attach(build_shared(robot, scene, float(clearance), options))

    # ----------------------------------------------------------------------------------- set-up

    def _attach(self, shared: SharedGeometry) -> None:
        self._s = shared
        self._data = shared.model.createData()
        self._gdata = shared.geom_model.createData()
        configure_requests(self._gdata, shared.pair_margin)
        self._manager: Any = None
        self._callback: Any = None
        if shared.options.broad_phase:
            self._manager = pin.BroadPhaseManager_NaiveCollisionManager(shared.model, shared.geom_model, self._gdata)
            self._callback = pin.CollisionCallBackDefault(shared.geom_model, self._gdata, True)
        self._present: tuple[bool, ...] = tuple(True for _ in shared.dynamic_ids)
        self._active_before = np.arange(len(shared.pair_a) + 1, dtype=np.int64)
        self._active = np.ones(len(shared.pair_a), dtype=bool)
        self._allowed = np.ones(len(shared.pair_a), dtype=bool)     # pairs this world checks at all
        self._pf = shared.prefilter if shared.options.broad_phase and shared.options.prefilter else None

    def copy(self, broad_phase: bool | None = None, prefilter: bool | None = None) -> CollisionWorld:
        """A world sharing this one's geometry, pairs and ACM, with its own scratch (for another thread).

        `broad_phase` and `prefilter` override the settings (e.g. False for an exhaustive-narrow-phase
        comparison, or coal's broad phase alone).
        """
        shared = self._s
        options = dataclasses.replace(
            shared.options,
            broad_phase=shared.options.broad_phase if broad_phase is None else broad_phase,
            prefilter=shared.options.prefilter if prefilter is None else prefilter,
        )
        if options != shared.options:
            shared = dataclasses.replace(shared, options=options)
        other = CollisionWorld.__new__(CollisionWorld)
        other._attach(shared)
        if not self._allowed.all():                      # a restricted world's copy stays restricted
            other._restrict(self._allowed)
        return other

    def restricted(self, obstacles: bool = True, self_pairs: bool = True) -> CollisionWorld:
        """A copy that checks only the robot/tool pairs against obstacles, or only the robot/tool
        pairs among themselves (e.g. a configuration-space map of the cell's objects alone)."""
        s = self._s
        other = self.copy()
        kinds = [(s.pieces[int(a)].kind, s.pieces[int(b)].kind) for a, b in zip(s.pair_a, s.pair_b)]
        with_obstacle = np.array([KIND_OBJECT in k or KIND_DYNAMIC in k for k in kinds], dtype=bool)
        other._restrict(self._allowed & np.where(with_obstacle, obstacles, self_pairs))
        return other

    def _restrict(self, allowed: np.ndarray) -> None:
        self._allowed = allowed.copy()
        for p in np.flatnonzero(~allowed):
            self._gdata.deactivateCollisionPair(int(p))
        self._refresh_active()

    # ----------------------------------------------------------------------------- properties

    @property
    def clearance(self) -> float:
        """m, the margin to obstacles."""
        return self._s.clearance

    @property
    def options(self) -> CollisionOptions:
        return self._s.options

    @property
    def acm(self) -> AllowedCollisions:
        """The allowed-collision matrix: disabled pairs with reasons, enabled pairs."""
        return self._s.acm

    @property
    def layout_contacts(self) -> tuple[tuple[str, str], ...]:
        """(base piece, obstacle) pairs touching in the cell layout (never reported by queries)."""
        return self._s.layout_contacts

    @property
    def lever_arms(self) -> FloatArray:
        """(n,) m/rad (m/m for a prismatic joint): bound on how far any robot or tool point moves per
        unit of each joint (see `sweep_length`)."""
        return self._s.lever.copy()

    @property
    def n_pairs(self) -> int:
        """Number of enabled pairs (robot/tool vs obstacles and self)."""
        return len(self._s.pair_a)

    @property
    def geometry_model(self) -> pin.GeometryModel:
        """The Pinocchio GeometryModel holding every piece and the enabled pairs (read-only!)."""
        return self._s.geom_model

    def pair_margins(self) -> FloatArray:
        """(p,) m: security margin of each enabled pair (clearance or 0), in `geometry_model` order."""
        return self._s.pair_margin.copy()

    def pair_names(self, pair: int) -> Contact:
        """The bodies of enabled pair `pair` (index into `geometry_model.collisionPairs`)."""
        return self._contact(pair)

    # -------------------------------------------------------------------------------- queries

    def is_free(self, q: FloatArray, t: float | None = None) -> bool:
        """Whether configuration q is collision-free (clearance applied); stops at the first contact.

        Parameters
        ----------
        q : (n,) float, rad (m for prismatic joints)
        t : float or None
            s from program start, for dynamic obstacles; None: all dynamic obstacles present.
        """
        self._set_presence(t, t)
        q = np.asarray(q, dtype=np.float64)
        if self._pf is not None:
            _, pairs = self._pf.uncleared(q[None], self._active)
            return self._exact(q, pairs)[0]
        return not self._collides(q)

    def check(self, q: FloatArray, t: float | None = None) -> ConfigCheck:
        """`is_free` plus one colliding pair and the number of narrow-phase tests."""
        self._set_presence(t, t)
        q = np.asarray(q, dtype=np.float64)
        if self._pf is not None:
            # Free by the pre-filter and coal's exact test of what it left; a contact is named by
            # coal's broad phase, so a colliding configuration reports the same pair either way.
            _, pairs = self._pf.uncleared(q[None], self._active)
            free, tests = self._exact(q, pairs)
            if free:
                return ConfigCheck(free=True, contact=None, narrow_phase_tests=tests)
        hit = self._collides(q)
        pair = self._hit_pair() if hit else -1
        return ConfigCheck(
            free=not hit, contact=self._contact(pair) if hit else None, narrow_phase_tests=self._tests(pair)
        )

    def first_contact(self, q: FloatArray, t: float | None = None) -> Contact | None:
        """One colliding pair of configuration q (the first found), or None when q is free."""
        return self.check(q, t).contact

    def are_free(self, qs: FloatArray, t: float | None = None) -> BoolArray:
        """Batch `is_free`.

        Parameters
        ----------
        qs : (k, n) float, rad
        t : float or None, s (one time for the whole batch)

        Returns
        -------
        (k,) bool
        """
        qs = np.ascontiguousarray(qs, dtype=np.float64)
        if qs.ndim != 2:
            raise ValueError(f"qs must be (k, n), got shape {qs.shape}")
        self._set_presence(t, t)
        out = np.empty(len(qs), dtype=bool)
        s = self._s
        if self._pf is not None:
            offsets, pairs = self._pf.uncleared(qs, self._active)
            left = np.diff(offsets)
            out[:] = left == 0
            for n in np.flatnonzero(left).tolist():
                out[n] = self._exact(qs[n], pairs[offsets[n]:offsets[n + 1]])[0]
        elif self._manager is not None:
            model, data, manager, callback = s.model, self._data, self._manager, self._callback
            for i in range(len(qs)):
                out[i] = not pin.computeCollisions(model, data, manager, callback, qs[i])
        else:
            model, data, gm, gd = s.model, self._data, s.geom_model, self._gdata
            for i in range(len(qs)):
                out[i] = not pin.computeCollisions(model, data, gm, gd, qs[i], True)
        return out

    def distance(self, q: FloatArray, t: float | None = None) -> float:
        """Smallest distance (m) over every enabled pair: to obstacles and between robot/tool bodies.

        The plain geometric distance (clearance not subtracted); <= 0 when touching (penetration depth
        is approximate). +inf when no pair is enabled. q is free iff its distance to obstacles exceeds
        `clearance` and its self distance exceeds 0 (up to GJK tolerance).
        """
        return self.closest(q, t).distance

    def closest(self, q: FloatArray, t: float | None = None) -> Proximity:
        """The closest enabled pair of configuration q and its distance (m)."""
        self._set_presence(t, t)
        s = self._s
        idx = int(pin.computeDistances(s.model, self._data, s.geom_model, self._gdata, np.asarray(q, dtype=np.float64)))
        if idx >= len(s.pair_a):
            return Proximity(distance=math.inf, pair=None)
        return Proximity(distance=float(self._gdata.distanceResults[idx].min_distance), pair=self._contact(idx))

    def active_pairs(self, t: float | None = None) -> BoolArray:
        """(p,) bool: which enabled pairs count at time t (a dynamic obstacle's pairs only while it is
        present; None: every obstacle present), in the indexing of `pair_distances`."""
        self._set_presence(t, t)
        return np.asarray(self._active, dtype=bool).copy()

    def pair_distances(self, q: FloatArray, pairs: IntArray) -> FloatArray:
        """Distances (m) of the enabled pairs `pairs` (indices into `geometry_model.collisionPairs`)
        at q, every dynamic obstacle present; each as `closest` computes it."""
        s = self._s
        pin.updateGeometryPlacements(s.model, self._data, s.geom_model, self._gdata, np.asarray(q, dtype=np.float64))
        gm, gd = s.geom_model, self._gdata
        return np.array([pin.computeDistance(gm, gd, int(p)).min_distance for p in pairs], dtype=float)

    def pair_approach_factors(self) -> FloatArray:
        """(p,) how fast each enabled pair's distance can shrink, in units of `sweep_length`: 1 for
        a robot or tool piece against a static obstacle (one side moves), 2 between two moving pieces."""
        s = self._s
        kinds = [(s.pieces[int(a)].kind, s.pieces[int(b)].kind) for a, b in zip(s.pair_a, s.pair_b)]
        return np.array([1.0 if KIND_OBJECT in pair else 2.0 for pair in kinds])

    def window_starts(self, ta: float, tb: float) -> list[float]:
        """Times in (ta, tb] at which a dynamic obstacle appears, in order."""
        s = self._s
        return sorted({float(w0) for i in s.dynamic_ids for w0, _ in (s.obstacles[int(i)].present or ())
                       if ta < w0 <= tb})

    @property
    def has_dynamic(self) -> bool:
        """Whether some obstacle comes and goes (present only in time windows)."""
        return bool(self._s.dynamic_ids.size)

    def sweep_length(self, q0: FloatArray, q1: FloatArray) -> float:
        """Upper bound (m) on how far any robot or tool point moves along the joint-space line q0 -> q1.

        Point p moves at |dp/ds| <= sum_i |dq_i| dist(p, axis_i); `lever_arms`[i] bounds dist(p, axis_i)
        over every p beyond joint i and every configuration: for pieces on joint i, the exact largest
        distance of their (hull / bounding-box) vertices from the axis; for pieces on a descendant
        joint j, dist(o_c, axis_i) + sum of the joint-origin offsets from c to j (plus the travel of
        prismatic joints on the way) + the largest vertex distance from o_j (triangle inequality;
        c is the child of i towards j).
        """
        dq = np.abs(np.asarray(q1, dtype=float) - np.asarray(q0, dtype=float))
        return float(np.dot(self._s.lever, dq))

    def segment_free(
        self,
        q0: FloatArray,
        q1: FloatArray,
        t0: float | None = None,
        t1: float | None = None,
        max_step: float = TOL.sweep_step_m,
    ) -> bool:
        """Whether the straight joint-space move q0 -> q1 is collision-free (see `check_segment`)."""
        return self.check_segment(q0, q1, t0, t1, max_step).free

    def check_segment(
        self,
        q0: FloatArray,
        q1: FloatArray,
        t0: float | None = None,
        t1: float | None = None,
        max_step: float = TOL.sweep_step_m,
    ) -> SegmentCheck:
        """Check the straight joint-space move q0 -> q1, both ends included.

        The move is split into m = ceil(sweep_length(q0, q1) / max_step) equal joint steps, so no
        robot or tool point moves more than `max_step` between consecutive states; states are
        checked coarse-to-fine (ends, middle, quarters, ...), stopping at the first collision.

        Parameters
        ----------
        q0, q1 : (n,) float, rad
        t0, t1 : float or None, s
            Times at q0 and q1 (both or neither); state k is at t0 + k/m (t1 - t0). Dynamic obstacles
            are included per the module docstring. None: every dynamic obstacle present.
        max_step : float, m
        """
        if (t0 is None) != (t1 is None):
            raise ValueError("give both t0 and t1, or neither")
        if not max_step > 0:
            raise ValueError(f"max_step must be > 0 m, got {max_step}")
        q0 = np.asarray(q0, dtype=np.float64)
        q1 = np.asarray(q1, dtype=np.float64)
        dq = q1 - q0
        m = math.ceil(self.sweep_length(q0, q1) / max_step - 1e-12)
        timed = t0 is not None and t1 is not None and self._s.dynamic_ids.size > 0
        if m == 0:
            m = 1 if timed and t0 != t1 else 0
        order = bisection_order(m)
        fractions = order / m if m else np.zeros(1)
        states = q0 + fractions[:, None] * dq
        states[order == m] = q1                       # the end exactly, not q0 + 1.0 * dq
        checks = tests = 0
        if not timed:
            self._set_presence(None, None)
        if not timed and self._pf is not None:        # the common case: pre-filter, then coal's exact test
            return self._scan(states, fractions, m + 1)
        if not timed and self._manager is not None:
            model, data, manager, callback = self._s.model, self._data, self._manager, self._callback
            for k in range(len(order)):
                hit = pin.computeCollisions(model, data, manager, callback, states[k])
                tests += callback.count
                if hit:
                    return SegmentCheck(False, k + 1, m + 1, int(tests), float(fractions[k]))
            return SegmentCheck(True, len(order), m + 1, int(tests), None)
        start = float(t0) if t0 is not None else 0.0
        span = float(t1) - start if t1 is not None else 0.0
        if self._pf is not None:
            return self._scan_timed(states, fractions, order, m, start, span)
        for k, step in enumerate(order):
            if timed:
                ta = start + max(step - 1, 0) / m * span
                tb = start + min(step + 1, m) / m * span
                self._set_presence(min(ta, tb), max(ta, tb))
            hit = self._collides(states[k])
            checks += 1
            tests += self._tests(self._hit_pair() if hit else -1)
            if hit:
                return SegmentCheck(False, checks, m + 1, tests, float(fractions[k]))
        return SegmentCheck(True, checks, m + 1, tests, None)

    def check_path(self, points: FloatArray, max_step: float = TOL.sweep_step_m) -> SegmentCheck:
        """Check the joint-space polyline through `points` (k, n), every dynamic obstacle present.

        Exactly the states `check_segment` checks on each segment, a state shared by two segments
        once, in coarse-to-fine order over the whole polyline (a blocked path is found early); the
        polyline is free iff every `check_segment` of its segments is. s_contact is the colliding
        state's fraction of the states, start to end.
        """
        if not max_step > 0:
            raise ValueError(f"max_step must be > 0 m, got {max_step}")
        pts = np.asarray(points, dtype=np.float64)
        if pts.ndim != 2 or len(pts) == 0:
            raise ValueError("points must be a non-empty (k, n) array")
        pieces = [pts[:1]]
        for q0, q1 in itertools.pairwise(pts):
            m = math.ceil(self.sweep_length(q0, q1) / max_step - 1e-12)
            if m == 0:
                continue                  # check_segment checks q0 alone: already in
            states = q0 + (np.arange(1, m + 1) / m)[:, None] * (q1 - q0)
            states[-1] = q1               # the end exactly, as check_segment
            pieces.append(states)
        states = np.concatenate(pieces)
        self._set_presence(None, None)
        last = len(states) - 1
        order = bisection_order(last)
        if self._pf is not None:
            return self._scan(states[order], order / last if last else np.zeros(len(order)), len(states))
        tests = 0
        for k, idx in enumerate(order):
            hit = self._collides(states[idx])
            tests += self._tests(self._hit_pair() if hit else -1)
            if hit:
                return SegmentCheck(False, k + 1, len(states), int(tests), float(idx) / last if last else 0.0)
        return SegmentCheck(True, len(order), len(states), int(tests), None)

    def path_free(self, points: FloatArray, max_step: float = TOL.sweep_step_m) -> bool:
        """Whether the joint-space polyline through `points` is collision-free (see `check_path`)."""
        return self.check_path(points, max_step).free

    # ------------------------------------------------------------------------------- internals

    def _exact(self, q: FloatArray, pairs: IntArray) -> tuple[bool, int]:
        """coal's verdict on the pairs the pre-filter left (in pair order): (free, pairs tested)."""
        if not pairs.size:
            return True, 0
        s, gd = self._s, self._gdata
        gm = s.geom_model
        pin.updateGeometryPlacements(s.model, self._data, gm, gd, q)
        for n, p in enumerate(pairs.tolist()):
            if pin.computeCollision(gm, gd, p):
                return False, n + 1
        return True, len(pairs)

    def _scan_timed(self, states: FloatArray, fractions: FloatArray, order: IntArray, m: int, start: float,
                    span: float) -> SegmentCheck:
        """`_scan` where dynamic obstacles come and go: state k (of `order`) counts the obstacles
        present during the time between its neighbouring steps, so the states are scanned in runs
        that share one presence, each with the pairs active then, stopping at the first collision."""
        windows = [(start + max(int(step) - 1, 0) / m * span, start + min(int(step) + 1, m) / m * span) for step in order]
        dynamic = [self._s.obstacles[int(i)] for i in self._s.dynamic_ids]
        presence = [tuple(_present_during(o, min(a, b), max(a, b)) for o in dynamic) for a, b in windows]
        tests, k0 = 0, 0
        while k0 < len(order):
            k1 = k0 + 1
            while k1 < len(order) and presence[k1] == presence[k0]:
                k1 += 1
            a, b = windows[k0]
            self._set_presence(min(a, b), max(a, b))
            res = self._scan(states[k0:k1], fractions[k0:k1], m + 1)
            tests += res.narrow_phase_tests
            if not res.free:
                return SegmentCheck(False, k0 + res.checks, m + 1, tests, res.s_contact)
            k0 = k1
        return SegmentCheck(True, len(order), m + 1, tests, None)

    def _scan(self, states: FloatArray, fractions: FloatArray, n_states: int) -> SegmentCheck:
        """Check `states` in the given order, stopping at the first collision (pre-filter on)."""
        assert self._pf is not None
        tests = 0
        start, chunk = 0, _FIRST_CHUNK
        while start < len(states):
            block = states[start:start + chunk]
            offsets, pairs = self._pf.uncleared(block, self._active)
            for i in np.flatnonzero(np.diff(offsets)):
                free, n = self._exact(block[i], pairs[offsets[i]:offsets[i + 1]])
                tests += n
                if not free:
                    k = start + int(i)
                    return SegmentCheck(False, k + 1, n_states, tests, float(fractions[k]))
            start += len(block)
            chunk *= 4
        return SegmentCheck(True, len(states), n_states, tests, None)

    def _collides(self, q: FloatArray) -> bool:
        s = self._s
        if self._manager is not None:
            return bool(pin.computeCollisions(s.model, self._data, self._manager, self._callback, q))
        return bool(pin.computeCollisions(s.model, self._data, s.geom_model, self._gdata, q, True))

    def _hit_pair(self) -> int:
        """Index of the pair that stopped the last colliding query."""
        if self._manager is not None:
            return int(self._callback.collisionPairIndex)
        # Exhaustive mode stops at the first colliding active pair, in order; later results are stale.
        results, active = self._gdata.collisionResults, self._gdata.activeCollisionPairs
        for p in range(len(self._s.pair_a)):
            if active[p] and results[p].isCollision():
                return p
        raise RuntimeError("collision reported but no colliding pair found")  # pragma: no cover

    def _tests(self, hit_pair: int) -> int:
        """Narrow-phase tests of the last query."""
        if self._manager is not None:
            return int(self._callback.count)
        return int(self._active_before[hit_pair + 1] if hit_pair >= 0 else self._active_before[-1])

    def _set_presence(self, ta: float | None, tb: float | None) -> None:
        """Activate the pairs of dynamic obstacles present at some time in [ta, tb] (None: present)."""
        s = self._s
        if not s.dynamic_ids.size:
            return
        present = tuple(
            True if ta is None or tb is None else _present_during(s.obstacles[int(i)], ta, tb) for i in s.dynamic_ids
        )
        if present == self._present:
            return
        for on_now, on_before, pairs in zip(present, self._present, s.dynamic_pairs):
            if on_now == on_before:
                continue
            for p in pairs:
                if on_now and self._allowed[p]:
                    self._gdata.activateCollisionPair(int(p))
                else:
                    self._gdata.deactivateCollisionPair(int(p))
        self._present = present
        self._refresh_active()

    def _refresh_active(self) -> None:
        active = np.fromiter(self._gdata.activeCollisionPairs, dtype=bool, count=len(self._s.pair_a))
        self._active = active
        self._active_before = np.concatenate([[0], np.cumsum(active)]).astype(np.int64)

    def _contact(self, pair: int) -> Contact:
        s = self._s
        a, b = s.pieces[int(s.pair_a[pair])], s.pieces[int(s.pair_b[pair])]
        return Contact(body_a=a.body, kind_a=a.kind, body_b=b.body, kind_b=b.kind, piece_a=a.name, piece_b=b.name)


_FIRST_CHUNK = 8     # states the first pre-filter call of a scan covers (blocked moves stop early)


def bisection_order(m: int) -> IntArray:
    """State indices 0..m in coarse-to-fine (dyadic) order, each exactly once.

    The ends first, then the interior k by decreasing lowest set bit of k, then increasing k:
    m = 8 gives 0, 8, 4, 2, 6, 1, 3, 5, 7 (bisection); for any m the checked states spread over the
    whole segment before any two neighbours are checked.
    """
    if m <= 0:
        return np.zeros(1, dtype=np.int64)
    interior = np.arange(1, m, dtype=np.int64)
    lowbit = interior & -interior
    return np.concatenate([[0, m], interior[np.argsort(-lowbit, kind="stable")]]).astype(np.int64)


def _present_during(obj: SceneObject, ta: float, tb: float) -> bool:
    if obj.present is None:
        return True
    return any(w0 <= tb and w1 >= ta for w0, w1 in obj.present)


# ---------------------------------------------------------------------------------- building



__all__ = [
    "KIND_DYNAMIC", "KIND_LINK", "KIND_OBJECT", "KIND_TOOL_BODY", "KIND_TOOL_TIPS", "AllowedCollisions",
    "CollisionOptions", "CollisionWorld", "ConfigCheck", "Contact", "DisabledPair", "Proximity", "SegmentCheck",
    "acm_samples", "bisection_order", "support_points",
]
