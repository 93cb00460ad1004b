#!/usr/bin/env python
"""Generate the parts of the shipped example cells (``cells/parts/*.stl``) and their weld spots.

Run from anywhere:  ``python cells/parts/make_parts.py [--out DIR] [--yaml]``  (DIR defaults to this
file's folder). The STL output is deterministic (fixed header, float32 vertices computed the same way
every run), so rerunning gives byte-identical files; ``tests/test_shipped_parts.py`` checks that
against the committed copies. ``--yaml`` prints, for each cell, the clamp objects and seams (spots in
the world frame, metres) that the cell files in ``cells/`` were written from.

Every part is modelled in its cell's world frame (the cell places it with the identity pose) as a
union of separate thin closed boxes (sheet metal, 1-2 mm), so the planner's scene turns it into one
exact convex piece per sheet. Spots lie on the mid-plane of the joined flange; ``normal`` points to
the side the moving electrode comes from, ``direction`` along the seam.

Parts
-----
cabin_rear_panel.stl  lower section of a truck-cabin rear panel: a floor-side sheet with a 40 mm
                      upturned flange (two sheets, inner panel and outer skin) along its robot-side
                      edge, kinked by 20 deg; a rear upstand. kr125 + spot_gun_c, 12 spots, 3 clamps.
frame.stl             a welded rectangular base frame of flanged rails (front, left, right, rear)
                      and an L-section pillar standing on the left rail. kr125 + spot_gun_c.
tray.stl              a shallow sheet-metal tray with a 25 mm outward rim flange carrying a welded-on
                      stiffening rim strip. ur10 + spot_gun_light.
"""

from __future__ import annotations

import argparse
import math
import struct
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt
import trimesh

FloatArray = npt.NDArray[np.float64]

SHEET_M = 0.0015          # sheet thickness of every panel
FLANGE_H_M = 0.040        # upturned flange height above the sheet it is bent from
UP = np.array([0.0, 0.0, 1.0])


# ----------------------------------------------------------------------------------------------
# Building blocks
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Spot:
    name: str
    xyz: tuple[float, float, float]
    normal: tuple[float, float, float]
    direction: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Seam:
    name: str
    ordered: bool
    spots: tuple[Spot, ...]


@dataclass(frozen=True, slots=True)
class BoxObject:
    """A cell obstacle written as a `box` primitive: full extents, centre and yaw (deg)."""

    name: str
    extents: tuple[float, float, float]
    xyz: tuple[float, float, float]
    yaw_deg: float


@dataclass(frozen=True, slots=True)
class Part:
    file: str
    shells: tuple[trimesh.Trimesh, ...]
    seams: tuple[Seam, ...]
    clamps: tuple[BoxObject, ...] = ()


def _unit(v: Sequence[float] | FloatArray) -> FloatArray:
    a = np.asarray(v, dtype=float)
    return a / float(np.linalg.norm(a))


def oriented_box(centre: Sequence[float] | FloatArray, x_axis: Sequence[float] | FloatArray,
                 extents: Sequence[float]) -> trimesh.Trimesh:
    """A closed box with local x along ``x_axis`` (made horizontal-perpendicular to z), z up."""
    x = _unit(x_axis)
    z = UP if abs(float(np.dot(x, UP))) < 0.99 else np.array([1.0, 0.0, 0.0])
    x = _unit(x - np.dot(x, z) * z)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, y, z, np.asarray(centre, dtype=float)
    return trimesh.creation.box(extents=list(extents), transform=T)


def slab(polygon: Sequence[tuple[float, float]], z_lo: float, z_hi: float) -> trimesh.Trimesh:
    """Closed convex prism over a convex plan polygon (x, y), between heights z_lo and z_hi."""
    pts = [(x, y, z) for x, y in polygon for z in (z_lo, z_hi)]
    hull: trimesh.Trimesh = trimesh.convex.convex_hull(np.asarray(pts, dtype=float))
    return hull


def wall(p0: Sequence[float], p1: Sequence[float], z_lo: float, z_hi: float,
         thickness: float, offset: float = 0.0) -> trimesh.Trimesh:
    """A vertical sheet along the plan segment p0 -> p1, its mid-plane shifted by ``offset`` to the
    segment's left (seen from above, looking along p0 -> p1)."""
    a, b = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    d = _unit(np.r_[b - a, 0.0])
    left = np.cross(UP, d)
    mid = 0.5 * (a + b)
    centre = np.r_[mid, 0.5 * (z_lo + z_hi)] + offset * left
    return oriented_box(centre, d, (float(np.linalg.norm(b - a)), thickness, z_hi - z_lo))


