"""Closed-form IK parameters read off a URDF, and the check that a solver agrees with the URDF.

A URDF states every number an OPW or UR solver needs, in its joint origins and axes; only the
conventions differ. The fit separates the two kinds of unknowns:

- angles (OPW: axis signs and joint offsets; UR: the DH base and flange rotations) follow from the
  joint axes and the flange frame at q = 0, with each structural condition of the class checked;
- lengths enter the forward kinematics *linearly* once the angles are known (the position of the
  flange is a sum of rotated length vectors), so they are the least-squares solution over a few
  dozen random configurations, exact when the chain belongs to the class.

Whatever the source of the parameters, `fk_agreement` then compares the solver's forward kinematics
with Pinocchio's on random configurations; a set that disagrees by more than FIT_TOL_M is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from robomax_py._typing import FloatArray
from robomax_py.errors import RobomaxError
from robomax_py.robot.ik._chain import chain_to_frame, joint_axes_at_zero
from robomax_py.robot.ik.opw import OpwParams, opw_fk
from robomax_py.robot.ik.ur import UrParams, ur_fk
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.transforms import closest_on_line, rot_x, rot_y, rot_z, rpy_from_matrix

# Structural conditions (parallel, perpendicular, intersecting axes) hold to this, in m or rad:
# URDFs write pi/2 as 1.5708 or 1.57079632679, so 1e-4 accepts them; the FK check then decides.
STRUCTURE_TOL = TOL.structure_tol
FIT_SAMPLES = 48
AGREEMENT_SAMPLES = 300


class FitError(RobomaxError):
    """The chain is not of the solver's class; `problem` says which condition fails."""

    def __init__(self, problem: str) -> None:
        super().__init__(problem)
        self.problem = problem


@dataclass(frozen=True, slots=True)
class Agreement:
    """Largest difference between the solver's FK and Pinocchio's over random configurations."""

    position_m: float
    rotation_rad: float
    samples: int

    @property
    def ok(self) -> bool:
        return self.position_m <= TOL.ik_fit_m and self.rotation_rad <= TOL.ik_fit_rad


@dataclass(frozen=True, slots=True)
class _Axes:
    """World joint axes (6, 3), points on them (6, 3) and the flange rotation (3, 3) at q = 0."""

    u: FloatArray
    p: FloatArray
    R_flange: FloatArray
    p_flange: FloatArray


def _axes_at_zero(model: pin.Model, frame_id: int) -> _Axes:
    chain = chain_to_frame(model, frame_id)
    if not np.all(chain.active):
        # An analytic solver takes q for the joints' own turns; a passive joint on the way (an offset
        # wrist's second half) turns with another joint, so the numeric solver takes such arms.
        raise FitError("a passive (<mimic>) joint lies on the chain to the flange")
    if len(chain.joints) != 6 or not np.all(chain.revolute):
        raise FitError(f"needs a chain of six revolute joints to the flange, found {len(chain.joints)} joints "
                       f"({int(np.sum(chain.revolute))} revolute)")
    axes = joint_axes_at_zero(model, frame_id)
    T = axes.T_flange
    return _Axes(axes.u, axes.p, T[:3, :3], T[:3, 3])




def _angle_between_lines(u1: FloatArray, u2: FloatArray) -> float:
    return float(np.arccos(np.clip(abs(u1 @ u2), 0.0, 1.0)))


def _require_parallel(u1: FloatArray, u2: FloatArray, what: str) -> None:
    if _angle_between_lines(u1, u2) > STRUCTURE_TOL:
        raise FitError(f"{what} must be parallel (angle {np.degrees(_angle_between_lines(u1, u2)):.3f} deg)")


def _require_perpendicular(u1: FloatArray, u2: FloatArray, what: str) -> None:
    if abs(float(u1 @ u2)) > STRUCTURE_TOL:
        raise FitError(f"{what} must be perpendicular (cos {float(u1 @ u2):.2e})")






def _wrap(a: float) -> float:
    w = float((a + np.pi) % (2 * np.pi) - np.pi)
    return np.pi if abs(w + np.pi) < 1e-12 else w


def _random_q(model: pin.Model, count: int, seed: int) -> FloatArray:
    rng = np.random.default_rng(seed)
    lo = np.maximum(np.asarray(model.lowerPositionLimit), -2 * np.pi)
    hi = np.minimum(np.asarray(model.upperPositionLimit), 2 * np.pi)
    return rng.uniform(lo, hi, size=(count, model.nq))


def _urdf_fk(model: pin.Model, frame_id: int, qs: FloatArray) -> FloatArray:
    data = model.createData()
    out = np.empty((len(qs), 4, 4))
    for k, q in enumerate(qs):
        pin.framesForwardKinematics(model, data, q)
        out[k] = data.oMf[frame_id].homogeneous
    return out


