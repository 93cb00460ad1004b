"""A Bézier TCP path (`timing.bezier`) followed by an arm in joint space and checked.

The planar path lies in a horizontal plane at height z of the robot's base frame, the TCP's
orientation fixed. The profile is sampled on a time grid (constant acceleration between its
points, as its clock is integrated); each sample's pose is solved by IK in the
branch of the sample before (the solution nearest it, so the arm never jumps branch), and the joint
motion is checked: position, velocity and acceleration limits by finite differences of the samples,
the TCP on the path (forward kinematics against the sampled pose), and every straight joint step
between samples free of collision in the cell's world. The outcome says which check failed first.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.robot.ik.turns import wrap_to_pi
from robomax_py.robot.solve import solve_all
from robomax_py.timing.bezier import Profile
from robomax_py.world.collision import CollisionWorld

SAMPLE_DT_S = 0.004
# A profile too fast for the joints is stretched at most this often, each time by the factor its
# peaks ask for times STRETCH_MARGIN.
MAX_STRETCHES = 8
STRETCH_MARGIN = 1.02


@dataclass(frozen=True, slots=True)
class Followed:
    """The arm's motion along a profile: samples t (k,) s and q (k, n) rad; `problem` is None when
    every check passed, else what failed first; the peaks are fractions of the joint limits;
    `slowdown` the factor (>= 1) the profile's clock was stretched by to keep the joint limits."""

    t: FloatArray
    q: FloatArray
    problem: str | None
    tcp_error_m: float
    velocity_ratio: float
    acceleration_ratio: float
    collision_checks: int
    slowdown: float = 1.0

    @property
    def ok(self) -> bool:
        return self.problem is None


def follow_within_limits(profile: Profile, robot: RobotModel, world: CollisionWorld, z: float,
                         R_tcp: FloatArray, q_start: FloatArray, dt: float = SAMPLE_DT_S) -> Followed:
    """`follow`, and where the joints' speed or acceleration limits are broken, the profile's clock
    stretched by the factor that keeps them (speeds scale with 1/k, accelerations with 1/k^2) and
    followed again: the TCP limits then hold a fortiori."""
    out = follow(profile, robot, world, z, R_tcp, q_start, dt)
    total = 1.0
    for _ in range(MAX_STRETCHES):
        k = max(out.velocity_ratio, float(np.sqrt(out.acceleration_ratio)))
        if out.problem is None or not np.isfinite(k) or k <= 1.0:
            break
        k *= STRETCH_MARGIN
        total *= k
        profile = Profile(profile.s, profile.v / k, profile.t * k, profile.points)
        out = follow(profile, robot, world, z, R_tcp, q_start, dt)
    return Followed(out.t, out.q, out.problem, out.tcp_error_m, out.velocity_ratio, out.acceleration_ratio,
                    out.collision_checks, total)


def follow(profile: Profile, robot: RobotModel, world: CollisionWorld, z: float, R_tcp: FloatArray,
           q_start: FloatArray, dt: float = SAMPLE_DT_S) -> Followed:
    """The profile's path at height z (base frame, m) with the TCP rotation R_tcp, from the branch of
    q_start (a configuration at or near the path's start)."""
    t = np.arange(0.0, profile.duration + dt / 2, dt)
    t[-1] = min(t[-1], profile.duration)
    s = arclength_at(profile, t)
    xy = np.column_stack([np.interp(s, profile.s, profile.points[:, j]) for j in range(2)])
    T = np.repeat(np.eye(4)[None], len(t), axis=0)
    T[:, :3, :3] = R_tcp
    T[:, :2, 3] = xy
    T[:, 2, 3] = z
    table = solve_all(robot, T)
    q = np.zeros((len(t), robot.dof))
    prev = np.asarray(q_start, dtype=float)
    for k in range(len(t)):
        valid = table.valid[k]
        if not valid.any():
            return _failed(t, q[:k], f"no IK solution at t = {t[k]:.3f} s ({xy[k, 0]:.3f}, {xy[k, 1]:.3f}) m")
        cand = table.q[k][valid]
        step = np.abs(wrap_to_pi(cand - prev)).max(axis=1)
        prev = prev + wrap_to_pi(cand[int(np.argmin(step))] - prev)
        q[k] = prev
    err = float(np.linalg.norm(fk_tcp(robot, q)[:, :3, 3] - T[:, :3, 3], axis=1).max())
    lim = robot.limits
    v = np.diff(q, axis=0) / dt
    a = np.diff(v, axis=0) / dt
    v_ratio = float(np.max(np.abs(v) / lim.velocity)) if len(v) else 0.0
    a_ratio = float(np.max(np.abs(a) / lim.acceleration)) if len(a) else 0.0
    problem = None
    if not bool(lim.contains(q).all()):
        problem = "a joint leaves its limits"
    elif v_ratio > 1.0:
        problem = f"a joint's speed reaches {v_ratio:.2f} x its limit"
    elif a_ratio > 1.0:
        problem = f"a joint's acceleration reaches {a_ratio:.2f} x its limit"
    checks = 0
    if problem is None:
        for k in range(len(t) - 1):
            res = world.check_segment(q[k], q[k + 1])
            checks += res.checks
            if not res.free:
                problem = f"collision at t = {t[k]:.3f} s"
                break
    return Followed(t, q, problem, err, v_ratio, a_ratio, checks)


def arclength_at(profile: Profile, t: FloatArray) -> FloatArray:
    """s(t) of the profile with v^2 linear in s between its points (a constant acceleration on each
    interval, which is what its clock `profile.t` integrates), m."""
    i = np.clip(np.searchsorted(profile.t, t, side="right") - 1, 0, len(profile.t) - 2)
    ds = np.diff(profile.s)[i]
    v0, v1 = profile.v[i], profile.v[i + 1]
    a = (v1**2 - v0**2) / (2.0 * ds)
    tau = np.clip(t - profile.t[i], 0.0, profile.t[i + 1] - profile.t[i])
    return np.minimum(profile.s[i] + v0 * tau + 0.5 * a * tau**2, profile.s[i + 1])


def _failed(t: FloatArray, q: FloatArray, why: str) -> Followed:
    return Followed(t[: len(q)], q, why, float("nan"), float("nan"), float("nan"), 0)
