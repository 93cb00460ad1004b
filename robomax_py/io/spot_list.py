"""Spot lists (docs/spot-lists.md): a CSV of weld spots in a part's frame -> seams in the cell's world.

Two callers read lists through this module and nothing else, so they give the same spots: the cell
key `spot_lists` (`io.cell`) and `robomax import-spots` (`app.import_spots`), which writes the seams
into a new cell file. What a list leaves out is recovered from the part:

- a missing normal is the normal of the part's surface nearest the spot, turned to the side the gun
  can reach (the side whose approach line is free of the part and the other objects; outward where
  the spot lies on a closed part's face and that side is free; else toward the robot base when both
  are, and the spot is reported as ambiguous);
- a missing direction follows the seam's course (its spots in the seam's order: the list's for a
  group column, along the chain for seams formed from the geometry);
- without a group column, spots are grouped into seams by the part's geometry: chains that turn
  gently at every spot, on one face (`io.spot_grouping`).

A spot further from the part's surface than the distance tolerance is an error naming its row.
Nothing here prints; what a person should check is returned in the `SpotListResult`.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from robomax_py._typing import FloatArray
from robomax_py.errors import CellFileError, _LocatedError
from robomax_py.io.spot_grouping import SpotGroup, geometric_groups
from robomax_py.io.yaml_files import MAX_LISTED_PROBLEMS, several
from robomax_py.robot.geometry import shape_trimesh
from robomax_py.safe_files import LIMITS, checked_file, read_text
from robomax_py.spec import ObjectSpec

# Rows of one list: as many as a cell may have spots (io.cell_file_values.CELL_LIMITS.spots).
MAX_ROWS = 2_000
UNITS = {"m": 1.0, "mm": 0.001}
DEFAULT_MAX_DISTANCE = 0.002        # m: a spot further from the part's surface is an error
# Coordinates in metres beyond this, in the part's own frame, are probably millimetres.
LOOKS_LIKE_MM = 10.0
# The side test's lines start this far inside the face nearest the spot (a line from the surface
# itself may or may not meet it, at zero).
SIDE_OFFSET = 5e-4
# The widest step between the surfaces of sheets stacked at a spot (m): a sheet's thickness, or the
# gap a model leaves between two that touch; a spot weld joins sheets of 0.5-4 mm.
STACK_GAP = 0.005
# A spot this close to a closed part's face lies on it (m): the face's outward sense is the side the
# list means, where it is free. Further in (a sheet's middle plane: 0.25 mm in a 0.5 mm sheet), or on
# an open mesh, whose faces' senses are the drawing's accident, both sides are weighed.
ON_FACE = 1e-4
# Rounding of what is written: 0.1 um and 1e-9 of a unit vector, far below any weld's accuracy, so
# the YAML stays readable and both callers give byte-identical cells.
XYZ_DECIMALS = 7
VECTOR_DECIMALS = 9

# Header names, matched case-insensitively (spaces, '-' and '.' read as '_'), as OLP spot importers
# name them.
ALIASES: dict[str, tuple[str, ...]] = {
    "id": ("id", "name", "spot", "spot_id", "spotid", "spot_name", "point", "label"),
    "x": ("x", "pos_x", "px"), "y": ("y", "pos_y", "py"), "z": ("z", "pos_z", "pz"),
    "nx": ("nx", "i", "normal_x", "n_x"), "ny": ("ny", "j", "normal_y", "n_y"), "nz": ("nz", "k", "normal_z", "n_z"),
    "dx": ("dx", "tx", "direction_x", "dir_x"), "dy": ("dy", "ty", "direction_y", "dir_y"),
    "dz": ("dz", "tz", "direction_z", "dir_z"),
    "group": ("group", "seam", "seam_name", "seam_id", "group_id"),
    "weld_time": ("weld_time", "time", "weldtime"),
    "schedule": ("schedule", "program", "weld_schedule", "prog"),
}
_TRIPLES = {"normal": ("nx", "ny", "nz"), "direction": ("dx", "dy", "dz")}


@dataclass(frozen=True, slots=True)
class SpotRow:
    """One row of a list, in the part's frame, metres; `row` is its line in the file."""

    row: int
    id: str
    xyz: FloatArray
    normal: FloatArray | None
    direction: FloatArray | None
    group: str | None
    weld_time: float | None
    schedule: int | None


