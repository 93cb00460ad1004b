"""Candidate robot configurations for every spot: orientation grid x IK branch, pruned with reasons.

A candidate survives when it is within joint limits, collision-free at the spot, and its approach
line (a straight TCP line of `process.approach` metres along the electrode axis) stays in the same
IK branch and is collision-free along its whole length. Every rejection is counted by reason.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from robomax_py._typing import FloatArray, IntArray
from robomax_py.errors import CellFileError
from robomax_py.plan.poses import (
    OrientationGrid,
    approach_poses,
    orientation_grid,
    pinned_index,
    spot_poses,
)
from robomax_py.robot import RobotModel, prismatic_mask
from robomax_py.robot.ik import same_config
from robomax_py.robot.ik.config import turn_bits
from robomax_py.robot.ik.turns import expand, variant_of, wrap_to_pi
from robomax_py.robot.solve import (
    Branches,
    config_text,
    ik_columns,
    ik_table_bytes,
    redundant,
    solve_lines,
)
from robomax_py.spec import CellSpec, SeamSpec
from robomax_py.transforms import invert
from robomax_py.world.collision import CollisionWorld

# The approach line is solved by IK at this TCP spacing; the sweep between samples is then checked
# by `check_path` with the collision world's own motion bound.
APPROACH_SAMPLE_M = 0.01
# Largest joint change between neighbouring approach samples before we call it a branch switch:
# 10 mm of TCP motion moves a well-conditioned wrist by well under 0.2 rad.
BRANCH_JUMP_RAD = 0.2
# Turn variants kept per (orientation, IK branch): those nearest home in joint time. An arm whose six
# joints all turn +-360 deg (UR10) has up to 64 variants of every solution, which multiplied the
# candidates of a spot by ~16 and the sequencing time with them; 4 keeps every variant of a KUKA-class
# arm (A4 and A6 beyond +-180 deg: at most 2 x 2).
MAX_TURN_VARIANTS = 4
# The most one IK table may take (bytes, `robot.solve.ik_table_bytes`): a seam's spots are solved in
# batches of this size, and a cell one of whose spots alone would need more is refused. A seam of
# 10,000 spots was solved as one table of 6.95 GiB.
IK_TABLE_BUDGET_BYTES = 512 * 2**20


RejectionKind = Literal["joint_limit", "approach_branch", "approach_joint_limit", "unreachable", "collision",
                        "approach_blocked", "turn_variant", "pinned_orientation", "pinned_config"]


@dataclass(frozen=True, slots=True)
class Rejection:
    """Why an (orientation, IK column) pair is not a candidate; `detail` names the bodies of a collision."""

    kind: RejectionKind
    detail: str = ""

    def __str__(self) -> str:
        return f"{self.kind}:{self.detail}" if self.detail else self.kind


@dataclass(frozen=True, slots=True, eq=False)
class SpotCandidates:
    """The surviving configurations of one spot.

    orient : (c,) int — index into the seam's OrientationGrid
    angles : (c, 3) float, rad — alpha, beta, gamma of each candidate
    column : (c,) int — IK table column (branch and turn variant)
    q_spot : (c, n) float, rad — configuration with the TCP at the spot
    q_app : (c, n) float, rad — configuration at the approach point (TCP `approach` m along +z)
    app_path : (c, s, n) float, rad — the approach line, from q_app to q_spot
    status, turn : (c,) int — configuration indicator bits
    rejected : reason -> number of (orientation, branch) pairs rejected for it
    """

    seam_index: int
    spot_index: int
    name: str
    orient: IntArray
    angles: FloatArray
    column: IntArray
    q_spot: FloatArray
    q_app: FloatArray
    app_path: FloatArray
    status: IntArray
    turn: IntArray
    rejected: Counter[Rejection] = field(default_factory=Counter)

    def __len__(self) -> int:
        return len(self.orient)


@dataclass(frozen=True, slots=True)
class CandidateStats:
    ik_poses: int
    collision_checks: int


def seam_candidates(
    cell: CellSpec, robot: RobotModel, world: CollisionWorld, seam_index: int,
    max_variants: int = MAX_TURN_VARIANTS, on_spot: Callable[[], None] | None = None,
    line_world: Callable[[int], CollisionWorld] | None = None,
) -> tuple[list[SpotCandidates], CandidateStats]:
    """Candidates for every spot of one seam; at most `max_variants` turn variants per orientation
    and IK branch (those nearest home), the others counted as rejected `turn_variant`;
    `on_spot()` is called as each spot is done; `line_world(s)`, when given, is the world spot s's
    approach line is checked in (a pick-and-place stop's line carries the part)."""
    seam = cell.seams[seam_index]
    grid = orientation_grid(seam)
    n_line = approach_samples(cell)
    per_spot = spot_table_bytes(robot, len(grid.angles), n_line, cell, seam.name)
    batch = max(1, IK_TABLE_BUDGET_BYTES // max(per_spot, 1))
    T_base_world = invert(np.asarray(cell.T_world_base))
    fractions = np.linspace(1.0, 0.0, n_line)                               # approach point -> spot
    checks = 0
    out: list[SpotCandidates] = []
    for first in range(0, len(seam.spots), batch):
        spots = seam.spots[first:first + batch]
        T_spot = T_base_world @ spot_poses(spots, grid)                     # (S, m, 4, 4)
        T_line = np.stack([approach_poses(T_spot, cell.process.approach * f) for f in fractions], axis=2)
        # The IK branches of every pose; each spot expands the turn variants it needs (`_spot_candidates`).
        branches = solve_lines(robot, T_line)                               # (S, m, L, K, n)
        branch_of_column = np.repeat(np.arange(branches.q.shape[-2]), branches.variants.count)
        for row in range(len(spots)):
            s = first + row
            result, used = _spot_candidates(robot, world if line_world is None else line_world(s), seam, grid, s,
                                            branches, seam_index, row)
            checks += used
            out.append(_nearest_variants(result, branch_of_column, np.asarray(cell.home), robot, max_variants))
            if on_spot is not None:
                on_spot()
        del branches, T_line
    return out, CandidateStats(ik_poses=len(seam.spots) * len(grid.angles) * n_line, collision_checks=checks)


def approach_samples(cell: CellSpec) -> int:
    """L, the TCP poses solved along each approach line (ends included)."""
    return max(2, int(np.ceil(cell.process.approach / APPROACH_SAMPLE_M)) + 1)


def spot_table_bytes(robot: RobotModel, orientations: int, n_line: int, cell: CellSpec, seam: str) -> int:
    """The IK table memory of one spot of a seam (bytes); CellFileError when it alone exceeds
    IK_TABLE_BUDGET_BYTES (the cell's seam grid or approach length ask too much of this robot)."""
    need = ik_table_bytes(robot, orientations * n_line)
    if need > IK_TABLE_BUDGET_BYTES:
        raise CellFileError(
            cell.source, "seams", f"seam {seam}: one spot's IK table would take {need / 2**30:.2f} GiB "
            f"({orientations:,} orientations x {n_line:,} approach samples x {ik_columns(robot):,} IK columns of "
            f"{robot.name}), more than the {IK_TABLE_BUDGET_BYTES / 2**30:.2f} GiB one table may take; "
            "lower the seam's grid or process.approach")
    return need


def check_ik_work(cell: CellSpec, robot: RobotModel) -> None:
    """Refuse, before planning, a cell one of whose spots' IK tables alone exceeds the budget, that
    pins configuration data on an arm whose targets carry none (`solve.brand_text_of`), or that
    gives no approach line (`verify` takes one of 0: it then checks none)."""
    if cell.process.approach <= 0:
        # A line of no length is a move that does not move: every junction's timing failed, and
        # the plan ended "infeasible", blaming the spots.
        raise CellFileError(cell.source, "process.approach", "0: plan reaches and leaves every spot on a straight "
                            "line this long along the electrode axis; for a gun that closes where it stops, give a "
                            "short one such as 0.001 (m)")
    for i, seam in enumerate(cell.seams):
        spot_table_bytes(robot, len(orientation_grid(seam).angles), approach_samples(cell), cell, seam.name)
        pinned = [j for j, spot in enumerate(seam.spots) if spot.config is not None]
        if pinned and redundant(robot):
            raise CellFileError(cell.source, f"seams[{i}].spots[{pinned[0]}].config",
                                f"{robot.name} has {robot.dof} joints: its targets carry no configuration data "
                                "(a six-axis arm's words do not name one of its configurations), so none can be "
                                "pinned; remove the key")


def _spot_candidates(
    robot: RobotModel, world: CollisionWorld, seam: SeamSpec, grid: OrientationGrid,
    s: int, branches: Branches, seam_index: int, row: int | None = None,
) -> tuple[SpotCandidates, int]:
    """Spot s of the seam, row `row` of its batch's IK branches (default: row s, branches of the whole seam).

    The tests are those of the IK table `solve_all` makes (column = branch * V + turn variant), but
    only the spot's own row of it is expanded into every turn variant: an approach line is needed
    only for the columns valid at the spot (`turns.variant_of`, the same values as the table's)."""
    row = s if row is None else row
    variants = branches.variants
    n_var = variants.count
    base_q = branches.q[row]                   # (m, L, K, n)
    base_valid = branches.valid[row]           # (m, L, K): the branch exists before limit filtering
    q_at, valid_at = expand(base_q[:, -1], base_valid[:, -1], variants)   # (m, B, n), (m, B): the spot's table
    limits = robot.limits
    revolute = ~prismatic_mask(robot.model)
    rejected: Counter[Rejection] = Counter()
    checks = 0
    n_line = base_q.shape[1]
    n_col = valid_at.shape[1]
    # The cheap tests for every (orientation, column) at once; collision checks only for survivors.
    # IK columns are fixed 2 pi shifts of wrapped values, so a joint crossing +-180 deg along the
    # line jumps within its column: unwrap revolute joints towards the spot value.
    at_spot = np.repeat(base_valid[:, -1], n_var, axis=-1)          # (m, B): reachable at the spot
    within = at_spot & valid_at                                      # (m, B)
    spot = seam.spots[s]
    pinned = pinned_index(grid, spot)
    if pinned is not None:                                           # only the pinned orientation
        others = np.ones(len(within), dtype=bool)
        others[pinned] = False
        n_other = int(within[others].sum())
        within = within & ~others[:, None]
    if spot.config is not None:                                      # only the pinned configuration
        ok = np.zeros_like(within)
        for o, k in zip(*np.nonzero(within)):
            ok[o, k] = same_config(spot.config, config_text(robot, q_at[o, k]))
        n_config = int((within & ~ok).sum())
        within = ok
    oo, kk = np.nonzero(within)                                      # in scan order
    bb = kk // n_var                                                 # their IK branches
    sub, _ = variant_of(base_q[oo, :, bb], base_valid[oo, :, bb], variants, (kk % n_var)[:, None])  # (c, L, n)
    spot_q = sub[:, -1:, :]
    # Samples without a solution within the limits are NaN, and stay NaN (the line then fails the
    # limit test below); they are wrapped as zeros, since np.mod of NaN is very slow.
    missing = np.isnan(sub)
    filled = np.where(missing, spot_q, sub)
    filled[..., revolute] = spot_q[..., revolute] + wrap_to_pi(filled[..., revolute] - spot_q[..., revolute])
    sub = np.where(missing, np.nan, filled)
    with np.errstate(invalid="ignore"):
        jump = np.abs(np.diff(sub, axis=1)).max(axis=(1, 2)) if len(sub) else np.zeros(0)
    branch_ok = base_valid[oo, :, bb].all(axis=1) & ~(jump > BRANCH_JUMP_RAD)
    inside = limits.contains(sub).all(axis=1)
    position = oo * n_col + kk                                       # of each line in the scan
    # Reasons are counted in the order an (orientation, column) scan first meets them, so reports
    # list equal counts in that order: reason -> (first position in the scan, count).
    found: dict[Rejection, tuple[float, int]] = {}

    def count(reason: Rejection, mask: np.ndarray, where: np.ndarray) -> None:
        n = int(np.sum(mask))
        if n:
            found[reason] = (float(where[np.argmax(mask)]), n)

    if pinned is not None and n_other:
        found[Rejection("pinned_orientation")] = (-2.0, n_other)
    if spot.config is not None and n_config:
        found[Rejection("pinned_config", spot.config)] = (-1.0, n_config)
    count(Rejection("joint_limit"), (at_spot & ~valid_at).reshape(-1), np.arange(at_spot.size))
    count(Rejection("approach_branch"), ~branch_ok, position)
    count(Rejection("approach_joint_limit"), branch_ok & ~inside, position)
    no_branch = ~at_spot.any(axis=1)
    if no_branch.any():            # counted after its orientation's columns
        found[Rejection("unreachable")] = (int(np.argmax(no_branch)) * n_col + n_col - 0.5, n_col * int(np.sum(no_branch)))
    tested = np.flatnonzero(branch_ok & inside)
    # Turn variants (q +- 2 pi) share their geometry: check each wrapped line once, the first of its
    # variants in scan order (a UR10 spot has ~30 variants of each of ~400 lines; + 0.0 makes -0.0 a 0.0).
    ends = sub[tested, -1]
    keys = np.round(np.where(revolute, wrap_to_pi(ends), ends), 9) + 0.0
    _, first_of, line_of = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    line_of = line_of.reshape(-1)
    verdicts: list[LineVerdict | None] = [None] * len(first_of)
    for u in np.argsort(first_of, kind="stable").tolist():
        verdicts[u] = verdict = _line_verdict(world, sub[tested[first_of[u]]])
        checks += verdict.checks
    reasons: dict[Rejection, int] = {}
    reason_of = np.array([-1 if v is None or v.free else reasons.setdefault(v.reason, len(reasons)) for v in verdicts],
                         dtype=np.int64)[line_of] if len(tested) else np.zeros(0, dtype=np.int64)
    for reason, n_r in reasons.items():
        count(reason, reason_of == n_r, position[tested])
    kept = tested[reason_of < 0]
    for reason, (_, n) in sorted(found.items(), key=lambda item: item[1][0]):
        rejected[reason] = n
    idx_o = oo[kept].astype(np.int64)
    idx_k = kk[kept].astype(np.int64)
    keep = len(kept) > 0
    n = robot.dof
    paths = sub[kept] if keep else np.zeros((0, n_line, n))
    return SpotCandidates(
        seam_index=seam_index, spot_index=s, name=spot.name,
        orient=idx_o, angles=grid.angles[idx_o] if keep else np.zeros((0, 3)), column=idx_k,
        q_spot=paths[:, -1] if keep else np.zeros((0, n)), q_app=paths[:, 0] if keep else np.zeros((0, n)),
        app_path=paths,
        status=branches.status[row][idx_o, -1, idx_k // n_var].astype(np.int64) if keep else np.zeros(0, dtype=np.int64),
        turn=turn_bits(q_at[idx_o, idx_k]) if keep else np.zeros(0, dtype=np.int64), rejected=rejected,
    ), checks


def _nearest_variants(
    c: SpotCandidates, branch_of_column: IntArray, home: FloatArray, robot: RobotModel, max_variants: int
) -> SpotCandidates:
    """At most `max_variants` candidates per (orientation, IK branch): the nearest to home in joint
    time (max over joints of |q_spot - home| / velocity limit); ties by column, so deterministic."""
    if len(c) == 0:
        return c
    branch = np.asarray(branch_of_column)[c.column]
    dist = np.max(np.abs(c.q_spot - home[None, :]) / robot.limits.velocity[None, :], axis=1)
    order = np.lexsort((c.column, dist, branch, c.orient))
    rank = np.zeros(len(c), dtype=np.int64)
    prev: tuple[int, int] | None = None
    n = 0
    for idx in order:
        key = (int(c.orient[idx]), int(branch[idx]))
        n = n + 1 if key == prev else 0
        prev = key
        rank[idx] = n
    sel = np.flatnonzero(rank < max_variants)
    if len(sel) == len(c):
        return c
    rejected = Counter(c.rejected)
    rejected[Rejection("turn_variant")] += len(c) - len(sel)
    return replace(
        c, orient=c.orient[sel], angles=c.angles[sel], column=c.column[sel], q_spot=c.q_spot[sel],
        q_app=c.q_app[sel], app_path=c.app_path[sel], status=c.status[sel], turn=c.turn[sel], rejected=rejected,
    )


@dataclass(frozen=True, slots=True)
class LineVerdict:
    """Whether a spot configuration and its approach line are free; the reason when not."""

    free: bool
    reason: Rejection
    checks: int


def _line_verdict(world: CollisionWorld, line: FloatArray) -> LineVerdict:
    """The collision verdict of a spot configuration (the line's last row) and its approach line."""
    check = world.check(line[-1])
    if not check.free:
        what = check.contact.describe() if check.contact is not None else "collision"
        return LineVerdict(False, Rejection("collision", what), 1)
    res = world.check_path(line, near=True)
    return LineVerdict(res.free, Rejection("approach_blocked"), 1 + res.checks)
