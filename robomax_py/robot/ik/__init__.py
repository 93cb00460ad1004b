"""Inverse kinematics per robot.yaml solver -> a fixed-order table of joint solutions.

Solvers (robot.yaml `ik.solver`) and their `ik.params` keys; lengths in metres, angles in DEGREES in
the file (converted to radians here):

opw
    a1, a2, b, c1, c2, c3, c4 (m, required; c2 > 0 and (a2, c3) not both 0);
    offsets (deg, 6, default all 0); sign_corrections (6 values of +1 or -1, default all +1).
    Conventions of the opw_kinematics reference implementation (see `opw`).
ur
    d1, a2, a3, d4, d5, d6 (m, required; Universal Robots' DH table, a2 and a3 non-zero, negative for
    URs); base_xyz (m, 3), base_rpy (deg, 3): pose of the DH base frame in the URDF root frame;
    flange_xyz (m, 3), flange_rpy (deg, 3): pose of the URDF flange frame in DH frame 6. All four
    default to zeros. For example-robot-data's ur10_robot.urdf with flange tool0:
    {d1: 0.1273, a2: -0.612, a3: -0.5723, d4: 0.163941, d5: 0.1157, d6: 0.0922, base_rpy: [0, 0, 180]}.
numeric
    seeds (int >= 1, default 32): random starts per pose; solutions (int >= 1, default 8): solution
    slots; max_iterations (int >= 1, default 50). All optional.

Table layout (`solve_all`): column = branch * V + variant. For opw and ur, branch k = 4 * wrist +
2 * shoulder + elbow as documented in `opw.opw_ik` and `ur.ur_ik`; V = number of turn variants the
joint limits allow (`turns.turn_shifts`, variant 0 = unshifted). For numeric arms with five or more
revolute joints, branch = status bits (column k holds the first-found solution whose `status` is k);
for other numeric arms branches are slots in the order solutions were found.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.errors import RobotModelError
from robomax_py.robot.ik._chain import chain_to_frame, revolute_mask
from robomax_py.robot.ik.config import (
    ConfigIndicator,
    brand_text,
    same_config,
    status_generic,
    status_opw,
    turn_bits,
)
from robomax_py.robot.ik.numeric import NumericIkParams, numeric_ik
from robomax_py.robot.ik.opw import OpwParams, opw_fk, opw_ik
from robomax_py.robot.ik.turns import expand, turn_shifts, wrap_to_pi
from robomax_py.robot.ik.ur import UrParams, ur_fk, ur_ik
from robomax_py.transforms import invert

if TYPE_CHECKING:
    from robomax_py.robot import RobotModel

__all__ = [
    "ConfigIndicator",
    "IkTable",
    "NumericIkParams",
    "OpwParams",
    "UrParams",
    "config_of",
    "config_text",
    "same_config",
    "numeric_ik",
    "opw_fk",
    "opw_ik",
    "params_from_mapping",
    "solve_all",
    "ur_fk",
    "ur_ik",
]

SOLVERS = ("opw", "ur", "numeric")
_OPW_LENGTHS = ("a1", "a2", "b", "c1", "c2", "c3", "c4")
_UR_LENGTHS = ("d1", "a2", "a3", "d4", "d5", "d6")
_UR_POSES = ("base_xyz", "base_rpy", "flange_xyz", "flange_rpy")
_NUMERIC_INTS = ("seeds", "solutions", "max_iterations")


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


def params_from_mapping(solver: str, params: Mapping[str, Any]) -> OpwParams | UrParams | NumericIkParams:
    """robot.yaml `ik.params` (m, deg) -> typed solver parameters (m, rad).

    Raises
    ------
    RobotModelError
        file None, key `ik.params.<key>` (or `ik.params.solver` for an unknown solver), naming
        the problem: unknown or missing key, wrong type or length, value out of range.
    """
    if solver not in SOLVERS:
        raise RobotModelError(None, "ik.params.solver", f"unknown IK solver {solver!r}; expected one of {', '.join(SOLVERS)}")
    if not isinstance(params, Mapping):
        raise RobotModelError(None, "ik.params", f"expected a mapping of parameters, got {type(params).__name__}")
    if solver == "opw":
        allowed: tuple[str, ...] = (*_OPW_LENGTHS, "offsets", "sign_corrections")
    elif solver == "ur":
        allowed = (*_UR_LENGTHS, *_UR_POSES)
    else:
        allowed = _NUMERIC_INTS
    for key in params:
        if key not in allowed:
            raise RobotModelError(
                None, f"ik.params.{key}", f"unknown key for solver '{solver}'; expected: {', '.join(allowed)}"
            )

    if solver == "opw":
        a1, a2, b, c1, c2, c3, c4 = (_number(params, k) for k in _OPW_LENGTHS)
        if c2 <= 0:
            raise RobotModelError(None, "ik.params.c2", f"must be > 0 (upper arm length), got {c2}")
        if math.hypot(a2, c3) == 0:
            raise RobotModelError(None, "ik.params.c3", "a2 and c3 cannot both be 0 (zero forearm)")
        offsets_deg = _vector(params, "offsets", 6, (0.0,) * 6)
        signs = _vector(params, "sign_corrections", 6, (1.0,) * 6)
        for i, s in enumerate(signs):
            if s not in (1.0, -1.0):
                raise RobotModelError(None, "ik.params.sign_corrections", f"entry {i} must be +1 or -1, got {s:g}")
        o = [math.radians(v) for v in offsets_deg]
        g = [int(v) for v in signs]
        return OpwParams(
            a1=a1, a2=a2, b=b, c1=c1, c2=c2, c3=c3, c4=c4,
            offsets=(o[0], o[1], o[2], o[3], o[4], o[5]),
            sign_corrections=(g[0], g[1], g[2], g[3], g[4], g[5]),
        )
    if solver == "ur":
        d1, a2, a3, d4, d5, d6 = (_number(params, k) for k in _UR_LENGTHS)
        for key, value in (("a2", a2), ("a3", a3)):
            if value == 0:
                raise RobotModelError(None, f"ik.params.{key}", "must be non-zero")
        bx, by, bz = _vector(params, "base_xyz", 3, (0.0, 0.0, 0.0))
        br, bp, bw = (math.radians(v) for v in _vector(params, "base_rpy", 3, (0.0, 0.0, 0.0)))
        fx, fy, fz = _vector(params, "flange_xyz", 3, (0.0, 0.0, 0.0))
        fr, fp, fw = (math.radians(v) for v in _vector(params, "flange_rpy", 3, (0.0, 0.0, 0.0)))
        return UrParams(
            d1=d1, a2=a2, a3=a3, d4=d4, d5=d5, d6=d6,
            base_xyz=(bx, by, bz), base_rpy=(br, bp, bw), flange_xyz=(fx, fy, fz), flange_rpy=(fr, fp, fw),
        )
    defaults = NumericIkParams()
    return NumericIkParams(
        seeds=_positive_int(params, "seeds", defaults.seeds),
        solutions=_positive_int(params, "solutions", defaults.solutions),
        max_iterations=_positive_int(params, "max_iterations", defaults.max_iterations),
    )


def _number(params: Mapping[str, Any], key: str) -> float:
    if key not in params:
        raise RobotModelError(None, f"ik.params.{key}", "missing (required)")
    value = params[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise RobotModelError(None, f"ik.params.{key}", f"expected a finite number, got {value!r}")
    return float(value)


def _vector(params: Mapping[str, Any], key: str, length: int, default: tuple[float, ...]) -> tuple[float, ...]:
    if key not in params:
        return default
    value = params[key]
    if not isinstance(value, (list, tuple)):
        raise RobotModelError(None, f"ik.params.{key}", f"expected a list of {length} numbers, got {value!r}")
    if len(value) != length:
        raise RobotModelError(None, f"ik.params.{key}", f"expected {length} values, got {len(value)}")
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise RobotModelError(None, f"ik.params.{key}", f"entry {i}: expected a finite number, got {v!r}")
    return tuple(float(v) for v in value)


def _positive_int(params: Mapping[str, Any], key: str, default: int) -> int:
    if key not in params:
        return default
    value = params[key]
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise RobotModelError(None, f"ik.params.{key}", f"expected an integer >= 1, got {value!r}")
    return int(value)


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
    elif solver == "numeric":
        if not isinstance(params, NumericIkParams):
            raise RobotModelError(robot.source, "ik.params", f"solver 'numeric' needs NumericIkParams, got {type(params).__name__}")
        q, valid = numeric_ik(
            model, robot.flange_frame_id, T_base_flange, lower, upper,
            np.random.default_rng(0) if rng is None else rng,
            params.seeds, q_hint, max_solutions=params.solutions, max_iterations=params.max_iterations,
        )
        q = np.where(rev, wrap_to_pi(q), q)
        status = status_generic(model, robot.flange_frame_id, q)
        if _has_status(model, robot.flange_frame_id):
            q, valid, status = _by_status(q, valid, status)
    else:
        raise RobotModelError(robot.source, "ik.solver", f"unknown IK solver {solver!r}; expected one of {', '.join(SOLVERS)}")

    variants = turn_shifts(lower, upper, rev) if expand_turns else turn_shifts(lower, upper, np.zeros(n, dtype=bool))
    n_var = variants.count
    q_all, valid_all = expand(q, valid, variants)
    reachable = np.repeat(valid, n_var, axis=-1)
    status_all = np.where(valid_all, np.repeat(status, n_var, axis=-1), -1)
    turn_all = np.where(valid_all, turn_bits(q_all), -1)
    return IkTable(
        q=q_all,
        valid=valid_all,
        status=status_all.astype(np.int64),
        turn=turn_all.astype(np.int64),
        reachable=reachable,
        branch=np.repeat(np.arange(q.shape[-2]), n_var),
    )


def _has_status(model: Any, frame_id: int) -> bool:
    chain = chain_to_frame(model, frame_id)
    return len(chain.joints) >= 5 and bool(np.all(chain.revolute[:5]))


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
    ind = config_of(robot, q)
    return brand_text(robot.controller.brand, ind.status, ind.turn, np.asarray(q, dtype=float))
