"""OPW kinematics: arms with an ortho-parallel base and a spherical wrist.

Parameters and joint conventions follow Brandstötter, Angerer and Hofbaur, "An Analytical Solution of
the Inverse Kinematics Problem of Industrial Serial Manipulators with an Ortho-parallel Basis and a
Spherical Wrist" (Austrian Robotics Workshop 2014), as used by the opw_kinematics reference
implementation: the paper's zero has the arm pointing straight up; a robot's own joint value q maps to
the paper's angle as  theta = q * sign_correction - offset.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.transforms import rpy_matrix

if TYPE_CHECKING:
    import pinocchio as pin


@dataclass(frozen=True, slots=True)
class OpwParams:
    """Seven lengths (m), six joint offsets (rad), six axis signs (+1 or -1), base and flange offsets (m)
    and a fixed flange rotation (rad).

    Two fixed translations around the paper's chain, for URDFs whose frames are not on the axes
    (ROS-Industrial's KR 210 L150: axis 1 2.6 mm off the root origin, tool0 0.24 mm off axis 6):
    `base_xy` is where axis 1 meets the robot base frame's xy plane (the paper's axis 1 is the base z
    axis); `flange_xy` is the flange origin's offset from axis 6 along the paper's flange x and y.
    FK adds them, IK takes them off the target first.

    `flange_rpy` (roll, pitch, yaw about fixed x, y, z, as URDF's rpy) turns the paper's flange frame
    (z along axis 6) into the robot's flange frame, for URDFs whose flange z is not along axis 6
    (ROS-Industrial's abb_irb4400_support irb4400l_30_243: tool0 = link_6's frame, x along axis 6):
    T_base_flange = T_base_paper_flange * R(flange_rpy), same origin. Zero for a flange with z
    along axis 6.
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    offsets: tuple[float, float, float, float, float, float] = (0.0,) * 6
    sign_corrections: tuple[int, int, int, int, int, int] = (1,) * 6
    base_xy: tuple[float, float] = (0.0, 0.0)
    flange_xy: tuple[float, float] = (0.0, 0.0)
    flange_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


def flange_rotation(params: OpwParams) -> FloatArray:
    """R(flange_rpy), (3, 3): the robot's flange frame in the paper's flange frame."""
    return rpy_matrix(*params.flange_rpy)


def to_paper_angles(params: OpwParams, q: FloatArray) -> FloatArray:
    """Robot joint values -> the paper's angles, (..., 6) rad."""
    theta: FloatArray = np.asarray(q, dtype=float) * np.asarray(params.sign_corrections) - np.asarray(params.offsets)
    return theta


def from_paper_angles(params: OpwParams, theta: FloatArray) -> FloatArray:
    """The paper's angles -> robot joint values, (..., 6) rad."""
    q: FloatArray = (np.asarray(theta, dtype=float) + np.asarray(params.offsets)) * np.asarray(params.sign_corrections)
    return q


def opw_fk(params: OpwParams, q: FloatArray) -> FloatArray:
    """Flange pose in the robot base frame.

    Parameters
    ----------
    q : (..., 6) float
        Joint values in the robot's own convention, radians.

    Returns
    -------
    (..., 4, 4) float
        T_base_flange, metres.
    """
    th = to_paper_angles(params, q)
    t1, t2, t3, t4, t5, t6 = (th[..., i] for i in range(6))
    psi3 = np.arctan2(params.a2, params.c3)
    k = np.hypot(params.a2, params.c3)

    cx1 = params.c2 * np.sin(t2) + k * np.sin(t2 + t3 + psi3) + params.a1
    cy1 = params.b
    cz1 = params.c2 * np.cos(t2) + k * np.cos(t2 + t3 + psi3)
    s1, c1 = np.sin(t1), np.cos(t1)
    wrist = np.stack([cx1 * c1 - cy1 * s1, cx1 * s1 + cy1 * c1, cz1 + params.c1], axis=-1)

    # R_0c = Rz(t1) Ry(t2 + t3); R_ce = Rz(t4) Ry(t5) Rz(t6).
    R_0c = _rot_z(t1) @ _rot_y(t2 + t3)
    R_ce = _rot_z(t4) @ _rot_y(t5) @ _rot_z(t6)
    R = R_0c @ R_ce

    T = np.zeros(th.shape[:-1] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = wrist + params.c4 * R[..., :, 2] + params.flange_xy[0] * R[..., :, 0] + params.flange_xy[1] * R[..., :, 1]
    T[..., 0, 3] += params.base_xy[0]
    T[..., 1, 3] += params.base_xy[1]
    T[..., 3, 3] = 1.0
    if params.flange_rpy != (0.0, 0.0, 0.0):
        T[..., :3, :3] = R @ flange_rotation(params)
    return T


def _rot_z(a: FloatArray) -> FloatArray:
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def _rot_y(a: FloatArray) -> FloatArray:
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def opw_pin_model(
    params: OpwParams,
    lower: FloatArray | None = None,
    upper: FloatArray | None = None,
    flange: str = "flange",
) -> pin.Model:
    """A geometry-free Pinocchio model of an OPW arm, root frame = robot base frame.

    Built joint by joint from the parameters (not from `opw_fk`), so Pinocchio's kinematics of it is
    an independent check of the closed forms. Joint origins: A1 at the base, A2 at (a1, 0, c1), A3
    c2 above A2 and b to the side, A4 a little before the wrist centre and A5, A6 at it (so the
    wrist point is the intersection of axes 4 and 5, not an origin), the flange frame c4 beyond.

    Parameters
    ----------
    lower, upper : (6,) float, optional
        Joint limits, rad; default +-2 pi.
    flange : str
        Name of the flange frame.
    """
    import pinocchio as pin

    th0 = -np.asarray(params.offsets, dtype=float)           # paper angle at q = 0
    sign = np.asarray(params.sign_corrections, dtype=float)
    model = pin.Model()
    z, y = np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])
    wrist_set_back = 0.2
    joints = [
        (z, _rot_z(np.asarray(th0[0])), (params.base_xy[0], params.base_xy[1], 0.0)),
        (y, _rot_y(np.asarray(th0[1])), (params.a1, 0.0, params.c1)),
        (y, _rot_y(np.asarray(th0[2])), (0.0, params.b, params.c2)),
        (z, _rot_z(np.asarray(th0[3])), (params.a2, 0.0, params.c3 - wrist_set_back)),
        (y, _rot_y(np.asarray(th0[4])), (0.0, 0.0, wrist_set_back)),
        (z, _rot_z(np.asarray(th0[5])), (0.0, 0.0, 0.0)),
    ]
    parent = 0
    for i, (axis, rot, xyz) in enumerate(joints):
        placement = pin.SE3(np.asarray(rot), np.array(xyz, dtype=float))
        parent = model.addJoint(parent, pin.JointModelRevoluteUnaligned(sign[i] * axis), placement, f"joint_{i + 1}")
    model.addFrame(pin.Frame(flange, parent, pin.SE3(flange_rotation(params), np.array([params.flange_xy[0], params.flange_xy[1], params.c4])), pin.FrameType.OP_FRAME))
    model.lowerPositionLimit = np.full(6, -2 * np.pi) if lower is None else np.asarray(lower, dtype=float)
    model.upperPositionLimit = np.full(6, 2 * np.pi) if upper is None else np.asarray(upper, dtype=float)
    return model


