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


# A `<mimic>` joint (a parallelogram link, a balancer's cylinder and piston) is passive: its value
# follows the joint it mimics (multiplier * q + offset), it has no configuration entry of its own
# and takes no part in IK or programs; its link moves and collides like every other. Pinocchio
# models it so when the URDF is read with `mimic=True` (JointModelMimic, nq = nv = 0), but the
# installed Pinocchio refuses a `continuous` joint mimicking a revolute one (their configuration
# spaces differ: cos/sin against an angle), the form ROS-Industrial ABB packages use for their
# balancers (abb_irb6640_support/urdf/irb6640_185_280_macro.xacro `joint_piston`). Its value
# follows a bounded joint, so it is read as a revolute joint with limits of a full turn either way.
_MIMIC_CONTINUOUS_LIMIT_RAD = 2 * np.pi


# Pinocchio's URDF reader walks the link tree depth first, a link's child joints in the order of
# their names (urdfdom keeps joints in a sorted map), and refuses a mimic joint met before the joint
# it follows ("The parent joint of the mimic joint is not in the kinematic tree"): the IRB 6700's
# `cylinder_joint` hangs from link_1 beside `joint_2`, which it follows
# (abb_irb6700_support/urdf/irb6700_200_260_macro.xacro). Pinocchio therefore reads every mimic
# joint under a name sorting after all others (this prefix; `~` is the last printable ASCII
# character), so that it meets each after its active siblings, and `urdf_model` gives the names back.
_PASSIVE_PREFIX = "~"


def pinocchio_urdf_text(text: str) -> str:
    """A URDF's text as `urdf_model` hands it to Pinocchio: `continuous` mimic joints made revolute
    and mimic joints renamed (see above); the text unchanged when it has none."""
    import xml.etree.ElementTree as ET

    if "mimic" not in text:
        return text
    root = ET.fromstring(text)
    joints = [joint for joint in root.findall("joint") if joint.find("mimic") is not None]
    if not joints:
        return text
    passive = {str(joint.get("name")) for joint in joints}
    for joint in joints:
        joint.set("name", _PASSIVE_PREFIX + str(joint.get("name")))
        mimic = joint.find("mimic")
        if mimic is not None and mimic.get("joint") in passive:
            mimic.set("joint", _PASSIVE_PREFIX + str(mimic.get("joint")))
        if joint.get("type") != "continuous":
            continue
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = ET.SubElement(joint, "limit", {"effort": "0", "velocity": "1"})
        limit.set("lower", repr(-_MIMIC_CONTINUOUS_LIMIT_RAD))
        limit.set("upper", repr(_MIMIC_CONTINUOUS_LIMIT_RAD))
    return ET.tostring(root, encoding="unicode")


def urdf_model(text: str) -> pin.Model:
    """Pinocchio's model of a URDF's text, `<mimic>` joints as passive joints (JointModelMimic)."""
    model = pin.buildModelFromXML(pinocchio_urdf_text(text), mimic=True)
    for j in range(1, model.njoints):
        if model.names[j].startswith(_PASSIVE_PREFIX) and is_passive(model, j):
            model.names[j] = model.names[j][len(_PASSIVE_PREFIX):]
    for frame in model.frames:
        if frame.type == pin.FrameType.JOINT and frame.name.startswith(_PASSIVE_PREFIX) and is_passive(model, frame.parentJoint):
            frame.name = frame.name[len(_PASSIVE_PREFIX):]
    return model


def is_passive(model: pin.Model, j: int) -> bool:
    """Joint j follows another joint (`<mimic>`): no configuration entry of its own."""
    return bool(model.joints[j].shortname() == "JointModelMimic")


def active_joints(model: pin.Model) -> list[int]:
    """The joint ids that own a configuration entry, in configuration order (passive ones left out)."""
    return sorted((j for j in range(1, model.njoints) if not is_passive(model, j)), key=lambda j: int(model.joints[j].idx_q))


def passive_joints(model: pin.Model) -> list[int]:
    """The ids of the `<mimic>` joints."""
    return [j for j in range(1, model.njoints) if is_passive(model, j)]


def mimic_relation(model: pin.Model, j: int) -> tuple[int, float, float]:
    """A passive joint's relation: (configuration index it follows, multiplier, offset)."""
    mimic = model.joints[j].extract()
    return int(mimic.idx_q), float(mimic.scaling), float(mimic.offset)


def _urdf_text(urdf: Path, error_file: Path) -> str:
    from robomax_py.safe_files import LIMITS, named_by, read_text

    return read_text(urdf, LIMITS.urdf, named_by(RobotModelError, error_file, "urdf"), f"URDF {urdf}")


