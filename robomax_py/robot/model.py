"""URDF + robot.yaml -> RobotModel: Pinocchio kinematics, convex collision geometry, limits, TCP.

A RobotModel is built once and read-only afterwards; Pinocchio `Data` is scratch made per call.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray
from robomax_py.errors import RobotModelError
from robomax_py.robot.geometry import convex_hull_shape, load_mesh
from robomax_py.spec import ControllerSpec, RobotSpec, frozen_array
from robomax_py.tolerances import DEFAULT as TOL

# When robot.yaml gives no acceleration or jerk limits (SPEC §1 makes them optional) we derive them
# from the URDF velocity: full speed in 0.4 s, full acceleration in 0.1 s. Conservative for
# industrial arms (data sheets imply 0.2-0.5 s to full speed), documented in the plan report.
DEFAULT_TIME_TO_FULL_SPEED_S = 0.4
DEFAULT_TIME_TO_FULL_ACCEL_S = 0.1


@dataclass(frozen=True, slots=True, eq=False)
class JointLimits:
    """Per joint: position (rad or m), velocity (/s), acceleration (/s^2), jerk (/s^3); each (n,)."""

    lower: FloatArray
    upper: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray

    def contains(self, q: FloatArray, tol: float = 0.0) -> np.ndarray:
        """(..., n) -> (...) bool: every joint within [lower - tol, upper + tol]."""
        q = np.asarray(q)
        return np.all((q >= self.lower - tol) & (q <= self.upper + tol), axis=-1)


@dataclass(frozen=True, slots=True, eq=False)
class RobotModel:
    """A robot ready for kinematics and collision queries; base frame = URDF root frame."""

    name: str
    source: Path
    model: pin.Model
    collision_model: pin.GeometryModel
    visual_model: pin.GeometryModel
    joint_names: tuple[str, ...]
    flange_frame_id: int
    limits: JointLimits
    ik_solver: str
    ik_params: Any
    T_flange_tcp: FloatArray  # (4, 4); identity until a tool is mounted
    controller: ControllerSpec = dataclasses.field(default_factory=ControllerSpec)
    disabled_links: frozenset[frozenset[str]] = frozenset()   # link pairs robot.yaml / SRDF exempt
    defaulted_limits: tuple[str, ...] = ()   # "acceleration", "jerk": derived, not given in robot.yaml
    warnings: tuple[str, ...] = ()           # what the user should know (fallbacks taken at load)
    loaded_limits: JointLimits | None = None  # with the rated payload (robot.yaml `limits.loaded`)
    payload_kg: float | None = None

    @property
    def dof(self) -> int:
        return int(self.model.nq)

    def limits_carrying(self, mass: float) -> JointLimits:
        """The joint limits carrying `mass` kg: linear in the mass from the unloaded limits to those
        with the rated payload (our model: robot data sheets give the two ends only); the unloaded
        limits when robot.yaml gives no loaded ones."""
        if self.loaded_limits is None or self.payload_kg is None or mass <= 0:
            return self.limits
        f = min(mass / self.payload_kg, 1.0)
        base, full = self.limits, self.loaded_limits
        return dataclasses.replace(base, **{k: (1 - f) * getattr(base, k) + f * getattr(full, k)
                                             for k in ("velocity", "acceleration", "jerk")})


def kinematic_model(spec: RobotSpec) -> pin.Model:
    """The URDF's Pinocchio model, checked: single-axis joints, finite limits, the flange frame exists."""
    try:
        model = pin.buildModelFromUrdf(str(spec.urdf))
    except Exception as exc:  # Pinocchio raises plain RuntimeError/ValueError for bad URDFs
        raise RobotModelError(spec.urdf, None, f"cannot parse URDF: {exc}") from None
    if not model.existFrame(spec.flange):
        raise RobotModelError(spec.source, "flange", f"URDF {spec.urdf.name} has no frame '{spec.flange}'")
    for j in range(1, model.njoints):
        if model.joints[j].nq != 1 or model.joints[j].nv != 1:
            raise RobotModelError(spec.urdf, f"joint {model.names[j]}", "only revolute and prismatic joints are supported")
        i = model.joints[j].idx_q
        lo, hi, v = model.lowerPositionLimit[i], model.upperPositionLimit[i], model.velocityLimit[i]
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise RobotModelError(spec.urdf, f"joint {model.names[j]}", "needs finite position limits lower < upper")
        if not (np.isfinite(v) and v > 0):
            raise RobotModelError(spec.urdf, f"joint {model.names[j]}", "needs a velocity limit > 0")
    return model


