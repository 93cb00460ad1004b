"""Closed-form kinematics of Universal-Robots-type arms (UR3/5/10/16/20 and e-series).

The arm is described by its six standard Denavit-Hartenberg lengths (Universal Robots' published
table, alpha = [pi/2, 0, 0, pi/2, -pi/2, 0], theta = q):

    A_i = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i),  a = [0, a2, a3, 0, 0, 0],  d = [d1, 0, 0, d4, d5, d6]

plus two fixed corrections that tie the DH chain to a URDF, because ROS-style URDFs do not use the
DH frames at either end:

    T_root_flange(q) = T_root_dhbase @ A_1 ... A_6 @ T_dh6_flange

For example-robot-data's ur10_robot.urdf (root frame `world` = `base_link`, flange `tool0`) the base
correction is a pi yaw (the URDF's `base_link -> base` joint) and the flange correction is identity.
The solution follows the geometric construction of K. P. Hawkins, "Analytic Inverse Kinematics for
the Universal Robots UR-5/UR-10 Arms" (2013), rewritten for batches and made exact near the wrist
singularity by computing theta5 with atan2 and theta2..theta4 from the residual transform.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.robot.ik.turns import wrap_to_pi
from robomax_py.transforms import invert, pose_matrix

N_BRANCHES = 8
# Same meaning as in `opw`: round-off slack at the workspace boundary, and singularity thresholds.
REACH_SLACK_M = 1e-10
SHOULDER_SINGULAR_M = 1e-10
WRIST_SINGULAR = 1e-10
_NUDGE_ERROR = 1e-11

_ALPHA = (np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0)


@dataclass(frozen=True, slots=True)
class UrParams:
    """DH lengths (m) and the fixed URDF corrections (m, rad; rpy = Rz(yaw) Ry(pitch) Rx(roll)).

    base_* : pose of the DH base frame in the URDF root frame.
    flange_* : pose of the URDF flange frame in the DH frame 6.
    """

    d1: float
    a2: float
    a3: float
    d4: float
    d5: float
    d6: float
    base_xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    base_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    flange_xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    flange_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def T_root_dhbase(self) -> FloatArray:
        """(4, 4) DH base frame in the URDF root frame."""
        return pose_matrix(list(self.base_xyz), list(self.base_rpy))

    @property
    def T_dh6_flange(self) -> FloatArray:
        """(4, 4) URDF flange frame in the DH frame 6."""
        return pose_matrix(list(self.flange_xyz), list(self.flange_rpy))


# example-robot-data's ur10_robot.urdf (UR10 CB-series), root frame -> tool0.
UR10_EXAMPLE_ROBOT_DATA = UrParams(
    d1=0.1273, a2=-0.612, a3=-0.5723, d4=0.163941, d5=0.1157, d6=0.0922, base_rpy=(0.0, 0.0, np.pi)
)


def ur_fk(params: UrParams, q: FloatArray) -> FloatArray:
    """Flange pose in the URDF root frame.

    Parameters
    ----------
    q : (..., 6) float
        Joint values, radians (URDF convention = DH theta).

    Returns
    -------
    (..., 4, 4) float
        T_root_flange, metres.
    """
    q = np.asarray(q, dtype=float)
    a = (0.0, params.a2, params.a3, 0.0, 0.0, 0.0)
    d = (params.d1, 0.0, 0.0, params.d4, params.d5, params.d6)
    T = np.broadcast_to(params.T_root_dhbase, q.shape[:-1] + (4, 4)).copy()
    for i in range(6):
        ct, st = np.cos(q[..., i]), np.sin(q[..., i])
        ca, sa = np.cos(_ALPHA[i]), np.sin(_ALPHA[i])
        A = np.zeros(q.shape[:-1] + (4, 4))
        A[..., 0, 0], A[..., 0, 1], A[..., 0, 2], A[..., 0, 3] = ct, -st * ca, st * sa, a[i] * ct
        A[..., 1, 0], A[..., 1, 1], A[..., 1, 2], A[..., 1, 3] = st, ct * ca, -ct * sa, a[i] * st
        A[..., 2, 1], A[..., 2, 2], A[..., 2, 3] = sa, ca, d[i]
        A[..., 3, 3] = 1.0
        T = T @ A
    return T @ params.T_dh6_flange


def ur_ik(
    params: UrParams, T_root_flange: FloatArray, q_hint: FloatArray | None = None
) -> tuple[FloatArray, BoolArray]:
    """Every closed-form solution for a batch of flange poses.

    Parameters
    ----------
    T_root_flange : (..., 4, 4) float
        Flange poses in the URDF root frame, metres.
    q_hint : (..., 6) or (6,) float, optional
        Joint values (rad) used only at singularities for the free angle: q1 when the wrist-3 point is
        on axis 1 (possible only when d4 = 0), q6 when sin(q5) = 0. Without a hint the free angle is 0.

    Returns
    -------
    q : (..., 8, 6) float
        Joint values, radians, wrapped into (-pi, pi]; NaN rows where a branch does not exist.
    valid : (..., 8) bool

    Notes
    -----
    Branch k = 4 * wrist + 2 * shoulder + elbow:

    - shoulder 0: q1 = phi + asin(d4 / r); 1: q1 = phi + pi - asin(d4 / r), where (r, phi) is the
      wrist-3 point (DH origin 5: on the last axis, d6 behind the flange, where the wrist-2 and
      wrist-3 axes meet) in polar form in the DH base frame;
    - elbow 0: q3 >= 0; 1: q3 <= 0;
    - wrist 0: q5 >= 0; 1: q5 <= 0.

    At a wrist singularity (q5 = 0 or pi) joints 2, 3, 4 and 6 are parallel and q6 is free: it moves the
    wrist-1 point (DH origin 4, where the wrist-1 and wrist-2 axes meet) on a circle of radius d5. q6 is the hint (or 0) when that keeps the elbow in reach,
    else the nearest value that does; the planar arm absorbs the rest. Both wrist columns coincide.
    """
    p = params
    T_in = np.asarray(T_root_flange, dtype=float)
    batch = T_in.shape[:-2]
    T = invert(p.T_root_dhbase) @ T_in.reshape(-1, 4, 4) @ invert(p.T_dh6_flange)   # DH base -> DH 6
    n = T.shape[0]
    if q_hint is None:
        hint1 = np.zeros(n)
        hint6 = np.zeros(n)
    else:
        hint = np.broadcast_to(np.asarray(q_hint, dtype=float), batch + (6,)).reshape(-1, 6)
        hint1, hint6 = hint[:, 0], hint[:, 5]

    x6 = T[:, :3, 0]
    y6 = T[:, :3, 1]
    z6 = T[:, :3, 2]
    p05 = T[:, :3, 3] - p.d6 * z6

    # q1: the wrist-3 point lies d4 along the (horizontal) joint-2 axis z1 = (s1, -c1, 0).
    r = np.hypot(p05[:, 0], p05[:, 1])
    reach_shoulder = r >= abs(p.d4) - REACH_SLACK_M
    singular1 = r < SHOULDER_SINGULAR_M
    alpha = np.arcsin(np.clip(p.d4 / np.where(singular1, 1.0, r), -1.0, 1.0))
    phi = np.arctan2(p05[:, 1], p05[:, 0])
    q1 = np.empty((n, 2))
    q1[:, 0] = np.where(singular1, hint1, phi + alpha)
    q1[:, 1] = np.where(singular1, hint1 + np.pi, phi + np.pi - alpha)
    c1, s1 = np.cos(q1), np.sin(q1)                                   # (n, 2)

    # q5, q6 from z1 seen in frame 6: (c6 s5, -s6 s5, c5).
    def dot_z1(vec: FloatArray) -> FloatArray:
        return vec[:, 0, None] * s1 - vec[:, 1, None] * c1

    zx, zy, zz = dot_z1(x6), dot_z1(y6), dot_z1(z6)                   # (n, 2)
    h = np.hypot(zx, zy)                                               # |sin q5|
    singular5 = h < WRIST_SINGULAR
    sign5 = np.array([1.0, -1.0])[None, :, None]                       # (1, wrist, 1)
    q5 = sign5 * np.arctan2(h, zz)[:, None, :]                         # (n, wrist, shoulder)
    q6_raw = np.where(
        singular5[:, None, :],
        hint6[:, None, None],
        np.arctan2(-zy[:, None, :] * sign5, zx[:, None, :] * sign5),
    )                                                                  # (n, wrist, shoulder)
    # Near the singularity q6 hardly changes the pose but moves the wrist-1 point: nudge it into the
    # elbow's reach when the pose error that costs, about |dq6| * |sin q5| * (1 + d5), is negligible.
    q6_reach = _reachable_q6(p, q6_raw, p05, x6, y6, c1, s1)
    nudge_ok = np.abs(wrap_to_pi(q6_reach - q6_raw)) * h[:, None, :] <= _NUDGE_ERROR
    q6 = np.where(singular5[:, None, :] | nudge_ok, q6_reach, q6_raw)
    c5, s5 = np.cos(q5), np.sin(q5)
    c6, s6 = np.cos(q6), np.sin(q6)

    # Frame 4 from the pose and q5, q6: origin p04 = p05 + d5 * y5, x axis x4 = c5 * x5 - s5 * z6.
    def ex(vec: FloatArray) -> FloatArray:
        return vec[:, None, None, :]

    x5 = c6[..., None] * ex(x6) - s6[..., None] * ex(y6)              # (n, w, s, 3)
    y5 = s6[..., None] * ex(x6) + c6[..., None] * ex(y6)
    p04 = ex(p05) + p.d5 * y5
    x4 = c5[..., None] * x5 - s5[..., None] * ex(z6)
    c1w, s1w = c1[:, None, :], s1[:, None, :]
    # In frame 1: x1 = (c1, s1, 0), y1 = (0, 0, 1), origin (0, 0, d1).
    px = c1w * p04[..., 0] + s1w * p04[..., 1]
    py = p04[..., 2] - p.d1
    q234 = np.arctan2(x4[..., 2], c1w * x4[..., 0] + s1w * x4[..., 1])

    cos3 = (px * px + py * py - p.a2 * p.a2 - p.a3 * p.a3) / (2.0 * p.a2 * p.a3)
    reach_elbow = np.abs(cos3) <= 1.0 + REACH_SLACK_M                # (n, w, s)
    cos3 = np.clip(cos3, -1.0, 1.0)
    sin3 = np.sqrt(1.0 - cos3 * cos3)
    sin3e = np.stack([sin3, -sin3], axis=-1)                           # (n, w, s, elbow)
    cos3e = cos3[..., None]
    q3 = np.arctan2(sin3e, cos3e)
    q2 = np.arctan2(py, px)[..., None] - np.arctan2(p.a3 * sin3e, p.a2 + p.a3 * cos3e)
    q4 = q234[..., None] - q2 - q3

    sol = np.empty((n, 2, 2, 2, 6))                                    # (pose, wrist, shoulder, elbow, joint)
    sol[..., 0] = q1[:, None, :, None]
    sol[..., 1] = q2
    sol[..., 2] = q3
    sol[..., 3] = q4
    sol[..., 4] = q5[..., None]
    sol[..., 5] = q6[..., None]
    q = wrap_to_pi(sol.reshape(n, N_BRANCHES, 6))
    valid = np.broadcast_to((reach_shoulder[:, None, None] & reach_elbow)[..., None], (n, 2, 2, 2))
    finite = np.isfinite(T).all(axis=(-2, -1)) & np.isfinite(hint1) & np.isfinite(hint6)
    valid = valid.reshape(n, N_BRANCHES) & finite[:, None]
    q[~valid] = np.nan
    return q.reshape(batch + (N_BRANCHES, 6)), valid.reshape(batch + (N_BRANCHES,))


def _reachable_q6(
    p: UrParams, q6: FloatArray, p05: FloatArray, x6: FloatArray, y6: FloatArray, c1: FloatArray, s1: FloatArray
) -> FloatArray:
    """q6 (n, wrist, shoulder) moved as little as needed for the elbow to reach the wrist-1 point.

    With sin(q5) = 0 the wrist-1 point is p04 = p05 + d5 (s6 x6 + c6 y6). Its squared distance from
    the shoulder (frame-1 origin, in the arm plane) is |w|^2 + d5^2 + 2 d5 rho cos(q6 - psi); the elbow
    reaches it when that lies in [(|a2| - |a3|)^2, (|a2| + |a3|)^2], an interval of |q6 - psi|.

    Returns
    -------
    (n, 2, 2) float, rad
    """
    o1 = np.array([0.0, 0.0, p.d1])
    w = p05 - o1                                                       # (n, 3)
    z1 = np.stack([s1, -c1, np.zeros_like(c1)], axis=-1)               # (n, 2, 3)
    w_in = w[:, None, :] - np.einsum("nj,nsj->ns", w, z1)[..., None] * z1   # in the arm plane
    A = np.einsum("nsj,nj->ns", w_in, x6)[:, None, :]
    B = np.einsum("nsj,nj->ns", w_in, y6)[:, None, :]
    rho = np.hypot(A, B)
    psi = np.arctan2(A, B)
    base = np.einsum("nsj,nsj->ns", w_in, w_in)[:, None, :] + p.d5 * p.d5
    lo2 = (abs(p.a2) - abs(p.a3)) ** 2
    hi2 = (abs(p.a2) + abs(p.a3)) ** 2
    scale = np.where(rho > 1e-12, 2.0 * p.d5 * rho, 1.0)
    # cos(q6 - psi) must lie in [c_lo, c_hi]; |q6 - psi| then in [acos(c_hi), acos(c_lo)].
    c_lo = np.clip((lo2 - base) / scale, -1.0, 1.0)
    c_hi = np.clip((hi2 - base) / scale, -1.0, 1.0)
    d_min, d_max = np.arccos(c_hi), np.arccos(c_lo)
    delta = wrap_to_pi(q6 - psi)
    side = np.where(delta < 0, -1.0, 1.0)
    moved = psi + side * np.clip(np.abs(delta), d_min, d_max)
    # Keep q6 exactly when it is already inside (clip would round it through psi + delta).
    inside = (np.abs(delta) >= d_min) & (np.abs(delta) <= d_max)
    return np.where((rho > 1e-12) & ~inside, wrap_to_pi(moved), q6)