def kinematic_model(spec: RobotSpec) -> pin.Model:
    """The URDF's Pinocchio model, checked: single-axis active joints, finite limits, the flange
    frame exists. `<mimic>` joints are passive (see `urdf_model`)."""
    try:
        model = urdf_model(_urdf_text(spec.urdf, spec.source))
    except RobotModelError:
        raise
    except Exception as exc:  # noqa: BLE001 - Pinocchio raises plain RuntimeError/ValueError for bad URDFs
        raise RobotModelError(spec.urdf, None, f"cannot parse URDF: {exc}") from None
    if not model.existFrame(spec.flange):
        raise RobotModelError(spec.source, "flange", f"URDF {spec.urdf.name} has no frame '{spec.flange}'")
    for j in range(1, model.njoints):
        if is_passive(model, j):
            continue
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
    return np.array([model.joints[j].shortname().startswith("JointModelP") for j in active_joints(model)])


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


# Link geometry already built in this process, by (URDF, package folders, kind): with the state
# (size, modification time, inode) of the URDF and of every mesh file it read. Loading an arm
# builds its meshes and their convex hulls (0.3-0.6 s); a batch, a preview that reloads or a
# sweep of checks loads the same arm again and again. An entry is used only while none of those
# files has changed, and a copy is handed out (the geometry objects are shared, never modified).
_GEOMETRY: dict[tuple[str, tuple[str, ...], str], tuple[tuple[tuple[str, int, int, int], ...], pin.GeometryModel]] = {}
_GEOMETRY_ENTRIES = 8


def _file_states(urdf: Path, geom_model: pin.GeometryModel) -> tuple[tuple[str, int, int, int], ...] | None:
    """(path, size, mtime_ns, inode) of the URDF and of each mesh file the model was built from;
    None when one cannot be read (then nothing is kept)."""
    paths = [str(urdf), *sorted({o.meshPath for o in geom_model.geometryObjects if o.meshPath
                                 and o.meshPath not in ("BOX", "SPHERE", "CYLINDER", "CAPSULE", "CONE")})]
    try:
        return tuple((p, (st := Path(p).stat()).st_size, st.st_mtime_ns, st.st_ino) for p in paths)
    except OSError:
        return None


def _geometry(model: pin.Model, spec: RobotSpec, kind: Any, package_dirs: list[str]) -> pin.GeometryModel:
    """The links' geometry of `kind` (collision meshes as convex hulls), built or reused."""
    key = (str(Path(spec.urdf).resolve()), tuple(package_dirs), f"{kind}|{model.njoints}|{model.nframes}")
    hit = _GEOMETRY.get(key)
    if hit is not None and _file_states(spec.urdf, hit[1]) == hit[0]:
        return hit[1].copy()
    geom_model = _build_geometry(model, spec, kind, package_dirs)
    if kind == pin.GeometryType.COLLISION:
        _make_meshes_convex(geom_model, spec)
    states = _file_states(spec.urdf, geom_model)
    if states is not None:
        if len(_GEOMETRY) >= _GEOMETRY_ENTRIES:
            del _GEOMETRY[next(iter(_GEOMETRY))]
        _GEOMETRY[key] = (states, geom_model)
    return geom_model.copy()


def _build_geometry(model: pin.Model, spec: RobotSpec, kind: Any, package_dirs: list[str]) -> pin.GeometryModel:
    text = pinocchio_urdf_text(_urdf_text(spec.urdf, spec.source))
    try:
        return pin.buildGeomFromUrdfString(model, text, kind, package_dirs=package_dirs)
    except Exception as exc:  # noqa: BLE001 - a missing or unreadable mesh surfaces here, of any kind
        raise RobotModelError(spec.urdf, None, f"cannot load link geometry: {exc}") from None


def _make_meshes_convex(geom_model: pin.GeometryModel, spec: RobotSpec) -> None:
    """Replace link meshes by their convex hulls: fast GJK instead of BVH, and conservative."""
    for obj in geom_model.geometryObjects:
        if not obj.meshPath or obj.meshPath in ("BOX", "SPHERE", "CYLINDER", "CAPSULE", "CONE"):
            continue
        try:
            mesh = load_mesh(Path(obj.meshPath), np.asarray(obj.meshScale))
        except Exception as exc:  # noqa: BLE001 - trimesh raises many kinds for unreadable files
            raise RobotModelError(spec.urdf, f"link {obj.name}", f"cannot read mesh {obj.meshPath}: {exc}") from None
        obj.geometry = convex_hull_shape(mesh.vertices)