def prismatic_mask(model: pin.Model) -> np.ndarray:
    """(n,) bool: which joints are prismatic (their values are metres, not radians)."""
    return np.array([model.joints[j].shortname().startswith("JointModelP") for j in range(1, model.njoints)])


def load_robot(spec: RobotSpec) -> RobotModel:
    """Build the Pinocchio model and convex link geometry named by a checked robot.yaml.

    The IK parameters (given, or fitted from the URDF when robot.yaml has none) must reproduce the
    URDF's forward kinematics within TOL.ik_fit_m on random configurations, else RobotModelError.
    """
    model = kinematic_model(spec)
    ik_params = checked_ik_params(spec, model)
    disabled = _disabled_links(spec, model)
    n = model.nq
    lower = np.array(model.lowerPositionLimit, dtype=float)
    upper = np.array(model.upperPositionLimit, dtype=float)
    velocity = np.array(model.velocityLimit, dtype=float)
    names = tuple(model.names[j] for j in range(1, model.njoints))
    acceleration = _limit_vector(spec, "acceleration", spec.acceleration, velocity / DEFAULT_TIME_TO_FULL_SPEED_S, n)
    jerk = _limit_vector(spec, "jerk", spec.jerk, acceleration / DEFAULT_TIME_TO_FULL_ACCEL_S, n)

    package_dirs = [str(spec.urdf.parent), *[str(d) for d in spec.package_dirs]]
    warnings: list[str] = list(spec.warnings)
    collision = _build_geometry(model, spec, pin.GeometryType.COLLISION, package_dirs)
    _make_meshes_convex(collision, spec)
    try:
        visual = _build_geometry(model, spec, pin.GeometryType.VISUAL, package_dirs)
    except RobotModelError as exc:
        # Visual meshes only serve the preview: plan with the collision meshes shown instead.
        warnings.append(f"{spec.urdf}: visual meshes not loaded ({exc.problem}); the preview shows the collision meshes")
        visual = collision.copy()
    limits = JointLimits(lower=frozen_array(lower), upper=frozen_array(upper), velocity=frozen_array(velocity),
                         acceleration=frozen_array(acceleration), jerk=frozen_array(jerk))
    loaded = _loaded_limits(spec, limits)
    defaulted = tuple(k for k, v in (("acceleration", spec.acceleration), ("jerk", spec.jerk)) if v is None)
    if defaulted:
        warnings.append(
            f"{spec.source}: limits.{' and limits.'.join(defaulted)} not given; derived from the URDF velocities "
            f"(full speed in {DEFAULT_TIME_TO_FULL_SPEED_S} s, full acceleration in {DEFAULT_TIME_TO_FULL_ACCEL_S} s)"
        )

    return RobotModel(
        name=spec.name,
        source=spec.source,
        model=model,
        collision_model=collision,
        visual_model=visual,
        joint_names=names,
        flange_frame_id=int(model.getFrameId(spec.flange)),
        limits=limits,
        loaded_limits=loaded,
        payload_kg=spec.payload_kg,
        ik_solver=spec.ik_solver,
        ik_params=ik_params,
        T_flange_tcp=frozen_array(np.eye(4)),
        controller=spec.controller,
        disabled_links=disabled,
        defaulted_limits=defaulted,
        warnings=tuple(warnings),
    )




def checked_ik_params(spec: RobotSpec, model: pin.Model) -> Any:
    """The robot's closed-form IK parameters, fitted when not given, and checked against the URDF."""
    from robomax_py.robot.ik.fit import FitError, fit_opw, fit_ur, fk_agreement

    if spec.ik_solver == "table":
        return _table_steps(spec, model)
    if spec.ik_solver not in ("opw", "ur"):
        return spec.ik_params
    if model.nq != 6:
        raise RobotModelError(spec.source, "ik.solver", f"the {spec.ik_solver} solver is for six joints; the URDF "
                              f"{spec.urdf.name} has {model.nq} ({', '.join(model.names[1:])}): use numeric or table")
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


def _disabled_links(spec: RobotSpec, model: pin.Model) -> frozenset[frozenset[str]]:
    links = {f.name for f in model.frames if f.type == pin.FrameType.BODY}
    for key, pairs in (("collision.disable", spec.disabled_links), ("srdf", spec.srdf_disabled_links)):
        for i, pair in enumerate(pairs):
            for name in pair:
                if name not in links:
                    where = f"{key}[{i}]" if key == "collision.disable" else key
                    raise RobotModelError(spec.source, where, f"link '{name}' is not in the URDF {spec.urdf.name} "
                                          f"(links: {', '.join(sorted(links))})")
    return frozenset(frozenset(p) for p in (*spec.disabled_links, *spec.srdf_disabled_links))


