#!/usr/bin/env python
"""Generate the STEP part of the CAD example cell and its CSV spot list (``cells/flanged_panel.yaml``).

Run from anywhere:  ``python cells/parts/make_step_part.py [--out DIR]``  (DIR defaults to the
``cells/`` folder above this file). It writes, as product engineering would hand them over:

- ``parts/flanged_panel.step``: a sheet-metal panel in millimetres, made with build123d
  (OpenCASCADE): a 500 x 700 x 1.5 mm floor sheet with a 40 mm upturned flange along its front
  edge (x = 0, the side the robot stands on) and another along its left edge (y = +350), bent with
  a 3 mm inner radius; five holes in the sheet (four 20 mm locating holes, one 80 mm lightening
  hole). Its frame: x from the front flange's outer face toward the back, z up from the sheet's
  underside, y across.
- ``flanged_panel_spots.csv``: its 12 weld spots in the part's coordinates, millimetres, columns
  ``id,x,y,z,group`` and no normals (the cell's ``spot_lists:`` recovers them from the part's
  surface): 4 on the front flange left of the middle clamp, 4 right of it, 4 on the side flange.
  Each spot lies on the flange's outer face, halfway up the flange's straight part.

The spots are computed from the same dimensions the solid is built from, so this script is the
source of truth for both. The STEP header's timestamp is fixed, so rerunning gives the same bytes
with the same build123d/OpenCASCADE version.
"""

from __future__ import annotations

import argparse
import re
from collections.abc import Sequence
from pathlib import Path

import build123d as b3d

NAME = "flanged_panel"
SHEET = 1.5                 # mm, sheet thickness
LENGTH = 500.0              # mm along x (away from the front flange)
WIDTH = 700.0               # mm along y, centred on y = 0
FLANGE = 40.0               # mm, flange height above the sheet's top face
BEND_R = 3.0                # mm, inner bend radius of both flanges
HOLES = ((150.0, -250.0, 10.0), (150.0, 200.0, 10.0), (420.0, -250.0, 10.0), (420.0, 200.0, 10.0),
         (300.0, -20.0, 40.0))                      # x, y, radius (mm)
# Spots along each flange (mm), clear of the bends and of the clamps in the fixture (at y = 0 on
# the front flange and x = 205 on the side flange).
FRONT_A_Y = (-300.0, -240.0, -180.0, -120.0)
FRONT_B_Y = (120.0, 180.0, 240.0, 300.0)
SIDE_X = (70.0, 135.0, 275.0, 340.0)
SPOT_Z = SHEET + BEND_R + (FLANGE - BEND_R) / 2      # halfway up the flange's straight part
FIXED_STAMP = "2024-01-01T00:00:00"


def panel() -> b3d.Part:
    """The panel as one solid: the sheet, both flanges, the bends between them, the holes."""
    half = WIDTH / 2
    top = SHEET + FLANGE
    sheet = b3d.Pos(LENGTH / 2, 0, SHEET / 2) * b3d.Box(LENGTH, WIDTH, SHEET)
    front = b3d.Pos(SHEET / 2, 0, top / 2) * b3d.Box(SHEET, WIDTH, top)
    side = b3d.Pos(LENGTH / 2, half - SHEET / 2, top / 2) * b3d.Box(LENGTH, SHEET, top)
    part = sheet + front + side
    # Bends: round the inside corners (flange to sheet) by the inner radius and the outside ones by
    # the inner radius plus the sheet, so the sheet keeps its thickness around each bend.
    inner = [e for e in part.edges().filter_by(b3d.Axis.Y) if abs(e.center().X - SHEET) < 1e-6
             and abs(e.center().Z - SHEET) < 1e-6]
    inner += [e for e in part.edges().filter_by(b3d.Axis.X) if abs(e.center().Y - (half - SHEET)) < 1e-6
              and abs(e.center().Z - SHEET) < 1e-6]
    part = b3d.fillet(inner, BEND_R)
    outer = [e for e in part.edges().filter_by(b3d.Axis.Y) if abs(e.center().X) < 1e-6 and abs(e.center().Z) < 1e-6]
    outer += [e for e in part.edges().filter_by(b3d.Axis.X) if abs(e.center().Y - half) < 1e-6
              and abs(e.center().Z) < 1e-6]
    part = b3d.fillet(outer, BEND_R + SHEET)
    for x, y, r in HOLES:
        part -= b3d.Pos(x, y, SHEET / 2) * b3d.Cylinder(r, 4 * SHEET)
    return part


def spots() -> list[tuple[str, float, float, float, str]]:
    """id, x, y, z (mm, part coordinates), group: on the front flange's outer face (x = 0) and the
    side flange's outer face (y = +350)."""
    rows = [(0.0, y, SPOT_Z, "front_a") for y in FRONT_A_Y]
    rows += [(0.0, y, SPOT_Z, "front_b") for y in FRONT_B_Y]
    rows += [(x, WIDTH / 2, SPOT_Z, "side") for x in SIDE_X]
    return [(f"s{i + 1}", x, y, z, g) for i, (x, y, z, g) in enumerate(rows)]


def spots_csv() -> str:
    lines = ["id,x,y,z,group"] + [f"{i},{x:g},{y:g},{z:g},{g}" for i, x, y, z, g in spots()]
    return "\n".join(lines) + "\n"


def write_step(part: b3d.Part, path: Path) -> None:
    b3d.export_step(part, str(path), unit=b3d.Unit.MM)
    text = path.read_text(encoding="utf-8")
    # FILE_NAME carries the time of writing; a fixed one keeps the committed file reproducible.
    text = re.sub(r"(FILE_NAME\('[^']*',')[^']*(')", rf"\g<1>{FIXED_STAMP}\g<2>", text, count=1)
    text = re.sub(r"FILE_NAME\('[^']*'", f"FILE_NAME('{NAME}.step'", text, count=1)
    path.write_text(text, encoding="utf-8")


def generate(out: Path) -> list[Path]:
    """Write the STEP part and the spot list under `out` (the cells folder); the files written."""
    (out / "parts").mkdir(parents=True, exist_ok=True)
    step = out / "parts" / f"{NAME}.step"
    write_step(panel(), step)
    csv = out / f"{NAME}_spots.csv"
    csv.write_text(spots_csv(), encoding="utf-8")
    return [step, csv]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent.parent,
                        help="the cells folder (default: the one above this script)")
    args = parser.parse_args(argv)
    for path in generate(args.out):
        print(path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
