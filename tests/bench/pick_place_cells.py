"""Seeded pick-and-place cells nobody laid out by hand (a generator, not a test):

    python tests/bench/pick_place_cells.py OUT_DIR [--count N] [--seed S] [--transfers T]

Each cell puts a robot (KR 16 class or UR10, drawn) at the origin and 2 to 4 stands round it at
jittered bearings and distances within its reach, each a table with two locations on its top;
sometimes a fence between two stands that the empty gripper clears but a part hanging below it
may not. One or two part kinds (a box of drawn size and mass, gripped 20 mm below its top, with
drawn TCP limits) start on drawn locations; each transfer moves a part from an occupied location
to a free one, so the transfers are a sequence a cell could run. `bench_pick_place_generated.py
OUT_DIR` plans and verifies them.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

# Per robot: model, home (deg), location radius range (m, from the base axis), table-top height
# range (m, base frame), the payload (kg) the parts' masses stay under.
ROBOTS = {
    "kr16": ("kr16", [0, -90, 90, 0, 30, 0], (0.75, 1.1), (0.45, 0.8), 16.0),
    "ur10": ("ur10", [0, -90, 90, -90, -90, 0], (0.55, 0.8), (-0.15, 0.15), 10.0),
}
# Nothing stands within this bearing (rad) of the direction the arm reaches at home (bearing 0).
HOME_CLEAR_RAD = 0.8


def _rot(bearing: float, x: float, y: float) -> tuple[float, float]:
    c, s = math.cos(bearing), math.sin(bearing)
    return c * x - s * y, s * x + c * y


def cell(rng: np.random.Generator, name: str, transfers: int) -> dict[str, Any]:
    robot = str(rng.choice(list(ROBOTS)))
    model, home, radii, tops, payload = ROBOTS[robot]
    n_stands = int(rng.integers(2, 5))
    spread = (2 * math.pi - 2 * HOME_CLEAR_RAD) / n_stands
    objects: list[dict[str, Any]] = []
    locations: list[dict[str, Any]] = []
    stands = []
    for k in range(n_stands):
        bearing = HOME_CLEAR_RAD + spread * (k + 0.5) + float(rng.uniform(-0.15, 0.15)) * spread
        radius = float(rng.uniform(*radii))
        top = float(rng.uniform(*tops))
        cx, cy = _rot(bearing, radius, 0.0)
        table = f"table_{k + 1}"
        objects.append({"name": table, "box": [0.34, 0.5, round(top + 1.0, 4)],     # from 1 m below the base
                        "pose": {"xyz": [round(cx, 4), round(cy, 4), round((top - 1.0) / 2, 4)],
                                 "rpy": [0, 0, round(math.degrees(bearing), 3)]}})
        stands.append((bearing, radius, top))
        for j, off in enumerate((-0.12, 0.12)):
            x, y = _rot(bearing, radius, off)
            locations.append({"name": f"s{k + 1}_{j + 1}", "pose": {"xyz": [round(x, 4), round(y, 4), None],
                              "rpy": [0, 0, round(math.degrees(bearing) + float(rng.choice([0, 90])), 3)]},
                              "support": [table], "_top": top})
    if rng.random() < 0.5:
        # A fence half way between two neighbouring stands, its top a little above the lower one.
        (b0, r0, t0), (b1, r1, t1) = stands[0], stands[1]
        bearing, radius = (b0 + b1) / 2, (r0 + r1) / 2
        height = min(t0, t1) + float(rng.uniform(0.05, 0.15))
        x, y = _rot(bearing, radius, 0.0)
        objects.append({"name": "fence", "box": [0.5, 0.04, round(height + 1.0, 4)],
                        "pose": {"xyz": [round(x, 4), round(y, 4), round((height - 1.0) / 2, 4)],
                                 "rpy": [0, 0, round(math.degrees(bearing) + 90, 3)]}})
    # Part kinds differ in footprint, mass and limits; they share a height, so a location (the
    # part's centre on its table) fits every kind.
    height = round(float(rng.uniform(0.05, 0.12)), 3)
    kinds = []
    for p in range(int(rng.integers(1, 3))):
        a = float(rng.uniform(2.0, 8.0))
        kinds.append({"name": f"part_{p + 1}",
                      "box": [round(float(rng.uniform(0.06, 0.15)), 3), round(float(rng.uniform(0.06, 0.15)), 3), height],
                      "mass": round(float(rng.uniform(0.5, 0.6 * payload)), 2),
                      "grasp": {"xyz": [0, 0, round(height / 2 - 0.02, 4)]},
                      "limits": {"v": round(float(rng.uniform(0.6, 1.5)), 3), "a_T": round(a, 2), "a_R": round(a, 2),
                                 "j_T": round(10 * a, 1), "j_R": round(10 * a, 1)}})
    for loc in locations:
        loc["pose"]["xyz"][2] = round(loc.pop("_top") + height / 2, 4)
    occupied: dict[str, str] = {}
    names = [loc["name"] for loc in locations]
    for i in rng.permutation(len(names))[: max(1, len(names) // 2)]:
        occupied[names[int(i)]] = str(kinds[int(rng.integers(len(kinds)))]["name"])
    moves = []
    for _ in range(transfers):
        src = sorted(occupied)[int(rng.integers(len(occupied)))]
        empty = [n for n in names if n not in occupied]
        dst = empty[int(rng.integers(len(empty)))]
        moves.append({"part": occupied[src], "from": src, "to": dst})
        occupied[dst] = occupied.pop(src)
    return {
        "robomax": 1, "name": name,
        "robot": {"model": model, "home": home},
        "tool": "gripper_2f",
        "objects": objects,
        "process": {"approach": 0.1, "clearance": 0.01},
        "planner": {"seed": 0},
        "pick_place": {"gripper": {"grip": 0.3, "release": 0.25}, "parts": kinds, "locations": locations,
                       "transfers": moves},
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("out", type=Path)
    ap.add_argument("--count", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--transfers", type=int, default=6)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    for i in range(args.count):
        name = f"pick_place_gen_{args.seed}_{i}"
        data = cell(rng, name, args.transfers)
        (args.out / f"{name}.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
        print(args.out / f"{name}.yaml")


if __name__ == "__main__":
    main()
