"""Named frames of a cell file (docs/frames.md): frame-relative poses resolved to the world.

A cell may name frames (`frames:`, each a pose in its parent: the world, another frame or an
object), and place its robot, objects, dynamic objects, spots, stations and pick-and-place
locations in any of them with `frame:`. An object is a frame too: its own frame is its pose, so
spots given in part coordinates name the part (`frame: door`). `resolve_frames` turns a validated
cell file into the same file with every pose in world coordinates and no `frame:` left; the rest of
the loader, the planner, the exporters and verify see world coordinates only, as before.

What is not placed in a frame is left exactly as written (no round trip through a matrix), so a
cell without frames loads bit for bit as it did.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from robomax_py.errors import CellFileError
from robomax_py.transforms import pose_matrix, rpy_from_matrix

if TYPE_CHECKING:
    from robomax_py.io.cell_file import CellFile
    from robomax_py.io.cell_file_values import PoseFile

# The frame everything else is placed in; no frame or object may take its name as a frame.
WORLD = "world"


@dataclass(frozen=True, slots=True)
class FrameNode:
    """One frame of the cell's tree: a named frame, or an object other things are placed in."""

    name: str
    kind: Literal["frame", "object"]
    parent: str                      # WORLD or another node's name
    T_parent: np.ndarray             # (4, 4) its pose in its parent, m
    T_world: np.ndarray              # (4, 4) its pose in the world, m
    key: str                         # where the cell file defines it (`frames[2]`, `objects[0]`)

    def as_dict(self) -> dict[str, Any]:
        """For `check --json`: poses as {xyz (m), rpy (deg)}, rounded to 1e-9."""
        return {"name": self.name, "kind": self.kind, "parent": self.parent,
                "pose": _pose_dict(self.T_parent), "world": _pose_dict(self.T_world), "key": self.key}


@dataclass(slots=True)
class _Node:
    name: str
    kind: Literal["frame", "object"]
    parent: str
    T: np.ndarray
    key: str
    parent_key: str                  # the key naming its parent, for errors


def resolve_frames(cell: CellFile, path: Path) -> tuple[CellFile, tuple[FrameNode, ...]]:
    """The cell with every frame-relative pose in world coordinates (`frame:` keys cleared), and
    its frame tree in file order: every named frame, every object something is placed in and
    every object placed in a frame.
    CellFileError naming the key for a duplicate or reserved frame name, a frame name that is also
    an object's, an unknown frame, a cycle."""
    nodes = _nodes(cell, path)
    world = _world_poses(nodes, path)
    used = _used_frames(cell)
    tree = tuple(FrameNode(n.name, n.kind, n.parent, n.T, world[n.name], n.key) for n in nodes.values()
                 if n.kind == "frame" or n.name in used or n.parent != WORLD)
    if not used:
        return cell, tree

    def frame_of(name: str | None, key: str) -> np.ndarray | None:
        if name is None:
            return None
        if name == WORLD:
            return np.eye(4)
        if name not in world:
            raise CellFileError(path, key, _unknown(name, nodes))
        return world[name]

    update: dict[str, Any] = {}
    T = frame_of(cell.robot.frame, "robot.frame")
    if T is not None:
        update["robot"] = _placed(cell.robot, {"base": _moved(cell.robot.base, T)})
    for group in ("objects", "dynamic"):
        items = getattr(cell, group)
        if any(o.frame is not None for o in items):
            moved = []
            for i, o in enumerate(items):
                if o.frame is None:
                    moved.append(o)
                    continue
                node = nodes.get(o.name)
                # Its world pose is its node's; a second object of the same name (the loader refuses
                # it next) is placed on its own.
                M = world[o.name] if node is not None and node.key == f"{group}[{i}]" else \
                    frame_of(o.frame, f"{group}[{i}].frame") @ _matrix(o.pose)
                moved.append(_placed(o, {"pose": _pose_file(M, o.pose)}))
            update[group] = moved
    if any(s.frame is not None or any(p.frame is not None for p in s.spots) for s in cell.seams):
        update["seams"] = [_seam(s, f"seams[{i}]", frame_of) for i, s in enumerate(cell.seams)]
    if cell.tending is not None:
        update["tending"] = _tending(cell, frame_of)
    if cell.pick_place is not None and any(loc.frame is not None for loc in cell.pick_place.locations):
        locations = []
        for i, loc in enumerate(cell.pick_place.locations):
            T = frame_of(loc.frame, f"pick_place.locations[{i}].frame")
            locations.append(loc if T is None else _placed(loc, {"pose": _moved(loc.pose, T)}))
        update["pick_place"] = cell.pick_place.model_copy(update={"locations": locations})
    return cell.model_copy(update=update), tree


