"""Probable mistakes in a valid cell file: `Notice`s (file, key, message), never errors.

A cell file can be valid and still almost certainly not what its author meant: written in
millimetres, a spot inside the table, a home pose in radians. Each of these plans (or fails to plan)
without saying why, so `load_cell` runs `lint_cell` on every cell it loads and keeps what it finds in
`CellSpec.notices`; `robomax check` and `robomax plan` print them on stderr and `plan --json` lists
them under `warnings`. The thresholds are stated beside each check with the reason for them: a
check that fires on a cell written as meant is worse than none, so each errs towards silence.

Nothing here prints or raises for a user's mistake; the public API (`robomax_py.load_cell`) turns the
notices into `CellWarning`s of Python's `warnings` module.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py.spec import (
    Box,
    Capsule,
    CellSpec,
    Cylinder,
    MeshShape,
    Notice,
    ObjectSpec,
    Sphere,
)

# `io.cell`'s schema objects (CellFile, ObjectFile), typed loosely here: `io.cell` imports this
# module, and the package keeps no import cycle, not even one for type checking.
CellFile = Any
ObjectFile = Any

# No robot reaches 50 m: the largest industrial arms reach about 4 m and a cell on a track or under
# a gantry spans tens of metres at most. A coordinate beyond 50 m in a metres file is far outside any
# cell, while the same number read as millimetres (5 cm) is an ordinary one.
MM_POSITION_M = 50.0
# A workshop hall is rarely over 100 m long; an object larger than that is a part or table drawn in
# millimetres (a 700 mm table read as 700 m), or a mesh exported in millimetres.
WORKSHOP_M = 100.0
# A tool is carried by an arm that reaches about 4 m at the most, so no gun or gripper measures 5 m
# across; the smallest gun body or electrode tip drawn in millimetres (tens of mm) read as metres
# measures tens of metres.
TOOL_MM_M = 5.0
# No part of a tool is smaller than 2 mm across (an electrode cap is 13-20 mm, a finger pad some
# 10 mm); a gun drawn in metres and read with `units: mm` (0.4 m -> 0.4 mm) is.
TOOL_TINY_M = 0.002
# An approach or a clearance of over a metre is longer than any gun's stroke or safety margin and
# more than a third of most arms' reach; 30 (meant as 30 mm) is the usual cause.
MM_PROCESS_M = 1.0
# A spot more than this inside a (non-workpiece) object: deeper than the round-off of coordinates
# copied from CAD to the millimetre, so a spot on the object's face is never called inside.
INSIDE_DEPTH_M = 0.001
# A weld spot lies on the part's sheet: within its thickness (1-3 mm per sheet, two or three sheets)
# of the modelled surface, or a mid-plane model's offset from it. 10 mm covers both and still catches
# a spot in the wrong frame or units, or a part mesh moved away from its spots.
SURFACE_TOLERANCE_M = 0.010
# A home pose in degrees whose every revolute joint is within 3.2 deg of zero is the arm stretched
# straight in every joint (wrist singular); in radians every joint of a usual home lies in [-pi, pi]
# (3.1416). With at least one fractional value (1.57, -0.785: radians are written with decimals,
# degrees mostly whole), such a home is read as radians written into a degrees file.
RADIAN_LIKE_DEG = 3.2
# A part lies on its supports where it is gripped and released: touching them, or within the
# round-off of coordinates copied from CAD to a tenth of a millimetre and a sheet's flatness.
# Further from every one, the gripper closes on air (or lets the part drop): the location's height,
# or the part's frame in its mesh, is off.
SUPPORT_GAP_M = 0.002
# A notice lists at most this many further keys of the same kind (the rest are counted).
LISTED = 5


def lint_cell(parsed: CellFile, cell: CellSpec, path: Path) -> tuple[Notice, ...]:
    """The probable mistakes of a loaded cell, in file order of the checks below.

    Parameters
    ----------
    parsed : CellFile
        The cell file as validated (file units: metres, degrees), for the keys as written.
    cell : CellSpec
        The cell built from it (SI), for the objects' shapes and poses.
    path : Path
        The cell file, named in every notice.
    """
    file = str(path)
    meshes: dict[MeshShape, Any] = {}
    units = _millimetre_positions(parsed, file) + _oversized_objects(parsed, cell, file, meshes)
    out = [*units, *_tool_sizes(cell, meshes), *_process_lengths(parsed, file), *_home_in_radians(parsed, cell, file),
           *_zero_clearance(parsed, cell, file), *_transfers_without_parts(parsed, file),
           *_parts_off_supports(parsed, cell, file, meshes), *_carried_without_ratings(parsed, cell, file)]
    if not units:                   # in millimetres, every spot is off every surface: one mistake, named above
        out += _spots_and_objects(parsed, cell, file, meshes)
    return tuple(out)


def library_hint(ref: str, kind: str) -> str:
    """' (did you mean 'kr16'?)' for a robot (`kind` 'robot') or tool ('tool') name the library lacks
    but spells closely (difflib's ratio >= 0.6, its default: 'kr16_2' -> 'kr16'), what '~' is not for a
    path that starts with it; '' for another path, a name the library has, or one like none of its
    names."""
    import difflib

    from robomax_py.io.robot import robot_library

    if ref.startswith("~"):
        # A shell's shorthand: a cell file's paths are taken as written (relative to the file), so a
        # cell folder means the same on every machine.
        return " ('~' is not the home folder in a cell file: give the path relative to the cell file, or in full)"
    if "/" in ref or "\\" in ref or ref.endswith((".yaml", ".yml")):
        return ""
    sub, filename = (("tools",), "tool.yaml") if kind == "tool" else ((), "robot.yaml")
    names: set[str] = set()
    for folder in robot_library():
        try:
            names.update(p.parent.name for p in Path(folder, *sub).glob(f"*/{filename}"))
        except OSError:
            continue                      # a library folder that cannot be listed names nothing
    if ref in names:
        return ""
    close = difflib.get_close_matches(ref, sorted(names), n=3)
    return f" (did you mean {' or '.join(repr(c) for c in close)}?)" if close else ""


def _grouped(file: str, found: Sequence[tuple[str, str]], more: str) -> list[Notice]:
    """One notice for the first (key, message) found, naming up to LISTED more keys and counting the rest."""
    if not found:
        return []
    key, message = found[0]
    rest = [k for k, _ in found[1:]]
    if rest:
        shown = ", ".join(rest[:LISTED]) + (f" and {len(rest) - LISTED} more" if len(rest) > LISTED else "")
        message += f" (also {len(rest)} more {more}: {shown})"
    return [Notice(file, key, message)]


def _positions(parsed: CellFile) -> Iterable[tuple[str, list[float]]]:
    """Every position the file gives, in metres, with its key."""
    yield "robot.base.xyz", parsed.robot.base.xyz
    for group, items in (("objects", parsed.objects), ("dynamic", parsed.dynamic)):
        for i, obj in enumerate(items):
            yield f"{group}[{i}].pose.xyz", obj.pose.xyz
    for i, seam in enumerate(parsed.seams):
        for j, spot in enumerate(seam.spots):
            yield f"seams[{i}].spots[{j}].xyz", spot.xyz
    if parsed.tending is not None:
        for i, st in enumerate(parsed.tending.stations):
            yield f"tending.stations[{i}].xyz", st.xyz
        for i, m in enumerate(parsed.tending.machines):
            yield f"tending.machines[{i}].door.pose.xyz", m.door.pose.xyz
    if parsed.pick_place is not None:
        for i, loc in enumerate(parsed.pick_place.locations):
            yield f"pick_place.locations[{i}].pose.xyz", loc.pose.xyz


def _millimetre_positions(parsed: CellFile, file: str) -> list[Notice]:
    found = []
    for key, xyz in _positions(parsed):
        far = max(abs(v) for v in xyz)
        if far > MM_POSITION_M:
            found.append((key, (f"{_fmt(xyz)} lies {far:g} m from the cell's origin along one axis: lengths in a "
                               f"cell file are metres, and no cell spans {MM_POSITION_M:g} m; written in "
                               "millimetres? (divide by 1000)")))
    return _grouped(file, found, f"positions beyond {MM_POSITION_M:g} m")


def _process_lengths(parsed: CellFile, file: str) -> list[Notice]:
    found = []
    for name in ("approach", "clearance"):
        value = getattr(parsed.process, name)
        if value > MM_PROCESS_M:
            found.append((f"process.{name}", (f"{value:g} m is longer than any {name} (over {MM_PROCESS_M:g} m): "
                                             f"lengths in a cell file are metres; {value:g} mm meant? "
                                             f"(write {value / 1000:g})")))
    return [Notice(file, k, m) for k, m in found]


def _shape_key(obj: ObjectFile) -> str:
    return next(k for k in ("box", "cylinder", "sphere", "capsule", "mesh") if getattr(obj, k) is not None)


def _oversized_objects(parsed: CellFile, cell: CellSpec, file: str, meshes: dict[MeshShape, Any]) -> list[Notice]:
    found = []
    for key, obj_file, obj in _static_objects(parsed, cell):
        size = float(np.max(_extents(obj, meshes)))
        if size > WORKSHOP_M:
            if isinstance(obj.shape, MeshShape):
                # The mesh file's numbers are read as metres unless `units` says otherwise.
                hint = (("a mesh's numbers are read as metres; drawn in millimetres? write `units: mm` beside "
                         "`mesh`") if obj_file.units is None and obj_file.scale is None else
                        "after its units and scale; are they right?")
                found.append((f"{key}.mesh", (f"{obj.name}: its mesh's extents are {size:g} m across, larger than "
                                              f"any workshop ({WORKSHOP_M:g} m): {hint}")))
                continue
            found.append((f"{key}.{_shape_key(obj_file)}",
                          (f"{obj.name}: it measures {size:g} m across, larger than any workshop ({WORKSHOP_M:g} m): "
                          "lengths in a cell file and its meshes are metres; drawn in millimetres?")))
    return _grouped(file, found, f"objects over {WORKSHOP_M:g} m")


def _tool_sizes(cell: CellSpec, meshes: dict[MeshShape, Any]) -> list[Notice]:
    """The tool's body or tips larger than any tool (a mesh in millimetres read as metres) or
    smaller than any part of one (in metres, read as millimetres); named in the tool.yaml."""
    from robomax_py.robot.cad import is_step

    large: list[tuple[str, str]] = []
    small: list[tuple[str, str]] = []
    for key, shape in (("body", cell.tool.body), ("tips", cell.tool.tips)):
        size = float(np.max(_mesh_extents(shape, meshes)))
        if TOOL_TINY_M <= size <= TOOL_MM_M:
            continue
        if is_step(shape.path):
            hint = "a STEP is read in the length unit it states: does the file state the right one?"
        elif size > TOOL_MM_M:
            hint = ("a mesh's numbers are read as metres; drawn in millimetres? write `units: mm` in the tool.yaml "
                    "(at the top for both meshes, or beside this one's `mesh`)"
                    if shape.scale == (1.0, 1.0, 1.0) else "after its units and scale; are they right?")
        else:
            hint = ("`units: mm` given to a mesh drawn in metres?" if max(shape.scale) < 1.0
                    else "are its units and scale right?")
        bound = (f"larger than any tool ({TOOL_MM_M:g} m)" if size > TOOL_MM_M
                 else f"smaller than any part of a tool ({TOOL_TINY_M * 1000:g} mm)")
        (large if size > TOOL_MM_M else small).append(
            (key, f"{cell.tool.name}: its {key} mesh measures {size:.3g} m across, {bound}: {hint}"))
    file = str(cell.tool.source)
    return _grouped(file, large, "meshes that large") + _grouped(file, small, "meshes that small")


def _home_in_radians(parsed: CellFile, cell: CellSpec, file: str) -> list[Notice]:
    from robomax_py.robot import kinematic_model, prismatic_mask

    given = np.asarray(parsed.robot.home, dtype=float)
    prismatic = np.asarray(prismatic_mask(kinematic_model(cell.robot)), dtype=bool)
    revolute = given[~prismatic] if len(prismatic) == len(given) else given
    if not len(revolute) or np.any(np.abs(revolute) >= RADIAN_LIKE_DEG):
        return []
    fractional = np.abs(revolute - np.round(revolute)) > 1e-9
    if not fractional.any():
        return []
    as_deg = ", ".join(f"{math.degrees(v):.0f}" for v in given)
    return [Notice(file, "robot.home", f"{_fmt(parsed.robot.home)} are degrees in a cell file; every joint within "
                                       f"{RADIAN_LIKE_DEG:g} deg of zero, with fractions, looks like radians "
                                       f"(in degrees: [{as_deg}])")]


def _weld_seams(parsed: CellFile) -> bool:
    return bool(parsed.seams) and parsed.tending is None and parsed.pick_place is None


def _transfers_without_parts(parsed: CellFile, file: str) -> list[Notice]:
    if parsed.planner.transfers == "moves" or parsed.pick_place is not None:
        return []
    return [Notice(file, "planner.transfers", f"{parsed.planner.transfers} plans the carried moves of a "
                                              "`pick_place` job, and this cell has none: it changes nothing")]


def _parts_off_supports(parsed: CellFile, cell: CellSpec, file: str, meshes: dict[MeshShape, Any]) -> list[Notice]:
    """A part at a location it is gripped or released at, farther than SUPPORT_GAP_M from every
    support the location names, as coal measures the part's shape (at the location's pose, which
    the file states in the world) against each support's."""
    job = parsed.pick_place
    if job is None:
        return []
    import coal

    from robomax_py.io.cell_objects import _pose

    index = {loc.name: i for i, loc in enumerate(job.locations)}
    objects = {obj.name: obj for obj in cell.objects}
    lying = dict.fromkeys((t.part, at) for t in job.transfers for at in (t.from_, t.to))
    found = []
    for part_name, at in lying:
        i = index[at]
        location = job.locations[i]
        if not location.support:
            continue
        part = cell.part(part_name)
        T_part = _pose(location.pose)
        gap, nearest = min((min(_distance(a, T_part, b, np.asarray(objects[name].T_world_object, dtype=float), coal)
                                for a in _pieces(part.shape, meshes) for b in _pieces(objects[name].shape, meshes)),
                            name) for name in location.support)
        if gap > SUPPORT_GAP_M:
            found.append((f"pick_place.locations[{i}].pose",
                          (f"{part_name} at {at} lies {gap * 1000:.0f} mm from its nearest support ({nearest}): "
                           "a part rests on its support where it is gripped and released, so the gripper would "
                           "close on air or let it drop; the location's height, or the part's frame, is off?")))
    return _grouped(file, found, "parts off their supports")