def _r(v: float) -> float:
    """Rounded as written into the cell files: 0.01 mm for positions, 1e-6 for unit vectors."""
    return round(float(v), 6) + 0.0      # + 0.0: no "-0" in the files


def _vec(v: Sequence[float] | FloatArray) -> tuple[float, float, float]:
    return (_r(v[0]), _r(v[1]), _r(v[2]))


# ----------------------------------------------------------------------------------------------
# Cabin rear panel (cells/cabin_flange.yaml)
# ----------------------------------------------------------------------------------------------

CABIN_Z_SHEET = 0.86          # top face of the floor-side sheet, m
CABIN_A0 = (1.33, -0.75)      # flange line: straight part A along +y ...
CABIN_KINK = (1.33, 0.15)     # ... to the kink, then part B turned 20 deg towards the robot
CABIN_B_DEG = 20.0
CABIN_B_LEN = 0.50
CABIN_REAR_X = 1.85
# Arc length along the flange line (from CABIN_A0) of every spot and clamp, m.
CABIN_SPOTS_S = (0.05, 0.125, 0.20, 0.39, 0.465, 0.54, 0.73, 0.805, 0.985, 1.06, 1.25, 1.325)
CABIN_CLAMPS_S = (0.295, 0.635, 1.155)


def _cabin_line() -> tuple[FloatArray, FloatArray, FloatArray]:
    a0, k = np.asarray(CABIN_A0, dtype=float), np.asarray(CABIN_KINK, dtype=float)
    t = math.radians(CABIN_B_DEG)
    b1 = k + CABIN_B_LEN * np.array([-math.sin(t), math.cos(t)])
    return a0, k, b1


def _cabin_at(s: float) -> tuple[FloatArray, FloatArray]:
    """Plan point and unit direction of the flange line at arc length s."""
    a0, k, b1 = _cabin_line()
    la = float(np.linalg.norm(k - a0))
    if s <= la:
        d = _unit(k - a0)
        return a0 + s * d, d
    d = _unit(b1 - k)
    return k + (s - la) * d, d


def cabin_rear_panel() -> Part:
    a0, k, b1 = _cabin_line()
    z0 = CABIN_Z_SHEET
    zs = (z0 - SHEET_M, z0)
    far_b = (CABIN_REAR_X, float(b1[1] + 0.0))
    shells = [
        # Floor-side sheet: two convex pieces meeting at the kink's perpendicular.
        slab([tuple(a0), (CABIN_REAR_X, a0[1]), (CABIN_REAR_X, k[1]), tuple(k)], *zs),
        slab([tuple(k), (CABIN_REAR_X, k[1]), far_b, tuple(b1)], *zs),
        # Rear upstand.
        wall((CABIN_REAR_X, a0[1]), (CABIN_REAR_X, b1[1]), z0 - SHEET_M, z0 + 0.22, SHEET_M, -0.5 * SHEET_M),
    ]
    # The flange: inner-panel sheet and outer-skin sheet, back to back on the flange line (the mid-plane
    # of the pair), both up to the same edge.
    for p, q in ((a0, k), (k, b1)):
        for side in (-0.5, 0.5):
            shells.append(wall(p, q, z0 - SHEET_M, z0 + FLANGE_H_M, SHEET_M, side * SHEET_M))
    z_spot = z0 + 0.5 * FLANGE_H_M
    spots = []
    for n, s in enumerate(CABIN_SPOTS_S, start=1):
        p, d = _cabin_at(s)
        normal = np.cross(UP, np.r_[d, 0.0])           # left of the line, seen from above: the robot side
        spots.append(Spot(f"s{n}", _vec(np.r_[p, z_spot]), _vec(normal), _vec(np.r_[d, 0.0])))
    clamps = []
    for n, s in enumerate(CABIN_CLAMPS_S, start=1):
        p, d = _cabin_at(s)
        back = -np.cross(UP, np.r_[d, 0.0])            # away from the robot, over the panel
        yaw = math.degrees(math.atan2(back[1], back[0]))
        top = z0 + FLANGE_H_M
        # Jaw straddling the flange edge, arm over the panel to a post standing on the sheet.
        jaw_c = np.r_[p, top - 0.005]
        arm_len = 0.40
        arm_c = np.r_[p, top + 0.045] + (0.5 * arm_len - 0.02) * back
        post_c = np.r_[p, 0.5 * (z0 + top + 0.065)] + (arm_len - 0.05) * back
        clamps += [
            BoxObject(f"clamp{n}_jaw", (0.05, 0.11, 0.07), _vec(jaw_c), _r(yaw)),
            BoxObject(f"clamp{n}_arm", (arm_len, 0.04, 0.04), _vec(arm_c), _r(yaw)),
            BoxObject(f"clamp{n}_post", (0.06, 0.05, _r(top + 0.065 - z0)), _vec(post_c), _r(yaw)),
        ]
    return Part("cabin_rear_panel.stl", tuple(shells), (Seam("flange", False, tuple(spots)),), tuple(clamps))


