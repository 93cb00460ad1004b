"""The damped-least-squares iterations of `numeric.numeric_ik`, compiled: every seed iterated to its
pose on its own, in one loop.

The arithmetic of the array code it replaced, which iterated all seeds at once (forward
kinematics and the frame Jacobian as `_chain.frame_pose_and_jacobian` states them), one seed at a
time: the array version spent most of its time in numpy's calls on small arrays (a seed's
iteration is a few hundred flops; its 20-odd array calls cost microseconds each), about 3.8 us per
seed and iteration on a seven-joint arm. The 6 x 6 system of each step is solved by Cholesky's
factorisation (J J^T + lambda I is symmetric positive definite for lambda > 0), not LU, so iterates
agree with the array version's to round-off, not to the bit: tests/robot/test_numeric_kernel.py
keeps that version and compares. Compiling it takes about 4 s of CPU, once per machine (the
cache, `robomax_py.jit`), at the first plan of an arm with numeric IK.
"""

from __future__ import annotations

import math

import numpy as np

from robomax_py._typing import BoolArray, FloatArray, IntArray
from robomax_py.jit import kernel

TWO_PI = 2.0 * math.pi


@kernel
def iterate_seeds(K: FloatArray, scale: FloatArray, offset: FloatArray, active: BoolArray, revolute: BoolArray,
                  q_index: IntArray, q: FloatArray, pose_of: IntArray, R_des: FloatArray, p_des: FloatArray,
                  lower: FloatArray, upper: FloatArray, rev_q: BoolArray, max_iterations: int, stop_pos: float,
                  stop_rot: float, max_step: float) -> None:  # pragma: no cover - compiled; see the tests
    """Iterate every row of q (M, nq), in place, towards the flange pose of its pose index.

    K, scale, offset, active, revolute, q_index: the chain (`_chain.Chain`, q_index as an array).
    pose_of : (M,) the pose of each row; R_des (P, 3, 3), p_des (P, 3): the poses.
    lower, upper : (nq,) limits; rev_q : (nq,) which entries of q are revolute.
    A row stops once its position and rotation errors are below stop_pos and stop_rot, after
    max_iterations steps, or where its 6 x 6 system is not positive definite (never seen: it would
    need lambda below round-off), as the array version stops a seed that converged.
    """
    n_joint = revolute.shape[0]
    nq = q.shape[1]
    T = np.empty((4, 3))
    out = np.empty((4, 3))
    aligned = np.empty((n_joint, 4, 3))
    J = np.empty((6, nq))
    A = np.empty((6, 6))
    L = np.empty((6, 6))
    e = np.empty(6)
    y = np.empty(6)
    x = np.empty(6)
    M = np.empty((3, 3))
    dq = np.empty(nq)
    for m in range(q.shape[0]):
        pose = pose_of[m]
        for _ in range(max_iterations):
            # Forward kinematics, columns of the top three rows (`_chain._walk`).
            for c in range(4):
                for r in range(3):
                    T[c, r] = K[0, r, c]
            for i in range(n_joint):
                qi = q[m, q_index[i]]
                if not active[i]:
                    qi = scale[i] * qi + offset[i]
                if revolute[i]:
                    cs, sn = math.cos(qi), math.sin(qi)
                    for r in range(3):
                        x0 = T[0, r]
                        T[0, r] = cs * x0 + sn * T[1, r]
                        T[1, r] = cs * T[1, r] - sn * x0
                else:
                    for r in range(3):
                        T[3, r] += qi * T[2, r]
                aligned[i] = T
                Kn = K[i + 1]
                for j in range(4):
                    for r in range(3):
                        acc = T[0, r] * Kn[0, j]
                        if Kn[1, j] != 0.0:
                            acc += T[1, r] * Kn[1, j]
                        if Kn[2, j] != 0.0:
                            acc += T[2, r] * Kn[2, j]
                        out[j, r] = acc
                for r in range(3):
                    out[3, r] += T[3, r]
                T[:] = out
            # The frame Jacobian at its origin, world-aligned (`_chain.frame_pose_and_jacobian`).
            J[:] = 0.0
            for i in range(n_joint):
                f = scale[i] if not active[i] else 1.0
                w0, w1, w2 = aligned[i, 2, 0] * f, aligned[i, 2, 1] * f, aligned[i, 2, 2] * f
                col = q_index[i]
                if revolute[i]:
                    r0 = T[3, 0] - aligned[i, 3, 0]
                    r1 = T[3, 1] - aligned[i, 3, 1]
                    r2 = T[3, 2] - aligned[i, 3, 2]
                    J[0, col] += w1 * r2 - w2 * r1
                    J[1, col] += w2 * r0 - w0 * r2
                    J[2, col] += w0 * r1 - w1 * r0
                    J[3, col] += w0
                    J[4, col] += w1
                    J[5, col] += w2
                else:
                    J[0, col] += w0
                    J[1, col] += w1
                    J[2, col] += w2
            # Errors: position, and the rotation vector of R_des R^T (near a half turn, its axis
            # from the symmetric part, where sin(theta) carries no direction).
            for i in range(3):
                e[i] = p_des[pose, i] - T[3, i]
                for j in range(3):
                    M[i, j] = R_des[pose, i, 0] * T[0, j] + R_des[pose, i, 1] * T[1, j] + R_des[pose, i, 2] * T[2, j]
            v0 = 0.5 * (M[2, 1] - M[1, 2])
            v1 = 0.5 * (M[0, 2] - M[2, 0])
            v2 = 0.5 * (M[1, 0] - M[0, 1])
            cos = min(1.0, max(-1.0, 0.5 * (M[0, 0] + M[1, 1] + M[2, 2] - 1.0)))
            sin = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
            theta = math.atan2(sin, cos)
            if sin < 1e-6 and cos < 0.0:
                # theta ~ pi: the axis from the symmetric part, (M + M^T) / 2 = cos I + (1 - cos) a a^T.
                best, jb = -1.0, 0
                for i in range(3):
                    aa = max((M[i, i] - cos) / (1.0 - cos), 0.0)
                    if aa > best:
                        best, jb = aa, i
                a_j = math.sqrt(best)
                norm = 0.0
                for i in range(3):
                    y[i] = a_j if i == jb else 0.5 * (M[i, jb] + M[jb, i]) / ((1.0 - cos) * a_j)
                    norm += y[i] * y[i]
                norm = math.sqrt(norm)
                for i in range(3):
                    e[3 + i] = y[i] / norm * theta
            else:
                factor = theta / max(sin, 1e-300) if sin > 1e-12 else 1.0
                e[3], e[4], e[5] = v0 * factor, v1 * factor, v2 * factor
            err_p = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
            err_r = math.sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5])
            if err_p < stop_pos and err_r < stop_rot:
                break
            # Levenberg-Marquardt step: (J J^T + lambda I) x = e, dq = J^T x.
            lam = min(max(1e-2 * (err_p * err_p + err_r * err_r), 1e-10), 1e-1)
            for i in range(6):
                for j in range(i + 1):
                    s = 0.0
                    for k in range(nq):
                        s += J[i, k] * J[j, k]
                    A[i, j] = s
                A[i, i] += lam
            positive = True
            for i in range(6):
                for j in range(i + 1):
                    s = A[i, j]
                    for k in range(j):
                        s -= L[i, k] * L[j, k]
                    if i == j:
                        if s <= 0.0:
                            positive = False
                            break
                        L[i, i] = math.sqrt(s)
                    else:
                        L[i, j] = s / L[j, j]
                if not positive:
                    break
            if not positive:
                break
            for i in range(6):
                s = e[i]
                for k in range(i):
                    s -= L[i, k] * y[k]
                y[i] = s / L[i, i]
            for i in range(5, -1, -1):
                s = y[i]
                for k in range(i + 1, 6):
                    s -= L[k, i] * x[k]
                x[i] = s / L[i, i]
            step = 0.0
            for k in range(nq):
                s = 0.0
                for i in range(6):
                    s += J[i, k] * x[i]
                dq[k] = s
                step = max(step, abs(s))
            shrink = min(1.0, max_step / max(step, 1e-300))
            for k in range(nq):
                # Into the limits: a revolute joint past a limit re-enters a full turn further round
                # where that is inside (else seeds of joints with ±2 pi limits pile up on the limit
                # and stall); then clipped.
                v = q[m, k] + dq[k] * shrink
                if rev_q[k] and v > upper[k] and v - TWO_PI >= lower[k]:
                    v -= TWO_PI
                if rev_q[k] and v < lower[k] and v + TWO_PI <= upper[k]:
                    v += TWO_PI
                q[m, k] = min(max(v, lower[k]), upper[k])
