"""Named numeric tolerances, passed explicitly rather than scattered as literals."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Tolerances:
    # Analytic IK must reproduce the pose to this (float64 round-off is ~1e-15 m at 2 m reach).
    ik_pos_m: float = 1e-9
    ik_rot_rad: float = 1e-9
    # Numeric IK stops here; looser because damped least squares converges linearly near the end.
    ik_numeric_pos_m: float = 1e-6
    ik_numeric_rot_rad: float = 1e-6
    # A closed-form solver's FK (given or fitted parameters) must agree with the URDF's to this:
    # far below any process tolerance, far above round-off of a correct parameter set.
    ik_fit_m: float = 1e-6
    ik_fit_rad: float = 1e-6
    # docs/cell-files.md, "The trajectory file": the TCP is at the spot within 0.1 mm.
    spot_pos_m: float = 1e-4
    # Largest motion of any robot or tool point between two checked states of a swept move.
    sweep_step_m: float = 0.002

    # --- Tolerances named where they are used (each module keeps NAME = TOL.<field>) -----------
    # app.preview_program.REST_TOL_RAD: joint change below which consecutive samples stand still.
    preview_rest_tol_rad: float = 1e-7
    # export.rebuild: a program's frame definitions match the cell's within its decimals.
    frame_tol_mm: float = 1.5e-3
    frame_tol_deg: float = 1.5e-4
    # plan.pipeline: the planner's own check's relative velocity slack (toppra is within ~1e-5).
    plan_velocity_rtol: float = 1e-3
    # plan.reach: wrist axes meeting within this count as a spherical wrist (m).
    wrist_meet_tol_m: float = 1e-6
    # robot.geometry: relative volume difference below which a closed piece counts as convex.
    convex_volume_rtol: float = 1e-6
    # robot.ik.fit: structural conditions of a URDF chain (m or rad); URDFs write pi/2 as 1.5708.
    structure_tol: float = 1e-4
    # timing._common: slack on boundary velocities read off another move; limits' round-off.
    boundary_vel_rtol: float = 1e-9
    limit_tol: float = 1e-9
    # timing._lin_track: orientation error allowed halfway between LIN samples (rad).
    lin_path_tol_rad: float = 1e-4
    # timing.lin: TCP distance to the line halfway between samples (m); q_start an IK solution (rad).
    lin_path_tol_m: float = 1e-5
    start_tol_rad: float = 1e-6
    # timing.paths: consecutive paths meet within this to be joined (rad or m).
    path_join_tol: float = 1e-9
    # timing.ptp: boundary velocities this collinear with the move count as along it (fraction).
    collinear_rtol: float = 1e-9
    # timing.trajectory: segments joined by `concatenate` meet within these (rad or m, and per s).
    join_pos_tol: float = 1e-6
    join_vel_tol: float = 1e-4
    # timing.via: slack on the corner-ball check and on straight pieces' monotonicity.
    jerk_ball_rtol: float = 1e-9
    jerk_monotone_tol: float = 1e-9
    # verify: home (rad), standing still while welding (rad, file precision), the orientation
    # window (rad), file times (s, written to 1 us).
    home_tol_rad: float = 1e-6
    rest_tol_rad: float = 1e-9
    angle_tol_rad: float = 1e-6
    time_tol_s: float = 2e-6
    # world.motion: finite differences of 10 ms samples; velocity exact for linear interpolation,
    # acceleration from second differences overshoots a jerk-limited peak slightly.
    velocity_rtol: float = 0.01
    acceleration_rtol: float = 0.05
    # publish: a written program's rebuilt motion may differ from the planned one by this much
    # (joint deg and TCP mm at the same fraction of every interval between welds, weld times s):
    # FANUC TP's 3 decimals move a target by < 0.001 deg, its 0.01 s waits shift welds by < 10 ms.
    rebuilt_joint_deg: float = 0.01
    rebuilt_tcp_mm: float = 0.1
    rebuilt_time_s: float = 0.02
    # ... and a program whose spline blocks its dialect writes as lines flown by (`export.spline_lines`):
    # the lines keep within 1 mm of sagitta of the planned path and their blends cut corners by
    # less; the blends turn more sharply than the spline, so the lines take longer, by at most this
    # fraction of the planned cycle (measured: docs/bezier-paper.md, "Cartesian moves as splines").
    spline_lines_mm: float = 2.5
    spline_lines_joint_deg: float = 0.5
    spline_lines_time: float = 0.1
    # A Cartesian target read back equals the written one when its rotation is within this (deg):
    # ZYX angles near B = ±90 deg can come back as other angles of the same rotation.
    readback_angle_deg: float = 1e-4
    # Configuration data names a branch as far as the joints are this far from where it changes
    # (docs/cell-files.md, "Controller programs": re-solving a target in its configuration gives the planned joints within 0.01 deg).
    config_tol_deg: float = 0.01
    # Over the approach distance the TCP stays on the electrode axis within this (m): the LIN
    # lines follow it to 1e-5 m (lin_path_tol_m); blends start beyond it.
    straight_tol_m: float = 1e-4
    # io.spot_grouping: a seam formed from a spot list's geometry turns by at most this at any spot
    # (deg): a flange curving at 200 mm radius turns 11.5 deg between spots 40 mm apart, while a
    # corner turns 45-90 deg and a chain zig-zagging between two rows 60-120 deg.
    seam_turn_deg: float = 20.0
    # ... and two steps meeting at a spot differ in length by at most this factor: a spot left out
    # (over a hole) doubles a step; a jump to another seam's end is longer still.
    seam_spacing_ratio: float = 2.5

DEFAULT = Tolerances()
