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
import math

import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.robot import RobotModel
from robomax_py.world.acm import (
    KIND_DYNAMIC,
    KIND_LINK,
    KIND_OBJECT,
    KIND_TOOL_BODY,
    KIND_TOOL_TIPS,
    AllowedCollisions,
    CollisionOptions,
    DisabledPair,
    acm_samples,
    build_shared,
)
from robomax_py.world.bounds import support_points
from robomax_py.world.collision_results import (
    ConfigCheck,
    Contact,
    MovesCheck,
    Proximity,
    SegmentCheck,
    bisection_order,
)
from robomax_py.world.collision_sweeps import SweptChecks
from robomax_py.world.prefilter import Prefilter
from robomax_py.world.scene import Scene


class CollisionWorld(SweptChecks):
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

    __slots__ = ()

    def __init__(
        self, robot: RobotModel, scene: Scene, clearance: float = 0.0, options: CollisionOptions = CollisionOptions()
    ) -> None:
        if not (math.isfinite(clearance) and clearance >= 0):
            raise ValueError(f"clearance must be a finite number >= 0 m, got {clearance}")
        if options.acm_samples < 1:
            raise ValueError("options.acm_samples must be >= 1")
        self._attach(build_shared(robot, scene, float(clearance), options))

    # ----------------------------------------------------------------------------------- set-up

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
            _, pairs, undecided = self._pf.left_for_coal(q[None], self._active)
            return self._exact(q, pairs.tolist(), bool(undecided[0]))[0]
        return not self._collides(q)

    def check(self, q: FloatArray, t: float | None = None) -> ConfigCheck:
        """`is_free` plus one colliding pair and the number of narrow-phase tests."""
        self._set_presence(t, t)
        q = np.asarray(q, dtype=np.float64)
        if self._pf is not None:
            # Free by the pre-filter and coal's exact test of what it left; a contact is named by
            # coal's broad phase, so a colliding configuration reports the same pair either way.
            _, pairs, undecided = self._pf.left_for_coal(q[None], self._active)
            free, tests = self._exact(q, pairs.tolist(), bool(undecided[0]))
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
            offsets, pairs, undecided = self._pf.left_for_coal(qs, self._active)
            left = np.diff(offsets)
            out[:] = left == 0
            at, listed, pending = offsets.tolist(), pairs.tolist(), undecided.tolist()
            for n in np.flatnonzero(left).tolist():
                out[n] = self._exact(qs[n], listed[at[n]:at[n + 1]], pending[n])[0]
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

    def distance_screen(self, distance: float) -> Prefilter | None:
        """The pre-filter with `distance` (m, >= 0) as every pair's margin, for `pairs_within`; None
        for a world without one."""
        return None if self._pf is None else self._pf.with_margin(distance)

    def pairs_within(self, q: FloatArray, pairs: BoolArray, screen: Prefilter) -> IntArray:
        """Of the pairs `pairs` ((p,) bool), those whose distance at q may be at most the distance
        `screen` was made for (`distance_screen`), in pair order: each other one is provably farther
        apart (its bounding volumes are), every dynamic obstacle present."""
        q = np.asarray(q, dtype=np.float64)
        return screen.uncleared(q[None], np.asarray(pairs, dtype=bool))[1]

    def pair_approach_factors(self) -> FloatArray:
        """(p,) how fast each enabled pair's distance can shrink, in units of `sweep_length`: 1 for
        a robot or tool piece against a static obstacle (one side moves), 2 between two moving pieces."""
        s = self._s
        kinds = [(s.pieces[int(a)].kind, s.pieces[int(b)].kind) for a, b in zip(s.pair_a, s.pair_b)]
        return np.array([1.0 if KIND_OBJECT in pair else 2.0 for pair in kinds])

    def obstacles_touched(self, qs: FloatArray) -> frozenset[int]:
        """Every obstacle some configuration of qs (k, n) collides with (clearance and margins
        applied), every dynamic obstacle present: indices into the scene's obstacles then its
        dynamic obstacles. Unlike `is_free` it does not stop at the first contact; self pairs are
        not looked at."""
        qs = np.ascontiguousarray(np.atleast_2d(qs), dtype=np.float64)
        self._set_presence(None, None)
        s = self._s
        owner = s.pair_obstacle
        active = self._active & (owner >= 0)
        if self._pf is not None:
            offsets, pairs = self._pf.uncleared(qs, active)
        else:
            every = np.flatnonzero(active)
            offsets, pairs = np.arange(len(qs) + 1) * len(every), np.tile(every, len(qs))
        hit: set[int] = set()
        gm, gd = s.geom_model, self._gdata
        for i in range(len(qs)):
            left = [int(p) for p in pairs[offsets[i]:offsets[i + 1]] if int(owner[p]) not in hit]
            if not left:
                continue
            pin.updateGeometryPlacements(s.model, self._data, gm, gd, qs[i])
            for p in left:
                if int(owner[p]) not in hit and pin.computeCollision(gm, gd, p):
                    hit.add(int(owner[p]))
        return frozenset(hit)

    def window_starts(self, ta: float, tb: float) -> list[float]:
        """Times in (ta, tb] at which a dynamic obstacle appears, in order."""
        s = self._s
        return sorted({float(w0) for i in s.dynamic_ids for w0, _ in (s.obstacles[int(i)].present or ())
                       if ta < w0 <= tb})

    @property
    def has_dynamic(self) -> bool:
        """Whether some obstacle comes and goes (present only in time windows)."""
        return bool(self._s.dynamic_ids.size)


# ---------------------------------------------------------------------------------- building



__all__ = [
    "KIND_DYNAMIC", "KIND_LINK", "KIND_OBJECT", "KIND_TOOL_BODY", "KIND_TOOL_TIPS", "AllowedCollisions",
    "CollisionOptions", "CollisionWorld", "ConfigCheck", "Contact", "DisabledPair", "MovesCheck", "Proximity",
    "SegmentCheck",
    "acm_samples", "bisection_order", "support_points",
]
