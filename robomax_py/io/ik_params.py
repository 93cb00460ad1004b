"""robot.yaml `ik.params` (metres and DEGREES in the file) -> typed solver parameters (m, rad).

Solvers (robot.yaml `ik.solver`) and their `ik.params` keys; lengths in metres, angles in DEGREES in
the file (converted to radians here):

opw
    a1, a2, b, c1, c2, c3, c4 (m, required; c2 > 0 and (a2, c3) not both 0);
    offsets (deg, 6, default all 0); sign_corrections (6 values of +1 or -1, default all +1);
    base_xy (m, 2, default [0, 0]): where axis 1 meets the xy plane of the URDF root frame, a fixed
    translation in front of the chain (the root frame need not lie on axis 1); flange_xy (m, 2,
    default [0, 0]): the flange origin's offset from axis 6, along the paper's flange x and y;
    flange_rpy (deg, 3, default [0, 0, 0]): the URDF flange frame's roll, pitch, yaw in the paper's
    flange frame (z along axis 6), for a flange whose z is not along axis 6.
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
table
    step (deg, or m for a prismatic joint; one number or one per joint, required): the grid of the
    associative memory; max_rows (int, default 1,000,000); neighbours (int, default 32): stored rows
    seeding each pose; solutions (default 8); max_iterations (default 40).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from robomax_py.errors import RobotModelError
from robomax_py.robot.ik.numeric import NumericIkParams
from robomax_py.robot.ik.opw import OpwParams
from robomax_py.robot.ik.pose_table import TableIkParams
from robomax_py.robot.ik.ur import UrParams

_OPW_LENGTHS = ("a1", "a2", "b", "c1", "c2", "c3", "c4")
_UR_LENGTHS = ("d1", "a2", "a3", "d4", "d5", "d6")
_UR_POSES = ("base_xyz", "base_rpy", "flange_xyz", "flange_rpy")
_NUMERIC_INTS = ("seeds", "solutions", "max_iterations")
_TABLE_INTS = ("max_rows", "neighbours", "solutions", "max_iterations")


SOLVERS = ("opw", "ur", "numeric", "table")


def params_from_mapping(solver: str, params: Mapping[str, Any]) -> OpwParams | UrParams | NumericIkParams | TableIkParams:
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
        allowed: tuple[str, ...] = (*_OPW_LENGTHS, "offsets", "sign_corrections", "base_xy", "flange_xy", "flange_rpy")
    elif solver == "ur":
        allowed = (*_UR_LENGTHS, *_UR_POSES)
    elif solver == "table":
        allowed = ("step", *_TABLE_INTS)
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
        bx, by = _vector(params, "base_xy", 2, (0.0, 0.0))
        fx, fy = _vector(params, "flange_xy", 2, (0.0, 0.0))
        fr, fp, fw = (math.radians(v) for v in _vector(params, "flange_rpy", 3, (0.0, 0.0, 0.0)))
        return OpwParams(
            a1=a1, a2=a2, b=b, c1=c1, c2=c2, c3=c3, c4=c4,
            offsets=(o[0], o[1], o[2], o[3], o[4], o[5]),
            sign_corrections=(g[0], g[1], g[2], g[3], g[4], g[5]),
            base_xy=(bx, by), flange_xy=(fx, fy), flange_rpy=(fr, fp, fw),
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
    if solver == "table":
        return _table_params(params)
    defaults = NumericIkParams()
    return NumericIkParams(
        seeds=_positive_int(params, "seeds", defaults.seeds),
        solutions=_positive_int(params, "solutions", defaults.solutions),
        max_iterations=_positive_int(params, "max_iterations", defaults.max_iterations),
    )


def _table_params(params: Mapping[str, Any]) -> TableIkParams:
    """The table's steps stay a tuple of degrees here (the joint count is the URDF's): converted by
    `robot.model.checked_ik_params` once the joints are known."""
    if "step" not in params:
        raise RobotModelError(None, "ik.params.step", "missing (required): the grid step, deg (one number or one per joint)")
    step = params["step"]
    values = step if isinstance(step, (list, tuple)) else [step]
    for i, v in enumerate(values):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
            raise RobotModelError(None, "ik.params.step", f"entry {i}: expected a number > 0, got {v!r}")
    defaults = TableIkParams(step=())
    return TableIkParams(
        step=tuple(float(v) for v in values),
        max_rows=_positive_int(params, "max_rows", defaults.max_rows),
        neighbours=_positive_int(params, "neighbours", defaults.neighbours),
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


