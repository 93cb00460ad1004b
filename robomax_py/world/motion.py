"""Sampled motion against the robot's limits and the world: the one check the planner runs on its
own trajectory before anything is written and `robomax verify` runs on a program's rebuilt motion."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.robot import RobotModel
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.world.collision import CollisionWorld

# Finite differences of 10 ms samples: velocity is exact for the linear interpolation the SPEC
# prescribes; acceleration from second differences of a jerk-limited profile overshoots the
# sampled peak slightly, hence the larger slack.
VELOCITY_RTOL = TOL.velocity_rtol
ACCELERATION_RTOL = TOL.acceleration_rtol
MAX_REPORTED_COLLISIONS = 20


@dataclass(frozen=True, slots=True)
class Violation:
    t: float | None
    kind: str                # collision | joint_limit | velocity | acceleration | spot | dwell | order | home | format
    #                          (.srcl also: lin | config | flyby | frame | signal | timing)
    detail: str
    line: int | None = None  # the program line whose statement commands the motion then
    t_end: float | None = None  # the end of the interval it lasts (s); None: an instant


@dataclass(frozen=True, slots=True)
class MotionCheck:
    """What `check_motion` found: violations (empty when clean) and collision checks spent."""

    violations: tuple[Violation, ...]
    checks: int

    @property
    def clean(self) -> bool:
        return not self.violations


def check_motion(
    world: CollisionWorld, robot: RobotModel, t: FloatArray, q: FloatArray,
    max_collisions: int = MAX_REPORTED_COLLISIONS, stop_at_first: bool = False,
    velocity_rtol: float = VELOCITY_RTOL,
) -> MotionCheck:
    """Limits and swept collisions of sampled motion, linear in joint space between samples.

    Parameters
    ----------
    t : (k,) float, s, strictly increasing
    q : (k, n) float, rad

    velocity_rtol : relative slack on the velocity limits (the planner's own check is tighter).

    Returns
    -------
    MotionCheck
        The violations (collisions in time order, at most `max_collisions`; with `stop_at_first`,
        at most one violation and no collision check once a limit is broken) and the number of
        collision checks spent.
    """
    lim = robot.limits
    out: list[Violation] = []
    outside = ~lim.contains(q, 1e-9)
    for i in np.flatnonzero(outside)[:5]:
        j = int(np.flatnonzero((q[i] < lim.lower - 1e-9) | (q[i] > lim.upper + 1e-9))[0])
        out.append(Violation(float(t[i]), "joint_limit", f"{robot.joint_names[j]} = {math.degrees(q[i, j]):.3f} deg"))
    dt = np.diff(t)
    v = np.diff(q, axis=0) / dt[:, None]
    for i, j in np.argwhere(np.abs(v) > lim.velocity * (1 + velocity_rtol))[:5]:
        out.append(Violation(float(t[i]), "velocity", f"{robot.joint_names[j]} {abs(v[i, j]):.3f} rad/s > "
                                                      f"{lim.velocity[j]:.3f}"))
    a = np.diff(v, axis=0) / ((dt[:-1] + dt[1:]) / 2)[:, None]
    for i, j in np.argwhere(np.abs(a) > lim.acceleration * (1 + ACCELERATION_RTOL))[:5]:
        out.append(Violation(float(t[i + 1]), "acceleration", f"{robot.joint_names[j]} {abs(a[i, j]):.3f} rad/s^2 > "
                                                              f"{lim.acceleration[j]:.3f}"))
    if stop_at_first and out:
        return MotionCheck(tuple(out[:1]), 0)
    checks = 0
    collisions = 0
    limit = 1 if stop_at_first else max_collisions
    for i in range(len(t) - 1):
        res = world.check_segment(q[i], q[i + 1], float(t[i]), float(t[i + 1]))
        checks += res.checks
        if not res.free:
            s_hit = res.s_contact or 0.0
            tc = float(t[i] + s_hit * (t[i + 1] - t[i]))
            contact = world.first_contact(q[i] + s_hit * (q[i + 1] - q[i]), tc)
            out.append(Violation(tc, "collision", contact.describe() if contact else "collision"))
            collisions += 1
            if collisions >= limit:
                break
    return MotionCheck(tuple(out), checks)
