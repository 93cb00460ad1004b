"""The trajectory file (docs/cell-files.md), both directions: a plan -> text (`render`) and a file -> checked data
(`load_trajectory_file`): dense joint samples, spots with arrive/leave times, angles and indicators.

Numbers are written with fixed decimals (t: 1 µs, q: 1e-9 rad) so that the same plan gives the same
bytes; angles in the file are degrees, as in every file people read.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py.errors import ProgramError
from robomax_py.plan import PlanResult
from robomax_py.robot import RobotModel
from robomax_py.safe_files import LIMITS, read_text

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


def load_trajectory_file(path: Path, robot: RobotModel) -> dict[str, Any]:
    """Read and check the structure of a trajectory file (docs/cell-files.md); ProgramError names what is wrong."""
    text = read_text(path, LIMITS.program, ProgramError, "program file")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ProgramError(path, f"line {exc.lineno}, column {exc.colno}", f"not valid JSON: {exc.msg}") from None
    except RecursionError:
        raise ProgramError(path, None, "not a trajectory file: nested too deeply") from None
    except ValueError as exc:     # e.g. an integer of thousands of digits
        raise ProgramError(path, None, f"not valid JSON: {exc}") from None
    if not isinstance(data, dict):
        raise ProgramError(path, None, "expected a JSON object at the top level")
    if data.get("format") != FORMAT:
        raise ProgramError(path, "format", f"expected 'robomax.trajectory/1', got {data.get('format')!r}")
    for key in ("joints", "t", "q", "spots"):
        if key not in data:
            raise ProgramError(path, key, "required key is missing")
    if list(data["joints"]) != list(robot.joint_names):
        raise ProgramError(path, "joints", f"expected {list(robot.joint_names)} for {robot.name}, got {data['joints']}")
    try:
        t = np.asarray(data["t"], dtype=float)
        q = np.asarray(data["q"], dtype=float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ProgramError(path, "t/q", f"not numeric arrays: {exc}") from None
    if t.ndim != 1 or len(t) < 2 or q.shape != (len(t), robot.dof) or not (np.isfinite(t).all() and np.isfinite(q).all()):
        raise ProgramError(path, "q", f"expected {len(t)} rows of {robot.dof} finite joint values and as many times")
    if not np.all(np.diff(t) > 0):
        raise ProgramError(path, "t", "times must be strictly increasing")
    if not isinstance(data["spots"], list) or not all(isinstance(x, dict) for x in data["spots"]):
        raise ProgramError(path, "spots", "expected a list of spot objects")
    for k, spot in enumerate(data["spots"]):
        missing = [key for key in ("seam", "name", "t_arrive", "t_leave", "alpha", "beta", "gamma") if key not in spot]
        if missing:
            raise ProgramError(path, f"spots[{k}]", f"missing {', '.join(missing)}")
        for key in ("t_arrive", "t_leave", "alpha", "beta", "gamma"):
            v = spot[key]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ProgramError(path, f"spots[{k}].{key}", f"expected a finite number, got {str(v)[:40]!r}")
        for key in ("seam", "name", "config"):
            if key in spot and not isinstance(spot[key], str):
                raise ProgramError(path, f"spots[{k}].{key}", f"expected text, got {str(spot[key])[:40]!r}")
    data["t"], data["q"] = t, q
    return data
