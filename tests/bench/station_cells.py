"""Seeded multi-robot welding stations for tests/bench/bench_station.py and the shipped example
(cells/stations/side_frame.yaml): a flat side-frame-like part (a rectangular rim of sheet lying on
four support bars of a fixture, its outer edge overhanging them) with spots along the rim's outer
edge in CAD order (rail by rail), clamps with signals on the rim, and 2-6 robots on the two long
sides, arms of the shipped library (KR 125-class with the C gun, KR 16-class and UR10 with the
light gun) or imported from ROS-Industrial packages (KR 120 R2500 pro, IRB 2400), each station a
valid station file.

    python tests/bench/station_cells.py OUT_DIR [--robots 4] [--spots 120] [--seed 0] [--count 1]

The shipped example: `--robots 4 --spots 120 --arms kr125,kr125,ur10,ur10 --name side_frame`.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

# arm -> tool, distance of its base from the rim's outer edge (m), base height (m), home (deg),
# brand's interlock I/O (inputs, outputs), clamp inputs start.
ARMS: dict[str, dict[str, Any]] = {
    "kr125": {"tool": "spot_gun_c", "reach": 1.7, "z": 0.0, "home": [0, -115, 115, 0, 50, 0],
              "io": ([101, 116], [101, 116]), "clamps": 11},
    "kr16": {"tool": "spot_gun_light", "reach": 1.0, "z": 0.2, "home": [0, -110, 110, 0, 50, 0],
             "io": ([101, 116], [101, 116]), "clamps": 11},
    "ur10": {"tool": "spot_gun_light", "reach": 0.45, "z": 0.6, "home": [0, -90, 90, -90, -90, 0],
             "io": ([2, 7], [0, 7]), "clamps": 0},
    # Imported from the ROS-Industrial support packages under tests/data/rosi (`robomax import-urdf`,
    # as tests/bench/corpus_cells.py imports them, into the station's folder): a KUKA and an ABB arm.
    "kr120": {"tool": "spot_gun_c", "reach": 1.7, "z": 0.0, "home": [0, -115, 115, 0, 50, 0],
              "io": ([101, 116], [101, 116]), "clamps": 11, "imported": True},
    "irb2400": {"tool": "spot_gun_light", "reach": 0.9, "z": 0.2, "home": [0, 20, -20, 0, 50, 0],
                "io": ([101, 116], [101, 116]), "clamps": 11, "imported": True},
}
SHIPPED = ("kr125", "kr16", "ur10")     # the arms a seed draws from
PREFIX = {"front": "f", "right": "r", "rear": "b", "left": "l"}   # spot names: f1, r1, b1, l1, ...
RIM_Z = 0.75            # m, the sheet's top
RIM_W = 0.12            # m, width of the rim's sheet
SHEET = 0.003           # m
EDGE = 0.02             # m, spot inside the outer edge
PITCH = 1.6             # m of rail per robot on a side (arms this far apart keep out of each other's homes)


def station(robots: int, spots: int, seed: int, arms: list[str] | None = None, name: str | None = None
            ) -> dict[str, Any]:
    """A station file's data (as YAML reads it)."""
    rng = np.random.default_rng(seed)
    arms = arms or [str(a) for a in rng.choice(list(SHIPPED), size=robots)]
    front = math.ceil(robots / 2)
    L = PITCH * front
    W = 1.0
    objects: list[dict[str, Any]] = []
    # The rim: four sheets; the fixture: four bars under their inner halves.
    for rail, (cx, cy, sx, sy) in {"front": (0, -W / 2 + RIM_W / 2, L, RIM_W), "rear": (0, W / 2 - RIM_W / 2, L, RIM_W),
                                   "left": (-L / 2 + RIM_W / 2, 0, RIM_W, W - 2 * RIM_W),
                                   "right": (L / 2 - RIM_W / 2, 0, RIM_W, W - 2 * RIM_W)}.items():
        objects.append({"name": f"rim_{rail}", "box": [round(sx, 4), round(sy, 4), SHEET], "workpiece": True,
                        "pose": {"xyz": [round(cx, 4), round(cy, 4), RIM_Z - SHEET / 2]}})
        inset = 0.09                       # the bar under the rim's inner part, clear of the gun's jaw
        bx = (cx - math.copysign(RIM_W / 2 - inset, cx)) if sx == RIM_W else cx
        by = (cy - math.copysign(RIM_W / 2 - inset, cy)) if sy == RIM_W else cy
        objects.append({"name": f"bar_{rail}", "box": [round(sx if sy == RIM_W else 0.04, 4),
                                                       round(sy if sx == RIM_W else 0.04, 4), 0.3],
                        "pose": {"xyz": [round(bx, 4), round(by, 4), RIM_Z - SHEET - 0.15]}})
    objects.append({"name": "fixture_base", "box": [round(L - 0.3, 4), round(W - 0.3, 4), 0.45],
                    "pose": {"xyz": [0, 0, 0.225]}})
    clamps = [("clamp_left", -L / 2 + 0.1, 0.0), ("clamp_right", L / 2 - 0.1, 0.0)]
    for cname, x, y in clamps:
        objects.append({"name": cname, "box": [0.04, 0.06, 0.05], "signal": f"{cname}_closed",
                        "pose": {"xyz": [round(x, 4), y, RIM_Z + 0.025]}})
    # Spots along the outer edges, in CAD order: front, right, rear, left; shared by rail length.
    rails = [("front", L, (-L / 2, -W / 2), (1, 0), (0, -1)), ("right", W, (L / 2, -W / 2), (0, 1), (1, 0)),
             ("rear", L, (L / 2, W / 2), (-1, 0), (0, 1)), ("left", W, (-L / 2, W / 2), (0, -1), (-1, 0))]
    total = sum(r[1] for r in rails)
    counts = [max(2, round(spots * r[1] / total)) for r in rails]
    counts[0] = max(2, counts[0] + spots - sum(counts))     # at least two per rail: 8 spots at least
    seams = []
    for (rail, length, start, along, out), n in zip(rails, counts, strict=True):
        ends = 0.2
        xs = np.linspace(ends, length - ends, n)
        pts = []
        for k, s in enumerate(xs):
            x = start[0] + along[0] * s - out[0] * EDGE
            y = start[1] + along[1] * s - out[1] * EDGE
            pts.append({"name": f"{PREFIX[rail]}{k + 1}", "xyz": [round(float(x), 4), round(float(y), 4), RIM_Z - SHEET / 2],
                        "normal": [0, 0, 1], "direction": [float(along[0]), float(along[1]), 0]})
        seams.append({"name": f"rim_{rail}", "tolerance": {"alpha": 15, "beta": 15, "gamma": [-30, 30]}, "grid": 3,
                      "spots": pts})
    # Robots: front side (facing +y), then rear (facing -y), spread along x.
    out_robots = []
    for i, arm in enumerate(arms):
        side_front = i < front
        k, n_side = (i, front) if side_front else (i - front, robots - front)
        x = -L / 2 + L * (k + 0.5) / n_side
        spec = ARMS[arm]
        y = -(W / 2 + spec["reach"]) if side_front else (W / 2 + spec["reach"])
        yaw = 90 if side_front else -90
        if spec["z"] > 0:
            objects.append({"name": f"pedestal_{i + 1}", "box": [0.3, 0.3, round(spec["z"] - 0.005, 4)],
                            "pose": {"xyz": [round(x, 4), round(y, 4), round((spec["z"] - 0.005) / 2, 4)]}})
        inputs = {f"{c}_closed": spec["clamps"] + j for j, (c, _, _) in enumerate(clamps)}
        model = f"robots/{arm}/robot.yaml" if spec.get("imported") else arm   # beside the station file (`write`)
        out_robots.append({"name": f"r{i + 1}", "model": model, "tool": spec["tool"],
                           "base": {"xyz": [round(x, 4), round(y, 4), spec["z"]], "rpy": [0, 0, yaw]},
                           "home": list(spec["home"]),
                           "controller": {"inputs": inputs,
                                          "interlock_io": {"inputs": list(spec["io"][0]),
                                                           "outputs": list(spec["io"][1])}}})
    return {"robomax": 1, "name": name or f"station_{robots}r_{spots}s_{seed}", "robots": out_robots,
            "objects": objects, "seams": seams,
            "process": {"weld_time": 0.4, "approach": 0.02, "clearance": 0.005}}


def write(folder: Path, data: dict[str, Any]) -> Path:
    """The station file in `folder`, with the imported arms it names under `folder/robots`."""
    folder.mkdir(parents=True, exist_ok=True)
    if any(str(r["model"]).startswith("robots/") for r in data["robots"]):
        from tests.bench.corpus_cells import import_arms

        import_arms(folder / "robots")
    path = folder / f"{data['name']}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=140))
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", type=Path)
    ap.add_argument("--robots", type=int, default=4)
    ap.add_argument("--spots", type=int, default=120)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--count", type=int, default=1)
    ap.add_argument("--arms", default="", help="comma-separated arms (default: drawn from the seed)")
    ap.add_argument("--name", default=None, help="the station's name (default: from its size and seed)")
    args = ap.parse_args()
    for k in range(args.count):
        arms = args.arms.split(",") if args.arms else None
        print(write(args.out, station(args.robots, args.spots, args.seed + k, arms, args.name)))


if __name__ == "__main__":
    main()
