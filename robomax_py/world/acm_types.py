"""The pieces, pair kinds, options and results of the allowed-collision matrix (`world.acm`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import pinocchio as pin

from robomax_py._typing import FloatArray, IntArray
from robomax_py.world.prefilter import Prefilter
from robomax_py.world.scene import SceneObject

KIND_LINK = "link"
KIND_TOOL_BODY = "tool_body"
KIND_TOOL_TIPS = "tool_tips"
KIND_OBJECT = "object"
KIND_DYNAMIC = "dynamic"
KIND_HELD = "held"            # a part in the gripper: moves with the tool, collides like its body
# A held part's stand-in against the supports it rests on, where the part or the support is a
# triangle mesh (`world.acm`, module docstring): the part lifted HELD_SUPPORT_PENETRATION_M along
# the world's up as it lies (`HeldPart.up`).
KIND_HELD_LIFTED = "held_lifted"
ROBOT_KINDS = (KIND_LINK, KIND_TOOL_BODY, KIND_TOOL_TIPS, KIND_HELD, KIND_HELD_LIFTED)
# A held part may touch its supports (the objects it rests on where it is gripped or released)
# but not sink into them by more than this (m): resting is a contact at distance 0.
HELD_SUPPORT_PENETRATION_M = 1e-3
OBSTACLE_KINDS = (KIND_OBJECT, KIND_DYNAMIC)


@dataclass(frozen=True, slots=True)
class CollisionOptions:
    """How a CollisionWorld is built (defaults are the production settings)."""

    broad_phase: bool = True
    prefilter: bool = True            # bounding-volume pre-filter before coal (with the broad phase only)
    acm_samples: int = 2000           # seeded random configurations for the ACM rules
    acm_margin: float = 0.02          # m: a self pair closer than this in any sample stays checked
    acm_seed: int = 0
    acm_proof_margin: float = 0.002   # m: "never close" must be proved with at least this separation
    acm_proof_joints: int = 3         # pairs moved by more joints than this are never disabled
    acm_proof_budget: int = 20000     # box evaluations per joint group for the proof
    flange_contact_m: float = 1e-4    # m: "touching at the flange" = closer than this in every sample


@dataclass(frozen=True, slots=True)
class DisabledPair:
    piece_a: str
    piece_b: str
    reason: str      # "rigid" | "adjacent" | "disabled in robot.yaml" | "tips on workpiece" | "fixed base" | "tool touches flange link" | "never close" | "passive linkage: ..."


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
class Piece:
    name: str
    body: str
    kind: str
    joint: int
    obstacle: int        # index into the world's obstacle list, -1 for robot/tool pieces


@dataclass(frozen=True, slots=True, eq=False)
class SharedGeometry:
    """Read-only state every copy of a world shares."""

    model: pin.Model
    geom_model: pin.GeometryModel
    pieces: tuple[Piece, ...]
    pair_a: IntArray                         # (p,) geometry index of each enabled pair
    pair_b: IntArray
    pair_margin: FloatArray                  # (p,) m
    obstacles: tuple[SceneObject, ...]       # static then dynamic
    dynamic_ids: IntArray                    # (d,) obstacle indices of dynamic obstacles
    dynamic_pairs: tuple[IntArray, ...]      # per dynamic obstacle: its pair indices
    pair_obstacle: IntArray                  # (p,) the obstacle of each enabled pair, -1 for a self pair
    lever: FloatArray                        # (n,) m per rad (m per m for prismatic joints)
    clearance: float
    options: CollisionOptions
    acm: AllowedCollisions
    layout_contacts: tuple[tuple[str, str], ...]
    prefilter: Prefilter | None              # bounding-sphere broad phase (None: coal's for every query)


@dataclass(slots=True)
class _PairRules:
    """Every piece pair sorted by the rules that need no sampling (see the module docstring)."""

    disabled: list[DisabledPair] = field(default_factory=list)
    obstacle_pairs: list[tuple[int, int]] = field(default_factory=list)   # robot/tool vs obstacle, checked
    self_candidates: list[tuple[int, int]] = field(default_factory=list)  # left to the sampling and the proof
    flange_candidates: set[tuple[int, int]] = field(default_factory=set)  # tool vs the link before the flange link
    base_obstacle: list[tuple[int, int]] = field(default_factory=list)    # fixed base vs obstacle: layout