def fit_opw(model: pin.Model, frame_id: int) -> OpwParams:
    """OPW parameters of a URDF chain (root frame = the OPW base frame up to a yaw, absorbed in the
    joint-1 offset, a vertical offset, absorbed in c1, and a horizontal one, kept as `base_xy`).

    Raises
    ------
    FitError
        The chain is not an ortho-parallel arm with a spherical wrist whose axis 1 is parallel to the
        root's z axis. A flange frame turned against axis 6 is kept as `flange_rpy` (`_paper_flange`).
    """
    ax = _axes_at_zero(model, frame_id)
    u = ax.u
    ez = np.array([0.0, 0.0, 1.0])
    _require_parallel(u[0], ez, "axis 1 and the root frame's z axis")
    # Axis 1 off the root origin is a fixed translation in front of the chain, not another class of
    # arm: the chain is fitted in the root frame moved (in x, y only, so the z conventions stay) to
    # the foot of axis 1, and the translation travels with the parameters as `base_xy`.
    foot = ax.p[0] - ax.p[0, 2] / u[0, 2] * u[0]
    base_xy = (0.0, 0.0) if np.hypot(foot[0], foot[1]) < 1e-12 else (float(foot[0]), float(foot[1]))
    p = ax.p - np.array([base_xy[0], base_xy[1], 0.0])
    s1 = 1 if u[0] @ ez > 0 else -1
    _require_perpendicular(u[1], ez, "axes 1 and 2")
    _require_parallel(u[1], u[2], "axes 2 and 3")
    _require_perpendicular(u[3], u[2], "axes 3 and 4")
    _require_perpendicular(u[4], u[3], "axes 4 and 5")
    _require_perpendicular(u[5], u[4], "axes 5 and 6")
    c45 = closest_on_line(p[3], u[3], p[4], u[4])
    c56 = closest_on_line(p[4], u[4], p[5], u[5])
    for (a, b), what in (((p[3], u[3]), "4"), ((p[4], u[4]), "5"), ((p[5], u[5]), "6")):
        off = np.linalg.norm(np.cross(c45 - a, b))
        if off > STRUCTURE_TOL:
            raise FitError(f"the wrist axes must meet in one point (axis {what} misses it by {off * 1000:.3f} mm)")
    if np.linalg.norm(c45 - c56) > STRUCTURE_TOL:
        raise FitError("the wrist axes must meet in one point")
    wrist = c45
    R_flange, flange_rpy = _paper_flange(ax.R_flange, ax.p_flange - np.array([base_xy[0], base_xy[1], 0.0]) - wrist, u[5])

    # The paper's x axis at q = 0: from axis 1 towards axis 2 (a1), else towards the wrist, else root x.
    foot2 = closest_on_line(p[1], u[1], np.zeros(3), ez)
    for v in (foot2, wrist, np.array([1.0, 0.0, 0.0])):
        h = np.array([v[0], v[1], 0.0])
        h -= (h @ u[1]) * u[1]
        if np.linalg.norm(h) > 1e-6:
            x_p = h / np.linalg.norm(h)
            break
    else:
        raise FitError("cannot tell the arm's front: axis 2 is parallel to the root x axis and the arm is vertical")
    y_p = np.cross(ez, x_p)
    th1 = float(np.arctan2(x_p[1], x_p[0]))
    s2 = 1 if u[1] @ y_p > 0 else -1
    s3 = 1 if u[2] @ y_p > 0 else -1

    def in_plane_angle(v: FloatArray) -> float:
        return float(np.arctan2(v @ x_p, v @ ez))

    p2 = closest_on_line(p[1], u[1], p[2], u[2])
    p3 = p2 + (((p[2] - p2) @ x_p) * x_p + ((p[2] - p2) @ ez) * ez)
    th2 = in_plane_angle(p3 - p2)
    if abs(u[3] @ y_p) > STRUCTURE_TOL:
        raise FitError("axis 4 must lie in the arm's plane (perpendicular to axes 2 and 3)")
    f = u[3] if u[3] @ (wrist - p3) > 0 else -u[3]
    s4 = 1 if u[3] @ f > 0 else -1
    th23 = in_plane_angle(f)
    R_c = rot_z(th1) @ rot_y(th23)
    u5c = R_c.T @ u[4]
    options = [(1, float(np.arctan2(-u5c[0], u5c[1]))), (-1, float(np.arctan2(u5c[0], -u5c[1])))]
    s5, th4 = min(options, key=lambda o: abs(o[1]))
    R_4 = R_c @ rot_z(th4)
    zf = R_4.T @ R_flange[:, 2]
    th5 = float(np.arctan2(zf[0], zf[2]))
    R_5 = R_4 @ rot_y(th5)
    s6 = 1 if u[5] @ R_flange[:, 2] > 0 else -1
    M = R_5.T @ R_flange
    th6 = float(np.arctan2(M[1, 0], M[0, 0]))
    if np.linalg.norm(M - rot_z(th6)) > STRUCTURE_TOL:
        raise FitError("the flange frame is not a rotation about axis 6 of the wrist")

    signs = (s1, s2, s3, s4, s5, s6)
    offsets = tuple(_wrap(-t) for t in (th1, th2, th23 - th2, th4, th5, th6))
    a1, a2, b, c1, c2, c3, c4, fx, fy = _opw_lengths(model, frame_id, signs, offsets, base_xy)
    return OpwParams(a1, a2, b, c1, c2, c3, c4, offsets=offsets, sign_corrections=signs,  # type: ignore[arg-type]
                     base_xy=base_xy, flange_xy=(fx, fy), flange_rpy=flange_rpy)