# ----------------------------------------------------------------------------------------------
# Frame (cells/frame.yaml)
# ----------------------------------------------------------------------------------------------

FRAME_Z = 0.84                # top of the rails' base sheets
FRAME_X = (1.30, 1.90)        # front and rear rail flange lines
FRAME_Y = 0.45                # side rails' flange lines at +-FRAME_Y
FRAME_RAIL_W = 0.10           # base-sheet width of a rail, behind its flange
FRAME_PILLAR_X = 1.60         # pillar on the left rail: its flange leg spans x +- 20 mm
FRAME_PILLAR_H = 0.42


def frame() -> Part:
    z0 = FRAME_Z
    xf, xr = FRAME_X
    y = FRAME_Y
    w = FRAME_RAIL_W
    zs = (z0 - 2 * SHEET_M, z0)
    shells = [
        # Base sheets of the four rails (front, rear, left, right), overlapping at the corners.
        slab([(xf, -y), (xf + w, -y), (xf + w, y), (xf, y)], *zs),
        slab([(xr - w, -y), (xr, -y), (xr, y), (xr - w, y)], *zs),
        slab([(xf, -y), (xr, -y), (xr, -y + w), (xf, -y + w)], *zs),
        slab([(xf, y - w), (xr, y - w), (xr, y), (xf, y)], *zs),
    ]
    # Upturned flanges (two sheets each) on the outer edges of the front, left and right rails.
    for p, q in (((xf, y), (xf, -y)), ((xr, -y), (xf, -y)), ((xf, y), (xr, y))):
        for side in (-0.5, 0.5):
            shells.append(wall(p, q, z0 - 2 * SHEET_M, z0 + FLANGE_H_M, SHEET_M, side * SHEET_M))
    # Pillar: an L-section standing on the left rail. Flange leg in the left rail's outer plane
    # (facing -y, 40 mm wide, welded to a gusset sheet behind it); web leg going +y from its -x edge.
    px, top = FRAME_PILLAR_X, z0 + FRAME_PILLAR_H
    leg_y = -y - 2 * SHEET_M - 0.0015
    for side in (-0.5, 0.5):
        shells.append(wall((px - 0.02, leg_y), (px + 0.02, leg_y), z0 + FLANGE_H_M + 0.005, top, SHEET_M,
                           side * SHEET_M))
    shells.append(wall((px - 0.02, leg_y + 0.002), (px - 0.02, -y + w), z0 + FLANGE_H_M + 0.005, top, 2 * SHEET_M,
                       -SHEET_M))
    seams: list[Seam] = []
    front = [Spot(f"f{n}", _vec((xf, yy, z0 + 0.5 * FLANGE_H_M)), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
             for n, yy in enumerate((-0.33, -0.11, 0.11, 0.33), start=1)]
    left = [Spot(f"l{n}", _vec((xx, -y, z0 + 0.5 * FLANGE_H_M)), (0.0, -1.0, 0.0), (1.0, 0.0, 0.0))
            for n, xx in enumerate((1.40, 1.48, 1.72, 1.80), start=1)]
    right = [Spot(f"r{n}", _vec((xx, y, z0 + 0.5 * FLANGE_H_M)), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))
             for n, xx in enumerate((1.40, 1.53, 1.67, 1.80), start=1)]
    pillar = [Spot(f"p{n}", _vec((px, leg_y, z0 + h)), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0))
              for n, h in enumerate((0.12, 0.22, 0.32), start=1)]
    seams = [Seam("front_rail", False, tuple(front)), Seam("left_rail", False, tuple(left)),
             Seam("right_rail", False, tuple(right)), Seam("pillar", True, tuple(pillar))]
    return Part("frame.stl", tuple(shells), tuple(seams))


# ----------------------------------------------------------------------------------------------
# Tray (cells/ur10_tray.yaml)
# ----------------------------------------------------------------------------------------------

TRAY_X = (0.55, 0.95)         # outer wall faces
TRAY_Y = 0.25                 # side walls at +-TRAY_Y
TRAY_Z = (-0.10, 0.02)        # bottom, rim height
TRAY_RIM_W = 0.025