def mount_tool(robot: RobotModel, T_flange_tcp: FloatArray) -> RobotModel:
    """The same robot with its TCP moved to a tool's TCP (flange frame, m)."""
    return dataclasses.replace(robot, T_flange_tcp=frozen_array(T_flange_tcp))


def fk_flange(robot: RobotModel, q: FloatArray) -> FloatArray:
    """Flange pose in the base frame for (n,) or (k, n) joint values -> (4, 4) or (k, 4, 4)."""
    q = np.asarray(q, dtype=float)
    single = q.ndim == 1
    qs = q.reshape(-1, robot.dof)
    data = robot.model.createData()
    out = np.empty((len(qs), 4, 4))
    for k, qk in enumerate(qs):
        pin.framesForwardKinematics(robot.model, data, qk)
        out[k] = data.oMf[robot.flange_frame_id].homogeneous
    return out[0] if single else out.reshape(q.shape[:-1] + (4, 4))


def fk_tcp(robot: RobotModel, q: FloatArray) -> FloatArray:
    """TCP pose in the base frame, (n,) or (..., n) -> (4, 4) or (..., 4, 4)."""
    return fk_flange(robot, q) @ robot.T_flange_tcp


def reach(robot: RobotModel, samples: int = 4000, seed: int = 0) -> float:
    """Largest flange distance from the axis-1 line over random configurations (m); for listings."""
    rng = np.random.default_rng(seed)
    qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(samples, robot.dof))
    p = fk_flange(robot, qs)[:, :3, 3]
    return float(np.max(np.hypot(p[:, 0], p[:, 1])))


def _loaded_limits(spec: RobotSpec, limits: JointLimits) -> JointLimits | None:
    """robot.yaml's `limits.loaded`, checked: one value per joint, none above the unloaded limit."""
    if spec.loaded is None:
        return None
    out = {}
    for key in ("velocity", "acceleration", "jerk"):
        given = np.asarray(getattr(spec.loaded, key), dtype=float)
        unloaded = getattr(limits, key)
        if len(given) != len(unloaded):
            raise RobotModelError(spec.source, f"limits.loaded.{key}",
                                  f"expected {len(unloaded)} values (one per joint), got {len(given)}")
        above = np.flatnonzero(given > unloaded * (1 + 1e-9))
        if above.size:
            j = int(above[0])
            raise RobotModelError(spec.source, f"limits.loaded.{key}", f"joint {j + 1}: {np.degrees(given[j]):g} is above "
                                  f"the unloaded limit {np.degrees(unloaded[j]):g} (a payload never makes an arm faster)")
        out[key] = given
    return dataclasses.replace(limits, **out)


def _limit_vector(spec: RobotSpec, key: str, given: FloatArray | None, default: FloatArray, n: int) -> FloatArray:
    if given is None:
        return default
    if len(given) != n:
        raise RobotModelError(spec.source, f"limits.{key}", f"expected {n} values (one per joint), got {len(given)}")
    return np.asarray(given, dtype=float)


def _build_geometry(model: pin.Model, spec: RobotSpec, kind: Any, package_dirs: list[str]) -> pin.GeometryModel:
    try:
        return pin.buildGeomFromUrdf(model, str(spec.urdf), kind, package_dirs=package_dirs)
    except Exception as exc:  # a missing or unreadable mesh surfaces here
        raise RobotModelError(spec.urdf, None, f"cannot load link geometry: {exc}") from None


def _make_meshes_convex(geom_model: pin.GeometryModel, spec: RobotSpec) -> None:
    """Replace link meshes by their convex hulls: fast GJK instead of BVH, and conservative."""
    for obj in geom_model.geometryObjects:
        if not obj.meshPath or obj.meshPath in ("BOX", "SPHERE", "CYLINDER", "CAPSULE", "CONE"):
            continue
        try:
            mesh = load_mesh(Path(obj.meshPath), np.asarray(obj.meshScale))
        except Exception as exc:
            raise RobotModelError(spec.urdf, f"link {obj.name}", f"cannot read mesh {obj.meshPath}: {exc}") from None
        obj.geometry = convex_hull_shape(mesh.vertices)