def _nodes(cell: CellFile, path: Path) -> dict[str, _Node]:
    """Every name a `frame:` may give: the named frames, then the objects and dynamic objects (a
    repeated object name is the loader's error to report; the first is the frame)."""
    nodes: dict[str, _Node] = {}
    for i, f in enumerate(cell.frames):
        if f.name == WORLD:
            raise CellFileError(path, f"frames[{i}].name", f"'{WORLD}' is the frame everything else is placed in; "
                                                           "name this one otherwise")
        if f.name in nodes:
            raise CellFileError(path, f"frames[{i}].name", f"duplicate frame name '{f.name}' (also {nodes[f.name].key})")
        nodes[f.name] = _Node(f.name, "frame", f.parent or WORLD, _matrix(f.pose), f"frames[{i}]", f"frames[{i}].parent")
    for group in ("objects", "dynamic"):
        for i, o in enumerate(getattr(cell, group)):
            other = nodes.get(o.name)
            if other is not None and other.kind == "frame":
                raise CellFileError(path, f"{group}[{i}].name", f"'{o.name}' is also the name of a frame "
                                    f"({other.key}): an object is a frame of its own name, so the two would be "
                                    "ambiguous; rename one")
            if other is None and o.name != WORLD:
                nodes[o.name] = _Node(o.name, "object", o.frame or WORLD, _matrix(o.pose), f"{group}[{i}]",
                                      f"{group}[{i}].frame")
    return nodes


def _world_poses(nodes: dict[str, _Node], path: Path) -> dict[str, np.ndarray]:
    """Each node's pose in the world: its parents' poses composed, root first."""
    world: dict[str, np.ndarray] = {}
    for start in nodes:
        chain: list[str] = []
        name = start
        while name != WORLD and name not in world:
            if name in chain:
                loop = chain[chain.index(name):] + [name]
                first = nodes[loop[0]]
                raise CellFileError(path, first.parent_key, "frames placed in each other: " + " -> ".join(loop)
                                    + f" (each is placed in the next; one must be placed in '{WORLD}' or a frame "
                                    "outside the loop)")
            chain.append(name)
            node = nodes[name]
            if node.parent != WORLD and node.parent not in nodes:
                raise CellFileError(path, node.parent_key, _unknown(node.parent, nodes))
            name = node.parent
        T = np.eye(4) if name == WORLD else world[name]
        for link in reversed(chain):
            T = T @ nodes[link].T
            world[link] = T
    return world


def _used_frames(cell: CellFile) -> set[str]:
    """The names given as a frame anywhere in the cell."""
    used = {f.parent for f in cell.frames if f.parent is not None}
    used |= {o.frame for o in (*cell.objects, *cell.dynamic) if o.frame is not None}
    used |= {cell.robot.frame} if cell.robot.frame is not None else set()
    used |= {sl.frame for sl in cell.spot_lists if sl.frame is not None}
    for s in cell.seams:
        used |= {s.frame} if s.frame is not None else set()
        used |= {p.frame for p in s.spots if p.frame is not None}
    if cell.tending is not None:
        used |= {st.frame for st in cell.tending.stations if st.frame is not None}
        used |= {m.door.frame for m in cell.tending.machines if m.door.frame is not None}
    if cell.pick_place is not None:
        used |= {loc.frame for loc in cell.pick_place.locations if loc.frame is not None}
    return used - {WORLD}