def _paper_flange(R_urdf: FloatArray, wrist_to_flange: FloatArray,
                  u6: FloatArray) -> tuple[FloatArray, tuple[float, float, float]]:
    """The paper's flange rotation at q = 0 (3, 3) and `flange_rpy` (rad) turning it into the URDF's.

    A URDF flange whose z axis is along axis 6 (either way) is the paper's flange: rpy zero, the
    parameters as they always were. Otherwise (ROS-Industrial's irb4400l_30_243: tool0 = link_6's
    frame, x along axis 6) the paper's flange frame is chosen as: z along axis 6, pointing away from
    the wrist centre (along the URDF flange's z side of it when the flange origin is at the wrist);
    x the URDF flange's x axis projected on the plane normal to z (its y axis when x is along axis 6).
    The choice is canonical up to a turn about axis 6, which the joint-6 offset would absorb anyway;
    this one keeps the paper's x nearest the URDF's. The URDF flange = paper flange * R(flange_rpy).
    """
    if _angle_between_lines(R_urdf[:, 2], u6) <= STRUCTURE_TOL:
        return R_urdf, (0.0, 0.0, 0.0)
    along = float(wrist_to_flange @ u6)
    side = along if abs(along) > 1e-9 else float(R_urdf[:, 2] @ u6)
    z = u6 if side >= 0 else -u6
    for v in (R_urdf[:, 0], R_urdf[:, 1]):
        h = v - (v @ z) * z
        if np.linalg.norm(h) > 1e-6:
            break
    x = h / np.linalg.norm(h)
    R_paper = np.stack([x, np.cross(z, x), z], axis=1)
    rpy = rpy_from_matrix(R_paper.T @ R_urdf)
    return R_paper, (float(rpy[0]), float(rpy[1]), float(rpy[2]))


def _opw_lengths(model: pin.Model, frame_id: int, signs: tuple[int, ...], offsets: tuple[float, ...],
                 base_xy: tuple[float, float]) -> tuple[float, ...]:
    """a1, a2, b, c1, c2, c3, c4 and the flange offset from axis 6 (x, y in the paper's flange frame)
    by least squares: the flange position (less `base_xy`) is linear in them (`flange_rpy` turns the
    frame about its origin, so it does not enter)."""
    qs = _random_q(model, FIT_SAMPLES, seed=1)
    T = _urdf_fk(model, frame_id, qs)
    T[:, 0, 3] -= base_xy[0]
    T[:, 1, 3] -= base_xy[1]
    th = qs * np.asarray(signs) - np.asarray(offsets)
    rows, rhs = [], []
    zero = OpwParams(0, 0, 0, 0, 1, 0, 0, offsets=offsets, sign_corrections=signs)  # type: ignore[arg-type]
    R = opw_fk(zero, qs)[:, :3, :3]
    for k in range(len(qs)):
        t1, t2, t23 = th[k, 0], th[k, 1], th[k, 1] + th[k, 2]
        Rz1 = rot_z(t1)
        cols = [
            Rz1 @ [1.0, 0.0, 0.0],                            # a1
            Rz1 @ [np.cos(t23), 0.0, -np.sin(t23)],           # a2
            Rz1 @ [0.0, 1.0, 0.0],                            # b
            np.array([0.0, 0.0, 1.0]),                        # c1
            Rz1 @ [np.sin(t2), 0.0, np.cos(t2)],              # c2
            Rz1 @ [np.sin(t23), 0.0, np.cos(t23)],            # c3
            R[k][:, 2],                                       # c4
            R[k][:, 0],                                       # flange x off axis 6
            R[k][:, 1],                                       # flange y off axis 6
        ]
        rows.append(np.stack(cols, axis=1))
        rhs.append(T[k, :3, 3])
    x, *_ = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)
    return tuple(float(v) for v in np.where(np.abs(x) < 1e-12, 0.0, x))


