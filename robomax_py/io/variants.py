"""Seeded perturbed copies of a cell, for robustness studies and batch benchmarks.

A variant moves every clamp and the part a little, and reorders the spots of seams that are not
ordered; everything else is copied as written:

- clamps: objects (not workpieces) whose name contains "clamp"; the parts of one clamp share the
  prefix before the first "_" (`clamp1_jaw`, `clamp1_arm`, ...) and move together, by dx, dy each
  uniform in ±`clamp` (z unchanged: clamps stay on the fixture);
- the part: every workpiece object and every spot move together, rigidly, by dx, dy each uniform in
  ±`part` and a turn uniform in ±`part_yaw` about the vertical axis through the spots' centroid (the
  part stays on its fixture: no z shift, no tilt);
- spot order: a seeded permutation of the spots of each seam with `ordered: false`.

Variant k of seed s draws from `np.random.default_rng([s, k])`, so it does not depend on how many are
made. Values are written rounded to 1e-6 (m, deg, unit vectors); files are byte-identical per seed.
Meshes named by relative paths inside the cell's folder are copied beside the variants (same relative
path); a robot, tool or mesh named by any other relative path is referenced from the output folder.
File keys are cell_io's: the cell is read and written through its schema.
"""

from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robomax_py.io.cell import dump_cell_file, load_cell, read_cell_file
from robomax_py.io.cell_file import CellFile, SeamFile
from robomax_py.io.cell_file_values import ObjectFile
from robomax_py.io.includes import rebased_reference
from robomax_py.io.robot import resolve_robot_file, resolve_tool_file

DECIMALS = 6                          # written values: µm, µdeg, 1e-6 of a unit vector
CLAMP_MARK = "clamp"


@dataclass(frozen=True, slots=True)
class VariantBounds:
    """Largest perturbations (uniform draws in ± these)."""

    clamp: float = 0.015              # m, x and y of each clamp
    part: float = 0.005               # m, x and y of the part
    part_yaw: float = math.radians(1.0)   # rad, turn of the part about the vertical through the spots' centroid


@dataclass(frozen=True, slots=True)
class Perturbation:
    """What one variant changed (SI units)."""

    clamps: tuple[tuple[str, float, float], ...]   # (clamp, dx, dy), m
    part_offset: tuple[float, float]               # (dx, dy), m
    part_yaw: float                                # rad
    centre: tuple[float, float]                    # (x, y) of the turn's axis, m
    orders: tuple[tuple[str, tuple[str, ...]], ...]   # (seam, spot names in the new order), unordered seams


@dataclass(frozen=True, slots=True)
class Variant:
    path: Path
    name: str
    perturbation: Perturbation


def clamp_group(name: str) -> str | None:
    """The clamp an object belongs to ('clamp1_jaw' -> 'clamp1'), or None when it is not a clamp."""
    if CLAMP_MARK not in name.lower():
        return None
    return name.split("_", 1)[0]


def perturb(cell: CellFile, rng: np.random.Generator, bounds: VariantBounds = VariantBounds()) -> tuple[CellFile, Perturbation]:
    """A perturbed copy of a cell's schema and what was changed; draws in a fixed order from `rng`."""
    groups: list[str] = []
    for obj in cell.objects:
        group = None if obj.workpiece else clamp_group(obj.name)
        if group is not None and group not in groups:
            groups.append(group)
    clamp_moves = {g: (float(rng.uniform(-bounds.clamp, bounds.clamp)), float(rng.uniform(-bounds.clamp, bounds.clamp)))
                   for g in groups}
    dx, dy = (float(v) for v in rng.uniform(-bounds.part, bounds.part, size=2))
    yaw = float(rng.uniform(-bounds.part_yaw, bounds.part_yaw))
    spots_xy = np.array([s.xyz[:2] for seam in cell.seams for s in seam.spots])
    centre = spots_xy.mean(axis=0)
    c, s = math.cos(yaw), math.sin(yaw)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    centre3 = np.array([centre[0], centre[1], 0.0])
    shift = np.array([dx, dy, 0.0])

    def move_point(xyz: list[float]) -> list[float]:
        return _rounded(centre3 + R @ (np.asarray(xyz) - centre3) + shift)

    def turn(v: list[float]) -> list[float]:
        return _rounded(R @ np.asarray(v))

    objects: list[ObjectFile] = []
    for obj in cell.objects:
        group = None if obj.workpiece else clamp_group(obj.name)
        if obj.workpiece:
            yaw_deg = obj.pose.rpy[2] + math.degrees(yaw)
            pose = obj.pose.model_copy(update={"xyz": move_point(obj.pose.xyz),
                                               "rpy": _rounded([obj.pose.rpy[0], obj.pose.rpy[1], yaw_deg])})
            objects.append(obj.model_copy(update={"pose": pose}))
        elif group is not None:
            mx, my = clamp_moves[group]
            x, y, z = obj.pose.xyz
            objects.append(obj.model_copy(update={"pose": obj.pose.model_copy(update={"xyz": _rounded([x + mx, y + my, z])})}))
        else:
            objects.append(obj)

    seams: list[SeamFile] = []
    orders: list[tuple[str, tuple[str, ...]]] = []
    for seam in cell.seams:
        spots = [sp.model_copy(update={"xyz": move_point(sp.xyz), "normal": turn(sp.normal),
                                       "direction": turn(sp.direction)}) for sp in seam.spots]
        if not seam.ordered:
            spots = [spots[int(k)] for k in rng.permutation(len(spots))]
            orders.append((seam.name, tuple(sp.name for sp in spots)))
        seams.append(seam.model_copy(update={"spots": spots}))
    perturbation = Perturbation(
        clamps=tuple((g, mx, my) for g, (mx, my) in clamp_moves.items()), part_offset=(dx, dy), part_yaw=yaw,
        centre=(float(centre[0]), float(centre[1])), orders=tuple(orders),
    )
    return cell.model_copy(update={"objects": objects, "seams": seams}), perturbation


