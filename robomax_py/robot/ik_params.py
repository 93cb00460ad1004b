"""A robot's IK parameters checked against its URDF: the closed-form solvers' parameters fitted when
robot.yaml gives none and their forward kinematics compared with the URDF's, the table solver's
steps in the joints' units and its grid within `max_rows`."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py.errors import RobotModelError
from robomax_py.robot.kinematics import active_joints, prismatic_mask
from robomax_py.spec import RobotSpec
from robomax_py.tolerances import DEFAULT as TOL


def checked_ik_params(spec: RobotSpec, model: pin.Model) -> Any:
    """The robot's closed-form IK parameters, fitted when not given, and checked against the URDF."""
    from robomax_py.robot.ik.fit import FitError, fit_opw, fit_ur, fk_agreement

    if spec.ik_solver == "table":
        return _table_steps(spec, model)
    if spec.ik_solver not in ("opw", "ur"):
        return spec.ik_params
    if model.nq != 6:
        raise RobotModelError(spec.source, "ik.solver", f"the {spec.ik_solver} solver is for six joints; the URDF "
                              f"{spec.urdf.name} has {model.nq} ({', '.join(model.names[j] for j in active_joints(model))}): "
                              "use numeric or table")
    frame_id = int(model.getFrameId(spec.flange))
    params = spec.ik_params
    origin = "ik.params"
    if params is None:
        origin = "ik.params (fitted from the URDF)"
        try:
            params = fit_opw(model, frame_id) if spec.ik_solver == "opw" else fit_ur(model, frame_id)
        except FitError as exc:
            raise RobotModelError(spec.source, "ik.solver", f"the URDF {spec.urdf.name} is not a "
                                  f"{spec.ik_solver.upper()}-class arm up to '{spec.flange}': {exc.problem}") from None
    agreement = fk_agreement(model, frame_id, params)
    if not agreement.ok:
        raise RobotModelError(
            spec.source, origin,
            f"the {spec.ik_solver} solver's forward kinematics disagrees with the URDF {spec.urdf.name}: "
            f"up to {agreement.position_m * 1000:.3f} mm and {np.degrees(agreement.rotation_rad):.4f} deg over "
            f"{agreement.samples} random configurations (allowed {TOL.ik_fit_m:g} m); parameters {params}",
        )
    return params


def _table_steps(spec: RobotSpec, model: pin.Model) -> Any:
    """The table solver's steps in the joints' units (rad; m for a prismatic joint), one per joint."""
    params = spec.ik_params
    steps = params.step
    n = int(model.nq)
    if len(steps) not in (1, n):
        raise RobotModelError(spec.source, "ik.params.step", f"expected one step or {n} (one per joint), got {len(steps)}")
    steps = steps * n if len(steps) == 1 else steps
    prismatic = prismatic_mask(model)
    out = dataclasses.replace(params, step=tuple(s if prismatic[i] else float(np.radians(s)) for i, s in enumerate(steps)))
    from robomax_py.robot.ik.pose_table import grid_of

    grid = grid_of(np.array(model.lowerPositionLimit), np.array(model.upperPositionLimit), out.step)
    if grid.size > out.max_rows:
        raise RobotModelError(spec.source, "ik.params.step", f"the grid has {grid.size:,} rows (J = {list(grid.counts)}), "
                              f"more than max_rows {out.max_rows:,}: take larger steps (the wrist's especially)")
    return out
