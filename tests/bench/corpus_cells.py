"""Seeded corpus of spot-welding cells nobody here laid out (a generator, not a test):

    python tests/bench/corpus_cells.py OUT_DIR [--count 200] [--seed 0] [--quick]

Each cell draws:

- an arm: the shipped kr16, kr125 and ur10, or the irb2400, m20ia and kr120r2500pro imported from
  the ROS-Industrial packages in tests/data/rosi (`robomax import-urdf`, written once into
  OUT_DIR/robots); the heavy arms carry the C-gun, the others the light gun;
- a placement: the robot off the cell origin (up to 2.5 m), yawed, on a riser of 0.3-0.7 m in
  about a third of the cells; the part at a drawn bearing and distance within the arm's reach;
- a part, a triangle mesh built here with trimesh (sheets as thin closed boxes, round parts as
  cylinders and rings): a panel with upturned flanges, an angle bracket with seams on both faces
  (gun horizontal on one, pointing down on the other), a box (a tray with a rim flange) or a
  frame of flanged rails, a tube with longitudinal flanges, or a round flange plate with a collar;
- 5-80 spots on 1-6 seams along the part's flanges, 20 mm from the edge the gun's C wraps over,
  at a drawn pitch;
- 0-6 toggle clamps where they constrain: a jaw on the gun side in a gap between two spots, its
  bar over the flange's edge, its arm behind the sheet and a post down to the fixture;
- the spot order a CAD export gives: seams listed in drawn order, each seam's spots along it,
  reversed, or by creation id (shuffled); most seams free (`ordered: false`), a few ordered.

Every cell is written as a user would write it (metres, degrees), its part as an STL beside it,
and loads through the normal cell reader. `bracket_regression_cell` is the 10-spot angle bracket
on an IRB 2400-class arm whose cross-face moves once found no detour.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

import numpy as np
import trimesh
import yaml

Vector = Sequence[float] | np.ndarray
ROSI = Path(__file__).resolve().parent.parent / "data" / "rosi"
SHEET_M = 0.003              # two 1.5 mm sheets joined at a flange
EDGE_M = 0.02                # spot to the flange edge the gun's C wraps over
MIN_PITCH_M = 0.035          # closest spots along a seam
CLAMP_GAP_M = 0.18           # a clamp's jaw takes this much of the seam (spot to spot across it)
FAMILIES = ("panel", "bracket", "box", "frame", "tube", "flange")


@dataclass(frozen=True, slots=True)
class Arm:
    """An arm of the corpus: model (a shipped name, or the imported folder's), tool, home (deg),
    the TCP's comfortable reach from the A1 axis and the shoulder's height above the base (m)."""

    name: str
    tool: str
    home: tuple[float, ...]
    reach: float
    shoulder: float
    base_width: float                   # m: the riser's top is this much wider
    xacro: str | None = None            # relative to tests/data/rosi: imported with import-urdf
    srdf: str | None = None


ARMS = {
    "kr16": Arm("kr16", "spot_gun_light", (0, -90, 90, 0, 0, 0), 1.45, 0.675, 0.5),
    "kr125": Arm("kr125", "spot_gun_c", (0, -90, 90, 0, 0, 0), 2.2, 0.865, 0.8),
    "ur10": Arm("ur10", "spot_gun_light", (0, -90, 90, -90, -90, 0), 1.1, 0.128, 0.2),
    "irb2400": Arm("irb2400", "spot_gun_light", (0, 0, 0, 0, 30, 0), 1.4, 0.615, 0.5,
                   "abb_irb2400_support/urdf/irb2400.xacro", "abb_irb2400_moveit_config/config/abb_irb2400.srdf"),
    "m20ia": Arm("m20ia", "spot_gun_light", (0, 0, 0, 0, 30, 0), 1.6, 0.525, 0.5,
                 "fanuc_m20ia_support/urdf/m20ia.xacro"),
    "kr120": Arm("kr120", "spot_gun_c", (0, -90, 90, 0, 30, 0), 2.2, 0.675, 0.8,
                 "kuka_kr120_support/urdf/kr120r2500pro.xacro"),
}


def import_arms(folder: Path) -> dict[str, Path]:
    """The imported arms' robot.yaml files, written into `folder` once (`robomax import-urdf`)."""
    from robomax_py.app.import_urdf import import_urdf

    out = {}
    for arm in ARMS.values():
        if arm.xacro is None:
            continue
        target = folder / arm.name
        if not (target / "robot.yaml").is_file():
            import_urdf(ROSI / arm.xacro, target, (ROSI,), srdf=None if arm.srdf is None else ROSI / arm.srdf,
                        name=arm.name)
        out[arm.name] = target / "robot.yaml"
    return out


# ----------------------------------------------------------------------------------------------
# Geometry in the part's frame P (x away from the robot, z up, origin on the part)


def _frame(x: Vector, y: Vector, z: Vector, origin: Vector) -> np.ndarray:
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, y, z, origin
    return T


def _box(extents: Sequence[float], T: np.ndarray) -> trimesh.Trimesh:
    mesh: trimesh.Trimesh = trimesh.creation.box(extents=list(extents), transform=T)
    return mesh


def _aligned_box(lo: Sequence[float], hi: Sequence[float]) -> trimesh.Trimesh:
    lo_, hi_ = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    T = np.eye(4)
    T[:3, 3] = (lo_ + hi_) / 2
    return _box(np.abs(hi_ - lo_), T)


@dataclass(frozen=True, slots=True)
class Flange:
    """Where spots go: a straight line or a circular arc on a sheet. At arc length s: the spot,
    the seam direction d, the outward normal n (the gun side) and e, in the sheet, towards the edge
    the gun's C wraps over."""

    origin: np.ndarray                 # straight: the start; arc: the centre
    d: np.ndarray                      # straight: along the line; arc: the first radial direction
    n: np.ndarray
    length: float                      # m of usable line (arc: of the spot circle)
    radius: float = 0.0                # arc: the spot circle's radius (e = radial outward)
    e_straight: np.ndarray | None = None

    def at(self, s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        if self.radius == 0.0:
            assert self.e_straight is not None
            return self.origin + s * self.d, self.d, self.n, self.e_straight
        phi = s / self.radius
        radial = math.cos(phi) * self.d + math.sin(phi) * np.cross(self.n, self.d)
        tangent = np.cross(self.n, radial)
        return self.origin + self.radius * radial, tangent, self.n, radial


def _line(start: Sequence[float], end: Sequence[float], n: Sequence[float], e: Sequence[float]) -> Flange:
    a, b = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    length = float(np.linalg.norm(b - a))
    return Flange(a, (b - a) / length, np.asarray(n, dtype=float), length, 0.0, np.asarray(e, dtype=float))


def _arc(centre: Vector, first: Vector, n: Vector, radius: float, angle: float) -> Flange:
    return Flange(np.asarray(centre, dtype=float), np.asarray(first, dtype=float), np.asarray(n, dtype=float),
                  radius * angle, radius)


@dataclass
class Part:
    """A part in P: its sheets (workpiece), its fixture (obstacles), its flanges; z_support is the
    height of the surface a clamp's post stands on."""

    kind: str
    sheets: list[trimesh.Trimesh]
    fixture: list[trimesh.Trimesh]
    flanges: list[Flange]
    z_support: float
    extent: float                      # m: farthest spot from P's origin, horizontally
    notes: dict[str, Any] = field(default_factory=dict)


def panel(rng: np.random.Generator, size: float, all_flanges: bool = False) -> Part:
    """A horizontal sheet lying on a table with upturned flanges (40-60 mm) along 1-3 edges (all
    three with `all_flanges`)."""
    w, depth = size * rng.uniform(0.8, 1.2), size * rng.uniform(0.45, 0.75)
    hf = rng.uniform(0.04, 0.06)
    sheets = [_aligned_box((-depth / 2, -w / 2, -SHEET_M), (depth / 2, w / 2, 0))]
    edges = ["front"] + [e for e in ("left", "right") if rng.random() < 0.5 or all_flanges]
    flanges = []
    z = hf - EDGE_M
    for e in edges:
        if e == "front":
            sheets.append(_aligned_box((-depth / 2 - SHEET_M, -w / 2, -SHEET_M), (-depth / 2, w / 2, hf)))
            flanges.append(_line((-depth / 2 - SHEET_M / 2, -w / 2 + 0.04, z), (-depth / 2 - SHEET_M / 2, w / 2 - 0.04, z),
                                 (-1, 0, 0), (0, 0, 1)))
        else:
            sign = -1.0 if e == "left" else 1.0
            y = sign * (w / 2 + SHEET_M / 2)
            sheets.append(_aligned_box((-depth / 2, sign * w / 2, -SHEET_M), (depth / 2, sign * (w / 2 + SHEET_M), hf)))
            flanges.append(_line((-depth / 2 + 0.04, y, z), (depth / 2 - 0.04, y, z), (0, sign, 0), (0, 0, 1)))
    table = _aligned_box((-depth / 2 + 0.02, -w / 2 + 0.02, -0.7), (depth / 2 - 0.02, w / 2 - 0.02, -SHEET_M))
    return Part("panel", sheets, [table], flanges, -SHEET_M, math.hypot(depth / 2, w / 2))


def bracket(rng: np.random.Generator, size: float, leg_away: bool | None = None) -> Part:
    """An angle bracket (an L of two legs, 70-90 mm) lying along y on two blocks: the vertical
    leg faces the robot (gun horizontal), the horizontal leg at its foot reaches away from the robot
    or towards it (gun pointing down, its C round the leg's free edge). Between the faces the gun
    turns over the vertical leg."""
    length = size * rng.uniform(0.8, 1.3)
    h, wl = rng.uniform(0.07, 0.09), rng.uniform(0.07, 0.09)
    away = bool(rng.random() < 0.7) if leg_away is None else leg_away
    sign = 1.0 if away else -1.0
    sheets = [_aligned_box((-SHEET_M / 2, -length / 2, 0), (SHEET_M / 2, length / 2, h)),
              _aligned_box((min(0, sign * wl), -length / 2, -SHEET_M), (max(0, sign * wl), length / 2, 0))]
    vertical = _line((-SHEET_M / 2, -length / 2 + 0.03, h - EDGE_M), (-SHEET_M / 2, length / 2 - 0.03, h - EDGE_M),
                     (-1, 0, 0), (0, 0, 1))
    x = sign * (wl - EDGE_M)
    horizontal = _line((x, -length / 2 + 0.03, -SHEET_M / 2), (x, length / 2 - 0.03, -SHEET_M / 2),
                       (0, 0, 1), (sign, 0, 0))
    # Blocks under the corner, clear of the lower jaw under the horizontal leg's spots.
    blocks = [_aligned_box((-0.025 - (0 if away else 0.0), y - 0.03, -0.25), (0.025, y + 0.03, -SHEET_M))
              for y in (-length / 2 + 0.05, length / 2 - 0.05)]
    table = _aligned_box((-0.2, -length / 2 - 0.05, -0.95), (0.2, length / 2 + 0.05, -0.25))
    return Part("bracket", sheets, [*blocks, table], [vertical, horizontal], -0.25, math.hypot(wl, length / 2),
                notes={"leg": "away" if away else "towards"})


def box(rng: np.random.Generator, size: float) -> Part:
    """An open sheet-metal box (tray) on a table with an outward rim flange (30 mm) at its top:
    spots on the rim, the gun pointing down, its C round the rim's edge."""
    w, depth, hb = size * rng.uniform(0.7, 1.1), size * rng.uniform(0.5, 0.8), rng.uniform(0.08, 0.2)
    rim = 0.03
    sheets = [_aligned_box((-depth / 2, -w / 2, 0), (depth / 2, w / 2, SHEET_M))]
    for sx in (-1, 1):
        sheets.append(_aligned_box((sx * depth / 2 - SHEET_M / 2, -w / 2, 0), (sx * depth / 2 + SHEET_M / 2, w / 2, hb)))
    for sy in (-1, 1):
        sheets.append(_aligned_box((-depth / 2, sy * w / 2 - SHEET_M / 2, 0), (depth / 2, sy * w / 2 + SHEET_M / 2, hb)))
    sheets.append(_aligned_box((-depth / 2 - rim, -w / 2 - rim, hb - SHEET_M), (-depth / 2, w / 2 + rim, hb)))
    sheets.append(_aligned_box((depth / 2, -w / 2 - rim, hb - SHEET_M), (depth / 2 + rim, w / 2 + rim, hb)))
    sheets.append(_aligned_box((-depth / 2, -w / 2 - rim, hb - SHEET_M), (depth / 2, -w / 2, hb)))
    sheets.append(_aligned_box((-depth / 2, w / 2, hb - SHEET_M), (depth / 2, w / 2 + rim, hb)))
    z = hb - SHEET_M / 2
    r = rim - EDGE_M
    flanges = [_line((-depth / 2 - r, -w / 2 + 0.03, z), (-depth / 2 - r, w / 2 - 0.03, z), (0, 0, 1), (-1, 0, 0)),
               _line((-depth / 2 + 0.03, -w / 2 - r, z), (depth / 2 - 0.03, -w / 2 - r, z), (0, 0, 1), (0, -1, 0)),
               _line((-depth / 2 + 0.03, w / 2 + r, z), (depth / 2 - 0.03, w / 2 + r, z), (0, 0, 1), (0, 1, 0)),
               _line((depth / 2 + r, -w / 2 + 0.03, z), (depth / 2 + r, w / 2 - 0.03, z), (0, 0, 1), (1, 0, 0))]
    order = rng.permutation(4)[:int(rng.integers(1, 5))]
    table = _aligned_box((-depth / 2, -w / 2, -0.7), (depth / 2, w / 2, 0))
    return Part("box", sheets, [table], [flanges[k] for k in sorted(order)], 0.0,
                math.hypot(depth / 2 + rim, w / 2 + rim))


def frame(rng: np.random.Generator, size: float, all_flanges: bool = False) -> Part:
    """A rectangular frame of four flanged rails (like cells/frame.yaml) on a table: each rail's
    upturned 40 mm flange on its outer edge; the rear rail's flange faces away from the robot.
    Spots on 1-4 of the flanges (all four with `all_flanges`)."""
    w, depth, rail, hf = size * rng.uniform(0.8, 1.2), size * rng.uniform(0.6, 0.9), 0.08, 0.045
    sheets: list[trimesh.Trimesh] = []
    flanges: list[Flange] = []
    z = hf - EDGE_M
    # front / rear rails along y, left / right along x; each: a base strip and its flange
    for sx in (-1, 1):
        x0 = sx * depth / 2
        sheets.append(_aligned_box((min(x0, x0 - sx * rail), -w / 2, -SHEET_M), (max(x0, x0 - sx * rail), w / 2, 0)))
        sheets.append(_aligned_box((min(x0, x0 + sx * SHEET_M), -w / 2, -SHEET_M), (max(x0, x0 + sx * SHEET_M), w / 2, hf)))
        xs = x0 + sx * SHEET_M / 2
        flanges.append(_line((xs, -w / 2 + 0.05, z), (xs, w / 2 - 0.05, z), (sx, 0, 0), (0, 0, 1)))
    for sy in (-1, 1):
        y0 = sy * w / 2
        sheets.append(_aligned_box((-depth / 2 + rail, min(y0, y0 - sy * rail), -SHEET_M),
                                   (depth / 2 - rail, max(y0, y0 - sy * rail), 0)))
        sheets.append(_aligned_box((-depth / 2 + rail, min(y0, y0 + sy * SHEET_M), -SHEET_M),
                                   (depth / 2 - rail, max(y0, y0 + sy * SHEET_M), hf)))
        ys = y0 + sy * SHEET_M / 2
        flanges.append(_line((-depth / 2 + rail + 0.04, ys, z), (depth / 2 - rail - 0.04, ys, z), (0, sy, 0), (0, 0, 1)))
    keep = sorted(rng.permutation(4)[:int(rng.integers(1, 5))])
    if all_flanges:
        keep = [0, 1, 2, 3]
    fixture = [_aligned_box((sx * depth / 2 - 0.04 - sx * 0.0, -w / 2 + 0.02, -0.7),
                            (sx * depth / 2 + 0.04 - sx * 0.08, w / 2 - 0.02, -SHEET_M)) for sx in (-1, 1)]
    fixture = [_aligned_box((min(b.bounds[0][0], b.bounds[1][0]), b.bounds[0][1], -0.7),
                            (max(b.bounds[0][0], b.bounds[1][0]), b.bounds[1][1], -SHEET_M)) for b in fixture]
    return Part("frame", sheets, fixture, [flanges[k] for k in keep], -SHEET_M, math.hypot(depth / 2, w / 2))


def tube(rng: np.random.Generator, size: float) -> Part:
    """A tube of two pressed half shells (radius 50-100 mm) along y on two saddles, joined by 30 mm
    flanges at its equator: the robot-side flange welded from above; sometimes a flange along its
    crest too, welded with the gun horizontal."""
    length, r = size * rng.uniform(0.8, 1.3), rng.uniform(0.05, 0.1)
    rim = 0.03
    shell = trimesh.creation.cylinder(radius=r, height=length, sections=32,
                                      transform=_frame((1, 0, 0), (0, 0, 1), (0, -1, 0), (0, 0, 0)))
    sheets = [shell,
              _aligned_box((-r - rim, -length / 2, -SHEET_M / 2), (-r, length / 2, SHEET_M / 2)),
              _aligned_box((r, -length / 2, -SHEET_M / 2), (r + rim, length / 2, SHEET_M / 2))]
    flanges = [_line((-r - rim + EDGE_M, -length / 2 + 0.04, 0), (-r - rim + EDGE_M, length / 2 - 0.04, 0),
                     (0, 0, 1), (-1, 0, 0))]
    if rng.random() < 0.4:
        crest = 0.035
        sheets.append(_aligned_box((-SHEET_M / 2, -length / 2, r - 0.005), (SHEET_M / 2, length / 2, r + crest)))
        flanges.append(_line((-SHEET_M / 2, -length / 2 + 0.04, r + crest - EDGE_M),
                             (-SHEET_M / 2, length / 2 - 0.04, r + crest - EDGE_M), (-1, 0, 0), (0, 0, 1)))
    saddles = [_aligned_box((-r * 0.8, y - 0.03, -r - 0.3), (r * 0.8, y + 0.03, -r * 0.7))
               for y in (-length / 2 + 0.08, length / 2 - 0.08)]
    table = _aligned_box((-0.2, -length / 2, -r - 0.9), (0.2, length / 2, -r - 0.3))
    return Part("tube", sheets, [*saddles, table], flanges, -r - 0.3, math.hypot(r + rim, length / 2))


def flange_plate(rng: np.random.Generator, size: float) -> Part:
    """A round flange plate (radius 150-400 mm) with a collar at its centre, standing facing the
    robot on a post, or lying on a pedestal (the collar a solid hub): spots on a circle 20 mm inside its rim."""
    R = float(np.clip(size * rng.uniform(0.3, 0.5), 0.15, 0.4))
    upright = bool(rng.random() < 0.5)
    # In the plate's own frame F the plate's face is z = 0 (the gun side +z), the collar on it.
    plate = trimesh.creation.cylinder(radius=R, height=SHEET_M, sections=48)
    collar = trimesh.creation.cylinder(radius=R * 0.35, height=0.08, sections=48,
                                       transform=_frame((1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, 0.04)))
    if upright:
        T = _frame((0, 1, 0), (0, 0, 1), (-1, 0, 0), (0, 0, 0))     # face towards the robot
        n = np.array([-1.0, 0, 0])
        first = np.array([0.0, 0, 1])
        post = _aligned_box((0.01, -0.04, -1.2), (0.07, 0.04, -R + 0.05))
        fixture, z_support = [post], -1.2
    else:
        T = np.eye(4)
        n = np.array([0.0, 0, 1])
        first = np.array([-1.0, 0, 0])
        pedestal = _aligned_box((-R * 0.5, -R * 0.5, -0.8), (R * 0.5, R * 0.5, -SHEET_M / 2))
        fixture, z_support = [pedestal], -0.8
    sheets = [plate.apply_transform(T), collar.apply_transform(T)]
    # The spot circle from the top (or robot side) round both ways; at most 300 deg of it.
    angle = rng.uniform(math.pi, 5 * math.pi / 3)
    start = np.array(first)
    c, s = math.cos(-angle / 2), math.sin(-angle / 2)
    start = c * first + s * np.cross(n, first)
    flanges = [_arc(n * SHEET_M / 2, start, n, R - EDGE_M, angle)]
    return Part("flange", sheets, fixture, flanges, z_support, R, notes={"upright": upright})


# ----------------------------------------------------------------------------------------------
# Spots, clamps, seams


def clamp_boxes(p: np.ndarray, d: np.ndarray, n: np.ndarray, e: np.ndarray, z_support: float) -> list[trimesh.Trimesh]:
    """A toggle clamp pressing the sheet at p: the jaw on the gun side (n), a bar from it over the
    edge the gun wraps round (e), the arm behind the sheet (-n) and, where the arm ends above the
    fixture, a post down to it (sizes of the reference cell's clamps)."""
    T = _frame(e, d, n, p)            # clamp frame: x = e, y = d, z = n

    def local(lo: Sequence[float], hi: Sequence[float]) -> trimesh.Trimesh:
        return _aligned_box(lo, hi).apply_transform(T)

    top = EDGE_M + 0.045
    out = [local((-0.025, -0.02, SHEET_M / 2), (0.025, 0.02, 0.055)),         # jaw
           local((0.0, -0.02, 0.03), (top + 0.02, 0.02, 0.06)),               # bar over the edge
           local((top - 0.02, -0.02, -0.45), (top + 0.02, 0.02, 0.06))]       # arm behind the sheet
    end = T @ np.array([top, 0.0, -0.45, 1.0])
    if end[2] > z_support + 0.03 and abs(n[2]) < 0.9:
        out.append(_aligned_box((end[0] - 0.025, end[1] - 0.025, z_support), (end[0] + 0.025, end[1] + 0.025, end[2])))
    return out


@dataclass(frozen=True, slots=True)
class Spot:
    name: str
    xyz: np.ndarray
    normal: np.ndarray
    direction: np.ndarray


def place_spots(rng: np.random.Generator, part: Part, n_spots: int, n_seams: int,
                n_clamps: int, min_pitch: float = MIN_PITCH_M) -> tuple[list[list[Spot]], list[trimesh.Trimesh], int]:
    """Spots along the part's flanges (seams never cross flanges; a long flange may hold several
    seams), with clamp gaps, no closer than `min_pitch`: the seams in their natural order along the
    flanges, the clamps' boxes and how many clamps there are (fewer than asked where a flange has
    no room)."""
    flanges = part.flanges
    order = rng.permutation(len(flanges)).tolist()
    used = max(1, min(len(flanges), n_seams, n_spots // 2))
    # Enough flanges for the spots at the closest pitch (a seam never crosses flanges).
    while used < len(flanges) and sum(int(flanges[k].length / min_pitch) + 1 for k in order[:used]) < n_spots:
        used += 1
    pick = sorted(order[:used])
    lengths = np.array([flanges[k].length for k in pick])
    clamps_per = np.zeros(used, dtype=int)
    for _ in range(n_clamps):
        clamps_per[int(rng.integers(used))] += 1
    clamps_per = np.minimum(clamps_per, ((lengths - min_pitch) / CLAMP_GAP_M).astype(int))
    caps = ((lengths - clamps_per * CLAMP_GAP_M) / min_pitch).astype(int) + 1
    # Spots per flange in proportion to its length, at least 2, at most what it holds.
    counts = np.minimum(caps, np.maximum(2, np.floor(lengths / lengths.sum() * n_spots))).astype(int)
    while counts.sum() < n_spots and (counts < caps).any():
        spare = np.flatnonzero(counts < caps)
        counts[spare[int(np.argmin(counts[spare] / lengths[spare]))]] += 1
    while counts.sum() > n_spots and counts.max() > 2:
        counts[int(np.argmax(counts))] -= 1
    seams_per = np.ones(used, dtype=int)
    for _ in range(max(0, n_seams - used)):
        k = int(np.argmax(counts / seams_per))
        if counts[k] // (seams_per[k] + 1) >= 2:
            seams_per[k] += 1
    seams: list[list[Spot]] = []
    clamps: list[trimesh.Trimesh] = []
    placed = 0
    for k, f_idx in enumerate(pick):
        f = flanges[f_idx]
        count, nc = int(counts[k]), int(min(clamps_per[k], counts[k] - 1))
        gap = CLAMP_GAP_M
        room = f.length - nc * gap
        pitch = min(0.08, room / max(1, count - 1)) if count > 1 else 0.0
        if count > 1 and pitch < min_pitch:               # too many: shorten to what fits
            count = max(2, int(room / min_pitch) + 1)
            pitch = room / (count - 1)
            nc = min(nc, count - 1)
        span = pitch * (count - 1) + nc * gap
        s0 = rng.uniform(0, max(0.0, f.length - span))
        after = sorted(rng.choice(np.arange(1, count), size=nc, replace=False).tolist()) if nc else []
        positions, s = [], s0
        for i in range(count):
            if i in after:
                clamp_at = s - pitch + gap / 2
                p, d, n, e = f.at(clamp_at)
                clamps.extend(clamp_boxes(p, d, n, e, part.z_support))
                placed += 1
                s += gap - pitch
            jitter = rng.uniform(-0.004, 0.004) if 0 < i < count - 1 else 0.0
            positions.append(s + jitter)
            s += pitch
        spots = []
        for s in positions:
            p, _, n, e = f.at(s)
            # The seam direction as CAD states the gun's nominal orientation: n x e, so that the
            # nominal TCP y axis (the side of the gun's C back) points to the edge the C wraps round.
            spots.append(Spot("", p, n, np.cross(n, e)))
        bounds = np.linspace(0, len(spots), int(seams_per[k]) + 1).round().astype(int)
        for a, b in itertools.pairwise(bounds):
            if b > a:
                seams.append(spots[a:b])
    return seams, clamps, placed


def capacity(part: Part, min_pitch: float = MIN_PITCH_M) -> int:
    """Spots the part's flanges hold at `min_pitch`."""
    return sum(int(f.length / min_pitch) + 1 for f in part.flanges)


# ----------------------------------------------------------------------------------------------
# Placement and the cell file


def _rz(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


def _pose(T: np.ndarray) -> dict[str, list[float]]:
    """A 4x4 pose as the cell file writes it: xyz (m), rpy (deg, R = Rz Ry Rx)."""
    R = T[:3, :3]
    pitch = math.asin(max(-1.0, min(1.0, -R[2, 0])))
    if abs(math.cos(pitch)) > 1e-9:
        roll, yaw = math.atan2(R[2, 1], R[2, 2]), math.atan2(R[1, 0], R[0, 0])
    else:
        roll, yaw = math.atan2(-R[1, 2], R[1, 1]), 0.0
    return {"xyz": [round(float(v), 6) for v in T[:3, 3]],
            "rpy": [round(math.degrees(a), 6) for a in (roll, pitch, yaw)]}


@dataclass
class GeneratedCell:
    """A cell file as a dict and the meshes it names (file name -> mesh, in the mesh's own frame)."""

    name: str
    data: dict[str, Any]
    meshes: dict[str, trimesh.Trimesh]
    family: str
    arm: str
    n_spots: int
    n_clamps: int

    def write(self, folder: Path, robots: dict[str, Path] | None = None) -> Path:
        """Write the cell and its meshes into `folder`; imported arms are named by the path to
        their robot.yaml (`robots`, as `import_arms` gives them), relative to the cell file."""
        (folder / "parts").mkdir(parents=True, exist_ok=True)
        data = dict(self.data)
        model = data["robot"]["model"]
        if robots and model in robots:
            data["robot"] = {**data["robot"], "model": _relative(robots[model], folder)}
        for file, mesh in self.meshes.items():
            mesh.export(folder / "parts" / file)
        path = folder / f"{self.name}.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False, default_flow_style=None), encoding="utf-8")
        meta = {"family": self.family, "arm": self.arm, "clamps": self.n_clamps}
        path.with_suffix(".meta.json").write_text(json.dumps(meta), encoding="utf-8")
        return path


def _relative(target: Path, start: Path) -> str:
    import os

    return os.path.relpath(target.resolve(), start.resolve())


def assemble(name: str, arm: Arm, T_world_robot: np.ndarray, riser: float, T_robot_part: np.ndarray, part: Part,
             seams: list[list[Spot]], clamps: list[trimesh.Trimesh], rng: np.random.Generator,
             listing: str | None = None, seam_names: Sequence[str] | None = None,
             spot_names: Sequence[Sequence[str]] | None = None, n_clamps: int = 1) -> GeneratedCell:
    """The cell: the robot at T_world_robot (on the floor frame; its base `riser` m up), the part's
    sheets (workpiece mesh), fixture and clamps (obstacle meshes) at T_world_robot @ T_robot_part,
    seams listed as a CAD export lists them (`listing`: along | reversed | by_id; drawn per seam
    when None)."""
    T_world_part = T_world_robot @ T_robot_part
    T_base = T_world_robot.copy()
    T_base[:3, 3] += T_world_robot[:3, 2] * riser
    sheet = cast(trimesh.Trimesh, trimesh.util.concatenate(part.sheets))
    obstacles = cast(trimesh.Trimesh, trimesh.util.concatenate(part.fixture + clamps))
    objects: list[dict[str, Any]] = [
        {"name": "part", "mesh": f"parts/{name}_part.stl", "workpiece": True, "pose": _pose(T_world_part)},
        {"name": "fixture", "mesh": f"parts/{name}_fixture.stl", "pose": _pose(T_world_part)},
    ]
    if riser > 0:
        T_riser = T_world_robot.copy()
        T_riser[:3, 3] += T_world_robot[:3, 2] * riser / 2
        side = round(1.1 * arm.base_width, 4)
        objects.append({"name": "riser", "box": [side, side, round(riser, 4)], "pose": _pose(T_riser)})
    seam_dicts = []
    for k, spots in enumerate(seams):
        how = listing or str(rng.choice(["along", "along", "reversed", "by_id"]))
        ids = list(range(len(spots)))
        listed = ids[::-1] if how == "reversed" else (rng.permutation(ids).tolist() if how == "by_id" else ids)
        sname = seam_names[k] if seam_names else f"seam{k + 1}"
        rows = []
        for i in listed:
            sp = spots[i]
            xyz = (T_world_part @ np.r_[sp.xyz, 1.0])[:3]
            nrm, drc = T_world_part[:3, :3] @ sp.normal, T_world_part[:3, :3] @ sp.direction
            label = spot_names[k][i] if spot_names else f"{sname}_{i + 1}"
            rows.append({"name": label, "xyz": [round(float(v), 6) for v in xyz],
                         "normal": [round(float(v), 6) for v in nrm], "direction": [round(float(v), 6) for v in drc]})
        ordered = bool(rng.random() < 0.15) if listing is None else False
        ab = int(rng.choice([10, 15, 20])) if listing is None else 10
        gamma = [-180, 180] if listing is not None or rng.random() < 0.8 else [-90, 90]
        seam_dicts.append({"name": sname, "ordered": ordered, "tolerance": {"alpha": ab, "beta": ab, "gamma": gamma},
                           "grid": 5 if listing is not None or rng.random() < 0.7 else 3, "spots": rows})
    if listing is None:
        seam_dicts = [seam_dicts[k] for k in rng.permutation(len(seam_dicts))]
    data = {
        "robomax": 1, "name": name,
        "robot": {"model": arm.name, "base": _pose(T_base), "home": list(arm.home)},
        "tool": arm.tool, "objects": objects, "seams": seam_dicts,
        "process": {"weld_time": 0.4, "approach": 0.03, "clearance": 0}, "planner": {"seed": 0},
    }
    meshes = {f"{name}_part.stl": sheet, f"{name}_fixture.stl": obstacles}
    return GeneratedCell(name, data, meshes, part.kind, arm.name, sum(len(s) for s in seams), n_clamps)


BUILDERS = {"panel": panel, "bracket": bracket, "box": box, "frame": frame, "tube": tube, "flange": flange_plate}


def corpus_cell(index: int, seed: int = 0, max_spots: int = 80) -> GeneratedCell:
    """Cell `index` of the corpus drawn with `seed` (at most `max_spots` spots): deterministic."""
    rng = np.random.default_rng([seed, index])
    arm = list(ARMS.values())[index % len(ARMS)]
    family = FAMILIES[(index // len(ARMS)) % len(FAMILIES)]
    n_spots = min(max_spots, round(math.exp(rng.uniform(math.log(5), math.log(80)))))
    n_seams = int(rng.integers(1, 7))
    n_clamps = int(rng.choice([0, 0, 1, 2, 3, 4, 6]))
    reach = arm.reach
    size = reach * rng.uniform(0.35, 0.6)
    part = BUILDERS[family](rng, size)
    # A part too small for its spots (at the closest pitch, with room for the clamps) grows.
    for _ in range(6):
        if capacity(part) >= n_spots + 3 * n_clamps:
            break
        size = min(size * 1.25, reach * 0.9)
        part = BUILDERS[family](rng, size)
    seams, clamps, n_placed = place_spots(rng, part, n_spots, n_seams, n_clamps)
    while sum(len(s) for s in seams) < min(5, n_spots) and n_clamps > 0:      # clamps took the room
        n_clamps -= 1
        seams, clamps, n_placed = place_spots(rng, part, n_spots, n_seams, n_clamps)
    riser = float(rng.choice([0.3, 0.5, 0.7])) if rng.random() < 0.35 else 0.0
    if arm.name == "ur10":
        riser = max(riser, 0.5)             # a UR10 stands on a pedestal in a welding cell
    # The part's centre at a bearing off the arm's home direction, at a distance within reach,
    # its working height near the shoulder's.
    bearing = rng.uniform(-50, 50)
    dist = rng.uniform(0.45, 0.62) * reach + 0.35 * part.extent
    height = riser + arm.shoulder + rng.uniform(-0.45, 0.1) * reach * 0.6
    T_robot_part = _rz(bearing) @ _translation(dist, 0.0, max(0.35, height))
    T_world_robot = _translation(rng.uniform(-2.5, 2.5), rng.uniform(-2.5, 2.5), 0.0) @ _rz(rng.uniform(-180, 180))
    name = f"c{index:03d}_{arm.name}_{family}_{sum(len(s) for s in seams)}"
    return assemble(name, arm, T_world_robot, riser, T_robot_part, part, seams, clamps, rng, n_clamps=n_placed)


def _translation(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = x, y, z
    return T


SCALED_ARM = "kr125"
SCALED_STATIONS = (-135.0, -45.0, 45.0, 135.0)     # deg: bearings of the fixtures round the robot
SCALED_MAX_SPOTS = 240                             # the part is sized for this many spots


def scaled_cell(family: str, n_spots: int, seed: int = 0) -> GeneratedCell:
    """A cell of `n_spots` spots on four copies of one corpus part (`family`), each in its own
    fixture at a bearing of SCALED_STATIONS round one KR 125 with the C-gun (as a welding cell with
    several fixtures), n_spots / 4 spots per part. The arm, the part's shape and size, the
    stations' distance and height and the riser are drawn from `seed` alone, so the cells of one
    family and seed differ only in their spots (their placement, clamps and seam listing are then
    drawn for each N as `corpus_cell` draws them). The part is sized for SCALED_MAX_SPOTS / 4 spots
    (every flange used); where its flanges are too short at the corpus's closest pitch, the pitch
    shrinks (not below 20 mm, a common minimum for two 1.5 mm sheets) rather than the part outgrowing
    the arm's reach."""
    family_index = FAMILIES.index(family)
    rng = np.random.default_rng([seed, 1000 + family_index])
    arm = ARMS[SCALED_ARM]
    n_seams = int(rng.integers(1, 7))
    n_clamps = int(rng.choice([0, 0, 1, 2, 3, 4, 6]))
    per_part_max = -(-SCALED_MAX_SPOTS // len(SCALED_STATIONS))
    builder = BUILDERS[family]
    build = (lambda size: builder(rng, size, all_flanges=True)) if family in ("panel", "frame") \
        else (lambda size: builder(rng, size))
    size = arm.reach * rng.uniform(0.35, 0.45)
    part = build(size)
    for _ in range(6):          # the corpus's growth, capped so that four stations keep apart
        if capacity(part) >= per_part_max + 3 * n_clamps:
            break
        size = min(size * 1.25, arm.reach * 0.5)
        part = build(size)
    riser = float(rng.choice([0.3, 0.5, 0.7])) if rng.random() < 0.35 else 0.0
    dist = rng.uniform(0.45, 0.55) * arm.reach + 0.35 * part.extent
    height = max(0.35, riser + arm.shoulder + rng.uniform(-0.45, 0.1) * arm.reach * 0.6)
    T_world_robot = _translation(rng.uniform(-2.5, 2.5), rng.uniform(-2.5, 2.5), 0.0) @ _rz(rng.uniform(-180, 180))
    usable = sum(f.length for f in part.flanges) - n_clamps * CLAMP_GAP_M
    min_pitch = max(0.02, min(MIN_PITCH_M, usable / (per_part_max + 1)))
    # Everything N changes is drawn after this point.
    sheets: list[trimesh.Trimesh] = []
    fixture: list[trimesh.Trimesh] = []
    clamps: list[trimesh.Trimesh] = []
    seams: list[list[Spot]] = []
    placed = 0
    counts = [n_spots // len(SCALED_STATIONS) + (k < n_spots % len(SCALED_STATIONS)) for k in range(len(SCALED_STATIONS))]
    for bearing, count in zip(SCALED_STATIONS, counts, strict=True):
        T = _rz(bearing) @ _translation(dist, 0.0, height)
        sheets += [m.copy().apply_transform(T) for m in part.sheets]
        fixture += [m.copy().apply_transform(T) for m in part.fixture]
        station_seams, station_clamps, k = place_spots(rng, part, count, n_seams, n_clamps, min_pitch)
        clamps += [m.apply_transform(T) for m in station_clamps]
        placed += k
        R = T[:3, :3]
        seams += [[Spot("", (T @ np.r_[s.xyz, 1.0])[:3], R @ s.normal, R @ s.direction) for s in seam]
                  for seam in station_seams]
    cell_part = Part(part.kind, sheets, fixture, [], part.z_support, part.extent)
    name = f"scaled_{family}_{sum(len(s) for s in seams)}_s{seed}"
    return assemble(name, arm, T_world_robot, riser, np.eye(4), cell_part, seams, clamps, rng, n_clamps=placed)


def bracket_regression_cell() -> GeneratedCell:
    """The 10-spot angle bracket on an IRB 2400-class arm: seam v (v1-v5) on the vertical leg,
    welded with the gun horizontal, its C round the leg's top edge; seam h (h1-h5) on the
    horizontal leg reaching away from the robot, welded with the gun pointing down, its C round the
    leg's far edge; one clamp on the horizontal leg between the two seams. The robot stands 1.9 m
    off the cell origin, turned 35 deg. Every move from one face to the other turns the gun over
    the vertical leg; h5, near the bracket's end and its block, takes the wrist turned 100-120 deg
    from the other h spots."""
    rng = np.random.default_rng(108)
    arm = ARMS["irb2400"]
    part = bracket(rng, 0.5, leg_away=True)
    vertical, horizontal = part.flanges
    v = [Spot(f"v{k + 1}", *_spot_at(vertical, s)) for k, s in enumerate(np.linspace(0.0, 0.16, 5))]
    h0 = 0.16 + CLAMP_GAP_M
    h = [Spot(f"h{k + 1}", *_spot_at(horizontal, s)) for k, s in enumerate(np.linspace(h0, h0 + 0.16, 5))]
    p, d, n, e = horizontal.at(0.16 + CLAMP_GAP_M / 2)
    clamps = clamp_boxes(p, d, n, e, part.z_support)
    T_robot_part = _translation(0.905, -0.254, 0.57)
    T_world_robot = _translation(1.4, -1.3, 0.0) @ _rz(35.0)
    return assemble("bracket_irb2400", arm, T_world_robot, 0.0, T_robot_part, part, [v, h], clamps, rng,
                    listing="along", seam_names=["v", "h"], spot_names=[[s.name for s in v], [s.name for s in h]])


def _spot_at(f: Flange, s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    p, d, n, _ = f.at(s)
    return p, n, d


QUICK = (7, 21)         # CI's smoke run: a cell the oracle and the planner refuse, and one both plan


def write_corpus(folder: Path, count: int = 200, seed: int = 0, indices: Sequence[int] | None = None,
                 max_spots: int = 80) -> list[Path]:
    """Write the corpus (its imported robots under folder/robots, cells under folder/cells)."""
    robots = import_arms(folder / "robots")
    out = []
    for index in (range(count) if indices is None else indices):
        out.append(corpus_cell(index, seed, max_spots).write(folder / "cells", robots))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", type=Path)
    ap.add_argument("--count", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="two small cells (CI's smoke run)")
    args = ap.parse_args()
    paths = write_corpus(args.out, args.count, args.seed, QUICK if args.quick else None, 8 if args.quick else 80)
    robots = import_arms(args.out / "robots")
    paths.append(bracket_regression_cell().write(args.out / "cells", robots))
    for p in paths:
        print(p)


if __name__ == "__main__":
    main()
