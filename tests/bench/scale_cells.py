"""Seeded generator of growing spot-welding cells for the scaling benchmark (`bench_scale.py`).

One KR 125-class robot with the C-gun welds N spots on vertical flanges arranged as arcs in front of
it (rows one above the other, like the side frame of a cab or a body side). Three families:

- ``open``: no clamps; each row is split into free seams of at most `SEAM_SPOTS` spots;
- ``clamped``: a toggle clamp (jaw, arm and post, the reference cell's clamp shape) on the flange
  every `CLAMP_EVERY` spots, in a gap between two spots; rows of 60 spots (~190 deg) on one
  flange radius, 0.3 m apart, clamps of neighbouring rows staggered;
- ``interleaved``: two free seams per row whose spots alternate along it, so a good tour finishes
  one seam before the other crosses the same ground.

Positions carry a seeded jitter (±6 mm along the row, ±4 mm in height, ±3° of the normal about the
vertical), so no two sizes or seeds give the same cell and nothing is tuned by hand. Files are
written as a user would write them (metres, degrees) and loaded through the normal cell reader.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

FAMILIES = ("open", "clamped", "interleaved")
ROW_SPOTS = 30              # spots per row (an arc of ~2.2 m)
SEAM_SPOTS = 10             # spots per free seam in the open and clamped families
CLAMP_EVERY = 8             # spots between clamps in the clamped family
PITCH_M = 0.075             # spot pitch along a row (typical body-in-white pitch 30-80 mm)
CLAMP_GAP_M = 0.2           # the extra room a clamp takes on the row (reference cell: ~0.2 m)
RADII_M = (1.35, 1.55)      # rows alternate between these flange radii from the robot axis
ROW_Z_M = 0.78              # height of the lowest row
ROW_DZ_M = 0.16             # height between rows
CLAMPED_DZ_M = 0.3          # clamped family: height between rows
CLAMPED_RADIUS_M = 1.4      # clamped family: one flange radius for every row
CLAMPED_ROW_SPOTS = 60      # clamped family: spots per row (an arc of ~190 deg)


def _row_angles(n: int, clamps: bool, rng: np.random.Generator, radius: float,
                offset: int = 0) -> tuple[np.ndarray, list[float]]:
    """Angles (rad) of n spots along an arc centred on the robot's x axis, and of the clamp gaps
    (after every CLAMP_EVERY spots, counted from `offset`)."""
    arc = []
    clamp_at = []
    s = 0.0
    for k in range(n):
        if clamps and k and (k + offset) % CLAMP_EVERY == 0:
            clamp_at.append(s + CLAMP_GAP_M / 2 - PITCH_M / 2)
            s += CLAMP_GAP_M - PITCH_M
        arc.append(s + rng.uniform(-0.006, 0.006))
        s += PITCH_M
    centre = (arc[-1] + arc[0]) / 2
    return (np.array(arc) - centre) / radius, [(c - centre) / radius for c in clamp_at]


def _clamp(name: str, phi: float, radius: float, z: float) -> list[dict]:
    """A toggle clamp at angle phi on a flange row: the jaw on the flange, the arm running outwards
    behind it, the post at the arm's end (sizes of the reference cell's clamps)."""
    out = []
    yaw = math.degrees(phi) + 90.0
    for part, box, dr, dz in (("jaw", [0.05, 0.11, 0.07], -0.012, 0.065),
                              ("arm", [0.04, 0.54, 0.04], 0.30, 0.08),
                              ("post", [0.05, 0.06, 0.14], 0.54, 0.03)):
        r = radius + dr
        out.append({"name": f"{name}_{part}", "box": box,
                    "pose": {"xyz": [round(r * math.cos(phi), 6), round(r * math.sin(phi), 6), round(z + dz, 6)],
                             "rpy": [0, 0, round(yaw, 6)]}})
    return out


def scale_cell(family: str, n: int, seed: int = 0) -> dict:
    """The cell file (as a dict) of `family` with n spots; seeded, deterministic."""
    if family not in FAMILIES:
        raise ValueError(f"family must be one of {FAMILIES}, got {family!r}")
    rng = np.random.default_rng([seed, n, FAMILIES.index(family)])
    per_row = CLAMPED_ROW_SPOTS if family == "clamped" else ROW_SPOTS
    rows = [per_row] * (n // per_row) + ([n % per_row] if n % per_row else [])
    objects: list[dict] = [{"name": "floor_table", "box": [1.0, 3.4, 0.5], "pose": {"xyz": [2.3, 0, 0.25]}}]
    seams: list[dict] = []
    spot_id = 0
    for r, count in enumerate(rows):
        radius = RADII_M[r % 2]
        if family == "clamped":
            # One flange radius, rows 0.3 m apart, clamps of neighbouring rows staggered by half
            # the clamp pitch: each clamp's arm runs outwards behind its own row, none under
            # another row's spots or straight above another clamp (with rows of two radii the
            # arms ran under the outer row, and no detour was found round them).
            radius = CLAMPED_RADIUS_M
            z0 = ROW_Z_M + CLAMPED_DZ_M * r
            offset = CLAMP_EVERY // 2 if r % 2 else 0
        else:
            z0 = ROW_Z_M + ROW_DZ_M * r
            offset = 0
        phis, clamp_phis = _row_angles(count, family == "clamped", rng, radius, offset)
        for c, phi in enumerate(clamp_phis):
            objects += _clamp(f"clamp{r + 1}x{c + 1}", phi, radius, z0)
        spots = []
        for phi in phis:
            spot_id += 1
            yaw = phi + math.radians(rng.uniform(-3, 3))
            normal = [-math.cos(yaw), -math.sin(yaw), 0.0]
            direction = [-math.sin(phi), math.cos(phi), 0.0]
            z = z0 + rng.uniform(-0.004, 0.004)
            spots.append({"name": f"p{spot_id}", "xyz": [round(radius * math.cos(phi), 6),
                                                          round(radius * math.sin(phi), 6), round(z, 6)],
                          "normal": [round(v, 6) for v in normal], "direction": [round(v, 6) for v in direction]})
        if family == "interleaved":
            groups = [spots[0::2], spots[1::2]]
        else:
            groups = [spots[k:k + SEAM_SPOTS] for k in range(0, len(spots), SEAM_SPOTS)]
        for g in groups:
            if g:
                seams.append({"name": f"row{r + 1}_{len(seams) + 1}", "ordered": False,
                              "tolerance": {"alpha": 10, "beta": 10, "gamma": [-180, 180]}, "grid": 5, "spots": g})
    return {"robomax": 1, "name": f"scale_{family}_{n}", "robot": {"model": "kr125", "base": {"xyz": [0, 0, 0]},
            "home": [0, -90, 90, 0, 0, 0]}, "tool": "spot_gun_c", "objects": objects, "seams": seams,
            "process": {"weld_time": 0.5, "approach": 0.03, "clearance": 0}, "planner": {"seed": seed}}


def write_scale_cell(folder: Path, family: str, n: int, seed: int = 0) -> Path:
    """Write the cell file and return its path."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"scale_{family}_{n}_s{seed}.yaml"
    path.write_text(yaml.safe_dump(scale_cell(family, n, seed), sort_keys=False), encoding="utf-8")
    return path
