"""Moving dynamic objects of a cell file (docs/cell-extensions.md, "Moving objects") as specs: a
rigid object carried along timed poses (`dynamic[i].path`), or another robot replaying a
trajectory file (`dynamic[i].robot` + `trajectory`). The trajectory file is read as data with the
project's size-checked reader and checked here (format, numbers, times); its joints are compared
with the robot's model when the scene is built (`world.moving`), where the model is loaded.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np

from robomax_py.errors import CellFileError
from robomax_py.io.cell_file_dynamic import DynamicObjectFile
from robomax_py.io.cell_file_values import PoseFile
from robomax_py.io.cell_objects import _object, _pose
from robomax_py.io.robot import load_robot_spec, load_tool_spec
from robomax_py.io.robot_paths import resolve_robot_file, resolve_tool_file
from robomax_py.safe_files import LIMITS, checked_file, named_by, read_text
from robomax_py.spec import ObjectSpec, PathMotion, RobotMotion, Sphere, frozen_array

TRAJECTORY_FORMAT = "robomax.trajectory/1"      # SPEC §5
DEFAULT_SWEEP_M = 0.02          # a part on a conveyor
DEFAULT_ROBOT_SWEEP_M = 0.05    # another robot: its distal links move fast, and every span is an obstacle


def moving_object(obj: DynamicObjectFile, path: Path, key: str, triangles: list[int], cycles: int) -> ObjectSpec:
    """The spec of a dynamic entry with `path` or `robot`; `cycles`: the default number of passes
    of a repeated path (the tending cycles, else 1)."""
    if obj.robot is not None:
        return _robot_object(obj, path, key, obj.sweep if obj.sweep is not None else DEFAULT_ROBOT_SWEEP_M)
    sweep = obj.sweep if obj.sweep is not None else DEFAULT_SWEEP_M
    assert obj.path is not None
    base = _object(obj, path, key, triangles)
    t = np.array([p.t for p in obj.path], dtype=float)
    poses = np.stack([_pose(PoseFile(xyz=p.xyz, rpy=p.rpy)) for p in obj.path])
    count = (obj.count or cycles) if obj.repeat is not None else 1
    motion = PathMotion(frozen_array(t), frozen_array(poses), obj.repeat, count, sweep)
    if obj.present is not None:
        present = tuple((float(a), float(b)) for a, b in obj.present)
    else:
        period = obj.repeat or 0.0
        present = _merged([(t[0] + n * period, t[-1] + n * period) for n in range(count)])
    if present[-1][1] > 86_400.0:
        raise CellFileError(path, f"{key}.count", f"the last pass ends at {present[-1][1]:g} s, beyond a day "
                            "(86400 s) of program time")
    return dataclasses.replace(base, T_world_object=frozen_array(poses[0]), present=present, motion=motion)


def _robot_object(obj: DynamicObjectFile, path: Path, key: str, sweep: float) -> ObjectSpec:
    other = obj.robot
    assert other is not None and obj.trajectory is not None
    robot_file = checked_file(resolve_robot_file(other.model, path), LIMITS.description,
                              named_by(CellFileError, path, f"{key}.robot.model"), f"unknown robot '{other.model}':")
    robot = load_robot_spec(robot_file)
    tool = None
    if other.tool is not None:
        tool_file = checked_file(resolve_tool_file(other.tool, path), LIMITS.description,
                                 named_by(CellFileError, path, f"{key}.robot.tool"), f"unknown tool '{other.tool}':")
        tool = load_tool_spec(tool_file)
    file = path.parent / obj.trajectory
    joints, t, q = read_trajectory(file, path, f"{key}.trajectory")
    # Checked at load, so `robomax check` refuses it too (the scene checks it again with the model).
    from robomax_py.robot.kinematics import active_joints, kinematic_model

    model = kinematic_model(robot)
    names = tuple(model.names[j] for j in active_joints(model))
    if joints != names:
        raise CellFileError(path, f"{key}.trajectory", f"{file.name}: joints {list(joints)} are not those of "
                            f"{robot.name} {list(names)}")
    lower, upper = np.asarray(model.lowerPositionLimit), np.asarray(model.upperPositionLimit)
    if not np.all((q >= lower - 1e-6) & (q <= upper + 1e-6)):
        raise CellFileError(path, f"{key}.trajectory", f"{file.name}: joint values outside {robot.name}'s limits")
    motion = RobotMotion(robot, frozen_array(_pose(other.base)), tool, joints, frozen_array(t), frozen_array(q),
                         file, key, sweep)
    # A robot is present throughout (held at its first and last samples), unless `present` says when.
    present = tuple((float(a), float(b)) for a, b in obj.present) if obj.present is not None else ((0.0, math.inf),)
    return ObjectSpec(name=obj.name, shape=Sphere(radius=1e-3), T_world_object=frozen_array(_pose(other.base)),
                      present=present, motion=motion)


def read_trajectory(file: Path, cell: Path, key: str) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
    """(joints, t (k,) s, q (k, n) rad) of a robomax trajectory file named by the cell at `key`;
    CellFileError naming the cell, the key and what is wrong."""
    error = named_by(CellFileError, cell, key)
    text = read_text(file, LIMITS.program, error, f"trajectory file {file.name}")

    def bad(problem: str) -> CellFileError:
        return CellFileError(cell, key, f"{file.name}: {problem}")

    try:
        data = json.loads(text)
    except (RecursionError, ValueError) as exc:
        raise bad(f"not a trajectory file (JSON): {str(exc)[:80]}") from None
    if not isinstance(data, dict) or data.get("format") != TRAJECTORY_FORMAT:
        raise bad(f"expected format '{TRAJECTORY_FORMAT}'")
    joints = data.get("joints")
    if not isinstance(joints, list) or not joints or not all(isinstance(j, str) for j in joints):
        raise bad("joints: expected a list of joint names")
    try:
        t = np.asarray(data.get("t"), dtype=float)
        q = np.asarray(data.get("q"), dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise bad("t, q: expected arrays of numbers") from None
    if t.ndim != 1 or len(t) < 2 or q.shape != (len(t), len(joints)):
        raise bad(f"t, q: expected as many rows of {len(joints)} joint values as times (at least 2)")
    if not (np.isfinite(t).all() and np.isfinite(q).all()):
        raise bad("t, q: every number must be finite")
    if not np.all(np.diff(t) > 0):
        raise bad("t: times must increase strictly")
    return tuple(joints), t, q


def _merged(windows: list[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    out: list[list[float]] = []
    for a, b in sorted(windows):
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([float(a), float(b)])
    return tuple((a, b) for a, b in out)