def _carried_without_ratings(parsed: CellFile, cell: CellSpec, file: str) -> list[Notice]:
    """A pick-and-place cell whose robot.yaml states no rated `payload` or no `limits.loaded`: the
    parts' masses are then not checked against what the arm may carry, nor do they slow it. An
    imported arm has neither (no URDF states them), and its plan would carry any mass at the
    unloaded limits without a word."""
    if parsed.pick_place is None or not cell.parts:
        return []
    robot = cell.robot
    missing = [key for key, value in (("payload", robot.payload_kg), ("limits.loaded", robot.loaded)) if value is None]
    if not missing:
        return []
    heaviest = max(cell.parts, key=lambda p: p.mass)
    what = ("its parts' masses are not checked against what the arm may carry, and they are carried at the "
            "unloaded joint limits" if robot.payload_kg is None
            else "its parts are carried at the unloaded joint limits, whatever their mass")
    return [Notice(file, "pick_place.parts", f"{robot.name} states no {' and no '.join(missing)} ({robot.source}): "
                                             f"{what} (the heaviest, {heaviest.name}, {heaviest.mass:g} kg); "
                                             "give them from the arm's data sheet")]


def _pieces(shape: Any, meshes: dict[MeshShape, Any]) -> list[Any]:
    from robomax_py.robot.geometry import mesh_collision_shapes, primitive_shape

    return mesh_collision_shapes(_mesh(shape, meshes)) if isinstance(shape, MeshShape) else [primitive_shape(shape)]