_UR_ALPHA = (np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0)




def fit_ur(model: pin.Model, frame_id: int) -> UrParams:
    """UR-type DH parameters (theta = q) of a URDF chain, with the DH base and flange corrections.

    Raises
    ------
    FitError
        The chain is not a UR-type arm whose joint values are the DH angles.
    """
    ax = _axes_at_zero(model, frame_id)
    u = ax.u
    _require_perpendicular(u[0], u[1], "axes 1 and 2")
    _require_parallel(u[1], u[2], "axes 2 and 3")
    _require_parallel(u[2], u[3], "axes 3 and 4")
    _require_perpendicular(u[3], u[4], "axes 4 and 5")
    _require_perpendicular(u[4], u[5], "axes 5 and 6")
    z0 = u[0]
    y0 = -u[1]                      # DH: z1 = Rx(pi/2) z0 = -y0 at q1 = 0
    x0 = np.cross(y0, z0)
    R0 = np.stack([x0, y0, z0], axis=1)
    # On axis 1, nearest the root origin: d1 then holds the shoulder height (it and a base offset
    # along z0 are interchangeable, as d6 and a flange offset along z6 are; we keep both in d).
    origin = ax.p[0] - (ax.p[0] @ z0) * z0
    qs = np.vstack([np.zeros((1, 6)), _random_q(model, FIT_SAMPLES, seed=2)])
    T = _urdf_fk(model, frame_id, qs)
    rows, rhs = [], []
    R6_zero = None
    for k, q in enumerate(qs):
        R = R0.copy()
        cols_a, cols_d = [], []
        for i in range(6):
            R = R @ rot_z(q[i])
            cols_d.append(R[:, 2])      # d_i along z before Tx and Rx
            cols_a.append(R[:, 0])      # a_i along the new x
            R = R @ rot_x(_UR_ALPHA[i])
        if k == 0:
            R6_zero = R
        # unknowns: base x, y (root frame, along x0 and y0), d1, a2, a3, d4, d5, d6, flange x, y (in DH 6)
        cols = [x0, y0, cols_d[0], cols_a[1], cols_a[2], cols_d[3], cols_d[4], cols_d[5], R[:, 0], R[:, 1]]
        rows.append(np.stack(cols, axis=1))
        rhs.append(T[k, :3, 3] - origin)
    x, *_ = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)
    x = np.where(np.abs(x) < 1e-12, 0.0, x)
    if R6_zero is None:
        raise FitError("no configurations sampled")
    R_fl = R6_zero.T @ ax.R_flange
    base_xyz = origin + x[0] * x0 + x[1] * y0
    br = rpy_from_matrix(R0)
    fr = rpy_from_matrix(R_fl)
    if x[3] == 0 or x[4] == 0:
        raise FitError("the upper arm and forearm lengths (a2, a3) come out as 0")
    return UrParams(
        d1=float(x[2]), a2=float(x[3]), a3=float(x[4]), d4=float(x[5]), d5=float(x[6]), d6=float(x[7]),
        base_xyz=(float(base_xyz[0]), float(base_xyz[1]), float(base_xyz[2])),
        base_rpy=(float(br[0]), float(br[1]), float(br[2])),
        flange_xyz=(float(x[8]), float(x[9]), 0.0),
        flange_rpy=(float(fr[0]), float(fr[1]), float(fr[2])),
    )


def fk_agreement(model: pin.Model, frame_id: int, params: OpwParams | UrParams,
                 samples: int = AGREEMENT_SAMPLES, seed: int = 0) -> Agreement:
    """The solver's FK against Pinocchio's on `samples` random configurations within the limits."""
    qs = _random_q(model, samples, seed)
    T_urdf = _urdf_fk(model, frame_id, qs)
    T_solver = opw_fk(params, qs) if isinstance(params, OpwParams) else ur_fk(params, qs)
    dp = float(np.max(np.linalg.norm(T_urdf[:, :3, 3] - T_solver[:, :3, 3], axis=1)))
    dR = np.einsum("kji,kjl->kil", T_urdf[:, :3, :3], T_solver[:, :3, :3])
    cos = np.clip((np.trace(dR, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    # arccos loses precision near 1; the Frobenius norm of R1 - R2 is the angle to first order.
    angle = np.where(cos > 0.999, np.linalg.norm(dR - np.eye(3), axis=(1, 2)) / np.sqrt(2.0), np.arccos(cos))
    return Agreement(dp, float(np.max(angle)), samples)
