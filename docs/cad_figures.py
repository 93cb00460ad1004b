"""The figures of docs/cad.md: STEP load time and triangle count at two tolerances, and the largest
distance between the mesh and the exact surface, on two parts made here with build123d
(OpenCASCADE) in millimetres:

- block: 100 x 60 x 20 mm with a 30 mm through hole (the part of tests/io/test_cad.py);
- door: a 1200 x 800 x 2 mm panel with rounded corners (R 80), a window 700 x 300 (R 60) and ten
  holes of 4 to 20 mm radius.

Each part's exact surface is known in closed form (a signed distance of boxes with rounded corners
and cylinders), so the distance is measured against the solid itself, not against a finer mesh.

    ROBOMAX_CACHE=$(mktemp -d) python docs/cad_figures.py
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import build123d as b3d
import numpy as np
import trimesh

from robomax_py.robot.cad import load_step

TOLERANCES_MM = (0.1, 1.0)
SAMPLES = 200_000
THICKNESS = 2.0
HOLES = [(-500.0 + 100.0 * k, -300.0, 4.0 + 16.0 * k / 9) for k in range(10)]     # x, y, r (mm)


def rounded_rect_sd(xy: np.ndarray, half: tuple[float, float], r: float, centre: tuple[float, float] = (0, 0)) -> np.ndarray:
    """Signed distance (mm) in the plane to a rectangle of half sizes `half` with corner radius r."""
    q = np.abs(xy - np.asarray(centre)) - (np.asarray(half) - r)
    return np.asarray(np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0) - r)


def block_sd(p: np.ndarray) -> np.ndarray:
    q = np.abs(p) - np.array([50.0, 30.0, 10.0])
    box = np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
    return np.asarray(np.maximum(box, 15.0 - np.hypot(p[:, 0], p[:, 1])))


def door_sd(p: np.ndarray) -> np.ndarray:
    xy = p[:, :2]
    plane = rounded_rect_sd(xy, (600.0, 400.0), 80.0)
    plane = np.maximum(plane, -rounded_rect_sd(xy, (350.0, 150.0), 60.0, (0.0, 150.0)))
    for x, y, r in HOLES:
        plane = np.maximum(plane, r - np.hypot(xy[:, 0] - x, xy[:, 1] - y))
    return np.asarray(np.maximum(plane, np.abs(p[:, 2]) - THICKNESS / 2))


def make_block(path: Path) -> None:
    b3d.export_step(b3d.Box(100, 60, 20) - b3d.Cylinder(15, 20), str(path))


def make_door(path: Path) -> None:
    outer = b3d.Box(1200, 800, THICKNESS)
    outer = b3d.fillet(outer.edges().filter_by(b3d.Axis.Z), 80)
    window = b3d.Pos(0, 150, 0) * b3d.Box(700, 300, THICKNESS)
    window = b3d.fillet(window.edges().filter_by(b3d.Axis.Z), 60)
    part = outer - window
    for x, y, r in HOLES:
        part = part - b3d.Pos(x, y, 0) * b3d.Cylinder(r, THICKNESS)
    b3d.export_step(part, str(path))


def main() -> None:
    folder = Path(tempfile.mkdtemp())
    os.environ.setdefault("ROBOMAX_CACHE", str(folder / "cache"))
    print("| part | STEP file | tolerance | triangles | CPU, first read | CPU, from the cache | largest mesh-to-surface distance |")
    print("|---|---|---|---|---|---|---|")
    for name, make, sd in (("block", make_block, block_sd), ("door", make_door, door_sd)):
        step = folder / f"{name}.step"
        make(step)
        for tol in TOLERANCES_MM:
            t0 = time.process_time()
            mesh = load_step(step, tol)
            first = time.process_time() - t0
            t0 = time.process_time()
            load_step(step, tol)
            cached = time.process_time() - t0
            mm = mesh.copy()
            mm.apply_scale(1000.0)
            samples, _ = trimesh.sample.sample_surface_even(mm, SAMPLES, seed=0)
            midpoints = np.asarray(mm.vertices)[mm.edges_unique].mean(axis=1)
            worst = float(np.abs(sd(np.vstack([samples, midpoints, mm.vertices]))).max())
            print(f"| {name} | {step.stat().st_size / 1024:.0f} kB | {tol:g} mm | {len(mesh.faces):,} | "
                  f"{first * 1000:.0f} ms | {cached * 1000:.0f} ms | {worst:.3f} mm |")


if __name__ == "__main__":
    main()