def _distance(a: Any, Ta: np.ndarray, b: Any, Tb: np.ndarray, coal: Any) -> float:
    result = coal.DistanceResult()
    coal.distance(a, coal.Transform3s(Ta[:3, :3], Ta[:3, 3]), b, coal.Transform3s(Tb[:3, :3], Tb[:3, 3]),
                  coal.DistanceRequest(), result)
    return float(result.min_distance)


def _zero_clearance(parsed: CellFile, cell: CellSpec, file: str) -> list[Notice]:
    if parsed.process.clearance > 0 or not _weld_seams(parsed) or not any(o.workpiece for o in cell.objects):
        return []
    return [Notice(file, "process.clearance", "0 m: the arm and the gun's body may pass the workpiece and every "
                                              "obstacle at any distance short of touching (a plan may pass a "
                                              "fraction of a millimetre from the part); give the safety margin "
                                              "you need in metres, e.g. 0.005")]


def _spots_and_objects(parsed: CellFile, cell: CellSpec, file: str, meshes: dict[MeshShape, Any]) -> list[Notice]:
    """Spots (and tending stations) inside an object; weld spots off every workpiece's surface; a
    cell without a workpiece whose spots lie on an object's surface (its tips may not touch it)."""
    stops: list[tuple[str, str, list[float]]] = []
    for i, seam in enumerate(parsed.seams):
        stops += [(f"seams[{i}].spots[{j}]", s.name, s.xyz) for j, s in enumerate(seam.spots) if not s.skip]
    if parsed.tending is not None:
        stops += [(f"tending.stations[{i}]", st.name, st.xyz) for i, st in enumerate(parsed.tending.stations)]
    if not stops:
        return []
    objects = list(_static_objects(parsed, cell))
    points = np.array([xyz for _, _, xyz in stops], dtype=float)
    # Signed distance (m, negative inside) of every stop to every object's surface.
    sd = np.array([_signed_distance(obj, points, meshes) for _, _, obj in objects]).reshape(len(objects), len(stops))
    inside, far, touching = [], [], []
    workpieces = [k for k, (_, _, obj) in enumerate(objects) if obj.workpiece]
    for n, (key, name, _) in enumerate(stops):
        depth = [(-sd[k, n], k) for k, (_, _, obj) in enumerate(objects) if not obj.workpiece]
        deepest = max(depth, default=(0.0, -1))
        if deepest[0] > INSIDE_DEPTH_M:
            obj = objects[deepest[1]][2]
            inside.append((f"{key}.xyz", (f"{name} lies {deepest[0] * 1000:.0f} mm inside {obj.name} "
                                         f"({objects[deepest[1]][0]}): no tool can get there")))
            continue
        if not _weld_seams(parsed):
            continue
        if workpieces:
            gap = float(np.min(np.abs(sd[workpieces, n])))
            if gap > SURFACE_TOLERANCE_M:
                near = objects[workpieces[int(np.argmin(np.abs(sd[workpieces, n])))]][2].name
                far.append((f"{key}.xyz", (f"{name} lies {gap * 1000:.0f} mm from the surface of every workpiece "
                                          f"(nearest: {near}; a spot lies on the part, within "
                                          f"{SURFACE_TOLERANCE_M * 1000:.0f} mm): wrong coordinates, or the part "
                                          "mesh in another frame?")))
        elif objects:
            k = int(np.argmin(np.abs(sd[:, n])))
            if abs(sd[k, n]) <= SURFACE_TOLERANCE_M:
                touching.append((k, key, name))
    out = _grouped(file, inside, "spots inside objects") + _grouped(file, far, "spots off the workpieces")
    for k in dict.fromkeys(k for k, _, _ in touching):
        on = [f"{name} ({key})" for kk, key, name in touching if kk == k]
        obj_key, _, obj = objects[k]
        shown = ", ".join(on[:LISTED]) + (f" and {len(on) - LISTED} more" if len(on) > LISTED else "")
        out.append(Notice(file, obj_key, f"{obj.name} is not marked `workpiece: true`, and no object is, but spots "
                                         f"lie on its surface: {shown}; the gun's tips may touch only a workpiece, "
                                         f"so every such spot will fail on 'tool_tips vs {obj.name}'. If it is "
                                         "the part being welded, add `workpiece: true`"))
    return out


