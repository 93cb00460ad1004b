"""One cell of a batch: the statuses, the batch's options, a cell's outcome and the worker that plans it.

The worker (`plan_cell_file`: load, plan, render) runs in a process of its own, started by the local
process pool (`app.batch_local`) or by a Ray task (`app.batch_ray`); nothing here writes a file.
"""

from __future__ import annotations

import hashlib
import os
import sys
import time
import traceback
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:                     # numpy and the specs are not imported for `robomax batch -h`
    from robomax_py.robot import RobotModel
    from robomax_py.spec import Notice

PLANNED = "planned"
INFEASIBLE = "infeasible"
BAD_INPUT = "bad input"
TIMEOUT = "timeout"
CRASHED = "crashed"
STATUSES = (PLANNED, INFEASIBLE, BAD_INPUT, TIMEOUT, CRASHED)

# Ray: how many times a cell is submitted again after its worker or node was lost (not after the
# cell's own failure, which is its outcome).
RETRIES = 3


@dataclass(frozen=True, slots=True)
class PlanSettings:
    """What every cell of a batch is planned for."""

    method: str = "optimised"        # or a baseline: "published", "teach-in" (plan.METHODS)
    formats: str = "srcl"            # `--format` LIST, as `robomax plan` takes it


@dataclass(frozen=True, slots=True)
class BatchOptions:
    """How to run a batch."""

    # Cells planned at once: local processes (None: the number of CPUs); on Ray, tasks in flight
    # (None: every cell submitted, Ray queues them by the cluster's resources).
    jobs: int | None = None
    timeout: float | None = None     # s of wall time per cell from its start (a Ray task's start); None: no limit
    method: str = "optimised"        # PlanSettings.method
    formats: str = "srcl"            # PlanSettings.formats
    retries: int = RETRIES           # Ray: submissions again after a lost worker or node
    task_memory_mb: float | None = None   # Ray: memory each task declares, MiB; None: `batch_memory.task_memory_mb`

    @property
    def settings(self) -> PlanSettings:
        return PlanSettings(self.method, self.formats)


@dataclass(frozen=True, slots=True)
class CellOutcome:
    """What became of one cell of a batch."""

    file: str                        # the cell file as given
    cell: str                        # the cell's name (the file stem when the file could not be read)
    status: str                      # one of STATUSES
    seconds: float                   # wall time: loading and planning (worker), or until killed / crashed
    cycle_time: float | None = None  # s, planned cells only
    spots: int | None = None         # spots in the cell (None when it could not be read)
    detours: int | None = None       # detours in the plan, planned cells only
    reasons: str = ""                # why it is not planned: failing spots, the file error, the crash
    programs: tuple[tuple[str, str], ...] = ()   # (file name, text) rendered by the worker
    written: tuple[str, ...] = ()    # program files written by the caller
    cell_sha256: str = ""            # the cell file's digest, named by the programs' manifest
    peak_rss_mb: float | None = None  # peak resident memory of the worker's process, MiB (Unix)
    inputs: tuple[tuple[str, str], ...] = ()     # (absolute path, sha256) of every file the plan read
    attempts: int = 1                # Ray: submissions it took (more after a lost worker or node)
    node: str = ""                   # Ray: the address of the node that planned it
    notes: str = ""                  # what to know about a cell that is not a reason: formats passed over, retries
    plan: str = ""                   # the id of the program set written (its manifest's `plan`)
    resumed: bool = False            # --resume: planned by an earlier run, its programs kept
    warnings: tuple[Notice, ...] = ()  # the cell file's likely mistakes (`CellSpec.notices`), cells read only


Worker = Callable[[str, PlanSettings], CellOutcome]


def plan_cell_file(file: str, settings: PlanSettings) -> CellOutcome:
    """The worker: load a cell file, plan it and render its programs (no file is written here).

    Every file it reads is listed, with its sha256, in the outcome's `inputs` (what `--resume`
    compares)."""
    from robomax_py.errors import RobomaxError
    from robomax_py.export import choose_formats, setup_signals
    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.plan import method_options, plan_cell
    from robomax_py.publish import publish
    from robomax_py.safe_files import recording_reads

    t0 = time.perf_counter()
    try:
        with recording_reads() as reads:
            spec = load_cell(file)
            robot = load_cell_robot(spec)
        chosen = choose_formats(settings.formats, robot, setup_signals(spec.controller), spec.source)
        result = plan_cell(spec, robot, method_options(settings.method))
        programs = (tuple(publish(result, spec, robot, chosen.names, method=settings.method)[0].items())
                    if result.status == PLANNED else ())
    except RobomaxError as exc:
        return CellOutcome(file, Path(file).stem, BAD_INPUT, time.perf_counter() - t0, reasons=str(exc))
    seconds = time.perf_counter() - t0
    n_spots = sum(len(seam.spots) for seam in spec.seams)
    if result.status != PLANNED:
        reasons = "; ".join(f"{f.seam}/{f.name}: {f.reason} ({f.detail})" for f in result.failures)
        return CellOutcome(file, spec.name, INFEASIBLE, seconds, spots=n_spots, reasons=reasons or result.message,
                           warnings=spec.notices + robot_notices(robot))
    detours = sum(1 for t in result.transitions if t.kind == "detour")
    return CellOutcome(file, spec.name, PLANNED, seconds, cycle_time=result.cycle_time, spots=n_spots,
                       detours=detours, programs=programs, cell_sha256=spec.digest, inputs=file_digests(reads),
                       notes="; ".join(s.message for s in chosen.skipped),
                       warnings=spec.notices + robot_notices(robot))


def robot_notices(robot: RobotModel) -> tuple[Notice, ...]:
    """The robot's warnings at load (each 'FILE: message', as `check` and `plan` print them, e.g.
    limits derived from the URDF), as notices of that file: a batch counts and prints them with the
    cell file's."""
    from robomax_py.spec import Notice

    out = []
    for warning in robot.warnings:
        file, sep, message = warning.partition(": ")
        out.append(Notice(file, "", message) if sep else Notice(str(robot.source), "", warning))
    return tuple(out)


def file_digests(paths: list[str] | tuple[str, ...]) -> tuple[tuple[str, str], ...]:
    """(path, sha256) of each distinct file, in first-read order; a file gone since is left out."""
    out = []
    for path in dict.fromkeys(paths):
        try:
            with open(path, "rb") as fh:
                out.append((path, hashlib.file_digest(fh, "sha256").hexdigest()))
        except OSError:
            continue
    return tuple(out)


def run_worker(worker: Worker, file: str, settings: PlanSettings,
               env: Mapping[str, str] | None = None) -> CellOutcome:
    """Run a worker in this (a cell's own) process, with `env` set; an exception escaping it (a bug,
    not a user's mistake) becomes a `crashed` outcome."""
    os.environ.update(env or {})
    t0 = time.perf_counter()
    try:
        outcome = worker(file, settings)
    except Exception as exc:  # noqa: BLE001 - reported per cell; the batch goes on
        where = traceback.extract_tb(exc.__traceback__)[-1]
        detail = f"{type(exc).__name__}: {exc} (at {Path(where.filename).name}:{where.lineno})"
        outcome = CellOutcome(file, Path(file).stem, CRASHED, time.perf_counter() - t0, reasons=detail)
    return replace(outcome, peak_rss_mb=_peak_rss_mb())


def _peak_rss_mb() -> float | None:
    """Peak resident set size of this process, MiB; None where the platform does not say."""
    try:
        import resource
    except ImportError:
        return None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 1024 / 1024 if sys.platform == "darwin" else peak / 1024   # bytes on macOS, KiB on Linux
