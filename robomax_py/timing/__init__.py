"""Timing of robot motion: joint paths -> sampled, limit-respecting trajectories (toppra, ruckig).

Module map:

- `estimate`    closed-form minimum times (trapezoid, double-S), vectorised for ranking
- `trajectory`  Segment / Trajectory / Phase, dwell, concatenate, resample (docs/cell-files.md, "The trajectory file" grid)
- `ptp`         jerk-limited state-to-state moves with ruckig (offline, no waypoints)
- `paths`       GeometricPath: joint paths as Bézier pieces (lines, splines), sampling, restriction
- `blend`       quintic G2 corner blends and fly-by joins between paths
- `topp`        toppra time-optimal timing of a GeometricPath (velocity, acceleration, path speed)
- `via`         `path_move`: moves through waypoints: stop, blend (toppra) or jerk-limited fly-by (ruckig)
- `lin`         Cartesian straight lines in one IK branch, timed with a TCP speed limit
- `bezier`      minimum-time quintic Bézier paths under box TCP limits (the project's own)
- `bezier_construct`, `quintic_chain`, `frenet_profile`, `frenet_measure`, `frenet_shape`
                the published method (Benko Loknar et al.): seven-step quintics, their chains, the
                two-step profile under ellipses of tangential and normal acceleration and jerk, its
                check from positions, shapes optimised for its time (docs/bezier-paper.md)
"""

from __future__ import annotations

from robomax_py.timing._common import (
    DEFAULT_DT_S,
    SPEC_MAX_DT_S,
    LinMoveError,
    TimingError,
)
from robomax_py.timing.blend import (
    BlendCorner,
    blend_corner,
    blend_join,
    blended_polyline_path,
)
from robomax_py.timing.estimate import (
    jerk_limited_time_estimate,
    polyline_time_estimate,
    ptp_time_estimate,
)
from robomax_py.timing.lin import LinPath, lin_move, lin_path, time_lin_path
from robomax_py.timing.paths import (
    GeometricPath,
    concatenate_paths,
    line_path,
    polyline_path,
    spline_path,
)
from robomax_py.timing.ptp import ptp_move
from robomax_py.timing.topp import time_path
from robomax_py.timing.trajectory import (
    SEGMENT_KINDS,
    JointStates,
    Phase,
    Segment,
    Trajectory,
    as_segment,
    concatenate,
    dwell,
    evaluate,
    resample,
)
from robomax_py.timing.via import PathMove, path_move, polyline_distance

__all__ = [
    "DEFAULT_DT_S",
    "SEGMENT_KINDS",
    "SPEC_MAX_DT_S",
    "BlendCorner",
    "GeometricPath",
    "JointStates",
    "LinMoveError",
    "LinPath",
    "PathMove",
    "Phase",
    "Segment",
    "TimingError",
    "Trajectory",
    "as_segment",
    "blend_corner",
    "blend_join",
    "blended_polyline_path",
    "concatenate",
    "concatenate_paths",
    "dwell",
    "evaluate",
    "jerk_limited_time_estimate",
    "lin_move",
    "lin_path",
    "line_path",
    "path_move",
    "polyline_distance",
    "polyline_path",
    "polyline_time_estimate",
    "ptp_move",
    "ptp_time_estimate",
    "resample",
    "spline_path",
    "time_lin_path",
    "time_path",
]
