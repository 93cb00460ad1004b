"""A program to show: joint samples on the program's clock, its phases by kind, and its spots.

`load_program` reads what `robomax plan` writes:

- `.srcl`: parsed and rebuilt (`rebuild.rebuild`, the motion `verify` checks); the phases are the
  rebuilt segments' kinds, and a PTP run the program comments as a detour is drawn as "detour".
- a controller program (KRL `.src`, RAPID `.mod`, FANUC `.ls`, URScript, INFORM, AS): read and
  rebuilt as `verify` reads it (`verify.rebuild_read`: the controller's joint counting and frames),
  its phases as for `.srcl`.
- `.json` (docs/cell-files.md, "The trajectory file"): the file holds samples and spots, not phases, so phases are recovered:
  "weld" during each spot's [t_arrive, t_leave]; "approach" / "retract" while the TCP is within the
  approach distance of the spot just before / after it; "wait" where the robot stands still outside
  welds; the remaining motion is "move", or "detour" where it strays from the straight joint-space
  line between its ends by more than DETOUR_DEVIATION_RAD (the planner's PTP moves are straight in
  joint space up to their fly-by corners).

A program of another cell or robot is bad input (ProgramError), as is a file of another extension.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import ProgramError
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.safe_files import LIMITS, read_text
from robomax_py.spec import CellSpec, frozen_array
from robomax_py.timing.trajectory import Phase
from robomax_py.tolerances import DEFAULT as TOL

if TYPE_CHECKING:
    from robomax_py.export.rebuild import Rebuilt

# A move straying further than this (rad, any joint) from its joint-space chord is a detour.
DETOUR_DEVIATION_RAD = 0.05
# A stand-still outside welds shorter than this (s) is a stop between moves, not a wait.
MIN_WAIT_S = 0.02
# Joint change (rad) below which consecutive samples count as standing still.
REST_TOL_RAD = TOL.preview_rest_tol_rad
# Slack (m) on the approach distance when recovering approach/retract phases of a .json file.
APPROACH_SLACK_M = 1e-4



@dataclass(frozen=True, slots=True)
class ShownSpot:
    """A welded spot: seam, name and its weld window on the program's clock, s."""

    seam: str
    name: str
    t_arrive: float
    t_leave: float


@dataclass(frozen=True, slots=True, eq=False)
class ShownProgram:
    """Motion to show.

    Attributes
    ----------
    name : str
        The program file (or "home" when there is none).
    t : (k,) float
        Sample times, s, strictly increasing, starting at 0.
    q : (k, n) float
        Joint values, rad (m for prismatic joints); linear between samples (docs/cell-files.md, "The trajectory file").
    phases : tuple of Phase
        Contiguous, in time order, covering [t[0], t[-1]]; empty for a single sample.
    spots : tuple of ShownSpot
        In weld order.
    """

    name: str
    t: FloatArray
    q: FloatArray
    phases: tuple[Phase, ...]
    spots: tuple[ShownSpot, ...]

    @property
    def duration(self) -> float:
        """Cycle time, s."""
        return float(self.t[-1] - self.t[0])

    def q_at(self, times: FloatArray) -> FloatArray:
        """(m, n) joint values at `times` (s, clipped to the program), linear between samples."""
        tq = np.clip(np.asarray(times, dtype=float), self.t[0], self.t[-1])
        if len(self.t) == 1:
            return np.repeat(self.q[:1], len(tq), axis=0)
        return np.stack([np.interp(tq, self.t, self.q[:, j]) for j in range(self.q.shape[1])], axis=1)


def home_program(cell: CellSpec) -> ShownProgram:
    """The robot standing at `robot.home`: one sample, no phases, no spots."""
    return ShownProgram("home", frozen_array([0.0]), frozen_array(np.asarray(cell.home, dtype=float)[None, :]), (), ())


def load_program(path: Path, cell: CellSpec, robot: RobotModel) -> ShownProgram:
    """Read a `.json` trajectory or a `.srcl` program written by `robomax plan` for this cell.

    Raises
    ------
    ProgramError
        Missing or unreadable file, another extension, a program of another cell or robot, or a
        `.srcl` program whose motion cannot be rebuilt.
    """
    from robomax_py.export import DIALECTS, dialect_for_file

    suffix = path.suffix.lower()
    if suffix != ".json" and dialect_for_file(suffix) is None:
        known = ", ".join(sorted({e for d in DIALECTS.values() for e in d.extensions}))
        raise ProgramError(path, None, f"expected a trajectory file (.json) or a program ({known}), got "
                           f"'{path.suffix}'")
    if not path.is_file():
        raise ProgramError(path, None, "program file not found")
    if suffix == ".json":
        return _load_json(path, cell, robot)
    if suffix == ".srcl":
        return _load_srcl(path, cell, robot)
    return _load_controller_program(path, cell, robot)


