"""A cell's `robot` section beyond its model: the home pose checked against the URDF, and the
controller's tool and user frames, registers, inputs and outputs."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from robomax_py.errors import CellFileError
from robomax_py.io.cell_file import CellFile, InputFile, OutputFile, RobotControllerFile
from robomax_py.io.cell_objects import _pose
from robomax_py.spec import (
    CellSpec,
    ControllerFrame,
    ControllerInput,
    ControllerOutput,
    ControllerSetup,
    RobotSpec,
    UserFrame,
    frozen_array,
)


def _controller(ctrl: RobotControllerFile, cell: CellSpec, path: Path) -> ControllerSetup:
    """`robot.controller`: the tool and user frame programs select, registers, inputs, weld style."""
    key = "robot.controller"
    tool = None
    if ctrl.tool is not None:
        tool = ControllerFrame(ctrl.tool.number or 1, ctrl.tool.name or f"{cell.tool.name}_tcp", ctrl.tool.name is not None)
    frame = None
    if ctrl.frame is not None:
        f = ctrl.frame
        if f.object is not None:
            obj = next((o for o in cell.objects if o.name == f.object), None)
            if obj is None:
                known = ", ".join(o.name for o in cell.objects) or "none"
                raise CellFileError(path, f"{key}.frame.object", f"no object '{f.object}' in the cell (objects: {known})")
            T = np.asarray(obj.T_world_object)
        else:
            assert f.pose is not None  # guaranteed by UserFrameFile._one_place
            T = _pose(f.pose)
        name = f.name or (f.object if f.object and re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,31}", f.object) else "user_frame")
        frame = UserFrame(ControllerFrame(f.number or 1, name, f.name is not None), frozen_array(T))
    signals = cell.signals
    inputs: list[ControllerInput] = []
    for signal, given in ctrl.inputs.items():
        if signal not in signals:
            raise CellFileError(path, f"{key}.inputs.{signal}", f"the cell has no signal '{signal}' (its signals: "
                                f"{', '.join(signals) or 'none'}; clamps name theirs, dynamic objects wait for "
                                "<name>_clear, machine doors for <machine>_open)")
        inputs.append(_numbered(ControllerInput, signal, given, inputs, path, f"{key}.inputs.{signal}", "input"))
    return ControllerSetup(tool=tool, frame=frame, position_registers=tuple(ctrl.registers.position),
                           numeric_registers=tuple(ctrl.registers.numeric), inputs=tuple(inputs), weld=ctrl.weld,
                           outputs=_outputs(ctrl, path))


def _outputs(ctrl: RobotControllerFile, path: Path) -> tuple[ControllerOutput, ...]:
    """`robot.controller.outputs`: the signals the robot sets for other robots of a station. Any
    name is allowed (another robot's input of the same name is what the signal drives); numbers
    must be unique, as inputs' are."""
    outputs: list[ControllerOutput] = []
    for signal, given in ctrl.outputs.items():
        outputs.append(_numbered(ControllerOutput, signal, given, outputs, path, f"robot.controller.outputs.{signal}",
                                 "output"))
    return tuple(outputs)


_Numbered = TypeVar("_Numbered", ControllerInput, ControllerOutput)


def _numbered(kind: type[_Numbered], signal: str, given: int | InputFile | OutputFile, taken: list[_Numbered],
              path: Path, key: str, word: str) -> _Numbered:
    """One input or output as the file gives it (a number, or a number and a RAPID name), its number
    not already one of `taken`'s."""
    entry = kind(signal, given, None) if isinstance(given, int) else kind(signal, given.number, given.name)
    twin = next((x for x in taken if x.number == entry.number), None)
    if twin is not None:
        raise CellFileError(path, key, f"{word} {entry.number} is also {twin.signal}'s")
    return entry


def _home(parsed: CellFile, robot: RobotSpec, path: Path) -> np.ndarray:
    """`robot.home` in SI, checked against the URDF: deg -> rad, prismatic joints stay in metres."""
    return _joint_values(parsed.robot.home, "robot.home", robot, path)


def _start(parsed: CellFile, robot: RobotSpec, path: Path) -> np.ndarray | None:
    """`robot.start` (where the program starts, when not at home) in SI, checked as home is."""
    given = parsed.robot.start
    return None if given is None else _joint_values(given, "robot.start", robot, path)


def _joint_limits(parsed: CellFile, robot: RobotSpec, path: Path) -> np.ndarray | None:
    """`robot.joint_limits` in SI, (n, 2) [lower, upper] per joint (the URDF's where null), each
    within the URDF's; None when not given."""
    from robomax_py.robot import kinematic_model

    given = parsed.robot.joint_limits
    if given is None:
        return None
    model = kinematic_model(robot)
    if len(given) != model.nq:
        raise CellFileError(path, "robot.joint_limits", f"expected {model.nq} ranges for {robot.name}, one per joint "
                            f"(null for a joint the URDF's range holds), got {len(given)}")
    lower, upper = np.asarray(model.lowerPositionLimit, dtype=float), np.asarray(model.upperPositionLimit, dtype=float)
    out = np.stack([lower, upper], axis=1)
    for i, pair in enumerate(given):
        if pair is None:
            continue
        name, unit, scale = _joint_unit(model, i)
        lo, hi = pair
        if lo >= hi:
            raise CellFileError(path, f"robot.joint_limits[{i}]", f"[{lo:g}, {hi:g}] {unit}: expected [min, max] with "
                                "min below max")
        if lo / scale < lower[i] - _LIMIT_TOL or hi / scale > upper[i] + _LIMIT_TOL:
            raise CellFileError(path, f"robot.joint_limits[{i}]",
                                f"[{lo:g}, {hi:g}] {unit} reaches beyond {name}'s limits in the URDF, "
                                f"[{lower[i] * scale:.3f}, {upper[i] * scale:.3f}] {unit}: software limits narrow a "
                                "joint's range, never widen it")
        out[i] = (lo / scale, hi / scale)
    return out


def within_joint_limits(q: np.ndarray | None, limits: np.ndarray | None, key: str, robot: RobotSpec,
                        path: Path) -> None:
    """A configuration the cell file gives (`key`: robot.home, robot.start) within `robot.joint_limits`."""
    from robomax_py.robot import kinematic_model

    if q is None or limits is None:
        return
    i = _first_outside(q, limits[:, 0], limits[:, 1])
    if i is not None:
        name, unit, scale = _joint_unit(kinematic_model(robot), i)
        raise CellFileError(path, f"{key}[{i}]", f"{name} = {q[i] * scale:.3f} {unit} is outside "
                            f"robot.joint_limits[{i}], [{limits[i, 0] * scale:.3f}, {limits[i, 1] * scale:.3f}] {unit}")


def _joint_values(values: list[float], key: str, robot: RobotSpec, path: Path) -> np.ndarray:
    """A configuration as a cell file gives it (deg, m for a prismatic joint) in SI, one value per
    joint of the URDF, each within its limits; CellFileError naming `key` otherwise."""
    from robomax_py.robot import kinematic_model, prismatic_mask

    model = kinematic_model(robot)
    given = np.asarray(values, dtype=float)
    if len(given) != model.nq:
        raise CellFileError(path, key, f"expected {model.nq} joint values for {robot.name}, got {len(given)}")
    q = np.where(prismatic_mask(model), given, np.radians(given))
    lower, upper = np.asarray(model.lowerPositionLimit), np.asarray(model.upperPositionLimit)
    i = _first_outside(q, lower, upper)
    if i is not None:
        name, unit, scale = _joint_unit(model, i)
        raise CellFileError(path, f"{key}[{i}]", f"{name} = {given[i]:.3f} {unit} is outside its limits "
                            f"[{lower[i] * scale:.3f}, {upper[i] * scale:.3f}] {unit}")
    return q


# How far a configuration or a range may stand outside a joint's limits and still count as within
# them (rounding of the degrees a file states), rad or m.
_LIMIT_TOL = 1e-9


def _first_outside(q: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> int | None:
    """The first joint whose value in q lies outside [lower, upper] (within `_LIMIT_TOL`), None for none."""
    outside = np.flatnonzero((q < lower - _LIMIT_TOL) | (q > upper + _LIMIT_TOL))
    return int(outside[0]) if outside.size else None


def _joint_unit(model: Any, i: int) -> tuple[str, str, float]:
    """Joint i's name and the unit a cell file states it in, with the factor from SI to that unit:
    m for a prismatic joint, deg for a revolute one."""
    from robomax_py.robot import active_joints, prismatic_mask

    name = str(model.names[active_joints(model)[i]])
    return (name, "m", 1.0) if prismatic_mask(model)[i] else (name, "deg", 180 / math.pi)
