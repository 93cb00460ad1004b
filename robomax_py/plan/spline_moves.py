"""What a junction flown as one smooth TCP path (`planner.cartesian_moves: spline`) hands the
program writer and the report: the short lines' targets, fly-by distances and speeds, and which
way of moving each junction took with the time of each."""

from __future__ import annotations

from dataclasses import dataclass

from robomax_py._typing import FloatArray


@dataclass(frozen=True, slots=True, eq=False)
class SplineMoves:
    """The spline block a junction's Bézier path is written as, in program order: the retract's
    end (the approach point of the spot left: a straight segment), the spline points sampled
    from the Bézier path, the next approach point, and the next spot (the straight approach,
    where the robot stops).

    targets : (k, 4, 4) TCP poses, robot base frame (URDF root), m, as the program states them.
    speeds : (k,) TCP speed of the stretch ending at each target, m/s, as written.
    q : (k, n) the configuration at each target as timed, rad.
    configs : the configuration data at each target (`robot.solve.config_text`).
    deviation_m : largest distance of the spline (through the written points, as the controller
        interpolates it) from the Bézier path they were sampled from, m.
    lines_time : s, the block as short lines flown by (the dialects without spline motion,
        `export.spline_lines`), timed as they run it; None where that could not be timed.
    """

    targets: FloatArray
    speeds: FloatArray
    q: FloatArray
    configs: tuple[str, ...]
    deviation_m: float
    lines_time: float | None = None


@dataclass(frozen=True, slots=True)
class CartesianChoice:
    """How one junction between two spots moves: "spline" (one smooth Bézier TCP path) or
    "flyby" (LIN retract and approach, PTP or LIN detour, with the fly-by the planner chose), and
    the time of each (s); the spline's time is None where it has none, `note` then says why."""

    chosen: str
    flyby_time: float
    spline_time: float | None
    note: str = ""