@dataclass(frozen=True, slots=True)
class SpotList:
    file: Path
    rows: tuple[SpotRow, ...]
    grouped: bool                      # the list has a group column
    warnings: tuple[str, ...] = ()


@dataclass(slots=True)
class SpotListResult:
    """The seams (as a cell file writes them: world frame, metres) and what a person should check."""

    seams: list[dict[str, Any]]
    formed: list[str] = field(default_factory=list)     # each seam formed: name, spots, rows
    sides: list[str] = field(default_factory=list)      # spots whose side the gun comes from is a guess
    by_geometry: bool = False                           # seams formed from the geometry (no group column)
    warnings: list[str] = field(default_factory=list)   # units that look wrong
    ambiguous: list[str] = field(default_factory=list)  # spot ids whose side was chosen toward the base
    recovered_normals: int = 0
    recovered_directions: int = 0


def _column_key(header: str) -> str:
    return header.strip().lower().replace(" ", "_").replace("-", "_").replace(".", "_")


def read_spot_list(path: Path, units: str | None, error_file: Path | str | None = None) -> SpotList:
    """The rows of a CSV spot list, scaled to metres (`units` 'm' or 'mm'; None: metres, with a
    warning when they look like millimetres). Every bad row is reported (up to MAX_LISTED_PROBLEMS
    together) naming the file, the row and the column."""
    shown = error_file or path
    if units is not None and units not in UNITS:
        raise CellFileError(shown, "units", f"expected m or mm, got {units!r}")
    checked = checked_file(path, LIMITS.cell, CellFileError, "spot list")
    text = read_text(checked, LIMITS.cell, CellFileError, "spot list")
    lines = text.splitlines()
    if not lines or not lines[0].strip():
        raise CellFileError(path, "row 1", "expected a header row (id, x, y, z, ...), the file starts empty")
    delimiter = _delimiter(lines[0])
    reader = csv.reader(io.StringIO(text), delimiter=delimiter)
    header = next(reader)
    columns = _columns(header, path)
    grouped = "group" in columns
    rows: list[SpotRow] = []
    problems: list[_LocatedError] = []
    seen: dict[str, int] = {}
    scale = UNITS[units or "m"]
    for cells in reader:
        line = reader.line_num
        if not any(c.strip() for c in cells):
            continue                                       # blank lines and trailing empty rows
        if len(rows) >= MAX_ROWS:
            raise CellFileError(path, f"row {line}", f"more than {MAX_ROWS:,} spots, the most a cell may have; "
                                                     "split the list")
        try:
            spot = _row(cells, columns, line, delimiter, scale, path)
        except CellFileError as exc:
            problems.append(exc)
            if len(problems) >= MAX_LISTED_PROBLEMS:
                raise several(problems, path, more=True) from None
            continue
        if spot.id in seen:
            problems.append(CellFileError(path, f"row {line}, column {columns['id'][1]}",
                                          f"spot '{spot.id}' is also on row {seen[spot.id]}"))
            continue
        seen[spot.id] = line
        rows.append(spot)
    if problems:
        raise several(problems, path)
    if not rows:
        raise CellFileError(path, None, "no spots: the list has a header but no rows")
    warnings = []
    largest = max(float(np.max(np.abs(r.xyz))) for r in rows)
    if units is None and largest > LOOKS_LIKE_MM:
        warnings.append(f"{path}: coordinates up to {largest:g} read as metres (no units given); if they are "
                        "millimetres, give units mm")
    return SpotList(path, tuple(rows), grouped, tuple(warnings))


def _delimiter(first_line: str) -> str:
    """`,`, `;` or tab: the one the header row holds most of (a header has no decimal commas)."""
    counts = {d: first_line.count(d) for d in (",", ";", "\t")}
    best = max(counts, key=lambda d: counts[d])
    return best if counts[best] else ","


