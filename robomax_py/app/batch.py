"""Plan many cells in parallel: one process per cell (or one Ray task), a deadline each, a summary.

Pure orchestration; nothing here prints. A cell is planned by a *worker* (`plan_cell_file`: load, plan,
render) in a process of its own, so a cell that fails, hangs or crashes its process never stops the
others: a worker past its deadline is killed and reported as `timeout`, a process that dies (signal,
`os._exit`, out of memory) is reported as `crashed`. Programs are rendered in the worker and written
by the caller's process with the same functions as `robomax plan`, so the bytes are the same.

A cell file that is unreadable or invalid is one cell's outcome (`bad input`, the message naming the
file, key and problem), like an infeasible one: the other cells still plan and the summary lists it
(`robomax batch` then exits 2). Paths that do not exist are refused by the CLI before anything runs.
"""

from __future__ import annotations

import csv
import io
import multiprocessing
import multiprocessing.connection
import signal
import sys
import time
import traceback
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from multiprocessing.context import ForkServerContext, SpawnContext
from multiprocessing.process import BaseProcess
from pathlib import Path
from typing import Any

from robomax_py.spec import Notice

PLANNED = "planned"
INFEASIBLE = "infeasible"
BAD_INPUT = "bad input"
TIMEOUT = "timeout"
CRASHED = "crashed"
STATUSES = (PLANNED, INFEASIBLE, BAD_INPUT, TIMEOUT, CRASHED)

SUMMARY_COLUMNS = ("cell", "file", "status", "cycle_time_s", "planning_s", "spots", "detours", "reasons",
                   "warnings", "peak_rss_mb")
# After a worker sent its result it exits at once; one that does not within this is killed.
EXIT_GRACE_S = 10.0
# Modules the fork server imports once, so each cell's process starts warm (the planner imports the
# timing libraries lazily: ~2 s per cell otherwise). A name that does not import is skipped.
PRELOAD = ("robomax_py.app.batch", "robomax_py.io.cell", "robomax_py.plan", "robomax_py.export", "robomax_py.export.srcl",
           "robomax_py.verify", "ruckig", "toppra", "toppra.algorithm", "toppra.constraint", "toppra.interpolator")


@dataclass(frozen=True, slots=True)
class BatchOptions:
    """How to run a batch."""

    jobs: int                        # cells planned at the same time (processes or Ray tasks)
    timeout: float | None = None     # s of wall time per cell from its start; None: no limit
    method: str = "optimised"       # or a baseline: "published", "teach-in" (plan.METHODS)


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
    peak_rss_mb: float | None = None  # peak resident memory of the worker's process so far, MiB (Unix)
    warnings: tuple[Notice, ...] = ()  # the cell file's likely mistakes (`CellSpec.notices`), cells read only


Worker = Callable[[str, str], CellOutcome]
Context = ForkServerContext | SpawnContext
# Called in the caller's process as each cell finishes (index, outcome); returns the outcome to keep.
OnDone = Callable[[int, CellOutcome], CellOutcome]


def plan_cell_file(file: str, method: str) -> CellOutcome:
    """The worker: load a cell file, plan it and render its programs (no file is written here)."""
    from robomax_py.errors import RobomaxError
    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.plan import method_options, plan_cell
    from robomax_py.publish import publish

    t0 = time.perf_counter()
    try:
        spec = load_cell(file)
        robot = load_cell_robot(spec)
        result = plan_cell(spec, robot, method_options(method))
        programs = (tuple(publish(result, spec, robot, ("srcl",), method=method)[0].items())
                    if result.status == PLANNED else ())
    except RobomaxError as exc:
        return CellOutcome(file, Path(file).stem, BAD_INPUT, time.perf_counter() - t0, reasons=str(exc))
    seconds = time.perf_counter() - t0
    n_spots = sum(len(seam.spots) for seam in spec.seams)
    if result.status != PLANNED:
        reasons = "; ".join(f"{f.seam}/{f.name}: {f.reason} ({f.detail})" for f in result.failures)
        return CellOutcome(file, spec.name, INFEASIBLE, seconds, spots=n_spots, reasons=reasons or result.message,
                           warnings=spec.notices)
    detours = sum(1 for t in result.transitions if t.kind == "detour")
    return CellOutcome(file, spec.name, PLANNED, seconds, cycle_time=result.cycle_time, spots=n_spots,
                       detours=detours, programs=programs, cell_sha256=spec.digest, warnings=spec.notices)