def write_variants(cell_path: str | Path, n: int, seed: int, out_dir: Path,
                   bounds: VariantBounds = VariantBounds()) -> tuple[Variant, ...]:
    """Check a cell, then write `n` variants of it into `out_dir` as `<name>_v00.yaml`, ...

    Raises CellFileError / RobotModelError when the cell is not valid (nothing is written then).
    """
    from robomax_py.io.files import write_atomic

    cell_path = Path(cell_path)
    spec = load_cell(cell_path)                     # the whole cell is valid before anything is written
    base = _relocated(read_cell_file(cell_path), cell_path, out_dir)
    width = max(2, len(str(n - 1)))
    variants: list[Variant] = []
    for k in range(n):
        name = f"{spec.name}_v{k:0{width}d}"
        cell, change = perturb(base, np.random.default_rng([seed, k]), bounds)
        cell = cell.model_copy(update={"name": name})
        path = out_dir / f"{name}.yaml"
        write_atomic(path, dump_cell_file(cell, _header(spec.name, k, seed, change)))
        variants.append(Variant(path, name, change))
    return tuple(variants)


def _relocated(cell: CellFile, cell_path: Path, out_dir: Path) -> CellFile:
    """The cell as it must be written in `out_dir`: meshes inside the cell's folder copied there, other
    relative references rewritten relative to `out_dir`."""
    src_dir = cell_path.resolve().parent
    dst_dir = out_dir.resolve()
    objects = []
    for obj in cell.objects:
        if obj.mesh is not None and not Path(obj.mesh).is_absolute():
            source = (src_dir / obj.mesh).resolve()
            if source.is_relative_to(src_dir):
                target = dst_dir / source.relative_to(src_dir)
                if target != source:
                    target.parent.mkdir(parents=True, exist_ok=True)
                    shutil.copyfile(source, target)
            else:
                obj = obj.model_copy(update={"mesh": Path(os.path.relpath(source, dst_dir)).as_posix()})
        objects.append(obj)
    dynamic = [o if o.mesh is None or Path(o.mesh).is_absolute()
               else o.model_copy(update={"mesh": Path(os.path.relpath((src_dir / o.mesh).resolve(), dst_dir)).as_posix()})
               for o in cell.dynamic]
    update: dict[str, object] = {"objects": objects, "dynamic": dynamic}
    # A robot or tool named by a relative path (not a library name) is referenced from out_dir.
    here, there = cell_path.resolve(), dst_dir / cell_path.name
    model = rebased_reference(cell.robot.model, here, there, resolve_robot_file)
    if model != cell.robot.model:
        update["robot"] = cell.robot.model_copy(update={"model": model})
    tool = rebased_reference(cell.tool, here, there, resolve_tool_file)
    if tool != cell.tool:
        update["tool"] = tool
    return cell.model_copy(update=update)


def _header(name: str, k: int, seed: int, change: Perturbation) -> str:
    lines = [f"variant {k} of {name} (robomax variants, seed {seed})"]
    for group, mx, my in change.clamps:
        lines.append(f"{group}: dx {mx * 1000:+.3f} mm, dy {my * 1000:+.3f} mm")
    dx, dy = change.part_offset
    cx, cy = change.centre
    lines.append(f"part and spots: dx {dx * 1000:+.3f} mm, dy {dy * 1000:+.3f} mm, "
                 f"yaw {math.degrees(change.part_yaw):+.4f} deg about x {cx:.4f}, y {cy:.4f} m")
    for seam, order in change.orders:
        lines.append(f"seam {seam} order: {' '.join(order)}")
    return "\n".join(lines)


def _rounded(values: np.ndarray | list[float]) -> list[float]:
    return [round(float(v), DECIMALS) + 0.0 for v in values]    # + 0.0: no "-0.0" in files
