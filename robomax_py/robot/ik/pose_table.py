"""`ik.solver: table` for any arm: the associative memory (`ik.table`) of the flange pose over a
joint grid, whose nearest stored rows seed damped least squares (`ik.numeric`).

The table is the arm's own: every row of the grid within the joint limits, keyed by the flange pose
in the root frame (position in m and the rotation matrix's columns times ROTATION_WEIGHT_M, so one
metre of position weighs as a radian of rotation does at that radius). Collisions are the
planner's business: each solution is checked in the cell. Built once per robot description and
step, kept in memory and in the cache folder (`ROBOMAX_CACHE`, else the XDG cache, `ik_tables/`),
named by the SHA-256 of the chain's kinematics, the flange and the grid.
"""

from __future__ import annotations

import hashlib
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
from scipy.spatial import cKDTree

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.cache_files import cache_folder, store_arrays
from robomax_py.errors import RobotModelError
from robomax_py.robot.ik._chain import chain_to_frame, frame_pose
from robomax_py.robot.ik.numeric import numeric_ik
from robomax_py.robot.ik.table import JointGrid, TableIk

ROTATION_WEIGHT_M = 0.3
TABLE_FORMAT = 1


@dataclass(frozen=True, slots=True)
class TableIkParams:
    """robot.yaml `ik.params` for `solver: table` (radians here).

    step : per joint, the grid step (rad, or m for a prismatic joint); J_i = ceil(range / step) + 1.
    max_rows : a grid larger than this is refused (memory: about 150 bytes a row with its k-d tree).
    neighbours : stored rows that seed the refinement of each pose.
    solutions : K, the solution slots returned per pose.
    max_iterations : damped-least-squares iterations per seed.
    """

    step: tuple[float, ...]
    max_rows: int = 1_000_000
    neighbours: int = 32
    solutions: int = 8
    max_iterations: int = 40


def grid_of(lower: FloatArray, upper: FloatArray, step: tuple[float, ...]) -> JointGrid:
    """The paper's grid over the joint limits: q_i(j) = lower + j (upper - lower) / (J_i - 1)."""
    counts = tuple(int(np.ceil((hi - lo) / s - 1e-9)) + 1 for lo, hi, s in zip(lower, upper, step))
    return JointGrid(tuple(float(x) for x in lower), tuple(float(x) for x in upper), tuple(max(c, 2) for c in counts))


def pose_features(T: FloatArray) -> FloatArray:
    """(m, 12) lookup points of flange poses (m, 4, 4): position, then the rotation's columns weighted."""
    T = np.asarray(T, dtype=float).reshape(-1, 4, 4)
    R = T[:, :3, :3].transpose(0, 2, 1).reshape(-1, 9)
    return np.concatenate([T[:, :3, 3], ROTATION_WEIGHT_M * R], axis=1)


_MEMORY: dict[str, TableIk] = {}


def flange_table(model: pin.Model, frame_id: int, lower: FloatArray, upper: FloatArray, params: TableIkParams,
                 source: Path | None = None) -> TableIk:
    """The robot's table, from memory, the cache folder or built (and stored)."""
    grid = grid_of(lower, upper, params.step)
    if grid.size > params.max_rows:
        raise RobotModelError(source, "ik.params.step", f"the grid has {grid.size:,} rows (J = {list(grid.counts)}), "
                              f"more than max_rows {params.max_rows:,}: take larger steps (the wrist's especially)")
    key = _key(model, frame_id, grid)
    if key in _MEMORY:
        return _MEMORY[key]
    path = cache_folder("ik_tables") / f"{key}.npz"
    table = _load(path)
    if table is None:
        chain = chain_to_frame(model, frame_id)
        q = np.concatenate([grid.rows(first, 65_536) for first in range(0, grid.size, 65_536)])
        x = pose_features(frame_pose(chain, q))
        table = TableIk(q, x, grid.size, cKDTree(x))
        _store(path, table)
    _MEMORY[key] = table
    return table


def table_ik(model: pin.Model, frame_id: int, T_root_frame: FloatArray, lower: FloatArray, upper: FloatArray,
             params: TableIkParams, q_hint: FloatArray | None = None,
             source: Path | None = None) -> tuple[FloatArray, BoolArray]:
    """As `numeric_ik`, seeded by the `neighbours` stored rows nearest each pose (and the hint)."""
    table = flange_table(model, frame_id, lower, upper, params, source)
    T = np.asarray(T_root_frame, dtype=float)
    batch = T.shape[:-2]
    flat = T.reshape(-1, 4, 4)
    k = min(params.neighbours, len(table))
    _, idx = table.tree.query(pose_features(flat), k=k)
    seeds = table.q[np.asarray(idx).reshape(len(flat), k)]
    q, valid = numeric_ik(model, frame_id, flat, lower, upper, np.random.default_rng(0), 0, q_hint,
                          max_solutions=params.solutions, max_iterations=params.max_iterations,
                          seeds=seeds)
    n = q.shape[-1]
    return q.reshape(batch + (params.solutions, n)), valid.reshape(batch + (params.solutions,))


def _key(model: pin.Model, frame_id: int, grid: JointGrid) -> str:
    """SHA-256 of what the table depends on: the chain's joints (kind, placement, axis) up to the
    frame, the frame's placement and the grid."""
    h = hashlib.sha256(f"robomax ik table {TABLE_FORMAT}|{grid.start}|{grid.end}|{grid.counts}".encode())
    for j in range(1, model.njoints):
        h.update(model.joints[j].shortname().encode())
        h.update(np.round(model.jointPlacements[j].homogeneous, 12).tobytes())
    h.update(np.round(model.frames[frame_id].placement.homogeneous, 12).tobytes())
    return h.hexdigest()


def _load(path: Path) -> TableIk | None:
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            q, x, size = data["q"], data["x"], int(data["grid_size"])
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, EOFError):
        return None
    if q.ndim != 2 or x.shape != (len(q), 12):
        return None
    return TableIk(q, x, size, cKDTree(x))


def _store(path: Path, table: TableIk) -> None:
    # An unwritable cache: the table is built again next time.
    store_arrays(path, {"q": table.q, "x": table.x, "grid_size": np.asarray(table.grid_size, dtype=np.int64)})
