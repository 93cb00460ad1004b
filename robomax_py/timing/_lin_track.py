"""Internals of `lin`: the Cartesian line's geometry and the IK branch tracker."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from scipy.spatial.transform import Rotation

from robomax_py._typing import FloatArray
from robomax_py.robot import RobotModel, fk_tcp, prismatic_mask
from robomax_py.robot.solve import continuation, redundant
from robomax_py.timing._common import TimingError
from robomax_py.timing.paths import spline_path
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.transforms import rotation_angle

# Path parameter per radian for a pure re-orientation (no TCP travel), m/rad.
ROT_LENGTH_M = 0.1
# Below this the line has no translation, m.
ZERO_LENGTH_M = 1e-9
# Orientation error allowed halfway between samples, rad.
LIN_PATH_TOL_RAD = TOL.lin_path_tol_rad

class IkSolver(Protocol):
    """(robot, T_base_tcp (..., 4, 4), q_hint) -> table with q (..., B, n) and valid (..., B), as
    `robomax_py.robot.solve.solve_all` (a seeded solver starts from `q_hint` first)."""

    def __call__(self, robot: RobotModel, T_base_tcp: FloatArray, q_hint: FloatArray | None = None, /) -> Any: ...


@dataclass(frozen=True, slots=True, eq=False)
class Line:
    """TCP poses T(u), u in [0, 1]: position linear, orientation R0 exp(u log(R0^T R1)).

    tcp_length : m; tcp_angle : rad; length : path-parameter length (m of travel, or ROT_LENGTH_M
    per radian when there is no travel).
    """

    T0: FloatArray
    p1: FloatArray
    rotvec: FloatArray
    tcp_length: float
    tcp_angle: float
    length: float

    @staticmethod
    def between(T_start: FloatArray, T_end: FloatArray) -> Line:
        T0 = np.asarray(T_start, dtype=float)
        T1 = np.asarray(T_end, dtype=float)
        rotvec = Rotation.from_matrix(T0[:3, :3].T @ T1[:3, :3]).as_rotvec()
        tcp_length = float(np.linalg.norm(T1[:3, 3] - T0[:3, 3]))
        tcp_angle = float(np.linalg.norm(rotvec))
        length = tcp_length if tcp_length > ZERO_LENGTH_M else ROT_LENGTH_M * tcp_angle
        return Line(T0=T0, p1=T1[:3, 3].copy(), rotvec=rotvec, tcp_length=tcp_length, tcp_angle=tcp_angle, length=length)

    def poses(self, u: FloatArray) -> FloatArray:
        """(k, 4, 4) poses at line fractions u (k,)."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        T = np.zeros((len(u), 4, 4))
        T[:, :3, :3] = self.T0[:3, :3] @ Rotation.from_rotvec(u[:, None] * self.rotvec).as_matrix()
        T[:, :3, 3] = self.T0[:3, 3] + u[:, None] * (self.p1 - self.T0[:3, 3])
        T[:, 3, 3] = 1.0
        return T


