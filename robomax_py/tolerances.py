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
    # A closed-form solver's FK (given or fitted parameters) must agree with the URDF's to this
    # (issue 14): far below any process tolerance, far above round-off of a correct parameter set.
    ik_fit_m: float = 1e-6
    ik_fit_rad: float = 1e-6
    # SPEC §5: the TCP is at the spot within 0.1 mm.
    spot_pos_m: float = 1e-4
    # Largest motion of any robot or tool point between two checked states of a swept move.
    sweep_step_m: float = 0.002


DEFAULT = Tolerances()
