"""The grid of a configuration-space map: the first three joints sampled, the wrist held fixed.

The published ROBOMAX method plans detours in a discrete map of A1-A3 with the wrist (A4-A6)
fixed; this is that grid. Each axis is sampled at `resolution` values evenly over the joint's
limits, ends included, so cell (i, j, k) is the configuration (q1[i], q2[j], q3[k], wrist).
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray, IntArray
from robomax_py.errors import RobomaxError
from robomax_py.robot import RobotModel
from robomax_py.robot.ik._chain import joint_axes_at_zero

MIN_RESOLUTION = 4
MAX_RESOLUTION = 400
# The 26 steps to a cell's neighbours, in a fixed order (the maps' edge lists, and so Dijkstra's ties, follow it).
_STEPS = np.array([d for d in itertools.product((-1, 0, 1), repeat=3) if d != (0, 0, 0)], dtype=np.int64)
VERTICAL_TOL = 1e-6          # |cos| of A1's axis to the base z axis must be within this of 1


class CSpaceError(RobomaxError):
    """A configuration-space map cannot be made for this robot, cell or request."""


@dataclass(frozen=True, slots=True)
class CSpaceGrid:
    """Sample values of A1-A3 (rad) and the fixed wrist (rad, joints 4..n)."""

    axes: tuple[FloatArray, FloatArray, FloatArray]
    wrist: FloatArray

    @property
    def resolution(self) -> int:
        return len(self.axes[0])

    @property
    def size(self) -> int:
        return len(self.axes[0]) * len(self.axes[1]) * len(self.axes[2])

    def configs(self, start: int, stop: int) -> FloatArray:
        """(stop - start, n) configurations of the flat cells start..stop-1 (C order over i, j, k)."""
        n2, n3 = len(self.axes[1]), len(self.axes[2])
        flat = np.arange(start, stop)
        i, rest = np.divmod(flat, n2 * n3)
        j, k = np.divmod(rest, n3)
        q = np.empty((len(flat), 3 + len(self.wrist)))
        q[:, 0], q[:, 1], q[:, 2] = self.axes[0][i], self.axes[1][j], self.axes[2][k]
        q[:, 3:] = self.wrist
        return q

    def cell_of(self, q: FloatArray) -> tuple[int, int, int]:
        """The cell whose sample values are nearest to q's first three joints."""
        return nearest_cell(self.axes, q)

    @staticmethod
    def of(robot: RobotModel, resolution: int, wrist: FloatArray) -> CSpaceGrid:
        """The grid over `robot`'s limits; a robot that is not a 6-axis arm with a vertical A1, or a
        resolution outside MIN_RESOLUTION..MAX_RESOLUTION, is a CSpaceError."""
        check_arm(robot)
        if not MIN_RESOLUTION <= resolution <= MAX_RESOLUTION:
            raise CSpaceError(f"resolution must be {MIN_RESOLUTION}..{MAX_RESOLUTION} samples per axis, got {resolution}")
        wrist = np.asarray(wrist, dtype=float).reshape(-1)
        if len(wrist) != robot.dof - 3 or not np.isfinite(wrist).all():
            raise CSpaceError(f"the wrist needs {robot.dof - 3} finite joint values, got {wrist.tolist()}")
        lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
        axes = tuple(np.linspace(lo[a], hi[a], resolution) for a in range(3))
        return CSpaceGrid(axes=axes, wrist=wrist)  # type: ignore[arg-type]


@functools.cache
def neighbour_moves(shape: tuple[int, int, int]) -> tuple[IntArray, IntArray]:
    """Every 26-connected move between the cells of a box of this shape (C order): the from-cell
    and to-cell indices, step by step in `_STEPS`' order. Cached, so read-only."""
    idx = np.arange(shape[0] * shape[1] * shape[2]).reshape(shape)
    src, dst = [], []
    for step in _STEPS:
        src.append(idx[tuple(slice(max(0, -s), n - max(0, s)) for s, n in zip(step, shape))].ravel())
        dst.append(idx[tuple(slice(max(0, s), n - max(0, -s)) for s, n in zip(step, shape))].ravel())
    moves = np.concatenate(src), np.concatenate(dst)
    for a in moves:
        a.flags.writeable = False
    return moves


@functools.cache
def neighbour_graph(shape: tuple[int, int, int]) -> tuple[IntArray, IntArray, IntArray]:
    """`neighbour_moves` as a graph in CSR form: (indptr, indices, order), the moves out of cell u
    being indices[indptr[u]:indptr[u + 1]], in `neighbour_moves`' order; order[e] is the place in
    `neighbour_moves` of the graph's move e (a move's cost array `w` is `w[order]` in the graph).
    Cached, so read-only."""
    src, dst = neighbour_moves(shape)
    order = np.argsort(src, kind="stable")
    indptr = np.searchsorted(src[order], np.arange(shape[0] * shape[1] * shape[2] + 1))
    graph = indptr.astype(np.int64), np.ascontiguousarray(dst[order], dtype=np.int64), order.astype(np.int64)
    for a in graph:
        a.flags.writeable = False
    return graph


@functools.cache
def reverse_moves(shape: tuple[int, int, int]) -> tuple[IntArray, IntArray]:
    """(one, reverse): the places in `neighbour_moves` of the moves from a lower cell to a higher
    one (one of each pair of opposite moves), and for every move the place of the opposite move.
    Cached, so read-only."""
    src, dst = neighbour_moves(shape)
    n = shape[0] * shape[1] * shape[2]
    code = src * n + dst
    order = np.argsort(code)
    reverse = order[np.searchsorted(code, dst * n + src, sorter=order)]
    moves = np.flatnonzero(src < dst), reverse.astype(np.int64)
    for a in moves:
        a.flags.writeable = False
    return moves


def nearest_cell(axes: tuple[FloatArray, ...] | list[FloatArray], q: FloatArray) -> tuple[int, int, int]:
    """Indices of the samples of three axes nearest to q's first three values."""
    return tuple(int(np.argmin(np.abs(axes[a] - q[a]))) for a in range(3))  # type: ignore[return-value]


def check_arm(robot: RobotModel) -> None:
    """The map's method needs a 6-axis arm whose A1 turns about the base's vertical axis."""
    if robot.dof != 6:
        raise CSpaceError(f"robot {robot.name} has {robot.dof} axes; the C-space map needs a 6-axis arm")
    linear = robot.prismatic_joints
    if linear:
        # Its grid is of the angles of A1-A3 and its bounds of the wrist's turns: a lift or a
        # track is neither (a vertical lift would pass the test below as a vertical A1).
        raise CSpaceError(f"robot {robot.name}: {', '.join(linear)} is prismatic; the C-space map needs six revolute axes")
    axes = joint_axes_at_zero(robot.model, robot.flange_frame_id)
    if abs(abs(float(axes.u[0][2])) - 1.0) > VERTICAL_TOL:
        raise CSpaceError(f"robot {robot.name}: A1 is not vertical (axis {np.round(axes.u[0], 6).tolist()} in the "
                          "base frame); the C-space map needs a vertical A1")
