"""URDF + robot.yaml -> RobotModel: Pinocchio kinematics, convex collision geometry, limits, TCP.

A RobotModel is built once and read-only afterwards; Pinocchio `Data` is scratch made per call.
Its parts come from the modules beside this one: the URDF's kinematic model and its joints
(`kinematics`), the links' geometry (`link_geometry`) and the checked IK parameters (`ik_params`).
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
from robomax_py.robot.ik_params import checked_ik_params
from robomax_py.robot.kinematics import (
    active_joints,
    is_passive,
    kinematic_model,
    mimic_relation,
    passive_joints,
    pinocchio_urdf_text,
    prismatic_mask,
    urdf_model,
)
from robomax_py.robot.link_geometry import _geometry
from robomax_py.spec import ControllerSpec, RobotSpec, frozen_array

# What this module offered before its parts moved out stays importable from here.
__all__ = [
    "DEFAULT_TIME_TO_FULL_ACCEL_S", "DEFAULT_TIME_TO_FULL_SPEED_S", "JointLimits", "RobotModel", "active_joints",
    "checked_ik_params", "fk_flange", "fk_tcp", "is_passive", "kinematic_model", "load_robot", "mimic_relation",
    "mount_tool", "passive_joints", "pinocchio_urdf_text", "prismatic_mask", "reach", "urdf_model",
]

# When robot.yaml gives no acceleration or jerk limits (docs/cell-files.md, "The robot folder" makes them optional) we derive them
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
        inside: np.ndarray = np.all((q >= self.lower - tol) & (q <= self.upper + tol), axis=-1)
        return inside


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

    @property
    def prismatic(self) -> tuple[bool, ...]:
        """Per joint: prismatic (its values are metres; a program states them in mm), else revolute."""
        return tuple(bool(v) for v in prismatic_mask(self.model))

    @property
    def prismatic_joints(self) -> tuple[str, ...]:
        """The names of the prismatic joints (a track, a lift), in joint order."""
        return tuple(name for name, linear in zip(self.joint_names, self.prismatic) if linear)

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


def load_robot(spec: RobotSpec) -> RobotModel:
    """Build the Pinocchio model and convex link geometry named by a checked robot.yaml.

    The IK parameters (given, or fitted from the URDF when robot.yaml has none) must reproduce the
    URDF's forward kinematics within TOL.ik_fit_m on random configurations, else RobotModelError.
    """
    model = kinematic_model(spec)
    ik_params = checked_ik_params(spec, model)
    disabled, srdf_warnings = _disabled_links(spec, model)
    n = model.nq
    lower = np.array(model.lowerPositionLimit, dtype=float)
    upper = np.array(model.upperPositionLimit, dtype=float)
    velocity = np.array(model.velocityLimit, dtype=float)
    names = tuple(model.names[j] for j in active_joints(model))
    acceleration = _limit_vector(spec, "acceleration", spec.acceleration, velocity / DEFAULT_TIME_TO_FULL_SPEED_S, n)
    jerk = _limit_vector(spec, "jerk", spec.jerk, acceleration / DEFAULT_TIME_TO_FULL_ACCEL_S, n)

    package_dirs = [str(spec.urdf.parent), *[str(d) for d in spec.package_dirs]]
    warnings: list[str] = [*spec.warnings, *srdf_warnings]
    collision = _geometry(model, spec, pin.GeometryType.COLLISION, package_dirs)
    try:
        visual = _geometry(model, spec, pin.GeometryType.VISUAL, package_dirs)
    except RobotModelError as exc:
        # Visual meshes only serve the preview: plan with the collision meshes shown instead.
        warnings.append(f"{spec.urdf}: visual meshes not loaded ({exc.problem}); the preview shows the collision meshes")
        visual = collision.copy()
    limits = JointLimits(lower=frozen_array(lower), upper=frozen_array(upper), velocity=frozen_array(velocity),
                         acceleration=frozen_array(acceleration), jerk=frozen_array(jerk))
    loaded = _loaded_limits(spec, limits)
    for key, given in (("joint_signs", spec.controller.joint_signs), ("joint_zeros_deg", spec.controller.joint_zeros)):
        if given and len(given) != n:
            raise RobotModelError(spec.source, f"controller.{key}", f"expected {n} values (one per joint), got {len(given)}")
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


def _disabled_links(spec: RobotSpec, model: pin.Model) -> tuple[frozenset[frozenset[str]], tuple[str, ...]]:
    """The link pairs exempt from collision checks, and warnings.

    robot.yaml's own `collision.disable` must name links of the URDF. An SRDF's pair naming a link
    the URDF lacks is skipped with a warning, as MoveIt does (srdfdom's model.cpp: "Link ... is not
    known to URDF. Cannot disable collisions."): a package's SRDF lists the links of the package's
    URDF, passive links too, and a URDF edited down still loads with it."""
    links = {f.name for f in model.frames if f.type == pin.FrameType.BODY}
    for i, pair in enumerate(spec.disabled_links):
        for name in pair:
            if name not in links:
                raise RobotModelError(spec.source, f"collision.disable[{i}]", f"link '{name}' is not in the URDF "
                                      f"{spec.urdf.name} (links: {', '.join(sorted(links))})")
    srdf = [p for p in spec.srdf_disabled_links if set(p) <= links]
    missing = sorted({name for p in spec.srdf_disabled_links for name in p} - links)
    warnings: tuple[str, ...] = ()
    if missing:
        skipped = len(spec.srdf_disabled_links) - len(srdf)
        warnings = ((f"{spec.source}: srdf: {skipped} disable_collisions pair(s) name links the URDF "
                     f"{spec.urdf.name} does not have ({', '.join(missing)}); skipped"),)
    return frozenset(frozenset(p) for p in (*spec.disabled_links, *srdf)), warnings


def with_joint_limits(robot: RobotModel, limits: FloatArray) -> RobotModel:
    """The same robot within narrower position limits, (n, 2) [lower, upper] (a cell's software
    limits): IK, planning and verify keep to them; speeds and the loaded limits' speeds are kept."""
    bounds = np.asarray(limits, dtype=float)
    lower, upper = frozen_array(bounds[:, 0]), frozen_array(bounds[:, 1])
    loaded = robot.loaded_limits
    return dataclasses.replace(
        robot, limits=dataclasses.replace(robot.limits, lower=lower, upper=upper),
        loaded_limits=None if loaded is None else dataclasses.replace(loaded, lower=lower, upper=upper))


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