def tray() -> Part:
    x0, x1 = TRAY_X
    y = TRAY_Y
    zb, zr = TRAY_Z
    t = 0.001
    r = TRAY_RIM_W
    shells = [
        slab([(x0, -y), (x1, -y), (x1, y), (x0, y)], zb, zb + t),            # bottom
        slab([(x0, -y), (x0 + t, -y), (x0 + t, y), (x0, y)], zb, zr),        # front wall
        slab([(x1 - t, -y), (x1, -y), (x1, y), (x1 - t, y)], zb, zr),        # rear wall
        slab([(x0, -y), (x1, -y), (x1, -y + t), (x0, -y + t)], zb, zr),      # left wall
        slab([(x0, y - t), (x1, y - t), (x1, y), (x0, y)], zb, zr),          # right wall
        # Rim flange bent outwards and the stiffening strip welded on top of it, as one 2 mm stack.
        slab([(x0 - r, -y - r), (x0, -y - r), (x0, y + r), (x0 - r, y + r)], zr - t, zr + t),
        slab([(x1, -y - r), (x1 + r, -y - r), (x1 + r, y + r), (x1, y + r)], zr - t, zr + t),
        slab([(x0, -y - r), (x1, -y - r), (x1, -y), (x0, -y)], zr - t, zr + t),
        slab([(x0, y), (x1, y), (x1, y + r), (x0, y + r)], zr - t, zr + t),
    ]
    mid = 0.5 * r
    # Directions chosen so that gamma = 0 puts the gun's C back outwards, round the rim's outer edge
    # (TCP y = -normal x direction).
    front = [Spot(f"f{n}", _vec((x0 - mid, yy, zr)), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0))
             for n, yy in enumerate((-0.18, -0.06, 0.06, 0.18), start=1)]
    left = [Spot(f"l{n}", _vec((xx, -y - mid, zr)), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
            for n, xx in enumerate((0.62, 0.75, 0.88), start=1)]
    right = [Spot(f"r{n}", _vec((xx, y + mid, zr)), (0.0, 0.0, 1.0), (-1.0, 0.0, 0.0))
             for n, xx in enumerate((0.62, 0.75, 0.88), start=1)]
    seams = (Seam("rim_front", False, tuple(front)), Seam("rim_left", False, tuple(left)),
             Seam("rim_right", False, tuple(right)))
    return Part("tray.stl", tuple(shells), seams)


PARTS = (cabin_rear_panel, frame, tray)


# ----------------------------------------------------------------------------------------------
# Output
# ----------------------------------------------------------------------------------------------


def stl_bytes(shells: Sequence[trimesh.Trimesh], source: str = "cells/parts/make_parts.py") -> bytes:
    """Binary STL of separate shells with a fixed header (no timestamps): reruns are byte-identical."""
    tris = np.vstack([np.asarray(m.vertices, dtype=np.float64)[np.asarray(m.faces)] for m in shells])
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, norm, out=np.zeros_like(n), where=norm > 0)
    rec = np.zeros(len(tris), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"] = n
    rec["v"] = tris
    header = f"robomax_py {source} binary STL, metres".encode().ljust(80, b" ")
    return header + struct.pack("<I", len(tris)) + rec.tobytes()


def cell_yaml(part: Part) -> str:
    """The clamp objects and seams of a part, as written into its cell file (metres, degrees)."""

    def v(x: Sequence[float]) -> str:
        return "[" + ", ".join(f"{c:g}" for c in x) + "]"

    lines = [f"# {part.file}"]
    for c in part.clamps:
        lines.append(f"  - {{name: {c.name}, box: {v(c.extents)}, pose: {{xyz: {v(c.xyz)}, rpy: [0, 0, {c.yaw_deg:g}]}}}}")
    for seam in part.seams:
        lines.append(f"  - name: {seam.name}\n    ordered: {str(seam.ordered).lower()}\n    spots:")
        for s in seam.spots:
            lines.append(f"      - {{name: {s.name}, xyz: {v(s.xyz)}, normal: {v(s.normal)}, "
                         f"direction: {v(s.direction)}}}")
    return "\n".join(lines)


def generate(out: Path) -> list[Path]:
    """Write every part's STL into ``out``; returns the files written, in a fixed order."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for make in PARTS:
        part = make()
        path = out / part.file
        path.write_bytes(stl_bytes(part.shells))
        written.append(path)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent,
                        help="output folder (default: the cells/parts/ folder holding this script)")
    parser.add_argument("--yaml", action="store_true", help="print the clamps and seams of every cell")
    args = parser.parse_args(argv)
    for path in generate(args.out):
        print(path)
    if args.yaml:
        for make in PARTS:
            print(cell_yaml(make()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