def _columns(header: list[str], path: Path) -> dict[str, tuple[int, str]]:
    """Canonical column -> (index, name as written); unknown columns are refused with the known ones."""
    by_alias = {alias: canon for canon, aliases in ALIASES.items() for alias in aliases}
    columns: dict[str, tuple[int, str]] = {}
    problems: list[_LocatedError] = []
    for i, name in enumerate(header):
        canon = by_alias.get(_column_key(name))
        if canon is None:
            if not name.strip():
                continue                      # a trailing delimiter
            problems.append(CellFileError(path, f"row 1, column {name.strip()!r}", "unknown column; known: id, x, y, "
                                          "z, nx, ny, nz (or i, j, k), dx, dy, dz, group (or seam), weld_time (or "
                                          "time), schedule (or program)"))
        elif canon in columns:
            problems.append(CellFileError(path, f"row 1, column {name.strip()!r}",
                                          f"names the same column as {columns[canon][1]!r}"))
        else:
            columns[canon] = (i, name.strip())
    missing = [c for c in ("id", "x", "y", "z") if c not in columns]
    if missing:
        problems.append(CellFileError(path, "row 1", f"missing column {', '.join(missing)} (a list needs id, x, y, z)"))
    for triple in _TRIPLES.values():
        given = [c for c in triple if c in columns]
        if given and len(given) != 3:
            problems.append(CellFileError(path, "row 1", f"columns {', '.join(triple)} go together; only "
                                                          f"{', '.join(given)} given"))
    if problems:
        raise several(problems, path)
    return columns


def _row(cells: list[str], columns: dict[str, tuple[int, str]], line: int, delimiter: str, scale: float,
         path: Path) -> SpotRow:
    def raw(canon: str) -> str:
        i = columns[canon][0] if canon in columns else None
        return cells[i].strip() if i is not None and i < len(cells) else ""

    def number(canon: str) -> float | None:
        text = raw(canon)
        if not text:
            return None
        if delimiter == ";":
            text = text.replace(",", ".")            # decimal comma: the reason a list is ;-separated
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value) or len(text) > 40:
            raise CellFileError(path, f"row {line}, column {columns[canon][1]}", f"expected a number, got {text!r}")
        return value

    def where(canon: str) -> str:
        return f"row {line}, column {columns[canon][1]}"

    spot_id = raw("id")
    if not spot_id or not spot_id.isprintable() or len(spot_id) > 200:
        raise CellFileError(path, where("id"), f"expected a spot name (printable, 1-200 characters), got {spot_id!r}")
    xyz = []
    for c in ("x", "y", "z"):
        v = number(c)
        if v is None:
            raise CellFileError(path, where(c), "missing coordinate")
        xyz.append(v * scale)
    vectors: dict[str, FloatArray | None] = {}
    for name, triple in _TRIPLES.items():
        values = [number(c) if c in columns else None for c in triple]
        if all(v is None for v in values):
            vectors[name] = None
            continue
        if any(v is None for v in values):
            gap = next(c for c, v in zip(triple, values, strict=True) if v is None)
            raise CellFileError(path, where(gap), f"the {name} is given in part: give all three components or none")
        vec = np.asarray(values, dtype=float)
        norm = float(np.linalg.norm(vec))
        if not 1e-9 < norm < 1e9:
            raise CellFileError(path, where(triple[0]), f"the {name} {values} has no direction (zero length)")
        vectors[name] = vec / norm
    group = raw("group") or None
    if "group" in columns and group is None:
        raise CellFileError(path, where("group"), "missing: the list groups its spots, this one has no group")
    if group is not None and (not group.isprintable() or len(group) > 200):
        raise CellFileError(path, where("group"), f"expected a seam name (printable, 1-200 characters), got {group!r}")
    weld_time = number("weld_time") if "weld_time" in columns else None
    if weld_time is not None and weld_time < 0:
        raise CellFileError(path, where("weld_time"), f"expected seconds >= 0, got {weld_time:g}")
    schedule = None
    if "schedule" in columns and raw("schedule"):
        sched = number("schedule")
        if sched is None or sched != int(sched) or not 1 <= sched <= 9999:
            raise CellFileError(path, where("schedule"), f"expected a whole number 1..9999, got {raw('schedule')!r}")
        schedule = int(sched)
    return SpotRow(line, spot_id, np.asarray(xyz), vectors["normal"], vectors["direction"], group, weld_time, schedule)


def world_mesh(obj: ObjectSpec) -> trimesh.Trimesh:
    """The object's surface in the cell's world."""
    mesh = shape_trimesh(obj.shape).copy()
    mesh.apply_transform(np.asarray(obj.T_world_object))
    return mesh


