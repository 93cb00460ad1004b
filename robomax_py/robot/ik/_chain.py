"""Batched forward kinematics and frame Jacobians of a Pinocchio model, in numpy.

Pinocchio's Python API evaluates one configuration per call (microseconds of overhead each); the
numeric IK iterates thousands of seeds at once, and the configuration indicators need joint
placements for whole IK tables. This module reads the model's constant data once (joint placements,
joint axes, parents) and evaluates any number of configurations with array operations. Only
single-axis joints (revolute or prismatic, nq = nv = 1) are supported, which `robot.kinematic_model`
already enforces. Results agree with `pin.framesForwardKinematics` to round-off (tests check).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from robomax_py._typing import BoolArray, FloatArray
from robomax_py.errors import RobotModelError


@dataclass(frozen=True, slots=True, eq=False)
class Chain:
    """The constant kinematic data of the joints that move one frame, root first.

    Each joint axis is turned onto the local z axis by a constant rotation A_i (A_i z = axis_i), so a
    configuration is K_0 Z(q_0) K_1 Z(q_1) ... K_{n-1} Z(q_{n-1}) K_n with constant K_i = A_{i-1}^T P_i A_i
    (P_i the joint placement) and Z a rotation about (or translation along) z: cheap column updates.

    joints : Pinocchio joint ids, root first; q_index : their index in q (for a passive joint, the
    index of the joint it follows).
    scale, offset : (len(joints),) float; joint i moves by scale_i * q[q_index_i] + offset_i (1 and 0
    for the active joints, a `<mimic>` joint's multiplier and offset for the passive ones).
    active : (len(joints),) bool; False = passive.
    revolute : (len(joints),) bool; False = prismatic.
    K : (len(joints) + 1, 4, 4) the constant factors above (K_n carries the frame placement).
    A : (len(joints), 4, 4) the axis-aligning rotations.
    nq : size of q.
    """

    joints: tuple[int, ...]
    q_index: tuple[int, ...]
    scale: FloatArray
    offset: FloatArray
    active: BoolArray
    revolute: BoolArray
    K: FloatArray
    A: FloatArray
    nq: int


def revolute_mask(model: pin.Model) -> BoolArray:
    """(nq,) bool: which configuration entries belong to revolute joints."""
    mask = np.zeros(model.nq, dtype=bool)
    for j in range(1, model.njoints):
        if model.joints[j].nq == 0:          # a passive (`<mimic>`) joint owns no entry
            continue
        mask[model.joints[j].idx_q] = model.joints[j].shortname().startswith("JointModelR")
    return mask


def chain_to_frame(model: pin.Model, frame_id: int) -> Chain:
    """The joints that move `frame_id`; the chain's end is that frame."""
    frame = model.frames[frame_id]
    return _chain(model, int(frame.parentJoint), frame.placement.homogeneous)


def chain_to_joint(model: pin.Model, joint_id: int) -> Chain:
    """The joints that move joint `joint_id`; the chain's end is that joint's own frame."""
    return _chain(model, joint_id, np.eye(4))


def _z_to(axis: FloatArray) -> FloatArray:
    """(4, 4) rotation taking the z axis onto the unit vector `axis`."""
    z = np.array([0.0, 0.0, 1.0])
    A = np.eye(4)
    c = float(axis @ z)
    v = np.cross(z, axis)
    s = float(np.linalg.norm(v))
    if s < 1e-12:
        if c < 0:
            A[:3, :3] = np.diag([1.0, -1.0, -1.0])
        return A
    K = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]) / s
    A[:3, :3] = np.eye(3) + s * K + (1.0 - c) * K @ K
    return A


