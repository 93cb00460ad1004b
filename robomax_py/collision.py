"""Collision and clearance queries for joint configurations of a robot carrying its tool in a scene.

`CollisionWorld` is built once from (robot, scene, clearance) and answers, for q in rad (robot joint
order) and an optional time t in s: is_free, first_contact, distance, are_free (batch) and
segment_free (a straight joint-space move, subdivided by a bound on how far any point moves).

Geometry (one Pinocchio GeometryModel)
--------------------------------------
Robot link pieces (coal convex hulls from `robot.load_robot`), tool body and tips pieces (fixed to
the flange frame), static obstacles and dynamic obstacles (fixed to the base frame, posed by
`scene.build_scene`). Checked pairs are the *enabled* pairs of the allowed-collision matrix below.

Allowed-collision matrix (pairs never checked), deterministic for a given `CollisionOptions`
-----------------------------------------------------------------------------------------------
- "rigid": two pieces on the same joint (a link's own pieces, the tool on the flange link, body vs
  tips): they never move relative to each other.
- "adjacent": robot link pieces on a joint and on its parent joint (they meet at the joint).
- "disabled in robot.yaml": link pairs named in robot.yaml `collision.disable` or its SRDF's
  `disable_collisions` (parts that touch by design, such as an ABB arm's link_4 and link_6).
- "tips on workpiece": tool tips vs objects marked `workpiece: true`. The tool *body* vs a workpiece
  stays checked.
- "fixed base": robot pieces on the fixed base (joint 0) vs obstacles: they never move, so their
  contact is a property of the layout, not of q (a base standing on a riser touches it). Such
  contacts are listed in `layout_contacts`, never reported by queries.
- "tool touches flange link": a tool piece vs a piece of the link before the flange link, when they
  are within `flange_contact_m` of each other in *every* sampled configuration (the gun's mounting
  plate sits on the wrist at the flange). A tool piece that only sometimes touches that link stays
  checked: that contact is the gun swinging into the wrist.
- "never close": self pairs (robot/tool vs robot/tool) that can never touch, *proved*, not guessed.
  First `acm_samples` seeded random configurations (half uniform within the joint limits, half with
  each joint at a limit with probability 1/2): a pair within `acm_margin` (2 cm), or colliding, in
  any sample stays checked. Sampling alone is not safe: on kr125 + spot_gun_c, 3000 samples left 9
  pairs "never within 2 cm" that 60000 samples showed colliding by up to 10 cm (base vs gun body).
  So each remaining pair must also be proved apart by branch and bound over the joints between its
  two pieces (`_prove_never_close`, a Lipschitz bound on the distance); pairs moved by more than
  `acm_proof_joints` (3) joints, or not proved within the budget, stay checked.

Margins
-------
Robot/tool vs obstacle pairs use `clearance` as coal's `security_margin`: a configuration closer than
`clearance` to an obstacle counts as colliding. Self pairs use margin 0 (touching counts). coal's GJK
decides the boundary to ~1e-9 m (tested at +-0.1 mm).

coal caveat
-----------
Every pair request has `enable_contact` on: without it coal 3.0.3 misses some overlaps of convex
pieces (see `_configure_requests`); the tests compare with `coal.collide` at coal's defaults.

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
With `broad_phase=True` (default) queries run Pinocchio's BroadPhaseManager over coal's
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
from dataclasses import dataclass
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.robot import RobotModel
from robomax_py.scene import Scene, SceneObject
from robomax_py.tolerances import DEFAULT as TOL

KIND_LINK = "link"
KIND_TOOL_BODY = "tool_body"
KIND_TOOL_TIPS = "tool_tips"
KIND_OBJECT = "object"
KIND_DYNAMIC = "dynamic"
_ROBOT_KINDS = (KIND_LINK, KIND_TOOL_BODY, KIND_TOOL_TIPS)
_OBSTACLE_KINDS = (KIND_OBJECT, KIND_DYNAMIC)


@dataclass(frozen=True, slots=True)
class CollisionOptions:
    """How a CollisionWorld is built (defaults are the production settings)."""

    broad_phase: bool = True
    acm_samples: int = 2000           # seeded random configurations for the ACM rules
    acm_margin: float = 0.02          # m: a self pair closer than this in any sample stays checked
    acm_seed: int = 0
    acm_proof_margin: float = 0.002   # m: "never close" must be proved with at least this separation
    acm_proof_joints: int = 3         # pairs moved by more joints than this are never disabled
    acm_proof_budget: int = 20000     # box evaluations per joint group for the proof
    flange_contact_m: float = 1e-4    # m: "touching at the flange" = closer than this in every sample


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


@dataclass(frozen=True, slots=True)
class DisabledPair:
    piece_a: str
    piece_b: str
    reason: str      # "rigid" | "adjacent" | "disabled in robot.yaml" | "tips on workpiece" | "fixed base" | "tool touches flange link" | "never close"


@dataclass(frozen=True, slots=True)
class AllowedCollisions:
    """The allowed-collision matrix as built: what is not checked, and why.

    enabled : (piece_a, piece_b) pairs that are checked.
    always_in_contact : enabled self pairs that touched in every ACM sample (likely bad link geometry:
        every configuration will be reported colliding with these bodies).
    """

    disabled: tuple[DisabledPair, ...]
    enabled: tuple[tuple[str, str], ...]
    always_in_contact: tuple[tuple[str, str], ...]
    samples: int


@dataclass(frozen=True, slots=True, eq=False)
class _Piece:
    name: str
    body: str
    kind: str
    joint: int
    obstacle: int        # index into the world's obstacle list, -1 for robot/tool pieces


@dataclass(frozen=True, slots=True, eq=False)
class _Shared:
    """Read-only state every copy of a world shares."""

    model: pin.Model
    geom_model: pin.GeometryModel
    pieces: tuple[_Piece, ...]
    pair_a: IntArray                         # (p,) geometry index of each enabled pair
    pair_b: IntArray
    pair_margin: FloatArray                  # (p,) m
    obstacles: tuple[SceneObject, ...]       # static then dynamic
    dynamic_ids: IntArray                    # (d,) obstacle indices of dynamic obstacles
    dynamic_pairs: tuple[IntArray, ...]      # per dynamic obstacle: its pair indices
    lever: FloatArray                        # (n,) m per rad (m per m for prismatic joints)
    clearance: float
    options: CollisionOptions
    acm: AllowedCollisions
    layout_contacts: tuple[tuple[str, str], ...]


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

    __slots__ = ("_s", "_data", "_gdata", "_manager", "_callback", "_present", "_active_before")

    def __init__(
        self, robot: RobotModel, scene: Scene, clearance: float = 0.0, options: CollisionOptions = CollisionOptions()
    ) -> None:
        if not (math.isfinite(clearance) and clearance >= 0):
            raise ValueError(f"clearance must be a finite number >= 0 m, got {clearance}")
        if options.acm_samples < 1:
            raise ValueError("options.acm_samples must be >= 1")
        self._attach(_build_shared(robot, scene, float(clearance), options))

    # ----------------------------------------------------------------------------------- set-up

    def _attach(self, shared: _Shared) -> None:
        self._s = shared
        self._data = shared.model.createData()
        self._gdata = shared.geom_model.createData()
        _configure_requests(self._gdata, shared.pair_margin)
        self._manager: Any = None
        self._callback: Any = None
        if shared.options.broad_phase:
            self._manager = pin.BroadPhaseManager_NaiveCollisionManager(shared.model, shared.geom_model, self._gdata)
            self._callback = pin.CollisionCallBackDefault(shared.geom_model, self._gdata, True)
        self._present: tuple[bool, ...] = tuple(True for _ in shared.dynamic_ids)
        self._active_before = np.arange(len(shared.pair_a) + 1, dtype=np.int64)

    def copy(self, broad_phase: bool | None = None) -> CollisionWorld:
        """A world sharing this one's geometry, pairs and ACM, with its own scratch (for another thread).

        `broad_phase` overrides the setting (e.g. False for an exhaustive-narrow-phase comparison).
        """
        shared = self._s
        if broad_phase is not None and broad_phase != shared.options.broad_phase:
            shared = dataclasses.replace(shared, options=dataclasses.replace(shared.options, broad_phase=broad_phase))
        other = CollisionWorld.__new__(CollisionWorld)
        other._attach(shared)
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
        return not self._collides(np.asarray(q, dtype=np.float64))

    def check(self, q: FloatArray, t: float | None = None) -> ConfigCheck:
        """`is_free` plus one colliding pair and the number of narrow-phase tests."""
        self._set_presence(t, t)
        hit = self._collides(np.asarray(q, dtype=np.float64))
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
        if self._manager is not None:
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
        m = int(math.ceil(self.sweep_length(q0, q1) / max_step - 1e-12))
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
        if not timed and self._manager is not None:   # the common case, with the least Python per state
            model, data, manager, callback = self._s.model, self._data, self._manager, self._callback
            for k in range(len(order)):
                hit = pin.computeCollisions(model, data, manager, callback, states[k])
                tests += callback.count
                if hit:
                    return SegmentCheck(False, k + 1, m + 1, int(tests), float(fractions[k]))
            return SegmentCheck(True, len(order), m + 1, int(tests), None)
        start = float(t0) if t0 is not None else 0.0
        span = float(t1) - start if t1 is not None else 0.0
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
        for q0, q1 in zip(pts[:-1], pts[1:]):
            m = int(math.ceil(self.sweep_length(q0, q1) / max_step - 1e-12))
            if m == 0:
                continue                  # check_segment checks q0 alone: already in
            states = q0 + (np.arange(1, m + 1) / m)[:, None] * (q1 - q0)
            states[-1] = q1               # the end exactly, as check_segment
            pieces.append(states)
        states = np.concatenate(pieces)
        self._set_presence(None, None)
        last = len(states) - 1
        order = bisection_order(last)
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
                if on_now:
                    self._gdata.activateCollisionPair(int(p))
                else:
                    self._gdata.deactivateCollisionPair(int(p))
        self._present = present
        active = np.fromiter(self._gdata.activeCollisionPairs, dtype=bool, count=len(s.pair_a))
        self._active_before = np.concatenate([[0], np.cumsum(active)]).astype(np.int64)

    def _contact(self, pair: int) -> Contact:
        s = self._s
        a, b = s.pieces[int(s.pair_a[pair])], s.pieces[int(s.pair_b[pair])]
        return Contact(body_a=a.body, kind_a=a.kind, body_b=b.body, kind_b=b.kind, piece_a=a.name, piece_b=b.name)


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


def _build_shared(robot: RobotModel, scene: Scene, clearance: float, options: CollisionOptions) -> _Shared:
    model = robot.model
    gm = pin.GeometryModel()
    pieces: list[_Piece] = []

    for g in robot.collision_model.geometryObjects:
        g.geometry.computeLocalAABB()
        gm.addGeometryObject(pin.GeometryObject(g))
        pieces.append(_Piece(g.name, model.frames[g.parentFrame].name, KIND_LINK, int(g.parentJoint), -1))

    flange = model.frames[scene.flange_frame_id]
    for kind, parts in ((KIND_TOOL_BODY, scene.tool.body), (KIND_TOOL_TIPS, scene.tool.tips)):
        for i, geom in enumerate(parts):
            name = f"{kind}[{i}]"
            gm.addGeometryObject(
                pin.GeometryObject(name, int(flange.parentJoint), int(scene.flange_frame_id), flange.placement, geom)
            )
            pieces.append(_Piece(name, kind, kind, int(flange.parentJoint), -1))

    obstacles = (*scene.obstacles, *scene.dynamic)
    for o, obj in enumerate(obstacles):
        kind = KIND_DYNAMIC if obj.dynamic else KIND_OBJECT
        placement = pin.SE3(np.asarray(obj.T_base_object, dtype=float))
        for i, geom in enumerate(obj.pieces):
            name = f"{kind}:{obj.name}[{i}]"
            gm.addGeometryObject(pin.GeometryObject(name, 0, 0, placement, geom))
            pieces.append(_Piece(name, obj.name, kind, 0, o))

    disabled: list[DisabledPair] = []
    obstacle_pairs: list[tuple[int, int]] = []
    self_candidates: list[tuple[int, int]] = []
    flange_candidates: set[tuple[int, int]] = set()
    base_obstacle: list[tuple[int, int]] = []
    mount_joint = int(flange.parentJoint)
    mount_parent = int(model.parents[mount_joint])
    n_geom = len(pieces)
    for a in range(n_geom):
        pa = pieces[a]
        for b in range(a + 1, n_geom):
            pb = pieces[b]
            if pa.kind in _OBSTACLE_KINDS and pb.kind in _OBSTACLE_KINDS:
                continue  # obstacles never move relative to each other: not a pair at all
            if pb.kind in _OBSTACLE_KINDS or pa.kind in _OBSTACLE_KINDS:
                rob, obs = (pa, pb) if pb.kind in _OBSTACLE_KINDS else (pb, pa)
                if rob.kind == KIND_TOOL_TIPS and obstacles[obs.obstacle].workpiece:
                    disabled.append(DisabledPair(pa.name, pb.name, "tips on workpiece"))
                elif rob.joint == 0:
                    disabled.append(DisabledPair(pa.name, pb.name, "fixed base"))
                    base_obstacle.append((a, b))
                else:
                    obstacle_pairs.append((a, b))
                continue
            if pa.joint == pb.joint:
                disabled.append(DisabledPair(pa.name, pb.name, "rigid"))
                continue
            tool_a, tool_b = pa.kind != KIND_LINK, pb.kind != KIND_LINK
            if not tool_a and not tool_b and (
                int(model.parents[pa.joint]) == pb.joint or int(model.parents[pb.joint]) == pa.joint
            ):
                disabled.append(DisabledPair(pa.name, pb.name, "adjacent"))
                continue
            if not tool_a and not tool_b and frozenset((pa.body, pb.body)) in robot.disabled_links:
                disabled.append(DisabledPair(pa.name, pb.name, "disabled in robot.yaml"))
                continue
            if (tool_a and pb.joint == mount_parent) or (tool_b and pa.joint == mount_parent):
                flange_candidates.add((a, b))
            self_candidates.append((a, b))

    bounds = _KinematicBounds.of(model)
    provable = {
        (a, b) for a, b in self_candidates
        if 0 < len(_joint_path(model, pieces[a].joint, pieces[b].joint) or ()) <= options.acm_proof_joints
    }
    sampled = _sample_self_pairs(robot, gm, self_candidates, provable, flange_candidates, options)
    proved_far = _prove_never_close(robot, gm, bounds, sorted(sampled.never_near), options)
    self_pairs: list[tuple[int, int]] = []
    for pair in self_candidates:
        a, b = pair
        if pair in sampled.flange_touch:
            disabled.append(DisabledPair(pieces[a].name, pieces[b].name, "tool touches flange link"))
        elif pair in proved_far:
            disabled.append(DisabledPair(pieces[a].name, pieces[b].name, "never close"))
        else:
            self_pairs.append(pair)

    # Exhaustive-mode order: obstacle pairs first (tips, body, then distal links), then self pairs.
    def _distal_key(pair: tuple[int, int]) -> tuple[int, int, int]:
        a, b = pair
        rob = pieces[a] if pieces[a].kind in _ROBOT_KINDS else pieces[b]
        tool_rank = 0 if rob.kind == KIND_TOOL_TIPS else (1 if rob.kind == KIND_TOOL_BODY else 2)
        return (tool_rank, -rob.joint, a * n_geom + b)

    obstacle_pairs.sort(key=_distal_key)
    self_pairs.sort(key=lambda p: (-max(pieces[p[0]].joint, pieces[p[1]].joint), p[0], p[1]))
    ordered = obstacle_pairs + self_pairs
    for a, b in ordered:
        gm.addCollisionPair(pin.CollisionPair(a, b))
    pair_a = np.array([a for a, _ in ordered], dtype=np.int64)
    pair_b = np.array([b for _, b in ordered], dtype=np.int64)
    pair_margin = np.array(
        [clearance if (pieces[a].kind in _OBSTACLE_KINDS or pieces[b].kind in _OBSTACLE_KINDS) else 0.0 for a, b in ordered],
        dtype=float,
    )
    dynamic_ids = np.array([o for o, obj in enumerate(obstacles) if obj.dynamic], dtype=np.int64)
    dynamic_pairs = tuple(
        np.array(
            [p for p, (a, b) in enumerate(ordered) if pieces[a].obstacle == o or pieces[b].obstacle == o], dtype=np.int64
        )
        for o in dynamic_ids
    )
    acm = AllowedCollisions(
        disabled=tuple(disabled),
        enabled=tuple((pieces[a].name, pieces[b].name) for a, b in ordered),
        always_in_contact=tuple((pieces[a].name, pieces[b].name) for a, b in self_pairs if (a, b) in sampled.always_touch),
        samples=options.acm_samples,
    )
    moving = [p.kind in _ROBOT_KINDS for p in pieces]
    return _Shared(
        model=model,
        geom_model=gm,
        pieces=tuple(pieces),
        pair_a=pair_a,
        pair_b=pair_b,
        pair_margin=pair_margin,
        obstacles=obstacles,
        dynamic_ids=dynamic_ids,
        dynamic_pairs=dynamic_pairs,
        lever=bounds.lever_arms(gm, moving),
        clearance=clearance,
        options=options,
        acm=acm,
        layout_contacts=_layout_contacts(gm, pieces, base_obstacle),
    )


def acm_samples(robot: RobotModel, count: int, seed: int) -> FloatArray:
    """(count, n) rad: the ACM's seeded samples, half uniform in the limits, half limit-biased."""
    rng = np.random.default_rng(seed)
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    qs = rng.uniform(lower, upper, size=(count, robot.dof))
    biased = np.arange(count) % 2 == 1
    at_limit = rng.random((count, robot.dof)) < 0.5
    pick_upper = rng.random((count, robot.dof)) < 0.5
    limits = np.where(pick_upper, upper, lower)
    qs = np.where(biased[:, None] & at_limit, limits, qs)
    return np.asarray(qs, dtype=float)


