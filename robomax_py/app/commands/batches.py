"""`robomax batch` and `robomax variants`: many cells planned at once, and seeded copies of one."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from robomax_py.app.commands.base import (
    EXIT_BAD_INPUT,
    EXIT_INFEASIBLE,
    EXIT_OK,
    RAY_LOCAL,
    JsonFlag,
    _command,
    _guarded,
    _json_failure,
    _method,
    _num,
    _print_json,
    _warn,
    err,
    out,
)


@_command()
def batch(
    cells: Annotated[list[Path], typer.Argument(help="cell files (YAML)")],
    jobs: Annotated[int | None, typer.Option("-j", "--jobs", min=1, help="cells planned at once (default: the number of CPUs)")] = None,
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder for programs and summary.csv / summary.md")] = Path("programs"),
    timeout: Annotated[float | None, typer.Option("--timeout", min=0.0, help="seconds per cell before its worker is killed")] = None,
    ray_address: Annotated[str | None, typer.Option("--ray", metavar="[ADDRESS]",
                                                    help="plan on Ray: a local Ray without ADDRESS (or with `local`), else the cluster at ADDRESS")] = None,
    baseline: Annotated[str | None, typer.Option("--baseline", metavar="published|teach-in", help="plan every cell by a baseline instead (see plan --baseline)")] = None,
    as_json: JsonFlag = False,
) -> None:
    """Plan many cells in parallel (one process per cell); write their programs and a summary table.

    Each cell file's warnings (as `check` prints them) are printed and counted in the summary.

    Exit 0 all planned; 3 some infeasible, timed out or crashed; 2 a cell file is bad (reported in its
    row, the others still plan) or does not exist (nothing is planned).
    """
    method = _method(baseline)

    def run() -> int:
        import os

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

        files = [str(c) for c in cells]
        use_ray = ray_address is not None
        address = None if ray_address in (None, "", RAY_LOCAL) else ray_address
        missing = [f for f in files if not Path(f).is_file()]
        if missing:
            for f in missing:
                err.print(f"[bold red]error:[/] {f}: cell file not found", soft_wrap=True)
            if as_json:
                more = f" ({len(missing) - 1} more)" if len(missing) > 1 else ""
                _print_json("batch", False, {"error": {"file": missing[0], "key": None,
                                                       "message": f"{missing[0]}: cell file not found{more}"}})
            return EXIT_BAD_INPUT
        if use_ray:
            try:
                import ray  # noqa: F401
            except ImportError:
                return _json_failure("batch", as_json, None, "--ray needs Ray: pip install 'robomax-py[ray]'")
        options = BatchOptions(jobs=jobs or os.cpu_count() or 1, timeout=timeout, method=method)
        where = f"Ray ({address or 'local'})" if use_ray else f"{options.jobs} process(es)"
        with Progress(TextColumn("planning"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                      console=err, transient=False) as progress:
            task = progress.add_task("cells", total=len(files))
            progress.console.print(f"{len(files)} cell(s) on {where}")

            def done(i: int, o: CellOutcome) -> CellOutcome:
                style = "green" if o.status == PLANNED else "red"
                detail = f"cycle {o.cycle_time:.2f} s" if o.cycle_time is not None else o.reasons
                progress.console.print(f"[{style}]{o.status}[/]: {o.file} ({o.seconds:.1f} s) {detail}",
                                       soft_wrap=True, markup=True, highlight=False)
                _warn([str(n) for n in o.warnings])    # as check and plan print them
                progress.advance(task)
                return o

            outcomes = run_batch(files, out_dir, options, use_ray=use_ray, ray_address=address, on_done=done)
        code = (EXIT_OK if all(o.status == PLANNED for o in outcomes) else
                EXIT_BAD_INPUT if any(o.status == BAD_INPUT for o in outcomes) else EXIT_INFEASIBLE)
        if as_json:
            _print_json("batch", code == EXIT_OK, {
                "out": str(out_dir), "summary": [str(out_dir / "summary.csv"), str(out_dir / "summary.md")],
                "cells": [{"cell": o.cell, "file": o.file, "status": o.status, "cycle_time": _num(o.cycle_time),
                           "seconds": round(o.seconds, 3), "spots": o.spots, "detours": o.detours,
                           "reasons": o.reasons, "written": list(o.written),
                           "warnings": [{"file": n.file, "key": n.key, "message": n.message} for n in o.warnings]}
                          for o in outcomes]})
            return code
        table = Table(title=f"batch: {out_dir / 'summary.md'}", title_justify="left")
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


@_command()
def variants(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    n: Annotated[int, typer.Option("--n", "-n", min=1, help="number of variants")] = 20,
    seed: Annotated[int, typer.Option("--seed", min=0, help="seed: the same seed writes the same files")] = 0,
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder")] = Path("variants"),
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