def _chain(model: pin.Model, last: int, T_joint_frame: FloatArray) -> Chain:
    path: list[int] = []
    j = last
    while j > 0:
        path.append(j)
        j = int(model.parents[j])
    path.reverse()
    n = len(path)
    A = np.empty((n, 4, 4))
    K = np.empty((n + 1, 4, 4))
    revolute = np.empty(n, dtype=bool)
    active = np.ones(n, dtype=bool)
    scale = np.ones(n)
    offset = np.zeros(n)
    q_index: list[int] = []
    prev_A_T = np.eye(4)
    for i, jid in enumerate(path):
        jm = model.joints[jid]
        jd = jm.createData()
        if jm.shortname() == "JointModelMimic":
            # Pinocchio's mimic joint reads q[idx_q] of the joint it follows; its motion subspace
            # is the mimicking joint's own axis times the multiplier.
            mimic = jm.extract()
            active[i] = False
            scale[i], offset[i] = float(mimic.scaling), float(mimic.offset)
            if scale[i] == 0.0:
                raise RobotModelError(None, f"joint {model.names[jid]}", "<mimic multiplier=0>: the joint never moves (make it fixed)")
            jm.calc(jd, np.zeros(model.nq))
            S = np.asarray(jd.S).reshape(6) / scale[i]
        elif jm.nq != 1 or jm.nv != 1:
            raise RobotModelError(None, f"joint {model.names[jid]}", "only revolute and prismatic joints are supported")
        else:
            jm.calc(jd, np.zeros(1))
            S = np.asarray(jd.S).reshape(6)                  # motion subspace: linear, angular
        revolute[i] = bool(np.linalg.norm(S[3:]) > 0.5)
        axis = S[3:] if revolute[i] else S[:3]
        A[i] = _z_to(axis / np.linalg.norm(axis))
        K[i] = prev_A_T @ model.jointPlacements[jid].homogeneous @ A[i]
        prev_A_T = A[i].T
        q_index.append(int(jm.idx_q))
    K[n] = prev_A_T @ np.asarray(T_joint_frame, dtype=float)
    return Chain(joints=tuple(path), q_index=tuple(q_index), scale=scale, offset=offset, active=active,
                 revolute=revolute, K=K, A=A, nq=int(model.nq))


def active_positions(chain: Chain) -> list[int]:
    """The positions in `chain.joints` of its active joints, root first."""
    return [i for i in range(len(chain.joints)) if chain.active[i]]


# Internally a pose batch is stored column-major as (4, 3, M): T[c] is column c (3, M) of the top
# three rows, so every update below is an elementwise operation on contiguous arrays. This avoids
# tiny batched matrix products, which are slow in numpy and start BLAS threads.


def _times_const(T: FloatArray, K: FloatArray) -> FloatArray:
    """T @ K for a (4, 3, M) pose batch and a constant (4, 4) rigid transform."""
    out = np.empty_like(T)
    for j in range(4):
        acc = T[0] * K[0, j]
        for k in (1, 2):
            if K[k, j] != 0.0:
                acc += T[k] * K[k, j]
        out[j] = acc
    out[3] += T[3]
    return out


def _walk(chain: Chain, q: FloatArray) -> tuple[FloatArray, list[FloatArray]]:
    """End pose and each joint's axis-aligned world frame, all (4, 3, M), for q (M, nq)."""
    m = q.shape[0]
    T = np.empty((4, 3, m))
    T[...] = chain.K[0][:3].T[:, :, None]
    aligned: list[FloatArray] = []
    for i in range(len(chain.joints)):
        qi = q[:, chain.q_index[i]]
        if not chain.active[i]:
            qi = chain.scale[i] * qi + chain.offset[i]
        if chain.revolute[i]:
            c, s = np.cos(qi), np.sin(qi)
            x = T[0].copy()
            T[0] = c * x + s * T[1]
            T[1] = c * T[1] - s * x
        else:
            T[3] += qi * T[2]
        aligned.append(T)
        T = _times_const(T, chain.K[i + 1])
    return T, aligned


def _full(T: FloatArray) -> FloatArray:
    """(4, 3, M) column-major batch -> (M, 4, 4) homogeneous matrices."""
    out = np.zeros((T.shape[2], 4, 4))
    out[:, :3, :] = T.transpose(2, 1, 0)
    out[:, 3, 3] = 1.0
    return out