@dataclass(frozen=True, slots=True)
class _SampledPairs:
    never_near: frozenset[tuple[int, int]]     # never within acm_margin in any sample
    flange_touch: frozenset[tuple[int, int]]   # flange pairs within flange_contact_m in every sample
    always_touch: frozenset[tuple[int, int]]   # touching (margin 0) in every sample


def _sample_self_pairs(
    robot: RobotModel,
    gm: pin.GeometryModel,
    candidates: list[tuple[int, int]],
    provable: set[tuple[int, int]],
    flange_candidates: set[tuple[int, int]],
    options: CollisionOptions,
) -> _SampledPairs:
    """Run the seeded ACM samples over the candidate self pairs (decided pairs drop out early).

    Only `provable` pairs are tested against `acm_margin` (the others can never be disabled).
    """
    if not candidates:
        return _SampledPairs(frozenset(), frozenset(), frozenset())
    tmp = pin.GeometryModel()
    for g in gm.geometryObjects:
        tmp.addGeometryObject(pin.GeometryObject(g))
    for a, b in candidates:
        tmp.addCollisionPair(pin.CollisionPair(a, b))
    n = len(candidates)
    model, data = robot.model, robot.model.createData()
    near_gd, flange_gd, touch_gd = tmp.createData(), tmp.createData(), tmp.createData()
    _configure_requests(near_gd, np.full(n, options.acm_margin))
    _configure_requests(flange_gd, np.full(n, options.flange_contact_m))
    _configure_requests(touch_gd, np.zeros(n))
    for p in range(n):
        if candidates[p] not in flange_candidates:
            flange_gd.deactivateCollisionPair(p)
        if candidates[p] not in provable:
            near_gd.deactivateCollisionPair(p)
    undecided_near = {p for p in range(n) if candidates[p] in provable}   # not yet seen within the margin
    undecided_flange = {p for p in range(n) if candidates[p] in flange_candidates}   # always touching so far
    undecided_touch = set(range(n))                              # always touching so far
    for q in acm_samples(robot, options.acm_samples, options.acm_seed):
        for gd, undecided, keep_if in (
            (near_gd, undecided_near, False),
            (flange_gd, undecided_flange, True),
            (touch_gd, undecided_touch, True),
        ):
            if not undecided:
                continue
            pin.computeCollisions(model, data, tmp, gd, q, False)
            results = gd.collisionResults
            decided = [p for p in undecided if results[p].isCollision() != keep_if]
            for p in decided:
                undecided.discard(p)
                gd.deactivateCollisionPair(p)
    return _SampledPairs(
        never_near=frozenset(candidates[p] for p in undecided_near),
        flange_touch=frozenset(candidates[p] for p in undecided_flange),
        always_touch=frozenset(candidates[p] for p in undecided_touch),
    )


