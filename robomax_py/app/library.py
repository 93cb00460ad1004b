"""The shipped robot and tool library, for `robomax robots`."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from robomax_py.io.robot import load_robot_spec, load_tool_spec, robot_library
from robomax_py.robot import kinematic_model
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
    brand: str = "kuka"
    shadowed: tuple[Path, ...] = ()   # robot.yaml files of the same name later in the library path


@dataclass(frozen=True, slots=True)
class ToolEntry:
    name: str
    tcp_xyz_m: tuple[float, float, float]
    tcp_distance_m: float     # TCP distance from the flange centre
    source: Path
    shadowed: tuple[Path, ...] = ()


def _found(roots: tuple[Path, ...], pattern: str) -> list[tuple[Path, tuple[Path, ...]]]:
    """(first file, later files of the same folder name) per name over the library path, by name."""
    by_name: dict[str, list[Path]] = {}
    for root in roots:
        for path in sorted(root.glob(pattern)):
            by_name.setdefault(path.parent.name, []).append(path)
    return [(paths[0], tuple(paths[1:])) for _, paths in sorted(by_name.items())]


def list_robots(roots: tuple[Path, ...] | None = None) -> list[RobotEntry]:
    """Every <library>/<name>/robot.yaml over the library path (first of a name wins), sorted by
    name; a broken one raises its RobotModelError. The IK parameters are checked against the URDF."""
    from robomax_py.robot import checked_ik_params

    entries = []
    for path, shadowed in _found(roots or robot_library(), "*/robot.yaml"):
        spec = load_robot_spec(path)
        model = kinematic_model(spec)
        checked_ik_params(spec, model)
        entries.append(RobotEntry(
            name=spec.name, axes=int(model.nq), reach_m=flange_reach(spec, model),
            payload_kg=spec.payload_kg, ik_solver=spec.ik_solver + ("" if spec.ik_params is not None else " (fitted)"),
            description=spec.description, source=path, brand=spec.controller.brand, shadowed=shadowed,
        ))
    return entries


def list_tools(roots: tuple[Path, ...] | None = None) -> list[ToolEntry]:
    entries = []
    for path, shadowed in _found(roots or robot_library(), "tools/*/tool.yaml"):
        tool = load_tool_spec(path)
        xyz = tool.T_flange_tcp[:3, 3]
        entries.append(ToolEntry(tool.name, (float(xyz[0]), float(xyz[1]), float(xyz[2])),
                                 float(np.linalg.norm(xyz)), path, shadowed))
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