def run_worker(worker: Worker, file: str, method: str) -> CellOutcome:
    """Run a worker; an exception escaping it (a bug, not a user's mistake) becomes a `crashed` outcome."""
    t0 = time.perf_counter()
    try:
        outcome = worker(file, method)
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


def _child_main(conn: multiprocessing.connection.Connection, worker: Worker, file: str, method: str) -> None:
    """Entry point of a cell's process: send the outcome back, then exit."""
    outcome = run_worker(worker, file, method)
    conn.send(outcome)
    conn.close()


@dataclass(frozen=True, slots=True)
class _Running:
    process: BaseProcess
    conn: multiprocessing.connection.Connection
    started: float                   # time.monotonic()


def default_context() -> Context:
    """forkserver where the platform has it (cheap starts, nothing inherited by fork), else spawn."""
    methods = multiprocessing.get_all_start_methods()
    if "forkserver" in methods:
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(list(PRELOAD))
        return ctx
    return multiprocessing.get_context("spawn")


def run_local(
    files: Sequence[str], options: BatchOptions, on_done: OnDone | None = None,
    worker: Worker = plan_cell_file, context: Context | None = None,
) -> tuple[CellOutcome, ...]:
    """Plan every file in its own process, at most `options.jobs` at a time; outcomes in argument order.

    `on_done(index, outcome)` is called in this process as each cell finishes (in finishing order) and
    returns the outcome to keep.
    `worker` must be importable by name in a fresh interpreter (a module-level function). As always
    with spawn / forkserver, each process imports the caller's main module: a script calling this
    needs the `if __name__ == "__main__":` guard.
    """
    ctx = context or default_context()
    pending = deque(enumerate(files))
    running: dict[int, _Running] = {}
    outcomes: dict[int, CellOutcome] = {}

    def finish(i: int, outcome: CellOutcome) -> None:
        outcomes[i] = outcome if on_done is None else on_done(i, outcome)

    try:
        while pending or running:
            while pending and len(running) < max(1, options.jobs):
                i, file = pending.popleft()
                receiver, sender = ctx.Pipe(duplex=False)
                process = ctx.Process(target=_child_main, args=(sender, worker, file, options.method),
                                      name=f"robomax-batch-{i}", daemon=True)
                process.start()
                sender.close()             # the child holds the only sending end: EOF when it dies
                running[i] = _Running(process, receiver, time.monotonic())
            wait_s = None
            if options.timeout is not None:
                first = min(r.started for r in running.values())
                wait_s = max(0.0, first + options.timeout - time.monotonic())
            multiprocessing.connection.wait([r.conn for r in running.values()], timeout=wait_s)
            now = time.monotonic()
            for i in list(running):
                r = running[i]
                outcome = _collect(r, files[i])
                if outcome is None and options.timeout is not None and now - r.started >= options.timeout:
                    _kill(r)
                    outcome = CellOutcome(files[i], Path(files[i]).stem, TIMEOUT, now - r.started,
                                          reasons=f"not planned within {options.timeout:g} s; worker killed")
                if outcome is not None:
                    del running[i]
                    finish(i, outcome)
    finally:
        for r in running.values():           # interrupted: leave no process behind
            _kill(r)
    return tuple(outcomes[i] for i in range(len(files)))


def _collect(r: _Running, file: str) -> CellOutcome | None:
    """The outcome of a finished process (sent, or its crash), or None while it is still working."""
    if not r.conn.poll():
        return None
    try:
        outcome: CellOutcome = r.conn.recv()
    except (EOFError, OSError):
        r.process.join(EXIT_GRACE_S)
        r.conn.close()
        return CellOutcome(file, Path(file).stem, CRASHED, time.monotonic() - r.started,
                           reasons=_exit_reason(r.process.exitcode))
    r.conn.close()
    r.process.join(EXIT_GRACE_S)
    if r.process.is_alive():
        r.process.kill()
        r.process.join()
    return outcome