def _load_json(path: Path, cell: CellSpec, robot: RobotModel) -> ShownProgram:
    from robomax_py.export.trajectory_json import load_trajectory_file

    stated = _peek_json(path).get("robot", robot.name)
    if stated != robot.name:
        raise ProgramError(path, "robot", f"program is for robot {stated!r}, the cell uses {robot.name!r}")
    data = load_trajectory_file(path, robot)
    if data.get("cell", cell.name) != cell.name:
        raise ProgramError(path, "cell", f"program is for cell {data['cell']!r}, not {cell.name!r}")
    t = np.asarray(data["t"], dtype=float)
    t = t - t[0]
    q = np.asarray(data["q"], dtype=float)
    spots = tuple(
        ShownSpot(str(s["seam"]), str(s["name"]), float(s["t_arrive"]), float(s["t_leave"])) for s in data["spots"]
    )
    phases = infer_phases(t, q, spots, robot, cell.process.approach)
    return ShownProgram(str(path), frozen_array(t), frozen_array(q), phases, spots)


def _peek_json(path: Path) -> dict[str, Any]:
    """The top-level object of a JSON file, or {} when it is not one (load_trajectory_file reports why)."""
    import json

    try:
        data = json.loads(read_text(path, LIMITS.program, ProgramError, "program file"))
    except (ProgramError, ValueError, RecursionError):
        return {}
    return data if isinstance(data, dict) else {}


def _load_srcl(path: Path, cell: CellSpec, robot: RobotModel) -> ShownProgram:
    from robomax_py.export.rebuild import rebuild
    from robomax_py.export.srcl import parse_program

    program = parse_program(read_text(path, LIMITS.program, ProgramError, "program file",
                                      max_lines=LIMITS.program_lines), path)
    if program.header.cell != cell.name:
        raise ProgramError(path, "CELL", f"program is for cell {program.header.cell!r}, not {cell.name!r}")
    return _shown(path, rebuild(program, cell, robot, path))


def _load_controller_program(path: Path, cell: CellSpec, robot: RobotModel) -> ShownProgram:
    from robomax_py.verify import read_program_files, rebuild_read

    # A KRL program comments a move on the line before it, so its rebuilt moves are named by their
    # statements alone: a detour is told by its via points instead.
    return _shown(path, rebuild_read(cell, robot, read_program_files(robot, path)), via_points=True)


def _shown(path: Path, rebuilt: Rebuilt, via_points: bool = False) -> ShownProgram:
    """A rebuilt program's motion (`export.rebuild.Rebuilt`) as shown, or why it has none."""
    if rebuilt.trajectory is None:
        first = rebuilt.problems[0] if rebuilt.problems else None
        why = "" if first is None else f": {first.kind}: {first.detail}"
        raise ProgramError(path, None, f"the program's motion cannot be rebuilt{why}")
    traj = rebuilt.trajectory
    t0 = float(traj.t[0])
    phases = _mark_detours(tuple(
        Phase(p.kind, p.label, p.t_start - t0, p.t_end - t0, p.i_start, p.i_end) for p in traj.phases
    ), via_points)
    spots = tuple(
        ShownSpot(str(s["seam"]), str(s["name"]), float(s["t_arrive"]) - t0, float(s["t_leave"]) - t0)
        for s in rebuilt.spots
    )
    return ShownProgram(str(path), frozen_array(traj.t - t0), frozen_array(traj.q), phases, spots)


def _mark_detours(phases: tuple[Phase, ...], via_points: bool = False) -> tuple[Phase, ...]:
    """PTP runs ("move"/"blend" phases in a row) whose comment names a detour become "detour"; with
    `via_points`, also those of more than one move (the planner joins two spots directly by one
    move, and goes round through via points, each a move of its own)."""
    out = list(phases)
    i = 0
    while i < len(out):
        if out[i].kind not in ("move", "blend"):
            i += 1
            continue
        j = i
        while j < len(out) and out[j].kind in ("move", "blend"):
            j += 1
        if any("detour" in p.label for p in out[i:j]) or (
                via_points and sum(p.kind == "move" for p in out[i:j]) > 1):
            for k in range(i, j):
                p = out[k]
                out[k] = Phase("detour", p.label, p.t_start, p.t_end, p.i_start, p.i_end)
        i = j
    return tuple(out)


