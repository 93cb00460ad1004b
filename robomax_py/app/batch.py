"""Plan many cells: one process per cell (or one Ray task), a deadline each, results as they come.

Pure orchestration; nothing here prints. A cell is planned by a *worker* (`batch_cell.plan_cell_file`:
load, plan, render) in a process of its own (`batch_local`), locally or in a Ray task (`batch_ray`),
so a cell that fails, hangs or crashes its process never stops the others. Programs are rendered in
the worker and written by the caller's process, as each cell finishes, with the same functions as
`robomax plan`, so the bytes are the same (`batch_results`).

A cell file that is unreadable or invalid is one cell's outcome (`bad input`, the message naming the
file, key and problem), like an infeasible one: the other cells still plan and the summary lists it
(`robomax batch` then exits 2). Paths that do not exist are refused by the CLI before anything runs.

`--shard I/N` plans every N-th cell from the I-th (1-based) in argument order, for machines that
split a batch without Ray (CI runners, a SLURM array); `--resume` keeps the cells an earlier run
planned when nothing they read has changed (`batch_results.resumed_outcome`).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robomax_py.app.batch_cell import (
    BAD_INPUT,
    CRASHED,
    INFEASIBLE,
    PLANNED,
    RETRIES,
    STATUSES,
    TIMEOUT,
    BatchOptions,
    CellOutcome,
    PlanSettings,
    Worker,
    plan_cell_file,
    run_worker,
)
from robomax_py.app.batch_local import (
    EXIT_GRACE_S,
    PRELOAD,
    Context,
    OnDone,
    default_context,
    run_local,
)
from robomax_py.app.batch_ray import connected, run_ray
from robomax_py.app.batch_results import (
    SUMMARY_COLUMNS,
    BatchWriter,
    resumable,
    resumed_outcome,
    summary_csv,
    summary_markdown,
    summary_rows,
    write_outcome_programs,
    write_summary,
)

__all__ = ["BAD_INPUT", "CRASHED", "EXIT_GRACE_S", "INFEASIBLE", "PLANNED", "PRELOAD", "RETRIES", "STATUSES",
           "SUMMARY_COLUMNS", "TIMEOUT", "BatchOptions", "CellOutcome", "Context", "OnDone", "PlanSettings", "Shard",
           "Worker", "default_context", "plan_cell_file", "run_batch", "run_local", "run_options", "run_ray",
           "run_worker", "summary_csv", "summary_markdown", "summary_rows", "write_outcome_programs", "write_summary"]


@dataclass(frozen=True, slots=True)
class Shard:
    """Shard `index` of `count` (1-based): the cells at argument positions index-1, index-1+count, ..."""

    index: int
    count: int

    @staticmethod
    def parse(text: str) -> Shard:
        """`I/N` -> Shard; ValueError saying what is wrong."""
        found = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", text)
        if found is None:
            raise ValueError(f"expected I/N (shard I of N, e.g. 1/4), got {text!r}")
        index, count = int(found.group(1)), int(found.group(2))
        if not 1 <= index <= count:
            raise ValueError(f"expected 1 <= I <= N, got {index}/{count}")
        return Shard(index, count)

    def picks(self, n: int) -> list[int]:
        """The argument positions of this shard's cells among n."""
        return list(range(self.index - 1, n, self.count))

    @property
    def suffix(self) -> str:
        """What the shard's summary and journal names carry: `.shard-I-of-N`."""
        return f".shard-{self.index}-of-{self.count}"


def run_options(options: BatchOptions) -> dict[str, Any]:
    """What a cell's programs depend on besides the files it reads, recorded in its journal row:
    `--resume` keeps a cell only when these are the same."""
    from robomax_py._version import __version__
    from robomax_py.io.robot_paths import robot_library

    formats = sorted({part.strip().lower() for part in options.formats.split(",") if part.strip()})
    return {"method": options.method, "formats": ",".join(formats),
            "robots": [os.path.abspath(p) for p in robot_library()], "robomax": __version__}


def run_batch(
    files: Sequence[str], out_dir: Path, options: BatchOptions, *, use_ray: bool = False,
    ray_address: str | None = None, on_done: OnDone | None = None,
    worker: Worker = plan_cell_file, ray_init: Mapping[str, Any] | None = None,
    resume: bool = False, shard: Shard | None = None,
) -> tuple[CellOutcome, ...]:
    """Plan the files (local processes, or Ray), writing each cell's programs, its journal row and
    the summary as it finishes (`batch_results.BatchWriter`). Outcomes of the shard's cells (all
    without `shard`) in argument order, without program texts; `on_done(k, outcome)` is called as
    each finishes, k its position among them (a resumed cell's first).
    """
    picked = [files[i] for i in (shard.picks(len(files)) if shard else range(len(files)))]
    record = run_options(options)
    suffix = shard.suffix if shard else ""
    earlier = resumable(out_dir, record) if resume and out_dir.is_dir() else {}
    kept: dict[int, CellOutcome] = {}
    for k, file in enumerate(picked):
        row = earlier.get(os.path.abspath(file))
        found = resumed_outcome(row, file, out_dir) if row is not None else None
        if found is not None:
            kept[k] = found
    todo = [k for k in range(len(picked)) if k not in kept]
    rest = [picked[k] for k in todo]
    # Ray first: a cluster that cannot be reached leaves the output folder as it was.
    with connected(ray_address, options.jobs, ray_init) if rest and use_ray else nullcontext():
        writer = BatchWriter(out_dir, picked, record, journal=f"results{suffix}", summary=f"summary{suffix}",
                             fresh=not resume)

        def done(k: int, outcome: CellOutcome) -> CellOutcome:
            added = writer.add(k, outcome)
            return added if on_done is None else on_done(k, added)

        for k, found in kept.items():
            done(k, found)

        def done_rest(j: int, outcome: CellOutcome) -> CellOutcome:
            return done(todo[j], outcome)

        if rest and use_ray:
            run_ray(rest, options, ray_address, done_rest, worker, ray_init)
        elif rest:
            run_local(rest, options, done_rest, worker)
    return writer.outcomes()