def _seam(seam: Any, key: str, frame_of: Any) -> Any:
    seam_T = frame_of(seam.frame, f"{key}.frame")
    spots = []
    for j, spot in enumerate(seam.spots):
        T = frame_of(spot.frame, f"{key}.spots[{j}].frame") if spot.frame is not None else seam_T
        if T is None:
            spots.append(spot)
            continue
        R, t = T[:3, :3], T[:3, 3]
        spots.append(_placed(spot, {
            "xyz": _listed(R @ np.asarray(spot.xyz, dtype=float) + t),
            "normal": _listed(R @ np.asarray(spot.normal, dtype=float)),
            "direction": _listed(R @ np.asarray(spot.direction, dtype=float))}))
    return _placed(seam, {"spots": spots})


def _tending(cell: CellFile, frame_of: Any) -> Any:
    tending = cell.tending
    assert tending is not None
    stations = []
    for i, st in enumerate(tending.stations):
        T = frame_of(st.frame, f"tending.stations[{i}].frame")
        if T is None:
            stations.append(st)
            continue
        M = T @ pose_matrix(st.xyz, np.radians(st.rpy))
        stations.append(_placed(st, {"xyz": _listed(M[:3, 3]), "rpy": _listed(np.degrees(rpy_from_matrix(M[:3, :3])))}))
    machines = []
    for i, m in enumerate(tending.machines):
        T = frame_of(m.door.frame, f"tending.machines[{i}].door.frame")
        machines.append(m if T is None else m.model_copy(update={"door": _placed(m.door, {"pose": _moved(m.door.pose, T)})}))
    return tending.model_copy(update={"stations": stations, "machines": machines})


def _placed(item: Any, update: dict[str, Any]) -> Any:
    """`item` with `update` and no `frame`: unset, as if never written (a cell rewritten from the
    resolved schema, `dump_cell_file`, has no `frame:` keys)."""
    out = item.model_copy(update={**update, "frame": None})
    out.__pydantic_fields_set__.discard("frame")
    return out


def _unknown(name: str, nodes: dict[str, _Node]) -> str:
    frames = [n.name for n in nodes.values() if n.kind == "frame"]
    return (f"unknown frame '{name}' (frames: {', '.join([WORLD, *frames])}; an object's name is its own frame "
            "too)")


def _matrix(pose: PoseFile) -> np.ndarray:
    return pose_matrix(pose.xyz, np.radians(pose.rpy))


def _moved(pose: PoseFile, T: np.ndarray) -> Any:
    return _pose_file(T @ _matrix(pose), pose)


def _pose_file(M: np.ndarray, like: PoseFile) -> Any:
    """The pose M as the file model `like` is (a copy of it: this module does not import the cell's
    models, which import it)."""
    return like.model_copy(update={"xyz": _listed(M[:3, 3]), "rpy": _listed(np.degrees(rpy_from_matrix(M[:3, :3])))})


def _listed(v: np.ndarray) -> list[float]:
    return [float(x) + 0.0 for x in v]          # + 0.0: no -0.0 in what is written back


def _pose_dict(M: np.ndarray) -> dict[str, list[float]]:
    return {"xyz": [round(float(v), 9) + 0.0 for v in M[:3, 3]],
            "rpy": [round(float(v), 9) + 0.0 for v in np.degrees(rpy_from_matrix(M[:3, :3]))]}


def format_tree(tree: tuple[FrameNode, ...]) -> list[str]:
    """The frame tree as indented lines, children under their parent in file order:
    `fixture (frame): xyz [...] m, rpy [...] deg in world`."""
    children: dict[str, list[FrameNode]] = {}
    for node in tree:
        children.setdefault(node.parent, []).append(node)
    lines = [WORLD]

    def walk(parent: str, depth: int) -> None:
        for node in children.get(parent, []):
            p = _pose_dict(node.T_parent)
            xyz = ", ".join(f"{v:g}" for v in p["xyz"])
            rpy = ", ".join(f"{v:g}" for v in p["rpy"])
            lines.append(f"{'  ' * depth}{node.name} ({node.kind}): xyz [{xyz}] m, rpy [{rpy}] deg in {parent}")
            walk(node.name, depth + 1)

    walk(WORLD, 1)       # every node's parent is in the tree: a frame, or an object placed in or holding one
    return lines