def _kill(r: _Running) -> None:
    r.process.kill()
    r.process.join()
    r.conn.close()


def _exit_reason(exitcode: int | None) -> str:
    if exitcode is not None and exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        return f"worker process killed by {name}"
    return f"worker process exited with code {exitcode} before sending a result"


def run_ray(
    files: Sequence[str], options: BatchOptions, address: str | None = None, on_done: OnDone | None = None,
    worker: Worker = plan_cell_file, init_kwargs: Mapping[str, Any] | None = None,
) -> tuple[CellOutcome, ...]:
    """Plan every file as a Ray task; outcomes in argument order, as `run_local` gives them.

    Without `address` a local Ray with `options.jobs` CPUs is started (and shut down at the end);
    with one, the cluster at that address is joined. Cell files (and the meshes they name) must be at
    the same absolute paths on every node. At most `options.jobs` tasks are in flight, so a task's
    deadline runs from its submission; a task past it is cancelled with force (its worker killed).
    `init_kwargs` are passed on to `ray.init` (tests set a runtime_env there).
    Raises ImportError when ray is not installed.
    """
    import ray

    kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
    if address is None:
        kwargs["num_cpus"] = max(1, options.jobs)
    else:
        kwargs["address"] = address
    kwargs.update(init_kwargs or {})
    started_here = not ray.is_initialized()
    if started_here:
        ray.init(**kwargs)
    try:
        remote = ray.remote(num_cpus=1, max_retries=0)(run_worker)
        pending = deque(enumerate(files))
        running: dict[Any, tuple[int, float]] = {}   # ObjectRef -> (index, submitted at)
        outcomes: dict[int, CellOutcome] = {}

        def finish(i: int, outcome: CellOutcome) -> None:
            outcomes[i] = outcome if on_done is None else on_done(i, outcome)

        try:
            while pending or running:
                while pending and len(running) < max(1, options.jobs):
                    i, file = pending.popleft()
                    ref = remote.remote(worker, str(Path(file).resolve()), options.method)
                    running[ref] = (i, time.monotonic())
                wait_s = None
                if options.timeout is not None:
                    first = min(t for _, t in running.values())
                    wait_s = max(0.0, first + options.timeout - time.monotonic())
                ready, _ = ray.wait(list(running), num_returns=1, timeout=wait_s)
                for ref in ready:
                    i, t_submit = running.pop(ref)
                    try:
                        got: CellOutcome = ray.get(ref)
                        # The task had the absolute path; report the file as given, as run_local does.
                        outcome = replace(got, file=files[i],
                                          reasons=got.reasons.replace(str(Path(files[i]).resolve()), files[i]))
                    except (ray.exceptions.WorkerCrashedError, ray.exceptions.RayTaskError,
                            ray.exceptions.TaskCancelledError, ray.exceptions.RayError) as exc:
                        outcome = CellOutcome(files[i], Path(files[i]).stem, CRASHED, time.monotonic() - t_submit,
                                              reasons=f"Ray task failed: {type(exc).__name__}: {_first_line(exc)}")
                    finish(i, outcome)
                now = time.monotonic()
                if options.timeout is not None:
                    for ref, (i, t_submit) in list(running.items()):
                        if now - t_submit >= options.timeout:
                            ray.cancel(ref, force=True)
                            del running[ref]
                            finish(i, CellOutcome(files[i], Path(files[i]).stem, TIMEOUT, now - t_submit,
                                                  reasons=f"not planned within {options.timeout:g} s; task cancelled"))
        finally:
            for ref in running:
                ray.cancel(ref, force=True)
        return tuple(outcomes[i] for i in range(len(files)))
    finally:
        if started_here:
            ray.shutdown()