def _prove_never_close(
    robot: RobotModel,
    gm: pin.GeometryModel,
    bounds: _KinematicBounds,
    pairs: list[tuple[int, int]],
    options: CollisionOptions,
) -> set[tuple[int, int]]:
    """The pairs proved to stay more than `acm_proof_margin` apart over the whole joint-limit box.

    For pieces a (joint i) and b (joint j, a descendant of i), their distance depends only on the
    joints K on the path i -> j. Branch and bound over the box of K's limits: at a box centre c with
    half-widths h, every q in the box has d(q) >= d(c) - sum_k L_k h_k, where L_k bounds the distance
    of b's points from axis k (same bound as `sweep_length`, for piece b alone). A box is proved when
    that bound exceeds the margin, split in two along its worst joint otherwise; a pair fails when
    d(c) <= margin at any centre, and is left checked when its joint group exceeds
    `acm_proof_joints` joints or `acm_proof_budget` box evaluations.
    """
    model = robot.model
    groups: dict[tuple[int, ...], list[tuple[int, int, int]]] = {}
    for a, b in pairs:
        ja, jb = int(gm.geometryObjects[a].parentJoint), int(gm.geometryObjects[b].parentJoint)
        distal = b if ja < jb else a
        path = _joint_path(model, ja, jb)
        if path is None or not 0 < len(path) <= options.acm_proof_joints:
            continue
        groups.setdefault(tuple(path), []).append((a, b, distal))
    proved: set[tuple[int, int]] = set()
    data = model.createData()
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    margin = options.acm_proof_margin
    for path, members in groups.items():
        idx = [int(model.joints[k].idx_q) for k in path]
        m = len(idx)
        # L[p][k]: m per rad (plain floats: this loop is Python-bound, numpy per box costs more).
        L = [[bounds.piece_lever(k, gm.geometryObjects[hi]) for k in path] for _, _, hi in members]
        tmp = pin.GeometryModel()
        for g in gm.geometryObjects:
            tmp.addGeometryObject(pin.GeometryObject(g))
        for a, b, _ in members:
            tmp.addCollisionPair(pin.CollisionPair(a, b))
        gd = tmp.createData()
        q = np.clip(pin.neutral(model), lower, upper)
        failed: set[int] = set()
        centre0 = [float(lower[i] + upper[i]) / 2 for i in idx]
        # A revolute joint repeats its poses every 2 pi: one period covers a wider range.
        half0 = [
            float(upper[i] - lower[i]) / 2 if bounds.prismatic[k] else min(float(upper[i] - lower[i]) / 2, math.pi)
            for i, k in zip(idx, path)
        ]
        stack = [(centre0, half0, list(range(len(members))))]
        evaluations = 0
        while stack and evaluations < options.acm_proof_budget:
            centre, half, todo = stack.pop()
            todo = [p for p in todo if p not in failed]
            if not todo:
                continue
            q[idx] = centre
            pin.updateGeometryPlacements(model, data, tmp, gd, q)
            evaluations += 1
            unproved = []
            for p in todo:
                d = pin.computeDistance(tmp, gd, p).min_distance
                if d <= margin:
                    failed.add(p)
                elif d - sum(l * h for l, h in zip(L[p], half)) <= margin:
                    unproved.append(p)
            if unproved:
                # Halve the joint contributing most to the worst unproved pair's bound.
                split = max(range(m), key=lambda k: max(L[p][k] for p in unproved) * half[k])
                h2 = list(half)
                h2[split] /= 2
                for sign in (-1.0, 1.0):
                    c2 = list(centre)
                    c2[split] += sign * h2[split]
                    stack.append((c2, h2, unproved))
        open_pairs = {p for _, _, todo in stack for p in todo}
        proved.update((a, b) for p, (a, b, _) in enumerate(members) if p not in failed and p not in open_pairs)
    return proved


