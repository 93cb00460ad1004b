"""The `dynamic` section of a cell file (docs/cell-files.md; docs/cell-extensions.md, "Moving
objects"): objects present only in time windows, rigid objects carried along timed poses, and
other robots replaying a trajectory file. `io.cell_moving` turns them into the cell's moving
obstacles.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field, field_validator, model_validator

from robomax_py.io.cell_file_values import (
    _SHAPE_KEYS,
    ObjectFile,
    Place,
    PoseFile,
    Positive,
    Reference,
    Vec3,
    Window,
    WindowTime,
    _check_one_shape,
    _Strict,
    _windows_in_order,
)
from robomax_py.io.mesh_keys import MESH_ONLY_KEYS


class PathPoseFile(_Strict):
    """One timed pose of a moving object (`dynamic[i].path`), in the world frame."""

    t: WindowTime                             # s from program start
    xyz: Place                                # m
    rpy: Vec3 = [0.0, 0.0, 0.0]               # deg


class OtherRobotFile(_Strict):
    """Another robot in the cell (`dynamic[i].robot`): which one, where it stands, its tool."""

    model: Reference                          # folder name in robots/, or a path to a robot.yaml
    base: PoseFile = PoseFile()
    tool: Reference | None = None             # folder name in robots/tools/, or a path to a tool.yaml


# m: how far a moving object may move within the time one of its sampled poses stands for (world.moving)
Sweep = Annotated[float, Field(gt=0, le=0.2, allow_inf_nan=False)]


class DynamicObjectFile(ObjectFile):
    present: Annotated[list[Window], Field(min_length=1)] | None = None
    # Extensions (docs/cell-extensions.md, "Moving objects"): a rigid object carried along timed
    # poses, or another robot replaying a trajectory file.
    path: Annotated[list[PathPoseFile], Field(min_length=2, max_length=10_000)] | None = None
    repeat: Positive | None = None            # s between passes of the path (a conveyor's next part)
    count: Annotated[int, Field(ge=1, le=10_000)] | None = None   # passes; default: the tending cycles, else 1
    robot: OtherRobotFile | None = None
    trajectory: Reference | None = None       # a robomax.trajectory/1 file, relative to this file
    sweep: Sweep | None = None                # m; default 0.02

    @model_validator(mode="after")
    def _one_shape(self) -> DynamicObjectFile:
        if self.robot is None:
            _check_one_shape(self)
            if self.trajectory is not None:
                raise ValueError("trajectory: only with robot (another robot replaying it)")
        else:
            given = [k for k in (*_SHAPE_KEYS, *MESH_ONLY_KEYS, "path", "repeat", "count") if getattr(self, k) is not None]
            if given or self.pose != PoseFile() or self.frame is not None or self.workpiece:
                raise ValueError(f"a robot has no {', '.join(given) or 'pose, frame or workpiece'}: its links are its "
                                 "shape, robot.base its place, the trajectory its motion")
            if self.trajectory is None:
                raise ValueError("trajectory: required with robot (a robomax.trajectory/1 file)")
        if self.path is not None and (self.pose != PoseFile() or self.frame is not None):
            raise ValueError("pose, frame: not with path (the path's poses place it, in the world frame)")
        if self.path is None and self.robot is None:
            if self.present is None:
                raise ValueError("present: required (the windows in which the object is there), unless it moves "
                                 "(path or robot)")
            extra = [k for k in ("repeat", "count", "sweep") if getattr(self, k) is not None]
            if extra:
                raise ValueError(f"{', '.join(extra)}: only for a moving object (path)")
        if self.count is not None and self.repeat is None:
            raise ValueError("count: only with repeat (the number of passes)")
        if self.repeat is not None and self.present is not None:
            raise ValueError("present: not with repeat (each pass is there from its first to its last pose)")
        return self

    @field_validator("path")
    @classmethod
    def _times_increase(cls, poses: list[PathPoseFile] | None) -> list[PathPoseFile] | None:
        for i in range(1, len(poses or ())):
            assert poses is not None
            if not poses[i].t > poses[i - 1].t:
                raise ValueError(f"[{i}].t = {poses[i].t:g} s: times must increase strictly "
                                 f"(after {poses[i - 1].t:g} s)")
        return poses

    @field_validator("signal")
    @classmethod
    def _no_signal(cls, v: str | None) -> str | None:
        if v is not None:
            raise ValueError("a dynamic object has no clamp signal (the program waits for <name>_clear instead)")
        return v

    @field_validator("present")
    @classmethod
    def _present_in_order(cls, windows: list[list[float]] | None) -> list[list[float]] | None:
        return _windows_in_order(windows)
