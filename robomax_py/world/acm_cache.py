"""The self-pair analysis of the allowed-collision proof, kept in memory and in the cache folder
(`ROBOMAX_CACHE`, else the XDG cache, `acm/`).

Which robot and tool pieces can never come close, which touch at the flange in every sample, which
always touch: seconds of sampling and branch and bound (`acm._sample_self_pairs`,
`acm._prove_never_close`) that depend only on the arm, its tool (and a held part), the candidate
pairs and the options, never on the cell's objects. Every plan and every `verify` of a cell builds
worlds for the same arm and tool, so the answer is computed once. The key is a SHA-256 of everything
the answer depends on, the analysis code and the collision library's version included, so an entry
is never stale: a changed arm, tool, option or code only misses."""

from __future__ import annotations

import hashlib
import pickle
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from robomax_py.cache_files import cache_folder, store_arrays
from robomax_py.robot import RobotModel

Pair = tuple[int, int]
_FIELDS = ("never_near", "flange_touch", "always_touch", "proved_far")


@dataclass(frozen=True, slots=True)
class SampledPairs:
    never_near: frozenset[Pair]     # never within acm_margin in any sample
    flange_touch: frozenset[Pair]   # flange pairs within flange_contact_m in every sample
    always_touch: frozenset[Pair]   # touching (margin 0) in every sample


Analysis = tuple[SampledPairs, set[Pair]]
_MEMORY: dict[str, Analysis] = {}


def source_digest(*names: str) -> bytes:
    """SHA-256 of the named modules' source in this folder: the code a cache's entries came from,
    so that a change to it makes every older entry miss."""
    here = Path(__file__).parent
    h = hashlib.sha256()
    for name in names:
        h.update((here / name).read_bytes())
    return h.digest()


_CODE = source_digest("acm.py", "acm_cache.py", "bounds.py")    # the analysis code


def _key(robot: RobotModel, gm: pin.GeometryModel, n_self: int, pair_sets: Sequence[Sequence[Pair]],
         options: Any) -> str | None:
    """SHA-256 of what the analysis depends on; None when a piece's geometry cannot be serialised
    (then it is computed every time)."""
    h = hashlib.sha256(b"robomax acm self pairs|" + _CODE)
    h.update(f"{coal.__version__}|{pin.__version__}|{options!r}".encode())
    model = robot.model
    for j in range(1, model.njoints):
        h.update(joint_bytes(model.joints[j]))
        h.update(np.asarray(model.jointPlacements[j].homogeneous, dtype=float).tobytes())
    h.update(np.asarray(robot.limits.lower, dtype=float).tobytes())
    h.update(np.asarray(robot.limits.upper, dtype=float).tobytes())
    for i in range(n_self):
        g = gm.geometryObjects[i]
        h.update(f"{g.name}|{int(g.parentJoint)}|".encode())
        h.update(np.asarray(g.placement.homogeneous, dtype=float).tobytes())
        shape = shape_bytes(g.geometry)
        if shape is None:
            return None
        h.update(shape)
    for pairs in pair_sets:
        h.update(np.asarray(list(pairs), dtype=np.int64).reshape(-1, 2).tobytes() + b"|")
    return h.hexdigest()


def joint_bytes(joint: Any) -> bytes:
    """The bytes that determine how a Pinocchio joint moves: its kind, and the axis of a joint
    whose kind does not name it (a revolute or prismatic joint about any axis, FANUC's J3 about
    -y) and a passive joint's multiplier and offset."""
    out = str(joint.shortname()).encode() + b"|"
    model = joint.extract()
    for name in ("axis", "scaling", "offset"):
        if hasattr(model, name):
            out += name.encode() + np.asarray(getattr(model, name), dtype=float).tobytes()
    return out


def shape_bytes(geometry: Any) -> bytes | None:
    """The bytes that determine a coal shape: a convex hull by its points (coal does not pickle
    `ConvexBase`), any other shape by its pickle; None for neither."""
    # A triangle BVH (a tool mesh that is not convex pieces) has no swept-sphere radius in coal 3.
    radius = geometry.getSweptSphereRadius() if hasattr(geometry, "getSweptSphereRadius") else None
    kind = f"{type(geometry).__name__}|{geometry.getNodeType()}|{radius!r}|".encode()
    if hasattr(geometry, "points") and hasattr(geometry, "num_points"):
        return kind + np.ascontiguousarray(np.asarray(geometry.points(), dtype=float)).tobytes()
    try:
        return kind + pickle.dumps(geometry)
    except Exception:  # noqa: BLE001 - a shape that cannot be serialised is analysed every time
        return None


def _as_set(a: np.ndarray) -> set[Pair]:
    return {(int(x), int(y)) for x, y in a.reshape(-1, 2)}


def _load(path: Path) -> Analysis | None:
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            sets = [_as_set(np.asarray(data[f], dtype=np.int64)) for f in _FIELDS]
    except (OSError, ValueError, KeyError, EOFError, Exception):  # noqa: BLE001 - a bad entry is rebuilt
        return None
    never, flange, touch, proved = sets
    return SampledPairs(frozenset(never), frozenset(flange), frozenset(touch)), proved


def cached_self_analysis(robot: RobotModel, gm: pin.GeometryModel, n_self: int,
                         pair_sets: Sequence[Sequence[Pair]], options: Any,
                         analyse: Callable[[], Analysis]) -> Analysis:
    """`analyse()` for this arm, tool and options: from memory, the cache folder, or computed (and
    stored). `n_self`: the geometry model's first pieces that are the robot's and the tool's (the
    analysis reads no other); `pair_sets`: the candidate, provable and flange pairs it is given."""
    key = _key(robot, gm, n_self, pair_sets, options)
    if key is None:
        return analyse()
    if key in _MEMORY:
        sampled, proved = _MEMORY[key]
        return sampled, set(proved)
    path = cache_folder("acm") / f"{key}.npz"
    found = _load(path)
    if found is None:
        found = analyse()
        sampled, proved = found
        store_arrays(path, {f: np.asarray(sorted(v), dtype=np.int64).reshape(-1, 2) for f, v in zip(
            _FIELDS, (sampled.never_near, sampled.flange_touch, sampled.always_touch, proved))})
    _MEMORY[key] = found
    return found[0], set(found[1])