def _configure_requests(gdata: Any, margins: FloatArray) -> None:
    """Per-pair coal requests: the pair's security margin, and `enable_contact` on.

    `enable_contact` must stay on (Pinocchio's GeometryData turns it off): in coal 3.0.3, when GJK
    ends with status Collision at a residual distance in (1e-12, gjk_tolerance] and EPA does not run,
    the shape-shape collider compares that positive distance with a 1e-12 threshold and reports *no*
    collision. We measured misses of convex-hull pairs overlapping by up to 19 mm. With contacts
    enabled, EPA runs on those cases and returns the (negative) penetration; measured cost: none.
    """
    for p, margin in enumerate(margins):
        request = gdata.collisionRequests[p]
        request.security_margin = float(margin)
        request.enable_contact = True


def _layout_contacts(gm: pin.GeometryModel, pieces: list[_Piece], pairs: list[tuple[int, int]]) -> tuple[tuple[str, str], ...]:
    out = []
    for a, b in pairs:
        ga, gb = gm.geometryObjects[a], gm.geometryObjects[b]
        req, res = coal.CollisionRequest(), coal.CollisionResult()
        Ta = coal.Transform3s(ga.placement.rotation, ga.placement.translation)
        Tb = coal.Transform3s(gb.placement.rotation, gb.placement.translation)
        if coal.collide(ga.geometry, Ta, gb.geometry, Tb, req, res):
            out.append((pieces[a].name, pieces[b].name))
    return tuple(out)


