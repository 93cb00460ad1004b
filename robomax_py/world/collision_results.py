"""The answers of `world.collision` queries (a contact, the closest pair, a configuration check, a
swept-segment check) and the coarse-to-fine order its swept checks visit states in."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import IntArray


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
class MovesCheck:
    """Consecutive swept moves checked until the first blocked one (`SweptChecks.first_blocked`).

    index : the first blocked move, None when every move is free.
    check : its `SegmentCheck` (as `check_segment` gives it), None when every move is free.
    free_checks : configurations the free moves before it took, as their own checks count them.
    """

    index: int | None
    check: SegmentCheck | None
    free_checks: int


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