def infer_phases(
    t: FloatArray, q: FloatArray, spots: tuple[ShownSpot, ...], robot: RobotModel, approach: float
) -> tuple[Phase, ...]:
    """Phases of a sampled program that carries none (see the module docstring for the rules).

    Parameters
    ----------
    t : (k,) float
        Sample times, s, strictly increasing.
    q : (k, n) float
        Joint values, rad; `robot` has its tool mounted (the TCP is the tool's).
    approach : float
        The cell's approach distance, m.

    Returns
    -------
    tuple of Phase
        Contiguous, covering [t[0], t[-1]]; () for a single sample.
    """
    k = len(t)
    if k < 2:
        return ()
    kinds = np.array(["move"] * (k - 1), dtype=object)     # kind of the interval [t[i], t[i+1]]
    labels = np.array([""] * (k - 1), dtype=object)
    still = np.max(np.abs(np.diff(q, axis=0)), axis=1) <= REST_TOL_RAD
    # Stand-stills outside welds long enough to be waits.
    i = 0
    while i < k - 1:
        if not still[i]:
            i += 1
            continue
        j = i
        while j < k - 1 and still[j]:
            j += 1
        if t[j] - t[i] >= MIN_WAIT_S:
            kinds[i:j] = "wait"
        i = j
    T = fk_tcp(robot, q)
    p = T[:, :3, 3]
    for s in spots:
        a = int(np.argmin(np.abs(t - s.t_arrive)))
        b = int(np.argmin(np.abs(t - s.t_leave)))
        label = f"{s.seam}/{s.name}"
        kinds[a:b] = "weld"
        labels[a:b] = label
        # Approach and retract: within the approach distance, or on the electrode axis beyond it
        # (the lines are continued there where a fly-by joins them).
        rel = p - p[a]
        along = rel @ T[a, :3, 2]
        off = np.linalg.norm(rel - along[:, None] * T[a, :3, 2], axis=1)
        near = (np.linalg.norm(rel, axis=1) <= approach + APPROACH_SLACK_M) | ((off <= APPROACH_SLACK_M) & (along >= 0))
        i = a
        while i > 0 and near[i - 1] and kinds[i - 1] in ("move", "wait"):
            i -= 1
        kinds[i:a] = "approach"
        labels[i:a] = label
        j = b
        while j < k - 1 and near[j + 1] and kinds[j] in ("move", "wait"):
            j += 1
        kinds[b:j] = "retract"
        labels[b:j] = label
    phases = _group(t, kinds, labels)
    return tuple(_detour_or_move(ph, q) for ph in phases)


def _group(t: FloatArray, kinds: Any, labels: Any) -> list[Phase]:
    out: list[Phase] = []
    start = 0
    for i in range(1, len(kinds) + 1):
        if i == len(kinds) or kinds[i] != kinds[start] or labels[i] != labels[start]:
            out.append(Phase(str(kinds[start]), str(labels[start]), float(t[start]), float(t[i]), start, i))
            start = i
    return out


def _detour_or_move(phase: Phase, q: FloatArray) -> Phase:
    if phase.kind != "move" or phase.i_end - phase.i_start < 2:
        return phase
    seg = q[phase.i_start:phase.i_end + 1]
    d = seg[-1] - seg[0]
    length2 = float(d @ d)
    u = np.zeros(len(seg)) if length2 <= 0.0 else np.clip((seg - seg[0]) @ d / length2, 0.0, 1.0)
    off_line = seg - (seg[0] + u[:, None] * d)          # distance from the chord, not along it
    if float(np.max(np.abs(off_line))) > DETOUR_DEVIATION_RAD:
        return Phase("detour", phase.label, phase.t_start, phase.t_end, phase.i_start, phase.i_end)
    return phase


__all__ = [
    "DETOUR_DEVIATION_RAD",
    "ShownProgram",
    "ShownSpot",
    "home_program",
    "infer_phases",
    "load_program",
]