def support_points(geom: coal.CollisionGeometry) -> FloatArray:
    """(m, 3) points in a piece's own frame whose convex hull contains the piece, metres.

    Convex polytope: its vertices; BVH: its vertices; anything else: its local AABB corners.
    """
    if isinstance(geom, coal.ConvexBase):
        return np.asarray(geom.points(), dtype=float).reshape(-1, 3)
    if isinstance(geom, coal.BVHModelBase):
        return np.asarray(geom.vertices(), dtype=float).reshape(-1, 3)
    geom.computeLocalAABB()
    lo, hi = np.asarray(geom.aabb_local.min_, dtype=float), np.asarray(geom.aabb_local.max_, dtype=float)
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


@dataclass(frozen=True, slots=True, eq=False)
class _KinematicBounds:
    """Joint axes and prismatic travel, for bounds on how far points move per unit joint motion."""

    model: pin.Model
    axis: FloatArray          # (njoints, 3) unit axis of each joint in its own frame
    prismatic: BoolArray      # (njoints,)
    travel: FloatArray        # (njoints,) m, largest |q| of prismatic joints (0 for revolute)

    @staticmethod
    def of(model: pin.Model) -> _KinematicBounds:
        njoints = model.njoints
        prismatic = np.array([model.joints[j].shortname().startswith("JointModelP") for j in range(njoints)])
        # Axes in their own frames, from the LOCAL joint Jacobian at the neutral configuration.
        data = model.createData()
        pin.computeJointJacobians(model, data, pin.neutral(model))
        axis = np.zeros((njoints, 3))
        travel = np.zeros(njoints)
        for j in range(1, njoints):
            J = pin.getJointJacobian(model, data, j, pin.ReferenceFrame.LOCAL)
            col = np.asarray(J[:, model.joints[j].idx_v], dtype=float)
            vec = col[:3] if prismatic[j] else col[3:]
            axis[j] = vec / np.linalg.norm(vec)
            if prismatic[j]:
                i = model.joints[j].idx_q
                travel[j] = max(abs(model.lowerPositionLimit[i]), abs(model.upperPositionLimit[i]))
        return _KinematicBounds(model=model, axis=axis, prismatic=prismatic, travel=travel)

    def piece_lever(self, k: int, geometry_object: Any) -> float:
        """Bound (m per rad; 1 for a prismatic k) of dist(p, axis_k) over the piece's points p and all q.

        Piece on joint k: exact largest distance of its support points from the axis. Piece on a
        descendant j: dist(o_c, axis_k) + |offsets| from c down to j (+ prismatic travel) + largest
        distance of its points from o_j, c being k's child towards j (triangle inequality). 0 when the
        piece is not beyond joint k.
        """
        if self.prismatic[k]:
            return 1.0
        j = int(geometry_object.parentJoint)
        placement = geometry_object.placement
        pts = support_points(geometry_object.geometry) @ np.asarray(placement.rotation).T + np.asarray(placement.translation)
        if j == k:
            radial = pts - np.outer(pts @ self.axis[k], self.axis[k])
            return float(np.max(np.linalg.norm(radial, axis=1)))
        path = _path_below(self.model, k, j)
        if path is None:
            return 0.0
        c = path[0]
        oc = np.asarray(self.model.jointPlacements[c].translation, dtype=float)
        d_c = float(np.linalg.norm(oc - np.dot(oc, self.axis[k]) * self.axis[k])) + float(self.travel[c])
        chain = sum(float(np.linalg.norm(self.model.jointPlacements[m].translation)) + float(self.travel[m]) for m in path[1:])
        return d_c + chain + float(np.max(np.linalg.norm(pts, axis=1)))

    def lever_arms(self, gm: pin.GeometryModel, moving: list[bool]) -> FloatArray:
        """(n,) per joint: the largest `piece_lever` over every moving piece (robot and tool)."""
        lever = np.zeros(self.model.nq)
        for k in range(1, self.model.njoints):
            idx = self.model.joints[k].idx_q
            best = 1.0 if self.prismatic[k] else 0.0
            for g, is_moving in zip(gm.geometryObjects, moving):
                if is_moving and g.parentJoint != 0:
                    best = max(best, self.piece_lever(k, g))
            lever[idx] = best
        return lever


def _joint_path(model: pin.Model, i: int, j: int) -> list[int] | None:
    """The joints whose motion changes the relative pose of bodies on joints i and j (either order):
    the path from the ancestor's child down to the descendant; None if neither is an ancestor."""
    lo, hi = (i, j) if i < j else (j, i)
    return _path_below(model, lo, hi)


def _path_below(model: pin.Model, i: int, j: int) -> list[int] | None:
    """Joints from the child of i down to j (inclusive) when j is a descendant of i, else None."""
    path = []
    k = j
    while k > i:
        path.append(k)
        k = int(model.parents[k])
    if k != i:
        return None
    return path[::-1]


__all__ = [
    "AllowedCollisions",
    "CollisionOptions",
    "CollisionWorld",
    "ConfigCheck",
    "Contact",
    "DisabledPair",
    "Proximity",
    "SegmentCheck",
    "acm_samples",
    "bisection_order",
    "support_points",
]