# --- inverse kinematics -------------------------------------------------------------------------------

# Branch index k = 4 * wrist + 2 * shoulder + elbow, identical for every pose (see `opw_ik`).
N_BRANCHES = 8
# A pose this close (m) outside the reachable set is still solved: the solution is off by at most
# this much, far below Tolerances.ik_pos_m. It absorbs round-off at full stretch and on the b-cylinder.
REACH_SLACK_M = 1e-10
# Wrist centre closer than this (m) to axis 1: shoulder singularity, theta1 taken from the hint.
SHOULDER_SINGULAR_M = 1e-10
# |sin(theta5)| below this: wrist singularity, theta4 taken from the hint. The pose error this adds
# is below 2e-10 rad; the rest of the wrist rotation goes to theta6.
WRIST_SINGULAR = 1e-10
_TWO_PI = 2.0 * np.pi


def opw_ik(
    params: OpwParams, T_base_flange: FloatArray, q_hint: FloatArray | None = None
) -> tuple[FloatArray, BoolArray]:
    """Every closed-form solution for a batch of flange poses.

    Parameters
    ----------
    params : OpwParams
    T_base_flange : (..., 4, 4) float
        Flange poses in the robot base frame, metres.
    q_hint : (..., 6) or (6,) float, optional
        Robot joint values (rad) used only at singularities, for the free angle: theta1 when the
        wrist centre is on axis 1, theta4 when theta5 = 0 or pi. Without a hint the free paper angle is 0.

    Returns
    -------
    q : (..., 8, 6) float
        Robot joint values, radians, each wrapped into (-pi, pi]. Rows of unreachable branches are NaN.
    valid : (..., 8) bool
        The branch exists for this pose. Valid rows never contain NaN.

    Notes
    -----
    Branch k = 4 * wrist + 2 * shoulder + elbow, in the paper's angles (theta = q * sign - offset):

    - shoulder 0 ("front"): the wrist centre lies on the +x side of the arm plane turned by theta1
      (x >= 0 in the axis-1 frame); 1 ("back", overhead): theta1 turned by about pi, wrist centre behind.
    - elbow 0: beta = theta3 + atan2(a2, c3) >= 0 (the forearm bends from the upper-arm direction
      towards +x; elbow up for the front shoulder); 1: beta < 0. beta = 0 is the stretched arm.
    - wrist 0: theta5 >= 0; 1: theta5 <= 0 ("flipped": theta4 + pi, -theta5, theta6 + pi).

    At a wrist singularity both wrist columns keep theta4 from the hint (so they may coincide).
    """
    T = np.asarray(T_base_flange, dtype=float)
    batch = T.shape[:-2]
    T = T.reshape(-1, 4, 4)
    n = T.shape[0]
    p = params
    if q_hint is None:
        hint1 = np.zeros(n)
        hint4 = np.zeros(n)
    else:
        th_hint = to_paper_angles(p, np.broadcast_to(np.asarray(q_hint, dtype=float), batch + (6,)).reshape(-1, 6))
        hint1, hint4 = th_hint[:, 0], th_hint[:, 3]

    R = T[:, :3, :3]
    if p.flange_rpy != (0.0, 0.0, 0.0):
        R = R @ flange_rotation(p).T        # the paper's flange frame: z along axis 6
    # Wrist centre C = flange position - c4 * approach axis (less the flange offset), in the frame
    # whose origin is on axis 1.
    fx, fy = p.flange_xy
    cx = T[:, 0, 3] - p.base_xy[0] - p.c4 * R[:, 0, 2] - fx * R[:, 0, 0] - fy * R[:, 0, 1]
    cy = T[:, 1, 3] - p.base_xy[1] - p.c4 * R[:, 1, 2] - fx * R[:, 1, 0] - fy * R[:, 1, 1]
    cz = T[:, 2, 3] - p.c4 * R[:, 2, 2] - fx * R[:, 2, 0] - fy * R[:, 2, 1]

    # theta1: the wrist centre, seen in the frame turned by theta1, sits at (+-s, b).
    r2 = cx * cx + cy * cy
    r = np.sqrt(r2)
    b_abs = abs(p.b)
    reach_shoulder = r >= b_abs - REACH_SLACK_M
    s = np.sqrt(np.maximum(r2 - p.b * p.b, 0.0))
    phi = np.arctan2(cy, cx)
    delta = np.arctan2(p.b, s)
    singular1 = r < SHOULDER_SINGULAR_M
    t1 = np.empty((n, 2))
    t1[:, 0] = np.where(singular1, hint1, phi - delta)
    t1[:, 1] = np.where(singular1, hint1 - np.pi, phi + delta - np.pi)
    c1 = np.cos(t1)
    s1 = np.sin(t1)

    # In-plane wrist-centre coordinates relative to axis 2, measured as the projection on the turned
    # x axis so that a theta1 that is slightly off (near axis 1) still gives a consistent arm.
    u = cx[:, None] * c1 + cy[:, None] * s1 - p.a1                    # (n, 2)
    v = (cz - p.c1)[:, None]                                           # (n, 1)

    # Planar two-link arm: upper arm c2, forearm k, angles measured from the vertical.
    k = float(np.hypot(p.a2, p.c3))
    psi3 = float(np.arctan2(p.a2, p.c3))
    cos_b = (u * u + v * v - p.c2 * p.c2 - k * k) / (2.0 * p.c2 * k)   # (n, 2)
    reach_elbow = np.abs(cos_b) <= 1.0 + REACH_SLACK_M
    cos_b = np.clip(cos_b, -1.0, 1.0)
    sin_b = np.sqrt(1.0 - cos_b * cos_b)
    sin_be = np.stack([sin_b, -sin_b], axis=-1)                        # (n, 2 shoulder, 2 elbow)
    cos_be = cos_b[:, :, None]
    beta = np.arctan2(sin_be, cos_be)
    t2 = np.arctan2(u, v)[:, :, None] - np.arctan2(k * sin_be, p.c2 + k * cos_be)
    t3 = beta - psi3
    t23 = t2 + t3
    c23 = np.cos(t23)
    s23 = np.sin(t23)

    # Wrist rotation R_ce = Ry(-t23) Rz(-t1) R: only its columns 0 and 2 are needed.
    c1e, s1e = c1[:, :, None], s1[:, :, None]

    def to_c(col: int) -> tuple[FloatArray, FloatArray, FloatArray]:
        vx, vy, vz = R[:, 0, col][:, None, None], R[:, 1, col][:, None, None], R[:, 2, col][:, None, None]
        wx = c1e * vx + s1e * vy
        wy = c1e * vy - s1e * vx
        return c23 * wx - s23 * vz, np.broadcast_to(wy, c23.shape), s23 * wx + c23 * vz

    m00, m10, m20 = to_c(0)
    m02, m12, m22 = to_c(2)
    h = np.hypot(m02, m12)                                             # |sin theta5|
    t5 = np.arctan2(h, m22)
    singular5 = h < WRIST_SINGULAR
    h_safe = np.where(singular5, 1.0, h)
    hint4e = hint4[:, None, None]
    t4 = np.where(singular5, hint4e, np.arctan2(m12, m02))
    c4 = np.where(singular5, np.cos(hint4e), m02 / h_safe)
    s4 = np.where(singular5, np.sin(hint4e), m12 / h_safe)

    # theta6 from what is left once theta4, theta5 are fixed: Rz(t6) = Ry(-t5) Rz(-t4) R_ce. Using the
    # residual (not an independent atan2) keeps t4 + t6 exact near the singularity.
    # Joint-major (joint, pose, wrist, shoulder, elbow): every step below is a contiguous array op.
    theta = np.empty((6, n, 2, 2, 2))
    theta[0] = t1[:, None, :, None]
    theta[1] = t2[:, None]
    theta[2] = t3[:, None]
    for w, sgn in ((0, 1.0), (1, -1.0)):
        c4w = c4 if w == 0 else np.where(singular5, c4, -c4)
        s4w = s4 if w == 0 else np.where(singular5, s4, -s4)
        n00 = c4w * m00 + s4w * m10
        n10 = c4w * m10 - s4w * m00
        theta[3, :, w] = t4 if w == 0 else np.where(singular5, t4, t4 + np.pi)
        theta[4, :, w] = sgn * t5
        theta[5, :, w] = np.arctan2(n10, m22 * n00 - sgn * h * m20)

    valid = np.broadcast_to((reach_shoulder[:, None] & reach_elbow)[:, None, :, None], (n, 2, 2, 2))
    finite = np.isfinite(T).all(axis=(-2, -1)) & np.isfinite(hint1) & np.isfinite(hint4)
    valid = valid.reshape(n, N_BRANCHES) & finite[:, None]
    q = np.empty((n, N_BRANCHES, 6))
    for jnt in range(6):
        # Robot joint value, wrapped into (-pi, pi] (rint, then the one boundary case).
        x = (theta[jnt].reshape(n, N_BRANCHES) + p.offsets[jnt]) * p.sign_corrections[jnt]
        x -= _TWO_PI * np.rint(x * (1.0 / _TWO_PI))
        x[x <= -np.pi] += _TWO_PI
        q[:, :, jnt] = x
    q[~valid] = np.nan
    return q.reshape(batch + (N_BRANCHES, 6)), valid.reshape(batch + (N_BRANCHES,))