def _static_objects(parsed: CellFile, cell: CellSpec) -> Iterable[tuple[str, ObjectFile, ObjectSpec]]:
    """The cell's static objects with their keys (`cell.objects` is `parsed.objects`, in order)."""
    for i, (obj_file, obj) in enumerate(zip(parsed.objects, cell.objects, strict=True)):
        yield f"objects[{i}]", obj_file, obj


def _mesh(shape: MeshShape, meshes: dict[MeshShape, Any]) -> Any:
    """The object's mesh as the cell states it (units, scale, tolerance), read once per lint."""
    from robomax_py.robot.geometry import mesh_shape_trimesh

    if shape not in meshes:
        meshes[shape] = mesh_shape_trimesh(shape)
    return meshes[shape]


def _extents(obj: ObjectSpec, meshes: dict[MeshShape, Any]) -> np.ndarray:
    """(3,) float, m: the object's size along its own axes (a mesh's bounding box)."""
    s = obj.shape
    if isinstance(s, Box):
        return np.asarray(s.extents, dtype=float)
    if isinstance(s, Sphere):
        return np.full(3, 2 * s.radius)
    if isinstance(s, Cylinder):
        return np.array([2 * s.radius, 2 * s.radius, s.length])
    if isinstance(s, Capsule):
        return np.array([2 * s.radius, 2 * s.radius, s.length + 2 * s.radius])
    return _mesh_extents(s, meshes)


