"""Seeded tending cells nobody laid out by hand (a generator, not a test):

    python tests/bench/tending_cells.py OUT_DIR [--count N] [--seed S]

Each cell puts a robot (KR 16 class or UR10, drawn) at the origin and 1 to 3 CNC enclosures round
it at jittered bearings and random distances within its reach, each a box open towards the robot with a
door in the opening and a work table inside, plus a conveyor and an outfeed table on free
bearings. The machines' schedules (start, machining share, period) and the number of cycles are
drawn too. `tests/bench/bench_tending.py --generated OUT_DIR` plans them both ways.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

# Per robot: model, home (deg), station radius range (m, from the base axis), station height (m).
ROBOTS = {
    "kr16": ("kr16", [0, -90, 90, 0, 0, 0], (1.05, 1.3), 0.75),
    "ur10": ("ur10", [0, -90, 90, -90, -90, 0], (0.7, 0.85), 0.25),
}


# Nothing stands within this bearing (rad) of the direction the arm reaches at home (bearing 0).
HOME_CLEAR_RAD = 1.0


def _rot(bearing: float, xyz: tuple[float, float, float]) -> list[float]:
    c, s = math.cos(bearing), math.sin(bearing)
    x, y, z = xyz
    return [round(c * x - s * y, 4), round(s * x + c * y, 4), round(z, 4)]


def _box(name: str, extents: tuple[float, float, float], bearing: float, centre: tuple[float, float, float]) -> dict[str, Any]:
    return {"name": name, "box": [round(e, 4) for e in extents],
            "pose": {"xyz": _rot(bearing, centre), "rpy": [0, 0, round(math.degrees(bearing), 4)]}}


def machine(name: str, bearing: float, radius: float, height: float) -> tuple[list[dict[str, Any]], dict[str, Any], dict[str, Any]]:
    """Walls and table (objects), the door, and the station of a machine whose station lies at
    `radius` on `bearing`; the enclosure's front wall 0.25 m nearer the robot."""
    front = radius - 0.25
    depth, width, opening, top = 0.7, 1.2, 0.8, height + 0.85
    objects = [
        _box(f"{name}_wall_low", (0.05, width, height), bearing, (front + 0.025, 0, height / 2)),
        _box(f"{name}_wall_high", (0.05, width, 0.3), bearing, (front + 0.025, 0, top + 0.15)),
        _box(f"{name}_wall_left", (0.05, (width - opening) / 2, top - height), bearing,
             (front + 0.025, -(opening + width) / 4, (height + top) / 2)),
        _box(f"{name}_wall_right", (0.05, (width - opening) / 2, top - height), bearing,
             (front + 0.025, (opening + width) / 4, (height + top) / 2)),
        _box(f"{name}_side_left", (depth, 0.05, top + 0.3), bearing, (front + depth / 2, -width / 2, (top + 0.3) / 2)),
        _box(f"{name}_side_right", (depth, 0.05, top + 0.3), bearing, (front + depth / 2, width / 2, (top + 0.3) / 2)),
        _box(f"{name}_back", (0.05, width, top + 0.3), bearing, (front + depth, 0, (top + 0.3) / 2)),
        _box(f"{name}_table", (0.4, 0.5, height - 0.05), bearing, (radius + 0.1, 0, (height - 0.05) / 2)),
    ]
    door = _box(f"{name}_door", (0.03, opening, top - height), bearing, (front - 0.02, 0, (height + top) / 2))
    station = {"name": f"{name}_load", "xyz": _rot(bearing, (radius, 0, height)),
               "rpy": [0, 0, round(math.degrees(bearing), 4)], "action": "release", "machine": name}
    return objects, door, station


def cell(rng: np.random.Generator, index: int) -> dict[str, Any]:
    robot = str(rng.choice(sorted(ROBOTS)))
    model, home, (r_lo, r_hi), height = ROBOTS[robot]
    n_machines = int(rng.integers(1, 4))
    # Bearings: machines and the two tables spread evenly (jittered, shuffled) over the circle
    # but the arc the arm reaches into at home (bearing 0).
    n_items = n_machines + 2
    arc = 2 * math.pi - 2 * HOME_CLEAR_RAD
    slots = HOME_CLEAR_RAD + (np.arange(n_items) + 0.5 + rng.uniform(-0.25, 0.25, n_items)) * arc / n_items
    bearings = [float((b + math.pi) % (2 * math.pi) - math.pi) for b in rng.permutation(slots)]
    objects: list[dict[str, Any]] = []
    machines, stations = [], []
    cycles = int(rng.integers(1, 4))
    for m in range(n_machines):
        name = f"cnc{m + 1}"
        objs, door, station = machine(name, bearings[m], float(rng.uniform(r_lo, r_hi)), height)
        objects += objs
        period = float(rng.uniform(10.0, 18.0))
        machines.append({"name": name, "door": door, "schedule": {
            "start": round(float(rng.uniform(0.0, period)), 3), "machining": round(float(rng.uniform(0.3, 0.7)) * period, 3),
            "period": round(period, 3)}})
        stations.append(station)
    for name, bearing, action in (("conveyor", bearings[-2], "grip"), ("outfeed", bearings[-1], "release")):
        r = float(rng.uniform(r_lo, r_hi)) - 0.1
        objects.append(_box(name, (0.4, 0.6, height - 0.05), bearing, (r, 0, (height - 0.05) / 2)))
        stations.insert(0 if action == "grip" else len(stations),
                        {"name": f"{name}_{'pick' if action == 'grip' else 'place'}",
                         "xyz": _rot(bearing, (r, 0, height)), "rpy": [0, 0, 0], "action": action})
    return {
        "robomax": 1, "name": f"tending_gen_{index:02d}",
        "robot": {"model": model, "base": {"xyz": [0, 0, 0]}, "home": home},
        "tool": "gripper_2f", "objects": objects,
        "process": {"approach": 0.1, "clearance": 0.01},
        "planner": {"seed": 0},
        "tending": {"cycles": cycles, "gripper": {"grip": 0.4, "release": 0.3}, "machines": machines,
                    "stations": stations},
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0] if __doc__ else None)
    parser.add_argument("out", type=Path)
    parser.add_argument("--count", type=int, default=8)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    for i in range(args.count):
        path = args.out / f"tending_gen_{i:02d}.yaml"
        path.write_text(f"# generated by tests/bench/tending_cells.py --seed {args.seed}\n"
                        + yaml.safe_dump(cell(rng, i), sort_keys=False, default_flow_style=None, width=120))
        print(path)


if __name__ == "__main__":
    main()