def joint_frames(chain: Chain, q: FloatArray) -> FloatArray:
    """World placement of every joint frame of the chain (Pinocchio's oMi).

    Parameters
    ----------
    q : (..., nq) float
        Configurations, rad or m.

    Returns
    -------
    (..., len(chain.joints), 4, 4) float
    """
    q = np.asarray(q, dtype=float)
    batch = q.shape[:-1]
    _, aligned = _walk(chain, q.reshape(-1, chain.nq))
    frames = np.stack([_full(_times_const(Ti, chain.A[i].T)) for i, Ti in enumerate(aligned)], axis=1)
    return frames.reshape(batch + (len(chain.joints), 4, 4))


def frame_pose(chain: Chain, q: FloatArray) -> FloatArray:
    """(..., 4, 4) world pose of the chain's end frame for (..., nq) configurations."""
    q = np.asarray(q, dtype=float)
    T, _ = _walk(chain, q.reshape(-1, chain.nq))
    return _full(T).reshape(q.shape[:-1] + (4, 4))


def frame_pose_and_jacobian(chain: Chain, q: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """End-frame pose and its Jacobian in the world-aligned frame at the frame origin.

    Parameters
    ----------
    q : (M, nq) float

    Returns
    -------
    R : (3, 3, M) float
        World rotation of the frame, R[:, c] its column c (component-major for speed).
    p : (3, M) float
        World position of the frame, m.
    J : (M, 6, nq) float
        Rows 0-2: linear velocity of the frame origin (world axes); rows 3-5: angular velocity (world
        axes), per unit joint velocity. Pinocchio calls this LOCAL_WORLD_ALIGNED. A passive joint adds
        its multiplier times its own column to the column of the joint it follows.
    """
    q = np.asarray(q, dtype=float)
    T, aligned = _walk(chain, q)
    J = np.zeros((q.shape[0], 6, chain.nq))
    p = T[3]
    for i, Ti in enumerate(aligned):
        w = Ti[2] * chain.scale[i] if not chain.active[i] else Ti[2]
        col = chain.q_index[i]
        if chain.revolute[i]:
            r = p - Ti[3]
            J[:, 0, col] += w[1] * r[2] - w[2] * r[1]
            J[:, 1, col] += w[2] * r[0] - w[0] * r[2]
            J[:, 2, col] += w[0] * r[1] - w[1] * r[0]
            J[:, 3:, col] += w.T
        else:
            J[:, :3, col] += w.T
    return T[:3].transpose(1, 0, 2), p, J


@dataclass(frozen=True, slots=True, eq=False)
class JointAxes:
    """The chain to a frame at q = 0, in the root frame: unit joint axes (k, 3) (a prismatic joint's:
    the way it slides), their origins (k, 3), the frame's pose (4, 4), and per axis whether it turns
    (k,) and its index in q (k,)."""

    u: FloatArray
    p: FloatArray
    T_flange: FloatArray
    revolute: BoolArray
    q_index: tuple[int, ...]


def joint_axes_at_zero(model: pin.Model, frame_id: int) -> JointAxes:
    """The active joint axes and origins of the chain to `frame_id` at q = 0 (for fitting and reach
    bounds); passive joints on the chain are left out (their turn at q = 0 is their offset)."""
    chain = chain_to_frame(model, frame_id)
    F = joint_frames(chain, np.zeros((1, model.nq)))[0]
    act = active_positions(chain)
    u = np.array([F[i, :3, :3] @ chain.A[i, :3, 2] for i in act])
    p = np.array([F[i, :3, 3] for i in act])
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.zeros(model.nq))
    return JointAxes(u / np.linalg.norm(u, axis=1, keepdims=True), p, np.asarray(data.oMf[frame_id].homogeneous),
                     np.array([bool(chain.revolute[i]) for i in act], dtype=bool), tuple(chain.q_index[i] for i in act))