def _mesh_extents(shape: MeshShape, meshes: dict[MeshShape, Any]) -> np.ndarray:
    """(3,) float, m: the mesh's bounding box size, read back from the cache when an earlier run
    read the same file."""
    from robomax_py.robot.mesh_cache import kept_arrays

    def compute() -> dict[str, np.ndarray]:
        return {"extents": np.asarray(_mesh(shape, meshes).extents, dtype=float)}

    return kept_arrays("extents", shape.path, ("extents", shape.scale, shape.tolerance), compute)["extents"]


def _signed_distance(obj: ObjectSpec, points: np.ndarray, meshes: dict[MeshShape, Any]) -> np.ndarray:
    """(n,) float, m: distance of world points (n, 3) to the object's surface, negative inside.

    Primitives are centred on their pose (as the collision world builds them). A mesh's points count
    as inside only when the mesh is closed (trimesh's `contains` is defined for watertight meshes);
    an open sheet's distance is its unsigned distance."""
    T = np.asarray(obj.T_world_object, dtype=float)
    local = (points - T[:3, 3]) @ T[:3, :3]
    s = obj.shape
    if isinstance(s, Box):
        q = np.abs(local) - np.asarray(s.extents, dtype=float) / 2
        return np.asarray(np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0))
    if isinstance(s, Sphere):
        return np.asarray(np.linalg.norm(local, axis=1) - s.radius)
    if isinstance(s, Cylinder):
        d = np.stack([np.hypot(local[:, 0], local[:, 1]) - s.radius, np.abs(local[:, 2]) - s.length / 2], axis=1)
        return np.asarray(np.linalg.norm(np.maximum(d, 0.0), axis=1) + np.minimum(d.max(axis=1), 0.0))
    if isinstance(s, Capsule):
        axis = np.zeros_like(local)
        axis[:, 2] = np.clip(local[:, 2], -s.length / 2, s.length / 2)
        return np.asarray(np.linalg.norm(local - axis, axis=1) - s.radius)
    return _mesh_signed_distance(s, np.ascontiguousarray(local, dtype=float), meshes)


def _mesh_signed_distance(shape: MeshShape, local: np.ndarray, meshes: dict[MeshShape, Any]) -> np.ndarray:
    """`_signed_distance` of points (n, 3) in the mesh's frame, read back from the cache when an
    earlier run computed it for the same file and points."""
    from robomax_py.robot.mesh_cache import kept_arrays

    def compute() -> dict[str, np.ndarray]:
        import trimesh

        mesh = _mesh(shape, meshes)
        _, distance, _ = trimesh.proximity.closest_point(mesh, local)  # type: ignore[no-untyped-call]
        distance = np.asarray(distance, dtype=float)
        if mesh.is_watertight:
            distance = np.where(mesh.contains(local), -distance, distance)
        return {"distance": distance}

    points = hashlib.sha256(local.tobytes() + repr(local.shape).encode()).hexdigest()
    return kept_arrays("distance", shape.path, ("signed distance", shape.scale, shape.tolerance, points),
                       compute)["distance"]


def _fmt(values: Sequence[float]) -> str:
    return "[" + ", ".join(f"{v:g}" for v in values) + "]"