def spot_list_seams(spots: SpotList, part: ObjectSpec, others: Sequence[ObjectSpec], T_world_base: FloatArray,
                    approach: float, max_distance: float = DEFAULT_MAX_DISTANCE,
                    T_world_frame: FloatArray | None = None, either_side: bool = False) -> SpotListResult:
    """The list's spots as seams in the world: each moved by the pose of the frame its coordinates
    are in (`T_world_frame`; the part's own frame when None), its normal and direction recovered
    where the list has none, grouped by the group column or the part's geometry. `either_side`: the
    seams' gun may stand on either side (`tolerance.sides: either`), so a spot free on both is no
    question for a person: the planner chooses, and it is not reported."""
    T = np.asarray(part.T_world_object if T_world_frame is None else T_world_frame, dtype=float)
    R = T[:3, :3]
    R_part = np.asarray(part.T_world_object, dtype=float)[:3, :3]
    rows = spots.rows
    xyz = np.array([R @ r.xyz + T[:3, 3] for r in rows])
    surface = world_mesh(part)
    closest, distance, triangle = trimesh.proximity.closest_point(surface, xyz)  # type: ignore[no-untyped-call]
    far = [(r, d) for r, d in zip(rows, distance, strict=True) if d > max_distance]
    if far:
        hint = [CellFileError(spots.file, "units", w.split(": ", 1)[1]) for w in spots.warnings]
        found: list[_LocatedError] = [*hint, *[CellFileError(spots.file, f"row {r.row}, column x", f"spot '{r.id}' is {d * 1000:.2f} mm from "
                                     f"the surface of the part '{part.name}' (tolerance {max_distance * 1000:g} "
                                     "mm): is the part, its pose or the units right?") for r, d in far]]
        raise several(found, spots.file)
    result = SpotListResult(seams=[], warnings=list(spots.warnings), by_geometry=not spots.grouped)
    normals = np.zeros((len(rows), 3))
    need = [i for i, r in enumerate(rows) if r.normal is None]
    for i, r in enumerate(rows):
        if r.normal is not None:
            normals[i] = R @ r.normal
    if need:
        sides = _reachable_sides(surface, [o for o in others if o is not part], closest[need],
                                 np.asarray(surface.face_normals)[triangle[need]], approach)
        base = np.asarray(T_world_base, dtype=float)[:3, 3]
        closed = bool(surface.is_watertight)
        for k, i in enumerate(need):
            n, (plus, minus) = np.asarray(surface.face_normals[triangle[i]], dtype=float), sides[k]
            toward_base = float(np.dot(base - closest[i], n)) >= 0
            if plus and closed and distance[i] <= ON_FACE:
                pass                # on a solid's face: its outward sense is the side the list meant
            elif plus and minus:
                n = n if toward_base else -n
                if not either_side:
                    result.ambiguous.append(rows[i].id)
                    result.sides.append(f"row {rows[i].row}: spot '{rows[i].id}': both sides of the part are free; "
                                         "the normal points toward the robot base, check it (tolerance.sides: "
                                         "either lets the planner choose)")
            elif minus:
                n = -n
            elif not plus:
                result.sides.append(f"row {rows[i].row}: spot '{rows[i].id}': neither side is free for the approach "
                                     f"({approach * 1000:g} mm); the normal points out of the part, check it")
            normals[i] = n
        result.recovered_normals = len(need)
    groups = _groups(rows) if spots.grouped else geometric_groups(xyz, normals)
    by = "the group column" if spots.grouped else "the part's geometry (one face, a chain turning gently at each spot)"
    x_axis, y_axis = R_part[:, 0], R_part[:, 1]
    for group in groups:
        name, members = group.name, list(group.members)
        result.formed.append(f"seam {name}: {len(members)} spots (rows {_rows_text([rows[i].row for i in members])}), "
                             f"grouped by {by}")
        course = xyz[members]
        out = []
        for k, i in enumerate(members):
            n = normals[i]
            if rows[i].direction is not None:
                d = R @ rows[i].direction
            else:
                result.recovered_directions += 1
                d = course[min(k + 1, len(members) - 1)] - course[max(k - 1, 0)]
            d = d - np.dot(d, n) * n
            if np.linalg.norm(d) < 1e-9:
                # A single spot (or one on top of its neighbours): the part's x axis in the spot's
                # plane, or its y axis when x is within 25 deg of the normal.
                d = x_axis - np.dot(x_axis, n) * n
                if abs(float(np.dot(x_axis, n))) > 0.9:
                    d = y_axis - np.dot(y_axis, n) * n
            d = d / np.linalg.norm(d)
            spot: dict[str, Any] = {"name": rows[i].id, "xyz": _rounded(xyz[i], XYZ_DECIMALS),
                                    "normal": _rounded(n, VECTOR_DECIMALS), "direction": _rounded(d, VECTOR_DECIMALS)}
            if rows[i].weld_time is not None:
                spot["weld_time"] = rows[i].weld_time
            if rows[i].schedule is not None:
                spot["schedule"] = rows[i].schedule
            out.append(spot)
        result.seams.append({"name": name, "spots": out})
    return result


