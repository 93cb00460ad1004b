"""`robomax batch` and `robomax variants`: many cells planned at once, and seeded copies of one."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from robomax_py.app.batch_cell import RETRIES  # standard library only: cheap for --help
from robomax_py.app.commands.base import (
    EXIT_BAD_INPUT,
    EXIT_INFEASIBLE,
    EXIT_OK,
    RAY_LOCAL,
    JsonFlag,
    _command,
    _compile_ahead,
    _guarded,
    _honour_signals,
    _json_failure,
    _method,
    _num,
    _print_json,
    _warn,
    err,
    out,
    output_folder,
)

if TYPE_CHECKING:                     # the command imports what it uses when it runs
    from robomax_py.app.batch import Shard


@_command()
def batch(
    cells: Annotated[list[Path], typer.Argument(help="cell files (YAML)")],
    jobs: Annotated[int | None, typer.Option("-j", "--jobs", min=1, help="cells planned at once: local processes (default: the number of CPUs); with --ray, tasks in flight (default: all, queued by Ray for the cluster's CPUs and memory) and the CPUs of a local Ray")] = None,
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder for programs, summary.csv / summary.md and the journal results.jsonl, written as each cell finishes", callback=output_folder)] = Path("programs"),
    timeout: Annotated[float | None, typer.Option("--timeout", min=0.0, help="seconds per cell from its start (on Ray, the task's start) before its worker is killed")] = None,
    formats: Annotated[str, typer.Option("--format", help="program dialects, comma-separated, as plan takes them: srcl, krl, rapid, fanuc, urscript, inform, as, native or all")] = "srcl",
    ray_address: Annotated[str | None, typer.Option("--ray", metavar="[ADDRESS]",
                                                    help="plan on Ray: without ADDRESS (or with `local`) the cluster at RAY_ADDRESS when set, else a new local Ray; `auto` Ray's own search; else the cluster at ADDRESS")] = None,
    ray_address_option: Annotated[str | None, typer.Option("--ray-address", metavar="ADDRESS", help="plan on the Ray cluster at ADDRESS (the same as --ray ADDRESS)")] = None,
    retries: Annotated[int, typer.Option("--retries", min=0, help="Ray: times a cell is submitted again after its worker or node was lost (not after its own failure)")] = RETRIES,
    task_memory: Annotated[float | None, typer.Option("--task-memory", min=1.0, metavar="MIB", help="Ray: memory each task declares, MiB (default: a measured model of the plan's peak by the cell's size)")] = None,
    resume: Annotated[bool, typer.Option("--resume", help="keep the cells an earlier batch into the same folder planned with the same options, whose programs are there whole and whose files (cell, includes, robot, tool, meshes) are unchanged")] = False,
    shard: Annotated[str | None, typer.Option("--shard", metavar="I/N", help="plan only shard I of N (1-based; every N-th cell from the I-th, in argument order), writing summary.shard-I-of-N.* and results.shard-I-of-N.jsonl")] = None,
    baseline: Annotated[str | None, typer.Option("--baseline", metavar="published|teach-in", help="plan every cell by a baseline instead (see plan --baseline)")] = None,
    as_json: JsonFlag = False,
) -> None:
    """Plan many cells in parallel (one process per cell, or one Ray task); write each cell's programs and
    its row of the summary table as it finishes.

    Each cell file's warnings (as `check` prints them) are printed and counted in the summary.

    Exit 0 all planned; 3 some infeasible, timed out or crashed; 2 a cell file is bad (reported in its
    row, the others still plan) or does not exist (nothing is planned).
    """
    method = _method(baseline)
    picked_shard = _shard(shard)

    def run() -> int:
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
        )

        from robomax_py.app.batch import (
            BAD_INPUT,
            PLANNED,
            BatchOptions,
            CellOutcome,
            run_batch,
        )
        from robomax_py.app.batch_ray import resolve_address

        files = [str(c) for c in cells]
        use_ray = ray_address is not None or ray_address_option is not None
        given = ray_address_option if ray_address_option is not None else ray_address
        address = None if given in (None, "", RAY_LOCAL) else given
        missing = [f for f in files if not Path(f).is_file()]
        if missing:
            for f in missing:
                err.print(f"[bold red]error:[/] {f}: cell file not found", soft_wrap=True)
            if as_json:
                more = f" ({len(missing) - 1} more)" if len(missing) > 1 else ""
                _print_json("batch", False, {"error": {"file": missing[0], "key": None,
                                                       "message": f"{missing[0]}: cell file not found{more}"}})
            return EXIT_BAD_INPUT
        unknown = _unknown_formats(formats)
        if unknown:
            return _json_failure("batch", as_json, None, unknown)
        if use_ray:
            try:
                import ray  # noqa: F401
            except ImportError:
                return _json_failure("batch", as_json, None, "--ray needs Ray: pip install 'robomax-py[ray]'")
        options = BatchOptions(jobs=jobs, timeout=timeout, method=method, formats=formats, retries=retries,
                               task_memory_mb=task_memory)
        n = len(picked_shard.picks(len(files))) if picked_shard else len(files)
        where = (f"Ray ({resolve_address(address)})" if use_ray else
                 f"{jobs or os.cpu_count() or 1} process(es)")
        part = f" (shard {picked_shard.index} of {picked_shard.count})" if picked_shard else ""
        # The kernels every cell's process calls, compiled once here where the cache has not got
        # them (each process would otherwise compile them all at once, side by side).
        _compile_ahead().wait(_honour_signals)
        with Progress(TextColumn("planning"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                      console=err, transient=False) as progress:
            task = progress.add_task("cells", total=n)
            progress.console.print(f"{n} cell(s){part} on {where}")

            def done(i: int, o: CellOutcome) -> CellOutcome:
                style = "green" if o.status == PLANNED else "red"
                detail = f"cycle {o.cycle_time:.2f} s" if o.cycle_time is not None else o.reasons
                extra = " (planned before: --resume)" if o.resumed else (
                    f" (attempt {o.attempts})" if o.attempts > 1 else "")
                progress.console.print(f"[{style}]{o.status}[/]: {o.file} ({o.seconds:.1f} s){extra} {detail}",
                                       soft_wrap=True, markup=True, highlight=False)
                _warn([str(n) for n in o.warnings])    # as check and plan print them
                progress.advance(task)
                return o

            try:
                outcomes = run_batch(files, out_dir, options, use_ray=use_ray, ray_address=address, on_done=done,
                                     resume=resume, shard=picked_shard)
            except (ConnectionError, TimeoutError) as exc:
                return _json_failure("batch", as_json, None, f"--ray: cannot reach the Ray cluster at "
                                                             f"{resolve_address(address)}: {exc}")
        code = (EXIT_OK if all(o.status == PLANNED for o in outcomes) else
                EXIT_BAD_INPUT if any(o.status == BAD_INPUT for o in outcomes) else EXIT_INFEASIBLE)
        suffix = picked_shard.suffix if picked_shard else ""
        summary = [out_dir / f"summary{suffix}.csv", out_dir / f"summary{suffix}.md"]
        if as_json:
            _print_json("batch", code == EXIT_OK, {
                "out": str(out_dir), "summary": [str(p) for p in summary],
                "journal": str(out_dir / f"results{suffix}.jsonl"),
                "cells": [{"cell": o.cell, "file": o.file, "status": o.status, "cycle_time": _num(o.cycle_time),
                           "seconds": round(o.seconds, 3), "spots": o.spots, "detours": o.detours,
                           "reasons": o.reasons, "written": list(o.written), "attempts": o.attempts,
                           "node": o.node, "resumed": o.resumed, "notes": o.notes,
                           "warnings": [{"file": n.file, "key": n.key, "message": n.message} for n in o.warnings]}
                          for o in outcomes]})
            return code
        table = Table(title=f"batch: {summary[1]}", title_justify="left")
        for col in ("cell", "status", "cycle (s)", "planning (s)", "spots", "detours", "warnings"):
            table.add_column(col)
        for o in outcomes:
            table.add_row(o.cell, o.status, "" if o.cycle_time is None else f"{o.cycle_time:.2f}",
                          f"{o.seconds:.1f}", "" if o.spots is None else str(o.spots),
                          "" if o.detours is None else str(o.detours),
                          "" if o.spots is None else str(len(o.warnings)))
        out.print(table)
        return code

    code = _guarded(run, "batch" if as_json else None)
    raise typer.Exit(code)


def _shard(text: str | None) -> Shard | None:
    """`--shard I/N`, or a usage error."""
    if text is None:
        return None
    from robomax_py.app.batch import Shard

    try:
        return Shard.parse(text)
    except ValueError as exc:
        raise typer.BadParameter(str(exc), param_hint="--shard") from None


def _unknown_formats(formats: str) -> str:
    """The message for a `--format` LIST naming no dialect or an unknown one ("" when it is good):
    found before any cell is planned (what a robot lacks for a dialect is each cell's own outcome)."""
    from robomax_py.export import DIALECTS

    parts = [p.strip().lower() for p in formats.split(",") if p.strip()]
    known = [*DIALECTS, "native", "all"]
    wrong = [p for p in parts if p not in known]
    if wrong:
        return f"--format: unknown program format '{wrong[0]}'; known: {', '.join(known)}"
    return "" if parts else "--format names no program format"


@_command()
def variants(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    n: Annotated[int, typer.Option("--n", "-n", min=1, help="number of variants")] = 20,
    seed: Annotated[int, typer.Option("--seed", min=0, help="seed: the same seed writes the same files")] = 0,
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder", callback=output_folder)] = Path("variants"),
    as_json: JsonFlag = False,
) -> None:
    """Write seeded perturbed copies of a cell (clamps ±15 mm, part ±5 mm / ±1°, spot order of free seams)."""

    def run() -> None:
        from robomax_py.io.variants import write_variants

        made = write_variants(cell, n, seed, out_dir)
        if as_json:
            _print_json("variants", True, {"cell": str(cell), "seed": seed, "out": str(out_dir),
                                           "files": [str(v.path) for v in made]})
            return
        out.print(f"wrote {len(made)} variant(s) of {cell}: {made[0].path} ... {made[-1].path}")

    _guarded(run, "variants" if as_json else None)