class Tracker:
    """IK calls along a line and the choice of the solution that continues the motion."""

    def __init__(self, robot: RobotModel, solve: IkSolver, line: Line, branch: int, max_step: float) -> None:
        self.robot = robot
        self.line = line
        self.branch = branch
        self.max_step = max_step
        self._solve = solve
        self._revolute = ~prismatic_mask(robot.model)
        # An arm with more joints than six: a column of its table at one pose and at the next are
        # unrelated points of the self-motion, so a motion is continued from its own last
        # configuration only (`continued`), never from a table.
        self.redundant = redundant(robot)

    def solve(self, u: FloatArray, q_hint: FloatArray | None = None) -> Any:
        """The IK table at line fractions u (k,); `q_hint` seeds a numeric solver first."""
        if q_hint is None:
            return self._solve(self.robot, self.line.poses(u))
        return self._solve(self.robot, self.line.poses(u), q_hint)

    @property
    def seeded(self) -> bool:
        """Whether the solver searches from seeds (numeric, table): its table at a pose holds the
        solutions its seeds reached, so the continuation of a motion may be missing from it and is
        found by seeding the solver at the configuration just before."""
        return self.robot.ik_solver in ("numeric", "table")

    def column(self, table: Any, row: int) -> FloatArray | None:
        """The start column's solution at this row, or None where it is not valid."""
        valid = np.asarray(table.valid)[row]
        if not (0 <= self.branch < len(valid)):
            raise TimingError(f"branch index {self.branch} outside the IK table's {len(valid)} columns")
        return np.array(np.asarray(table.q)[row, self.branch], dtype=float) if valid[self.branch] else None

    def any_valid(self, table: Any, row: int) -> bool:
        return bool(np.any(np.asarray(table.valid)[row]))

    def reachable(self, table: Any, row: int) -> bool:
        """Some column's branch exists here, if only outside the limits (tables without `reachable`: no)."""
        reach = getattr(table, "reachable", None)
        return bool(np.any(np.asarray(reach)[row])) if reach is not None else False

    def own_reachable(self, table: Any, row: int) -> bool:
        """The start column's branch exists here, if only outside the limits."""
        reach = getattr(table, "reachable", None)
        return bool(np.asarray(reach)[row, self.branch]) if reach is not None else False

    def nearest(self, table: Any, row: int, q_prev: FloatArray) -> FloatArray | None:
        """The valid solution (any column, shifted by whole turns) nearest q_prev, or None."""
        q = np.asarray(table.q)[row]
        valid = np.asarray(table.valid)[row]
        if not np.any(valid):
            return None
        cand = self.unwrap(q[valid], q_prev)
        k = int(np.argmin(np.max(np.abs(cand - q_prev), axis=1)))
        return np.asarray(cand[k], dtype=float)

    def continued(self, u: float, q_prev: FloatArray) -> FloatArray | None:
        """A redundant arm's continuation of q_prev at line fraction u (`solve.continuation`), or None
        where there is none within max_step."""
        q, ok = continuation(self.robot, self.line.poses(np.array([u])), np.asarray(q_prev, dtype=float)[None])
        if not ok[0]:
            return None
        near = self.unwrap(q, q_prev)[0]
        return np.asarray(near, dtype=float) if float(np.max(np.abs(near - q_prev))) <= self.max_step else None

    def step(self, table: Any, row: int, u: float, q_prev: FloatArray) -> FloatArray | None:
        """The motion's configuration at line fraction u after q_prev: a redundant arm's continuation
        (`continued`, `table` unused); else `follow` at `row` of `table` (the IK table at u), and for
        a seeded solver, where that finds none, `follow` in the table solved from q_prev."""
        if self.redundant:
            return self.continued(u, q_prev)
        q = self.follow(table, row, q_prev)
        if q is None and self.seeded:
            q = self.follow(self.solve(np.array([u]), q_prev), 0, q_prev)
        return q

    def follow(self, table: Any, row: int, q_prev: FloatArray) -> FloatArray | None:
        """The continuation of q_prev at this row: own column first, else any solution within max_step."""
        own = self.column(table, row)
        if own is not None:
            own = self.unwrap(own[None], q_prev)[0]
            if float(np.max(np.abs(own - q_prev))) <= self.max_step:
                return np.asarray(own, dtype=float)
        near = self.nearest(table, row, q_prev)
        if near is not None and float(np.max(np.abs(near - q_prev))) <= self.max_step:
            return near
        return None

    def unwrap(self, q: FloatArray, q_prev: FloatArray) -> FloatArray:
        """(k, n) solutions with revolute joints shifted by 2 pi multiples to lie nearest q_prev (n,)."""
        turns = np.round((q_prev - q) / (2.0 * np.pi)) * self._revolute
        return np.asarray(q + 2.0 * np.pi * turns, dtype=float)


def off_line(robot: RobotModel, line: Line, u: FloatArray, q: FloatArray, tol: float) -> np.ndarray:
    """(k - 1,) bool: intervals whose spline midpoint puts the TCP further than tol (m) from the line."""
    if len(u) < 2:
        return np.zeros(0, dtype=bool)
    s = u * line.length
    q_mid = spline_path(s, q)(0.5 * (s[:-1] + s[1:]))
    T_got = fk_tcp(robot, q_mid)
    T_want = line.poses(0.5 * (u[:-1] + u[1:]))
    pos_err = np.linalg.norm(T_got[:, :3, 3] - T_want[:, :3, 3], axis=1)
    rot_err = rotation_angle(T_got[:, :3, :3], T_want[:, :3, :3])
    return np.asarray((pos_err > tol) | (rot_err > LIN_PATH_TOL_RAD))
