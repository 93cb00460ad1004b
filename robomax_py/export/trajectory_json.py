"""SPEC §5 trajectory file: dense joint samples, spots with arrive/leave times, angles and indicators.

Numbers are written with fixed decimals (t: 1 µs, q: 1e-9 rad) so that the same plan gives the same
bytes; angles in the file are degrees, as in every file people read.
"""

from __future__ import annotations

import json
import math

from robomax_py.plan import PlanResult

FORMAT = "robomax.trajectory/1"


def render(result: PlanResult) -> str:
    traj = result.trajectory
    assert traj is not None  # checked by export.render
    t0 = float(traj.t[0])
    lines = [
        "{",
        f'  "format": {json.dumps(FORMAT)},',
        f'  "cell": {json.dumps(result.cell)},',
        f'  "robot": {json.dumps(result.robot)},',
        f'  "joints": {json.dumps(list(result.joint_names))},',
        f'  "cycle_time": {traj.duration:.6f},',
        '  "t": [' + ", ".join(f"{t - t0:.6f}" for t in traj.t) + "],",
        '  "q": [',
        ",\n".join("    [" + ", ".join(f"{v:.9f}" for v in row) + "]" for row in traj.q),
        "  ],",
        '  "spots": [',
        ",\n".join(
            "    {"
            + f'"seam": {json.dumps(s.seam)}, "name": {json.dumps(s.name)}, '
            + f'"t_arrive": {s.t_arrive - t0:.6f}, "t_leave": {s.t_leave - t0:.6f}, '
            + f'"alpha": {_deg(s.angles[0])}, "beta": {_deg(s.angles[1])}, "gamma": {_deg(s.angles[2])}, '
            + f'"config": {json.dumps(s.config)}'
            + "}"
            for s in result.spots
        ),
        "  ]",
        "}",
        "",
    ]
    return "\n".join(lines)


def _deg(rad: float) -> str:
    value = math.degrees(float(rad))
    return f"{0.0 if abs(value) < 5e-7 else value:.6f}"
