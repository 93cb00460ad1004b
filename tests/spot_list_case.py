"""A known part and a 200-spot list on it, with the normals and seams the list was made from."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from robomax_py.transforms import invert, pose_matrix

# A 50 mm plate lying on a table, turned 30 deg about z: spots on its top (four lines), on the face
# toward the robot and on one side.
PLATE = [0.8, 0.6, 0.05]
PLATE_POSE = {"xyz": [1.6, 0.0, 0.645], "rpy": [0, 0, 30]}


def cell_data(**extra: Any) -> dict[str, Any]:
    return {
        "robomax": 1, "name": "plate",
        "robot": {"model": "kr125", "base": {"xyz": [0, 0, 0]}, "home": [0, -90, 90, 0, 0, 0]},
        "tool": "spot_gun_c",
        "objects": [{"name": "table", "box": [1.2, 1.2, 0.62], "pose": {"xyz": [1.6, 0, 0.31]}},
                    {"name": "plate", "box": PLATE, "pose": PLATE_POSE, "workpiece": True}],
        **extra,
    }


def known_spots() -> list[dict[str, Any]]:
    """200 spots in the plate's frame (m): id, xyz, outward normal, seam."""
    hx, hy, hz = (e / 2 for e in PLATE)
    spots: list[dict[str, Any]] = []
    for k, y in enumerate(np.linspace(-0.2, 0.2, 4)):
        for x in np.linspace(-0.35, 0.35, 30):
            spots.append({"xyz": [x, y, hz], "normal": [0, 0, 1], "seam": f"top{k + 1}"})
    for y in np.linspace(-0.28, 0.28, 40):
        spots.append({"xyz": [-hx, y, 0.0], "normal": [-1, 0, 0], "seam": "front"})
    for x in np.linspace(-0.35, 0.35, 40):
        spots.append({"xyz": [x, hy, 0.0], "normal": [0, 1, 0], "seam": "side"})
    for i, s in enumerate(spots):
        s["id"] = f"P{i + 1:03d}"
    return spots


def world_normal(n: list[float]) -> np.ndarray:
    R = pose_matrix(PLATE_POSE["xyz"], [math.radians(a) for a in PLATE_POSE["rpy"]])[:3, :3]
    return np.asarray(R @ np.asarray(n, dtype=float))


def write_csv(path: Path, spots: list[dict[str, Any]], *, normals: bool = False, groups: bool = False,
              mm: bool = False, delimiter: str = ",") -> Path:
    scale = 1000.0 if mm else 1.0
    head = ["Spot_ID", "X", "Y", "Z"] + (["I", "J", "K"] if normals else []) + (["Group"] if groups else [])
    lines = [delimiter.join(head)]
    for s in spots:
        cells = [s["id"], *(f"{c * scale:.6f}" for c in s["xyz"])]
        if normals:
            cells += [f"{c:g}" for c in s["normal"]]
        if groups:
            cells.append(s["seam"])
        if delimiter == ";":
            cells = [c.replace(".", ",") for c in cells]
        lines.append(delimiter.join(cells))
    path.write_text("\n".join(lines) + "\n")
    return path


def write_cell(path: Path, data: dict[str, Any]) -> Path:
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


# A frame the list may be given in instead of the part's: a station turned about z, off the origin.
STATION: dict[str, Any] = {"name": "station", "pose": {"xyz": [1.0, 0.2, 0.3], "rpy": [0, 0, -20]}}


def station_spots() -> list[dict[str, Any]]:
    """The known spots moved from the plate's frame into the station's (same places in the world)."""
    T_plate = pose_matrix(PLATE_POSE["xyz"], [math.radians(a) for a in PLATE_POSE["rpy"]])
    T_station = pose_matrix(STATION["pose"]["xyz"], [math.radians(a) for a in STATION["pose"]["rpy"]])
    M = invert(T_station) @ T_plate
    return [{**s, "xyz": list(M[:3, :3] @ np.asarray(s["xyz"]) + M[:3, 3])} for s in known_spots()[:80]]
