"""The cells' decisions (`pair_cells`) kept across the worlds of a process and across runs, in the
cache folder (`ROBOMAX_CACHE`, else the XDG cache, `cells/`).

A decision is a fact about two robot or tool pieces, their margin and a box of the joints between
them: certified, the pair is farther apart than its margin at every configuration of the cell, by a
proof (`collision_core`, `chunk_reach`); uncertified, coal tests it. It depends on nothing of the
cell's objects. Every plan and `verify` of a cell with the same arm and tool, and every cell of a
corpus or a batch that shares them, decides the same cells again: on a 23-spot UR10 box cell that
was 14,000 decisions, about 3 s of a plan. The key is a SHA-256 of everything a decision depends on
(each such pair's two pieces, the joints, the margin and the cells' layout), with the deciding code
and the collision libraries' versions, so an entry is never stale: a changed arm, tool, margin or
code only misses.

The worlds of one process with the same key share one decisions array. `keep_decisions` writes the
arrays that gained decisions since they were read, merged with what another process wrote meanwhile
(a decision is the same whoever makes it; a write lost to a race costs only deciding again).
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from collections.abc import Sequence
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray, IntArray
from robomax_py.cache_files import cache_folder, store_arrays
from robomax_py.world.acm_cache import joint_bytes, shape_bytes, source_digest
from robomax_py.world.pair_cells import (
    CELL_RAD,
    CERTIFIED,
    UNCERTIFIED,
    UNKNOWN,
    CellTable,
)

# The code that decides a cell, and this file: a change to any makes every older entry miss.
_CODE = source_digest("pair_cells.py", "chunk_reach.py", "collision_core.py", "prefilter.py", "prefilter_kernels.py",
                      "prefilter_reach.py", "prefilter_layout.py", "bounds.py", "cell_cache.py")
# Decisions by key, shared by the worlds of this process (a few arms and tools at most; each array
# is at most a few hundred kB), with how many were decided when the array was last read or written.
_MEMORY: OrderedDict[str, tuple[np.ndarray, int]] = OrderedDict()
_MEMORY_SIZE = 16


def decisions_key(model: pin.Model, gm: pin.GeometryModel, pair_a: IntArray, pair_b: IntArray,
                  pair_margin: FloatArray, tables: Sequence[CellTable | None]) -> str | None:
    """SHA-256 of what the decisions of these cells depend on; None when no pair has cells, or a
    piece's shape cannot be serialised (its decisions are then kept in its world only)."""
    if all(t is None for t in tables):
        return None
    h = hashlib.sha256(b"robomax cell decisions|" + _CODE)
    h.update(f"{coal.__version__}|{pin.__version__}|{CELL_RAD!r}".encode())
    for j in range(1, model.njoints):
        h.update(joint_bytes(model.joints[j]))
        h.update(np.asarray(model.jointPlacements[j].homogeneous, dtype=float).tobytes())
    for k, table in enumerate(tables):
        if table is None:
            continue
        h.update(f"{table!r}|{float(pair_margin[k])!r}|".encode())
        for g in (int(pair_a[k]), int(pair_b[k])):
            piece = gm.geometryObjects[g]
            shape = shape_bytes(piece.geometry)
            if shape is None:
                return None
            h.update(f"{int(piece.parentJoint)}|".encode())
            h.update(np.asarray(piece.placement.homogeneous, dtype=float).tobytes())
            h.update(shape)
    return h.hexdigest()


def shared_decisions(key: str | None, size: int) -> np.ndarray:
    """The decisions array (int8, `size` cells) of the worlds with this key: this process's, else
    the cache folder's, else none decided. No key: an array of its own."""
    if key is None:
        return np.zeros(size, dtype=np.int8)
    hit = _MEMORY.get(key)
    if hit is not None and len(hit[0]) == size:
        _MEMORY.move_to_end(key)
        return hit[0]
    found = _load(_path(key), size)
    decided = np.zeros(size, dtype=np.int8) if found is None else found
    _MEMORY[key] = (decided, int(np.count_nonzero(decided)))
    while len(_MEMORY) > _MEMORY_SIZE:
        _MEMORY.popitem(last=False)
    return decided


def keep_decisions() -> None:
    """Write each shared array that gained decisions since it was read or written, merged with the
    cache folder's entry (this process's decision where it made one)."""
    for key, (decided, counted) in list(_MEMORY.items()):
        now = int(np.count_nonzero(decided))
        if now <= counted:
            continue
        path = _path(key)
        stored = _load(path, len(decided))
        if stored is not None:
            unknown = decided == UNKNOWN
            decided[unknown] = stored[unknown]
        store_arrays(path, {"decided": decided}, compressed=True)    # mostly undecided: a few kB
        _MEMORY[key] = (decided, int(np.count_nonzero(decided)))


def _path(key: str) -> Path:
    return cache_folder("cells") / f"{key}.npz"


def _load(path: Path, size: int) -> np.ndarray | None:
    """An entry's decisions, or None when there is none or it is not an int8 array of `size`
    decisions each UNKNOWN, CERTIFIED or UNCERTIFIED (a bad entry is decided again and rewritten)."""
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            decided = np.array(data["decided"])
    except Exception:  # noqa: BLE001 - a truncated or foreign file is a miss
        return None
    if decided.dtype != np.int8 or decided.shape != (size,):
        return None
    if not np.isin(decided, (UNKNOWN, CERTIFIED, UNCERTIFIED)).all():
        return None
    return decided
