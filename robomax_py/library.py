"""The shipped robot and tool library, for `robomax robots`."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from robomax_py.robot import kinematic_model
from robomax_py.robot_io import load_robot_spec, load_tool_spec, package_robots_dir
from robomax_py.spec import RobotSpec

REACH_SAMPLES = 20000


@dataclass(frozen=True, slots=True)
class RobotEntry:
    name: str
    axes: int
    reach_m: float            # largest flange distance from the axis-1 line, over the joint ranges
    payload_kg: float | None
    ik_solver: str
    description: str
    source: Path


@dataclass(frozen=True, slots=True)
class ToolEntry:
    name: str
    tcp_xyz_m: tuple[float, float, float]
    tcp_distance_m: float     # TCP distance from the flange centre
    source: Path


def list_robots(root: Path | None = None) -> list[RobotEntry]:
    """Every robots/<name>/robot.yaml, sorted by name; a broken one raises its RobotModelError."""
    root = root or package_robots_dir()
    entries = []
    for path in sorted(root.glob("*/robot.yaml")):
        spec = load_robot_spec(path)
        model = kinematic_model(spec)
        entries.append(RobotEntry(
            name=spec.name, axes=int(model.nq), reach_m=flange_reach(spec, model),
            payload_kg=spec.payload_kg, ik_solver=spec.ik_solver, description=spec.description, source=path,
        ))
    return entries


def list_tools(root: Path | None = None) -> list[ToolEntry]:
    root = root or package_robots_dir()
    entries = []
    for path in sorted((root / "tools").glob("*/tool.yaml")):
        tool = load_tool_spec(path)
        xyz = tool.T_flange_tcp[:3, 3]
        entries.append(ToolEntry(tool.name, (float(xyz[0]), float(xyz[1]), float(xyz[2])),
                                 float(np.linalg.norm(xyz)), path))
    return entries


def flange_reach(spec: RobotSpec, model: pin.Model, seed: int = 0) -> float:
    """Largest horizontal flange distance from the base z axis over random joint values (m).

    Sampling underestimates the true maximum slightly; the extended arm is added explicitly by
    also trying each sample with the wrist straightened (joint 5 at its value nearest zero).
    """
    rng = np.random.default_rng(seed)
    lower, upper = np.asarray(model.lowerPositionLimit), np.asarray(model.upperPositionLimit)
    qs = rng.uniform(lower, upper, size=(REACH_SAMPLES, model.nq))
    if model.nq >= 5:
        straight = qs.copy()
        straight[:, 4] = np.clip(0.0, lower[4], upper[4])
        qs = np.vstack([qs, straight])
    data = model.createData()
    frame = model.getFrameId(spec.flange)
    best = 0.0
    for q in qs:
        pin.framesForwardKinematics(model, data, q)
        p = data.oMf[frame].translation
        best = max(best, float(np.hypot(p[0], p[1])))
    return best
