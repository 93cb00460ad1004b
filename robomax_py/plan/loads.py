"""What the robot carries on each move of a pick-and-place job, and what that changes.

From a grip until the matching release the gripper holds a part: every move in between is checked
with the part attached to the tool (a collision world of its own, `world.scene.build_scene(held=)`)
and timed under the part's limits (the joint limits for its mass, `RobotModel.limits_carrying`, and
its TCP limits). Moves are named by the stop they leave: the load after stop i is the part gripped
at i, until a release.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.plan.sequence import HOME
from robomax_py.program import written_speed, written_tcp_speed
from robomax_py.robot import JointLimits, RobotModel, fk_tcp
from robomax_py.spec import CellSpec, SpotSpec, TcpLimits
from robomax_py.timing import Segment
from robomax_py.timing.tcp_motion import TcpPeaks, tcp_peaks, tcp_series
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.motion import (
    MotionCheck,
    Violation,
    check_motion,
    rate_violations,
)
from robomax_py.world.scene import build_scene


@dataclass(frozen=True, slots=True, eq=False)
class Loads:
    """Per stop (the planner's spot index), the part held when the robot leaves it, and per part
    the collision world with it in the gripper."""

    held_after: tuple[str | None, ...]
    worlds: dict[str, CollisionWorld]

    @classmethod
    def of(cls, cell: CellSpec, robot: RobotModel) -> Loads | None:
        """The loads of a pick-and-place cell's stops, numbered as the planner numbers them (every
        seam's spots in order), or None for a cell that carries nothing."""
        if not cell.parts:
            return None
        held: list[str | None] = []
        now: str | None = None
        for spot in (s for seam in cell.seams for s in seam.spots):
            now = spot.part if spot.action == "grip" else None if spot.action == "release" else now
            held.append(now)
        worlds = {p.name: CollisionWorld(robot, build_scene(cell, robot, held=p), cell.process.clearance)
                  for p in cell.parts}
        return cls(tuple(held), worlds)

    def part_after(self, i: int) -> str | None:
        """The part held on leaving stop i (HOME: none)."""
        return None if i == HOME else self.held_after[i]

    def world_after(self, i: int, empty: CollisionWorld) -> CollisionWorld:
        part = self.part_after(i)
        return empty if part is None else self.worlds[part]

    def line_world(self, i: int, empty: CollisionWorld) -> CollisionWorld:
        """The world of stop i's approach and retract line: with the part gripped or released there
        (the part is held on one of the two, and the same line serves both)."""
        return self.world_after(i, empty) if self.held_after[i] is not None else \
            self.world_after(i - 1, empty) if i > 0 and self.held_after[i - 1] is not None else empty


def tcp_limits_after(cell: CellSpec, part: str | None) -> TcpLimits | None:
    """The TCP limits of a move carrying `part` (None: empty): the part's own, else the cell's
    unloaded ones (None: no TCP limits)."""
    if part is not None:
        own = cell.part(part).limits
        if own is not None:
            return own
    return cell.tcp_limits


def joint_limits_after(cell: CellSpec, robot: RobotModel, part: str | None) -> JointLimits:
    return robot.limits if part is None else robot.limits_carrying(cell.part(part).mass)


# A junction over its TCP limits is slowed down and timed again at most this often; each time by the
# factors that would bring its peaks within the limits, times RETIME_MARGIN.
MAX_TCP_RETIMES = 8
RETIME_MARGIN = 0.97


def _floor_percent(fraction: float) -> float:
    """A speed or acceleration fraction rounded down to the whole percent every dialect can state
    (KRL and FANUC TP write whole percents: rounding up would exceed the part's limits)."""
    return max(math.floor(fraction * 100.0 + 1e-9), 1) / 100.0


@dataclass(frozen=True, slots=True)
class LoadOverrides:
    """The overrides a junction is timed and written with: the PTP speed fraction and the
    acceleration fraction of all its moves, lines included (of the robot's unloaded limits; it
    scales the jerk limit too), and the lines' TCP speed (m/s)."""

    speed: float
    accel: float
    tcp_speed: float

    @classmethod
    def of(cls, cell: CellSpec, robot: RobotModel, part: str | None, speed: float, tcp_speed: float) -> LoadOverrides:
        """The overrides carrying `part` (None: nothing) from the plan's `speed` fraction and TCP
        speed: the joint limits for its mass as fractions, the TCP speed capped by its limit."""
        limits = joint_limits_after(cell, robot, part)
        tcp = tcp_limits_after(cell, part)
        v_ratio = float(np.min(limits.velocity / robot.limits.velocity))
        a_ratio = float(min(np.min(limits.acceleration / robot.limits.acceleration),
                            np.min(limits.jerk / robot.limits.jerk)))
        if v_ratio < 1.0:
            speed = _floor_percent(speed * v_ratio)
        accel = _floor_percent(a_ratio) if a_ratio < 1.0 else 1.0
        if tcp is not None and tcp.v < tcp_speed:
            tcp_speed = math.floor(tcp.v * 1000.0) / 1000.0
        return cls(written_speed(speed), accel, written_tcp_speed(tcp_speed))

    def slowed(self, peaks: TcpPeaks, limits: TcpLimits) -> LoadOverrides | None:
        """The overrides that bring a motion with these TCP peaks within the limits, rounded down;
        None when it is within them or nothing can be slowed further. The speed override answers
        the TCP speed, the acceleration override the tangential acceleration, and both the radial
        acceleration (v^2 times the path's curvature, and the joints' acceleration where a straight
        joint move bends the TCP's path); the lines keep their TCP speed (their peaks come from
        accelerating to it)."""
        def ratio(peak: float, limit: float) -> float:
            return 1.0 if peak <= limit else limit / peak

        radial = ratio(peaks.a_R[0], limits.a_R)
        speed = min(ratio(peaks.v[0], limits.v), math.sqrt(radial))
        accel = min(ratio(peaks.a_T[0], limits.a_T), radial)
        if speed >= 1.0 and accel >= 1.0:
            return None
        out = LoadOverrides(_floor_percent(self.speed * speed * RETIME_MARGIN) if speed < 1.0 else self.speed,
                            _floor_percent(self.accel * accel * RETIME_MARGIN) if accel < 1.0 else self.accel,
                            self.tcp_speed)
        return None if out == self else out


def tcp_block_peaks(robot: RobotModel, segments: list[Segment]) -> TcpPeaks:
    """The TCP peaks of segments run end to end (each starts where the one before ends)."""
    ts: list[FloatArray] = []
    qs: list[FloatArray] = []
    t0 = 0.0
    for seg in (seg for seg in segments if len(seg.t) > 1):
        first = 0 if not ts else 1
        ts.append(np.asarray(seg.t[first:]) + t0)
        qs.append(np.asarray(seg.q[first:]))
        t0 += float(seg.t[-1])
    t, q = np.concatenate(ts), np.concatenate(qs)
    keep = np.concatenate([[True], np.diff(t) > 0])
    return tcp_peaks(t[keep], fk_tcp(robot, q[keep])[:, :3, 3])


# Finite differences of 10 ms samples: speeds within 1 %, accelerations within 5 % (as the joints'
# checks, `tolerances`). TCP jerk is reported, not enforced (see `check_carried_motion`).
TCP_SPEED_RTOL = 0.01
TCP_ACCEL_RTOL = 0.05


@dataclass(frozen=True, slots=True, eq=False)
class Hold:
    """A part in the gripper from t_start (the arrival at its grip) to t_end (the departure from
    its release; inf when the motion ends holding it)."""

    t_start: float
    t_end: float
    part: str
    grip: SpotSpec
    release: SpotSpec | None


def holds(cell: CellSpec, spots: list[dict[str, Any]]) -> list[Hold]:
    """Every hold of a written motion, from its spot entries (`seam`, `name`, `t_arrive`,
    `t_leave`, as a trajectory file gives them): from the arrival at a grip to the departure from
    the release that follows it. The part is in the gripper while it closes: the checks take it as
    held."""
    wanted = {(seam.name, s.name): s for seam in cell.seams for s in seam.spots}
    entries = sorted((e for e in spots if (str(e["seam"]), str(e["name"])) in wanted), key=lambda e: float(e["t_arrive"]))
    out: list[Hold] = []
    start: tuple[float, SpotSpec] | None = None
    for e in entries:
        spot = wanted[(str(e["seam"]), str(e["name"]))]
        if spot.action == "grip" and spot.part is not None:
            start = (float(e["t_arrive"]), spot)
        elif spot.action == "release" and start is not None:
            out.append(Hold(start[0], float(e["t_leave"]), str(start[1].part), start[1], spot))
            start = None
    if start is not None:
        out.append(Hold(start[0], math.inf, str(start[1].part), start[1], None))
    return out


def check_carried_motion(
    cell: CellSpec, robot: RobotModel, empty: CollisionWorld, worlds: dict[str, CollisionWorld], t: FloatArray,
    q: FloatArray, spots: list[dict[str, Any]], stop_at_first: bool = False, velocity_rtol: float = TOL.velocity_rtol,
) -> MotionCheck:
    """`world.motion.check_motion` hold by hold: while a part is held, with it in the gripper and
    within the joint limits for its mass and the part's TCP limits (speed, tangential and radial
    acceleration); elsewhere within the unloaded TCP limits, if any. TCP jerk is not checked:
    blended moves are timed by toppra without a jerk limit, so a program cannot promise it."""
    t, q = np.asarray(t, dtype=float), np.asarray(q, dtype=float)
    out: list[Violation] = []
    checks = 0
    p = (np.asarray(cell.T_world_base) @ fk_tcp(robot, q))[:, :3, 3]
    for i0, i1, hold in _runs(t, holds(cell, spots)):
        part = hold.part if hold is not None else None
        res = check_motion(empty if part is None else worlds[part], robot, t[i0:i1 + 1], q[i0:i1 + 1],
                           stop_at_first=stop_at_first, velocity_rtol=velocity_rtol)
        checks += res.checks
        out.extend(dataclasses.replace(v, detail=f"carrying {part}: {v.detail}") if part else v for v in res.violations)
        # The limits of the load apply to its own samples: the run's first sample is the last of the
        # run before (where the robot arrived, decelerating under the limits of that load).
        j0 = i0 + 1 if i0 > 0 and i1 > i0 else i0
        out.extend(_load_limits(cell, robot, part, t[j0:i1 + 1], q[j0:i1 + 1], p[j0:i1 + 1], velocity_rtol))
        if stop_at_first and out:
            break
    out.sort(key=lambda x: (x.t if x.t is not None else -1.0))
    return MotionCheck(tuple(out[:1] if stop_at_first else out), checks)


def _runs(t: FloatArray, spans: list[Hold]) -> list[tuple[int, int, Hold | None]]:
    """(first, last, hold) sample runs of constant load; a run starts on the last sample of the one before."""
    held: list[Hold | None] = [None] * len(t)
    for h in spans:
        for n in np.flatnonzero((t >= h.t_start - 1e-9) & (t <= h.t_end + 1e-9)).tolist():
            held[n] = h
    runs: list[tuple[int, int, Hold | None]] = []
    start = 0
    for i in range(1, len(t) + 1):
        if i == len(t) or held[i] is not held[start]:
            runs.append((start - 1 if runs else start, i - 1, held[start]))
            start = i
    return runs


def _load_limits(cell: CellSpec, robot: RobotModel, part: str | None, t: FloatArray, q: FloatArray, p: FloatArray,
                 velocity_rtol: float) -> list[Violation]:
    """The joint limits for the part's mass and the TCP limits of the load."""
    out: list[Violation] = []
    what = f"carrying {part}" if part else "empty"
    if len(t) < 3:
        return out
    if part is not None:
        mass = cell.part(part).mass
        out.extend(dataclasses.replace(v, detail=f"{what}: {v.detail} (the limit for {mass:g} kg)")
                   for v in rate_violations(joint_limits_after(cell, robot, part), robot.joint_names, t, q, velocity_rtol))
    tcp = tcp_limits_after(cell, part)
    if tcp is None:
        return out
    v_tcp, a_t, a_r = tcp_series(t, p)
    for name, x, limit, rtol, unit in (
        ("v", v_tcp, tcp.v, TCP_SPEED_RTOL, "m/s"),
        ("a_T", a_t, tcp.a_T, TCP_ACCEL_RTOL, "m/s^2"),
        ("a_R", a_r, tcp.a_R, TCP_ACCEL_RTOL, "m/s^2"),
    ):
        worst = np.abs(x)
        if worst.max() > limit * (1 + rtol):
            i = int(np.argmax(worst))
            out.append(Violation(float(t[i]), "tcp_limit", f"{what}: TCP {name} {worst[i]:.3f} {unit} > {limit:g}"))
    return out