def _first_line(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return lines[0] if lines else ""


def write_outcome_programs(out_dir: Path, outcome: CellOutcome, taken: dict[str, str]) -> CellOutcome:
    """Write a planned outcome's programs as `robomax plan` does (one set with its manifest,
    `io.files.commit_set`); the outcome without texts, with paths.

    `taken` maps program file names already written in this batch to the cell file that wrote them:
    a second cell of the same name would overwrite them, so it becomes `bad input` and writes nothing.
    """
    from robomax_py.io.files import commit_set

    if outcome.status != PLANNED:
        return outcome
    from robomax_py.export import SHARED_FILES

    # Files every cell writes alike (FANUC's SPOT_WELD.ls) do not belong to one cell.
    own = [name for name, _ in outcome.programs if name not in SHARED_FILES]
    clash = next((taken[name] for name in own if name in taken), None)
    if clash is not None:
        return replace(outcome, status=BAD_INPUT, programs=(), cycle_time=None, detours=None,
                       reasons=f"{outcome.file}: name: cell name '{outcome.cell}' is also that of {clash}; "
                               "its programs would overwrite those")
    # The set is named as its trajectory file (publish renders it first): the cell, or <cell>_published / <cell>_teach_in.
    name = next((n.removesuffix(".json") for n, _ in outcome.programs if n.endswith(".json")), outcome.cell)
    committed = commit_set(out_dir, name, dict(outcome.programs), outcome.cell_sha256, SHARED_FILES)
    written = [*committed.paths, committed.manifest]
    for name in own:
        taken[name] = outcome.file
    return replace(outcome, programs=(), written=tuple(str(p) for p in written))


def summary_rows(outcomes: Sequence[CellOutcome]) -> list[dict[str, str]]:
    """One row per cell, columns SUMMARY_COLUMNS, fixed formats (s with 3 decimals)."""
    def num(v: float | None, fmt: str) -> str:
        return "" if v is None else format(v, fmt)

    return [
        {"cell": o.cell, "file": o.file, "status": o.status, "cycle_time_s": num(o.cycle_time, ".3f"),
         "planning_s": num(o.seconds, ".3f"), "spots": num(o.spots, "d"), "detours": num(o.detours, "d"),
         "reasons": o.reasons, "warnings": "" if o.spots is None else str(len(o.warnings)),
         "peak_rss_mb": num(o.peak_rss_mb, ".0f")}
        for o in outcomes
    ]


def summary_csv(outcomes: Sequence[CellOutcome]) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=SUMMARY_COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(summary_rows(outcomes))
    return buf.getvalue()


def summary_markdown(outcomes: Sequence[CellOutcome]) -> str:
    counts = {s: sum(1 for o in outcomes if o.status == s) for s in STATUSES}
    head = ", ".join(f"{n} {s}" for s, n in counts.items() if n)
    lines = [f"# Batch summary: {len(outcomes)} cell(s), {head}", "",
             "| " + " | ".join(SUMMARY_COLUMNS) + " |", "|" + "---|" * len(SUMMARY_COLUMNS)]
    for row in summary_rows(outcomes):
        cells = (row[c].replace("|", "\\|").replace("\n", " ") for c in SUMMARY_COLUMNS)
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_summary(out_dir: Path, outcomes: Sequence[CellOutcome]) -> list[Path]:
    """DIR/summary.csv and DIR/summary.md, each written atomically."""
    from robomax_py.io.files import write_atomic

    paths = [out_dir / "summary.csv", out_dir / "summary.md"]
    write_atomic(paths[0], summary_csv(outcomes))
    write_atomic(paths[1], summary_markdown(outcomes))
    return paths


def run_batch(
    files: Sequence[str], out_dir: Path, options: BatchOptions, *, use_ray: bool = False,
    ray_address: str | None = None, on_done: OnDone | None = None,
    worker: Worker = plan_cell_file, ray_init: Mapping[str, Any] | None = None,
) -> tuple[CellOutcome, ...]:
    """Plan the files (local processes, or Ray), then write every planned cell's programs into
    `out_dir` in argument order (so a clash of cell names resolves the same way every time), then
    DIR/summary.csv and DIR/summary.md. Outcomes in argument order, without program texts.
    """
    if use_ray:
        outcomes = run_ray(files, options, ray_address, on_done, worker, ray_init)
    else:
        outcomes = run_local(files, options, on_done, worker)
    taken: dict[str, str] = {}
    kept = tuple(write_outcome_programs(out_dir, o, taken) for o in outcomes)
    write_summary(out_dir, kept)
    return kept
