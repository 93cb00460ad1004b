"""A robot's inverse kinematics as a table: every solution of a batch of TCP poses, in a column
order shared by all poses, and the configuration data of a joint vector.

Table layout (`solve_all`): column = branch * V + variant. For opw and ur, branch k = 4 * wrist +
2 * shoulder + elbow as documented in `opw.opw_ik` and `ur.ur_ik`; V = number of turn variants the
joint limits allow (`turns.turn_shifts`, variant 0 = unshifted). For numeric arms with five or more
revolute joints, branch = status bits (column k holds the first-found solution whose `status` is k);
for other numeric arms branches are slots in the order solutions were found.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.errors import RobotModelError
from robomax_py.robot.ik._chain import active_positions, chain_to_frame, revolute_mask
from robomax_py.robot.ik.config import (
    ConfigIndicator,
    brand_text,
    status_generic,
    status_opw,
    turn_bits,
)
from robomax_py.robot.ik.numeric import NumericIkParams, numeric_ik
from robomax_py.robot.ik.opw import OpwParams, opw_ik
from robomax_py.robot.ik.pose_table import TableIkParams, table_ik
from robomax_py.robot.ik.turns import TurnVariants, expand, turn_shifts, wrap_to_pi
from robomax_py.robot.ik.ur import UrParams, ur_ik
from robomax_py.robot.model import RobotModel
from robomax_py.transforms import invert

SOLVERS = ("opw", "ur", "numeric", "table")


@dataclass(frozen=True, slots=True, eq=False)
class IkTable:
    """Every IK solution of a batch of poses, in a column order shared by all poses.

    q : (..., B, n) float
        Joint values, rad (m for prismatic joints); NaN rows where not valid.
    valid : (..., B) bool
        The solution exists and lies within the joint limits.
    status : (..., B) int
        KUKA status bits (see `config`); -1 where not valid.
    turn : (..., B) int
        KUKA turn bits; -1 where not valid.
    reachable : (..., B) bool
        The column's IK branch exists for the pose, before joint-limit filtering (so
        `reachable & ~valid` means: reachable, but only outside the limits).
    branch : (B,) int
        The IK branch of each column (column // V).
    """

    q: FloatArray
    valid: BoolArray
    status: IntArray
    turn: IntArray
    reachable: BoolArray
    branch: IntArray


@dataclass(frozen=True, slots=True, eq=False)
class Branches:
    """Every IK branch of a batch of poses, before the turn variants: `solve_all`'s first half.

    q : (..., K, n) float
        Joint values, rad (m for prismatic joints), revolute angles in (-pi, pi]; NaN rows where not valid.
    valid : (..., K) bool
        The branch exists for the pose (joint limits not yet applied).
    status : (..., K) int
        KUKA status bits (see `config`); -1 where not valid.
    variants : TurnVariants
        The turn variants `solve_all` expands every branch into (`turns.expand`).
    """

    q: FloatArray
    valid: BoolArray
    status: IntArray
    variants: TurnVariants


def solve_all(
    robot: RobotModel,
    T_base_tcp: FloatArray,
    q_hint: FloatArray | None = None,
    rng: np.random.Generator | None = None,
    *,
    expand_turns: bool = True,
) -> IkTable:
    """Every IK solution within the joint limits, for a batch of TCP poses.

    Parameters
    ----------
    robot : RobotModel
        Base frame = URDF root frame; `T_flange_tcp` is the mounted tool.
    T_base_tcp : (..., 4, 4) float
        TCP poses in the robot base frame, metres.
    q_hint : (..., n) or (n,) float, optional
        Joint values, rad: the free angle at singularities (opw, ur); the first seed (numeric).
    rng : np.random.Generator, optional
        Seeds of the numeric solver; default `np.random.default_rng(0)`, so plans are repeatable.
    expand_turns : bool
        False: only the wrapped solutions (V = 1), still filtered by the limits.

    Returns
    -------
    IkTable
        q : (..., B, n) with B = branches * V (opw, ur: 8 * V; numeric: 8 * V or `solutions` * V).
        Column k means the same branch and turn variant for every pose.
    """
    return expand_branches(solve_branches(robot, T_base_tcp, q_hint, rng, expand_turns=expand_turns))


def expand_branches(b: Branches) -> IkTable:
    """The IK table of every branch's turn variants (`solve_all`'s second half)."""
    n_var = b.variants.count
    q_all, valid_all = expand(b.q, b.valid, b.variants)
    reachable = np.repeat(b.valid, n_var, axis=-1)
    status_all = np.where(valid_all, np.repeat(b.status, n_var, axis=-1), -1)
    turn_all = np.where(valid_all, turn_bits(q_all), -1)
    return IkTable(
        q=q_all,
        valid=valid_all,
        status=status_all.astype(np.int64),
        turn=turn_all.astype(np.int64),
        reachable=reachable,
        branch=np.repeat(np.arange(b.q.shape[-2]), n_var),
    )


def solve_branches(
    robot: RobotModel,
    T_base_tcp: FloatArray,
    q_hint: FloatArray | None = None,
    rng: np.random.Generator | None = None,
    *,
    expand_turns: bool = True,
) -> Branches:
    """`solve_all` before the turn variants are expanded (same arguments): a caller that needs the
    variants of only a few branches (`plan.candidates`) expands those alone (`turns.variant_of`)."""
    T = np.asarray(T_base_tcp, dtype=float)
    T_base_flange = T @ invert(np.asarray(robot.T_flange_tcp, dtype=float))
    model = robot.model
    n = int(model.nq)
    lower = np.asarray(robot.limits.lower, dtype=float)
    upper = np.asarray(robot.limits.upper, dtype=float)
    rev = revolute_mask(model)
    params = robot.ik_params
    solver = robot.ik_solver

    if solver in ("opw", "ur"):
        expected = OpwParams if solver == "opw" else UrParams
        if not isinstance(params, expected):
            raise RobotModelError(robot.source, "ik.params", f"solver '{solver}' needs {expected.__name__}, got {type(params).__name__}")
        if n != 6 or not rev.all():
            raise RobotModelError(robot.source, "ik.solver", f"solver '{solver}' needs six revolute joints, the URDF has {n} joints")
        if isinstance(params, OpwParams):
            q, valid = opw_ik(params, T_base_flange, q_hint)
            status = status_opw(params, q)
        else:
            q, valid = ur_ik(params, T_base_flange, q_hint)
            status = status_generic(model, robot.flange_frame_id, q)
    elif solver in ("numeric", "table"):
        expected_params = NumericIkParams if solver == "numeric" else TableIkParams
        if not isinstance(params, expected_params):
            raise RobotModelError(robot.source, "ik.params", f"solver '{solver}' needs {expected_params.__name__}, "
                                  f"got {type(params).__name__}")
        if isinstance(params, NumericIkParams):
            q, valid = numeric_ik(
                model, robot.flange_frame_id, T_base_flange, lower, upper,
                np.random.default_rng(0) if rng is None else rng,
                params.seeds, q_hint, max_solutions=params.solutions, max_iterations=params.max_iterations,
            )
        else:
            q, valid = table_ik(model, robot.flange_frame_id, T_base_flange, lower, upper, params, q_hint, robot.source)
        q = np.where(rev, wrap_to_pi(q), q)
        status = status_generic(model, robot.flange_frame_id, q)
        if _has_status(model, robot.flange_frame_id):
            q, valid, status = _by_status(q, valid, status)
    else:
        raise RobotModelError(robot.source, "ik.solver", f"unknown IK solver {solver!r}; expected one of {', '.join(SOLVERS)}")

    variants = turn_shifts(lower, upper, rev) if expand_turns else turn_shifts(lower, upper, np.zeros(n, dtype=bool))
    return Branches(q=q, valid=np.asarray(valid, dtype=bool), status=status, variants=variants)


def solve_lines(robot: RobotModel, T_base_tcp: FloatArray) -> Branches:
    """`solve_branches` of TCP poses along lines (..., L, 4, 4), each line ending at its last pose
    (a spot), where a column of a line is one motion along it.

    An arm with more joints than the six a pose fixes has a continuum of solutions in each branch
    (its self-motion: an iiwa's elbow turning about the shoulder-wrist line), and the first solution
    found from random starts at one pose is unrelated to the one found at the next: a line of them
    jumps between every two samples. So for such an arm every pose but the last is solved again from
    its neighbour nearer the end, in the same column (damped least squares from there converges to
    the nearby solution), and kept where it has the neighbour's status: a line follows its spot's
    configuration as the robot would move along it."""
    branches = solve_branches(robot, T_base_tcp)
    return _followed(robot, T_base_tcp, branches) if redundant(robot) else branches


def _followed(robot: RobotModel, T_base_tcp: FloatArray, branches: Branches) -> Branches:
    """`branches` of lines (..., L, K, n) with every pose but the last solved from its successor."""
    q, valid, status = branches.q.copy(), branches.valid.copy(), branches.status.copy()
    for at in range(q.shape[-3] - 2, -1, -1):
        nearer = valid[..., at + 1, :]                                       # (..., K)
        where = np.nonzero(nearer)
        poses = np.broadcast_to(np.asarray(T_base_tcp)[..., at, None, :, :], nearer.shape + (4, 4))[where]
        found, ok = continuation(robot, poses, q[..., at + 1, :, :][where])
        found_status = status_generic(robot.model, robot.flange_frame_id, found)
        keep = ok & (found_status == status[..., at + 1, :][where])
        kept = tuple(w[keep] for w in where)
        q[..., at, :, :] = np.nan
        valid[..., at, :] = False
        status[..., at, :] = -1
        q[..., at, :, :][kept] = found[keep]
        valid[..., at, :][kept] = True
        status[..., at, :][kept] = found_status[keep]
    return Branches(q=q, valid=valid, status=status, variants=branches.variants)


def continuation(robot: RobotModel, T_base_tcp: FloatArray, q_from: FloatArray) -> tuple[FloatArray, BoolArray]:
    """The solution damped least squares reaches for each TCP pose (..., 4, 4) from q_from (..., n)
    alone, revolute angles in (-pi, pi], and whether it did (within the limits): for a redundant
    arm the continuation of a motion through q_from, which random starts would not give."""
    T_flange = np.asarray(T_base_tcp, dtype=float) @ invert(np.asarray(robot.T_flange_tcp, dtype=float))
    params = robot.ik_params
    iterations = params.max_iterations if isinstance(params, NumericIkParams) else NumericIkParams().max_iterations
    found, ok = numeric_ik(robot.model, robot.flange_frame_id, T_flange, np.asarray(robot.limits.lower, dtype=float),
                           np.asarray(robot.limits.upper, dtype=float), np.random.default_rng(0), 0,
                           np.asarray(q_from, dtype=float), max_solutions=1, max_iterations=iterations)
    found = found[..., 0, :]
    return np.where(revolute_mask(robot.model), wrap_to_pi(found), found), ok[..., 0]


# Bytes `solve_all` may hold for one table column of one pose, per joint value and per flag: the
# table (q float64; valid, reachable bool; status, turn int64) and, for temporaries (the solver's
# arrays before the turn variants are expanded, `np.where` copies), as much again.
_COLUMN_BYTES_PER_JOINT = 2 * 8
_COLUMN_BYTES_FLAGS = 2 * (1 + 1 + 8 + 8)


def ik_columns(robot: RobotModel) -> int:
    """B, the number of columns `solve_all` returns per pose: branches times turn variants."""
    model = robot.model
    params = robot.ik_params
    if robot.ik_solver in ("opw", "ur"):
        branches = 8
    elif isinstance(params, (NumericIkParams, TableIkParams)):
        branches = 8 if _has_status(model, robot.flange_frame_id) else params.solutions
    else:
        branches = 8
    variants = turn_shifts(np.asarray(robot.limits.lower, dtype=float), np.asarray(robot.limits.upper, dtype=float),
                           revolute_mask(model))
    return branches * variants.count


def ik_table_bytes(robot: RobotModel, poses: int) -> int:
    """An estimate (from above) of the memory `solve_all` takes for `poses` TCP poses, bytes."""
    per_pose = ik_columns(robot) * (int(robot.model.nq) * _COLUMN_BYTES_PER_JOINT + _COLUMN_BYTES_FLAGS)
    return int(poses) * per_pose


def _has_status(model: Any, frame_id: int) -> bool:
    chain = chain_to_frame(model, frame_id)
    act = active_positions(chain)
    return len(act) >= 5 and bool(np.all(chain.revolute[act[:5]]))


def redundant(robot: RobotModel) -> bool:
    """Whether the arm has more driven joints than the six a pose fixes: each of its IK branches is a
    continuum of solutions (the self-motion), not one."""
    return _driven_joints(robot.model, robot.flange_frame_id) > 6


@functools.lru_cache(maxsize=16)
def _driven_joints(model: Any, frame_id: int) -> int:
    """The active joints on the chain to `frame_id`. Kept per model: asked for every LIN move and
    every target's configuration data (some 170 times a plan of the reference cell), and walking
    the chain costs 0.2 ms."""
    return len(active_positions(chain_to_frame(model, frame_id)))


def _by_status(q: FloatArray, valid: BoolArray, status: IntArray) -> tuple[FloatArray, BoolArray, IntArray]:
    """Numeric solutions (..., K, n) -> (..., 8, n) with column k = the first solution of status k."""
    slots = np.arange(8)
    match = valid[..., None, :] & (status[..., None, :] == slots[:, None])   # (..., 8, K)
    has = match.any(axis=-1)
    first = np.argmax(match, axis=-1)                                         # (..., 8)
    q_out = np.take_along_axis(q, first[..., None], axis=-2)
    q_out[~has] = np.nan
    status_out = np.where(has, np.broadcast_to(slots, has.shape), -1)
    return q_out, has, status_out


def config_of(robot: RobotModel, q: FloatArray) -> ConfigIndicator:
    """The configuration indicator of one joint configuration q (n,), rad."""
    q = np.asarray(q, dtype=float)
    if robot.ik_solver == "opw" and isinstance(robot.ik_params, OpwParams):
        status = status_opw(robot.ik_params, q)
    else:
        status = status_generic(robot.model, robot.flange_frame_id, q)
    return ConfigIndicator(status=int(status), turn=int(turn_bits(q)))


def config_text(robot: RobotModel, q: FloatArray) -> str:
    """The configuration data the robot's controller brand writes for q (n,), rad (`config.brand_text`)."""
    return brand_text_of(robot, q, robot.controller.brand)


def controller_values(robot: RobotModel, q: FloatArray, inverse: bool = False) -> FloatArray:
    """URDF joint values q (..., n), rad, as the controller counts its joints (robot.yaml
    `controller.joint_signs`, `controller.joint_zeros_deg`): sign * q + zero; `inverse` the other
    way. Without the keys q itself."""
    q = np.asarray(q, dtype=float)
    c = robot.controller
    if not c.joint_signs and not c.joint_zeros:
        return q
    n = q.shape[-1]
    signs = np.asarray(c.joint_signs or (1.0,) * n, dtype=float)
    zeros = np.asarray(c.joint_zeros or (0.0,) * n, dtype=float)
    if signs.shape[0] != n or zeros.shape[0] != n:
        return q
    out: FloatArray = (q - zeros) * signs if inverse else signs * q + zeros
    return out


def brand_text_of(robot: RobotModel, q: FloatArray, brand: str, controller: bool = False) -> str:
    """The configuration data `brand`'s controller writes for q (n,), rad.

    controller: the data as a controller program states it, from the joint values as the controller
    counts them (`controller_values`): the turn bits, the wrist bit (A5 < 0), ABB's quadrants, FANUC's
    flip and turn numbers, Yaskawa's R/T/S halves. The shoulder and elbow bits are geometric (where
    the wrist point lies, docs/cell-files.md, "Controller programs") and do not depend on how the joints are counted. Without it (SRCL,
    the trajectory file, the planner) the URDF's joint values, as those state them.

    None ("") for an arm with more than six joints: the bits are those of a six-axis arm (the wrist
    point against the A2-A3 line), which its third joint, a roll of the upper arm on a KUKA LBR
    iiwa or a Yaskawa SIA, leaves undefined (they flipped between two programs' readings of one
    configuration), and no six-axis word picks one of its continuum of configurations anyway; its
    LIN moves follow the configuration they start in (docs/srcl.md)."""
    if redundant(robot):
        return ""
    q = np.asarray(q, dtype=float)
    ind = config_of(robot, q)
    q_c = controller_values(robot, q) if controller else q
    if q_c is q:
        return brand_text(brand, ind.status, ind.turn, q)
    status = ind.status
    if len(q_c) >= 5 and status >= 0:
        status = (status & 3) | (4 if np.mod(q_c[4], 2.0 * np.pi) >= np.pi else 0)
    return brand_text(brand, status, int(turn_bits(q_c)), q_c)


def config_texts_near(robot: RobotModel, q: FloatArray, brand: str, tol_rad: float, controller: bool = False) -> set[str]:
    """The configuration data of `brand` for q and for q with each joint that lies within tol_rad
    of a boundary the data changes at (0 and multiples of 90 deg: turn signs, ABB quadrants,
    FANUC turns at 180 deg) moved to either side: a target written with one of them names the
    branch q is in, as far as the program's decimals can tell (docs/cell-files.md, "Controller programs": within 0.01 deg).
    controller: as `brand_text_of`; the boundaries are then those of the controller's joint values."""
    q = np.asarray(q, dtype=float)
    q_c = controller_values(robot, q) if controller else q
    quarter = np.pi / 2.0
    near = [j for j in range(len(q_c)) if abs(q_c[j] - quarter * round(q_c[j] / quarter)) <= tol_rad]
    texts = set()
    for mask in range(1 << len(near)):
        for sign in (1.0, -1.0):
            p = q_c.copy()
            for bit, j in enumerate(near):
                if mask >> bit & 1:
                    p[j] = quarter * round(q_c[j] / quarter) + sign * 2.0 * tol_rad
            p_urdf = controller_values(robot, p, inverse=True) if controller else p
            texts.add(brand_text_of(robot, p_urdf, brand, controller))
    return texts
