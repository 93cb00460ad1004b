"""Verify a station: the programs of its robots, any dialect each, replayed together on one clock as
their controllers run them, and what each does alone.

`verify_station(members)` reads each robot's program as `verify` does and rebuilds its motion
alone (`export.rebuild`), the waits for and settings of signals between robots as events at rest;
replays them on one clock (`replay`: a wait holds the robot until another robot's program has set
the signal; a clamp's input that no robot sets counts as set, as a lone program's verify takes it);
poses every pair of robots at the same moments (`world.robot_pairs`, coal: links and tools) on
every sample time of any robot's motion on the station clock (<= 10 ms apart) and sweeps them
between those (linear in joint space, as a trajectory's samples are taken; every contact deeper
than the collision world's 2 mm step is found); and reports, as
typed values: contacts between robots (each stretch of contact of a pair, with when it starts and
ends and the pieces that touch first), each program's own violations (its lone verify: cell
objects, limits, spots, home), and robots that wait forever (a deadlock: each waits for a signal
that a robot held itself would set; or a signal that no robot sets). Each robot's timeline (moving,
welding, waiting for which signal of which robot) comes with it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import ProgramError
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.verify import VerifyReport, read_program_files, verify_read
from robomax_py.verify_station.replay import Hold, Stuck, replay
from robomax_py.verify_station.timeline import (
    Activity,
    StationMotion,
    station_motion,
    timeline,
)

# Between samples, a contact shallower than this may pass (the collision world's swept bound).
SWEEP_STEP_M = TOL.sweep_step_m

__all__ = ["Activity", "Hold", "MemberReport", "RobotCollision", "StationMember", "StationReport", "Stuck",
           "verify_station"]


@dataclass(frozen=True, slots=True, eq=False)
class StationMember:
    """A robot of the station: its name, its cell view (a single-robot cell: its placement, tool,
    spots, controller), its robot model (tool mounted) and its program file (any dialect)."""

    name: str
    cell: CellSpec
    robot: RobotModel
    program: Path


@dataclass(frozen=True, slots=True)
class RobotCollision:
    """Robots `robot_a` and `robot_b` in contact from `t_start` to `t_end` (s, station clock; sample
    times), first between `piece_a` and `piece_b`."""

    robot_a: str
    robot_b: str
    t_start: float
    t_end: float
    piece_a: str
    piece_b: str


@dataclass(frozen=True, slots=True, eq=False)
class MemberReport:
    """One robot: its program's own verify, its timeline and motion on the station clock, when
    its program ends there (None: it waits forever, or its motion could not be rebuilt)."""

    name: str
    report: VerifyReport
    timeline: tuple[Activity, ...]
    motion: StationMotion | None
    end: float | None


@dataclass(frozen=True, slots=True, eq=False)
class StationReport:
    members: tuple[MemberReport, ...]
    collisions: tuple[RobotCollision, ...]
    stuck: tuple[Stuck, ...]
    makespan: float                    # s, when the last program that ends ends
    samples: int                       # station clock times at which the robots were posed together
    unwelded: tuple[tuple[str, str], ...] = ()     # station spots (seam, spot) no program welds
    repeated: tuple[tuple[str, str], ...] = ()     # station spots welded by more than one program

    @property
    def deadlock(self) -> bool:
        """Robots wait for one another."""
        return any(s.setters for s in self.stuck)

    @property
    def clean(self) -> bool:
        return not (self.collisions or self.stuck or self.unwelded or self.repeated) and \
            all(m.report.clean for m in self.members)

    def idle_share(self, robot: str) -> float:
        """The share of the makespan the robot is idle (0..1): waiting for another robot's signal,
        or done while others still work; its own program's time (moves, welds, its own dwells)
        is not idle. As the station plan counts it: (makespan - own cycle) / makespan."""
        member = next(m for m in self.members if m.name == robot)
        if self.makespan <= 0:
            return 0.0
        busy = sum(max(0.0, min(a.t_end, self.makespan) - a.t_start) for a in member.timeline
                   if not (a.kind == "waiting" and a.signal))
        return max(0.0, 1.0 - busy / self.makespan)


def verify_station(members: Sequence[StationMember], margin: float = 0.0,
                   spots: Sequence[tuple[str, str]] = ()) -> StationReport:
    """Replay the members' programs together (see the module docstring); `margin` m: robots closer
    than this count as in contact; `spots`: the station's (seam, spot), each to be welded by one
    program exactly (each program's own verify checks the spots of its cell view). ProgramError
    when a program cannot be read (bad input)."""
    from robomax_py.export.rebuild.signals import output_signal
    from robomax_py.program import SetSignal, Spot, identifier
    from robomax_py.world.robot_pairs import robot_body
    from robomax_py.world.scene import build_scene

    names = [m.name for m in members]
    if len(set(names)) != len(names):
        raise ProgramError("station", None, f"robot names must be unique, got {names}")
    reads = [read_program_files(m.robot, m.program) for m in members]
    # The signals the programs set, by the cell's names (their outputs read through robot.controller.outputs).
    driven = frozenset(s for m, r in zip(members, reads) for ins in r[2].program.instructions
                       if isinstance(ins, SetSignal) for s in [output_signal(m.cell, ins)] if s is not None)
    alone: list[tuple[VerifyReport, Any]] = [verify_read(m.cell, m.robot, m.program, r, station=driven)
                                              for m, r in zip(members, reads)]
    timed = {m.name: (rebuilt.events, float(rebuilt.trajectory.t[-1] - rebuilt.trajectory.t[0]))
             for m, (_, rebuilt) in zip(members, alone) if rebuilt is not None and rebuilt.trajectory is not None}
    result = replay(timed)
    until = max([result.makespan, *(s.t for s in result.stuck)])
    out: list[MemberReport] = []
    motions: dict[str, StationMotion] = {}
    for m, (report, rebuilt) in zip(members, alone):
        if m.name not in timed:
            out.append(MemberReport(m.name, report, (), None, None))
            continue
        stuck = next((s for s in result.stuck if s.robot == m.name), None)
        holds = result.holds[m.name]
        stuck_at = None if stuck is None else stuck.t - sum(h.seconds for h in holds)
        motions[m.name] = station_motion(rebuilt.trajectory, holds, stuck_at)
        out.append(MemberReport(m.name, report,
                                timeline(rebuilt.trajectory, holds, stuck_at, stuck.signal if stuck else "", until),
                                motions[m.name], result.ends.get(m.name)))
    bodies = {m.name: robot_body(m.name, m.robot, build_scene(m.cell, m.robot)) for m in members if m.name in motions}
    grid = _grid(list(motions.values()), until)
    collisions = _collisions(bodies, motions, grid, margin)
    welded = [(ins.seam, ins.name) for r in reads for ins in r[2].program.instructions if isinstance(ins, Spot)]
    # A program names a spot as an identifier of the dialect (`identifier`: a seam called seam is seam_).
    written = [(identifier(a), identifier(b)) for a, b in spots]
    unwelded = tuple(k for k, w in zip(spots, written) if w not in welded)
    repeated = tuple(k for k, w in zip(spots, written) if welded.count(w) > 1)
    return StationReport(tuple(out), tuple(collisions), result.stuck, result.makespan, len(grid), unwelded, repeated)


def _grid(motions: list[StationMotion], until: float) -> FloatArray:
    """Every sample time of any robot's motion on the station clock, up to `until` (s)."""
    if not motions:
        return np.zeros(0)
    t = np.unique(np.concatenate([m.t for m in motions] + [np.array([0.0, until])]))
    return t[t <= until + 1e-9]


def _collisions(bodies: dict[str, Any], motions: dict[str, StationMotion], grid: FloatArray,
                margin: float) -> list[RobotCollision]:
    """Each stretch of contact of each pair of robots: posed at the grid's times, and between two
    times where they are apart swept as both move (linearly in joint space between samples, as the
    trajectory file's motion is taken), to `SWEEP_STEP_M`."""
    from robomax_py.world.robot_pairs import robots_contact, swept_contact

    names = list(motions)
    qs = {n: motions[n].at(grid) for n in names}
    out: list[RobotCollision] = []
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            ba, bb, qa, qb = bodies[a], bodies[b], qs[a], qs[b]
            hits = [robots_contact(ba, qa[k], bb, qb[k], margin) for k in range(len(grid))]
            found: list[tuple[float, Any]] = [(float(t), h) for t, h in zip(grid, hits)]
            for k in range(len(grid) - 1):
                if hits[k] is None and hits[k + 1] is None:
                    inner = swept_contact(ba, (qa[k], qa[k + 1]), bb, (qb[k], qb[k + 1]), margin, SWEEP_STEP_M)
                    if inner is not None:
                        found.append((float(grid[k] + inner[0] * (grid[k + 1] - grid[k])), inner[1]))
            out += _stretches(a, b, sorted(found, key=lambda x: x[0]))
    return out


def _stretches(a: str, b: str, found: list[tuple[float, Any]]) -> list[RobotCollision]:
    """The stretches of contact in time-ordered (t, contact or None)."""
    out: list[RobotCollision] = []
    open_: tuple[float, str, str] | None = None
    last = 0.0
    for t, contact in found:
        if contact is not None and open_ is None:
            open_ = (t, contact.piece_a, contact.piece_b)
        elif contact is None and open_ is not None:
            out.append(RobotCollision(a, b, open_[0], last, open_[1], open_[2]))
            open_ = None
        last = t
    if open_ is not None:
        out.append(RobotCollision(a, b, open_[0], last, open_[1], open_[2]))
    return out
