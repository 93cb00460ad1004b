"""The frames a cell's programs state their targets in (docs/cell-files.md, "Controller programs"), as the programs state them.

A controller with factory settings knows nothing of the cell: its robot base frame is the robot's
own (robot.yaml `controller.base` in the URDF root frame), never the robot's placement in the cell.
Cartesian targets are TCP poses relative to the program's user frame: by default the robot base
frame itself; when the cell names one (`robot.controller.frame`, placed in the cell's world), that
frame's pose in the robot base frame, so that recalibrating the one frame moves every target. The
tool frame is the tool's TCP in the flange frame.

Both are rounded as the programs write them, and the targets are stated relative to the *written*
user frame: the controller composes written frame and written target, and gets the planned pose
back to the targets' own rounding. The planner times and checks exactly these poses.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.program import (
    FrameDef,
    as_written_pose,
    frame_in_world,
    from_frame,
    pose_mm_zyx,
    to_frame,
)
from robomax_py.spec import CellSpec, ControllerSetup
from robomax_py.transforms import invert

__all__ = ["DEFAULT_TOOL_NUMBER", "ProgramFrames", "cell_program_frames", "program_frames"]

# The tool number programs select when the cell names none: the first tool slot of every brand
# (KUKA TOOL_DATA[1], FANUC UTOOL[1]).
DEFAULT_TOOL_NUMBER = 1


@dataclass(frozen=True, slots=True, eq=False)
class ProgramFrames:
    """The tool and user frame of a cell's programs.

    tool : FrameDef
        The TCP in the flange frame, with its controller number and name.
    base : FrameDef | None
        The user frame in the controller's robot base frame; None: the robot base frame itself.
    T_root_frame : (4, 4) float
        Where stated targets are measured from, in the URDF root frame: the controller's base
        times the user frame as written.
    """

    tool: FrameDef
    base: FrameDef | None
    T_root_frame: FloatArray

    @property
    def base_name(self) -> str:
        """The LIN statements' `base`: the user frame's name, or "" (the robot base frame)."""
        return "" if self.base is None else self.base.name

    def stated(self, T_root_tcp: FloatArray) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """A TCP pose in the URDF root frame as a LIN target states it: mm and ZYX deg."""
        return pose_mm_zyx(to_frame(self.T_root_frame, T_root_tcp))

    def written(self, T_root_tcp: FloatArray) -> FloatArray:
        """A TCP pose in the URDF root frame as the controller gets it back from the statement."""
        return from_frame(self.T_root_frame, as_written_pose(to_frame(self.T_root_frame, T_root_tcp)))


def program_frames(tool: str, T_flange_tcp: FloatArray, T_world_base: FloatArray, T_root_controller: FloatArray,
                   setup: ControllerSetup) -> ProgramFrames:
    """The frames of a robot's programs from its tool, placement, controller base and the cell's
    `robot.controller` setup."""
    xyz, zyx = pose_mm_zyx(T_flange_tcp)
    if setup.tool is not None:
        tool_frame = FrameDef(setup.tool.name, "tool", xyz, zyx, setup.tool.number)
    else:
        tool_frame = FrameDef(f"{tool}_tcp", "tool", xyz, zyx, DEFAULT_TOOL_NUMBER)
    C = np.asarray(T_root_controller, dtype=float)
    if setup.frame is None:
        return ProgramFrames(tool_frame, None, C)
    T_world_controller = frame_in_world(np.asarray(T_world_base, dtype=float), C)
    xyz, zyx = pose_mm_zyx(invert(T_world_controller) @ np.asarray(setup.frame.T_world_frame, dtype=float))
    base = FrameDef(setup.frame.frame.name, "base", xyz, zyx, setup.frame.frame.number)
    return ProgramFrames(tool_frame, base, C @ base.pose)


def cell_program_frames(cell: CellSpec) -> ProgramFrames:
    """`program_frames` of a cell's robot and tool."""
    return program_frames(cell.tool.name, cell.tool.T_flange_tcp, cell.T_world_base,
                          cell.robot.controller.T_root_base, cell.controller)
