"""The local process pool of `robomax batch`: one process per cell, a deadline each.

A cell is planned by a worker in a process of its own, so a cell that fails, hangs or crashes its
process never stops the others: a worker past its deadline is killed and reported as `timeout`, a
process that dies (signal, `os._exit`, out of memory) is reported as `crashed`. A Ray task runs one
cell through this pool too (`app.batch_ray`), so both report a cell's own failures alike.
"""

from __future__ import annotations

import multiprocessing
import multiprocessing.connection
import os
import signal
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from multiprocessing.context import ForkServerContext, SpawnContext
from multiprocessing.process import BaseProcess
from pathlib import Path

from robomax_py.app.batch_cell import (
    CRASHED,
    TIMEOUT,
    BatchOptions,
    CellOutcome,
    PlanSettings,
    Worker,
    plan_cell_file,
    run_worker,
)

# After a worker sent its result it exits at once; one that does not within this is killed.
EXIT_GRACE_S = 10.0
# Modules the fork server imports once, so each cell's process starts warm (the planner imports the
# timing libraries lazily: ~2 s per cell otherwise). A name that does not import is skipped.
PRELOAD = ("robomax_py.app.batch_cell", "robomax_py.io.cell", "robomax_py.plan", "robomax_py.export",
           "robomax_py.export.srcl", "robomax_py.verify", "ruckig", "toppra", "toppra.algorithm",
           "toppra.constraint", "toppra.interpolator")

Context = ForkServerContext | SpawnContext
# Called in the caller's process as each cell finishes (index, outcome); returns the outcome to keep.
OnDone = Callable[[int, CellOutcome], CellOutcome]


def _child_main(conn: multiprocessing.connection.Connection, worker: Worker, file: str, settings: PlanSettings,
                env: Mapping[str, str] | None) -> None:
    """Entry point of a cell's process: send the outcome back, then exit."""
    outcome = run_worker(worker, file, settings, env)
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
    worker: Worker = plan_cell_file, context: Context | None = None, env: Mapping[str, str] | None = None,
) -> tuple[CellOutcome, ...]:
    """Plan every file in its own process, at most `options.jobs` (default: the CPUs) at a time;
    outcomes in argument order.

    `on_done(index, outcome)` is called in this process as each cell finishes (in finishing order) and
    returns the outcome to keep. `env`: environment variables set in each cell's process.
    `worker` must be importable by name in a fresh interpreter (a module-level function). As always
    with spawn / forkserver, each process imports the caller's main module: a script calling this
    needs the `if __name__ == "__main__":` guard.
    """
    ctx = context or default_context()
    jobs = max(1, options.jobs or os.cpu_count() or 1)
    pending = deque(enumerate(files))
    running: dict[int, _Running] = {}
    outcomes: dict[int, CellOutcome] = {}

    def finish(i: int, outcome: CellOutcome) -> None:
        outcomes[i] = outcome if on_done is None else on_done(i, outcome)

    try:
        while pending or running:
            while pending and len(running) < jobs:
                i, file = pending.popleft()
                receiver, sender = ctx.Pipe(duplex=False)
                process = ctx.Process(target=_child_main, args=(sender, worker, file, options.settings, env),
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