def _rounded(v: FloatArray, decimals: int) -> list[float]:
    return [round(float(c), decimals) + 0.0 for c in v]      # + 0.0: no -0.0 in the file


def _rows_text(rows: list[int]) -> str:
    return ", ".join(str(r) for r in rows) if len(rows) <= 6 else f"{rows[0]}..{rows[-1]}"


def _reachable_sides(surface: trimesh.Trimesh, others: Sequence[ObjectSpec], points: FloatArray,
                     normals: FloatArray, approach: float) -> list[tuple[bool, bool]]:
    """Per surface point: whether the approach line on the face normal's side, and on the other
    side, is free of the part and the other objects.

    A side's line starts where the sheets stacked at the spot end, not at the face nearest the spot:
    a spot given on the sheet's middle plane (or on the faying surface of two sheets, as weld-spot
    exports place it) is as near the one face as the other, and which of the two is taken is a
    rounding accident. From the face taken, the other side's line runs through the sheet itself,
    and the sheet must not count as what blocks it, or the normals of one seam's spots point now up,
    now down. Sheets are stacked where each begins within `STACK_GAP` of the one before (a spot weld
    joins sheets of 0.5-4 mm that touch). The line is blocked where it starts inside a closed object
    or meets a surface within `approach` of where the stack ends."""
    meshes = [surface] + [world_mesh(o) for o in others if o.present is None]
    n = len(points)
    directions = np.concatenate([normals, -normals])
    # Both lines start just inside the face taken: on the normal's side the stack is then the sheet's
    # own face (at SIDE_OFFSET), on the other side the sheet's thickness.
    origins = np.concatenate([points - SIDE_OFFSET * normals, points + SIDE_OFFSET * normals])
    hits: list[list[float]] = [[] for _ in range(2 * n)]
    for mesh in meshes:
        found, ray_index, _ = mesh.ray.intersects_location(origins, directions, multiple_hits=True)
        along = np.einsum("ij,ij->i", np.reshape(found, (-1, 3)) - origins[ray_index], directions[ray_index])
        for t, i in zip(along, ray_index, strict=True):
            if t > 0.0:
                hits[i].append(float(t))
    ends = np.array([_stack_end(sorted(h)) for h in hits])
    # Just past the stack (past the face itself where a line from inside missed it at a triangle's edge).
    past = origins + (np.maximum(ends, SIDE_OFFSET) + SIDE_OFFSET)[:, None] * directions
    blocked = np.array([any(t > end and t <= end + approach for t in h) for h, end in zip(hits, ends, strict=True)])
    for mesh in meshes:
        if mesh.is_watertight:
            blocked |= mesh.contains(past)
    return [(not blocked[i], not blocked[n + i]) for i in range(n)]


def _stack_end(distances: Sequence[float]) -> float:
    """How far along a line (sorted hit distances from its start) the sheets stacked at its start
    reach: each hit within STACK_GAP of the last one taken (the first of the start) is part of it."""
    end = 0.0
    for t in distances:
        if t - end > STACK_GAP:
            break
        end = t
    return end


def _groups(rows: Sequence[SpotRow]) -> list[SpotGroup]:
    """Seams by the group column, in the order each group first appears; spots in list order."""
    out: dict[str, list[int]] = {}
    for i, r in enumerate(rows):
        assert r.group is not None
        out.setdefault(r.group, []).append(i)
    return [SpotGroup(name, tuple(members)) for name, members in out.items()]
