"""The `robomax` command: exit codes and messages per SPEC §4.

A RobomaxError (a user's mistake) becomes one line on stderr and exit code 2, never a traceback.
Heavy modules are imported inside commands so `robomax --help` stays fast.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, TypeVar

import typer
from rich.console import Console
from rich.table import Table

from robomax_py.errors import RobomaxError

EXIT_OK = 0
EXIT_VIOLATIONS = 1
EXIT_BAD_INPUT = 2
EXIT_INFEASIBLE = 3

app = typer.Typer(add_completion=False, no_args_is_help=True, help="Offline programming for spot-welding robot cells.")
out = Console(highlight=False)
err = Console(stderr=True, highlight=False)

T = TypeVar("T")


def _guarded(action: Callable[[], T]) -> T:
    """Run a command body; a RobomaxError becomes one message and exit code 2."""
    try:
        return action()
    except RobomaxError as exc:
        err.print(f"[bold red]error:[/] {exc}", markup=True, soft_wrap=True)
        raise typer.Exit(EXIT_BAD_INPUT) from None


@app.command()
def robots() -> None:
    """List the robot and tool library: axes, reach, IK solver, tool TCP."""

    def run() -> None:
        from robomax_py.library import list_robots, list_tools

        table = Table(title="Robots", title_justify="left")
        for col in ("name", "axes", "flange reach (m)", "payload (kg)", "IK", "description"):
            table.add_column(col)
        for r in list_robots():
            payload = "-" if r.payload_kg is None else f"{r.payload_kg:g}"
            table.add_row(r.name, str(r.axes), f"{r.reach_m:.3f}", payload, r.ik_solver, r.description)
        out.print(table)
        tools = Table(title="Tools", title_justify="left")
        for col in ("name", "TCP offset from flange (m)", "TCP distance (m)"):
            tools.add_column(col)
        for t in list_tools():
            xyz = ", ".join(f"{v:.3f}" for v in t.tcp_xyz_m)
            tools.add_row(t.name, f"[{xyz}]", f"{t.tcp_distance_m:.3f}")
        out.print(tools)

    _guarded(run)


@app.command()
def check(cell: Annotated[Path, typer.Argument(help="cell file (YAML)")]) -> None:
    """Validate a cell (and its robot, tool and meshes) and print a summary."""

    def run() -> None:
        from robomax_py.cell_io import load_cell, load_cell_robot
        from robomax_py.summary import cell_summary

        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        out.print(cell_summary(spec, robot))
        out.print(f"[green]ok[/]: {cell} is a valid cell")

    _guarded(run)


@app.command()
def plan(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder")] = Path("programs"),
    baseline: Annotated[bool, typer.Option("--baseline", help="the published method: given order, nominal orientation, first branch")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="print a machine-readable report instead of tables")] = False,
    speed: Annotated[float | None, typer.Option("--speed", min=0.01, max=1.0, help="override of every programmed speed, fraction in (0, 1] (default: the cell's planner.speed, else 1)")] = None,
    verbose: Annotated[bool, typer.Option("-v", "--verbose", help="debug logging: stage sizes, counts and times")] = False,
    plot: Annotated[bool, typer.Option("--plot", help="also write DIR/<name>.png: a cycle-time Gantt chart, one row per spot")] = False,
) -> None:
    """Plan a cell and write its program files (only when the plan is complete and verified)."""

    def run() -> int:
        import json as _json
        import time

        from robomax_py.cell_io import load_cell, load_cell_robot
        from robomax_py.export import render_programs
        from robomax_py.files import write_programs
        from robomax_py.plan import PlanOptions, plan_cell
        from robomax_py.progress_bars import configure_logging, stage_bars
        from robomax_py.report import plan_report, report_tables

        configure_logging(err, verbose)
        t0 = time.perf_counter()
        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        with stage_bars(err, enabled=not verbose) as progress:
            result = plan_cell(spec, robot, PlanOptions(baseline=baseline, speed=speed), progress)
        seconds = time.perf_counter() - t0
        written: list[Path] = []
        if result.status == "planned":
            from robomax_py.cycle_chart import cycle_chart, render_png
            from robomax_py.files import write_atomic_bytes

            texts = render_programs(result)   # everything rendered before any write
            png = render_png(cycle_chart(result)) if plot else None
            written = write_programs(out_dir, texts)
            if png is not None:
                path = out_dir / f"{spec.name}.png"
                write_atomic_bytes(path, png)
                written.append(path)
        report = plan_report(result, seconds, written)
        if as_json:
            out.print_json(_json.dumps(report))
        else:
            for renderable in report_tables(report):
                out.print(renderable)
        if result.status != "planned":
            err.print(f"[bold red]infeasible:[/] {result.message}", soft_wrap=True)
            for f in result.failures:
                err.print(f"  {f.seam}/{f.name}: {f.reason} ({f.detail})", soft_wrap=True)
            return EXIT_INFEASIBLE
        return EXIT_OK

    code = _guarded(run)
    raise typer.Exit(code)


@app.command()
def verify(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    program: Annotated[Path, typer.Argument(help="program written by plan: .srcl (motion rebuilt from its statements) or .json")],
) -> None:
    """Re-simulate a program against the cell; report collisions, limit and tolerance violations."""

    def run() -> int:
        from robomax_py.cell_io import load_cell, load_cell_robot
        from robomax_py.verify import verify_program

        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        report = verify_program(spec, robot, program)
        out.print(f"{program}: {report.samples} samples, cycle {report.cycle_time:.3f} s, "
                  f"{report.collision_checks} collision checks")
        for v in report.violations:
            when = "" if v.t is None else f"t = {v.t:.3f} s: "
            out.print(f"  [red]{v.kind}[/]: {when}{v.detail}", soft_wrap=True)
        if report.clean:
            out.print("[green]clean[/]: no collisions, limits kept, every spot welded within tolerance")
            return EXIT_OK
        out.print(f"[red]{len(report.violations)} violation(s)[/]")
        return EXIT_VIOLATIONS

    code = _guarded(run)
    raise typer.Exit(code)


@app.command()
def bench(
    cell: Annotated[Path, typer.Argument(help="cell to plan (default: the shipped cabin_flange cell)")] = Path("cells/cabin_flange.yaml"),
    runs: Annotated[int, typer.Option("--runs", min=1, help="planning runs (median)")] = 3,
    quick: Annotated[bool, typer.Option("--quick", help="smaller IK and collision batches")] = False,
) -> None:
    """Measure this machine: IK/s, collision checks/s, planning time, cycle vs baseline vs lower bound."""

    def run() -> None:
        from rich.status import Status

        from robomax_py.bench import run_bench
        from robomax_py.cell_io import load_cell, load_cell_robot

        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        with Status("", console=err) as status:
            rows = run_bench(spec, robot, runs=runs, quick=quick, on_step=lambda s: status.update(f"measuring {s}"))
        table = Table(title=f"robomax bench: {spec.name} ({robot.name}), one process", title_justify="left")
        for col, justify in (("figure", "left"), ("value", "right"), ("unit", "left"), ("note", "left")):
            table.add_column(col, justify=justify)  # type: ignore[arg-type]
        for r in rows:
            value = f"{r.value:,.0f}" if r.value >= 1000 else f"{r.value:.3f}"
            table.add_row(r.name, value, r.unit, r.note)
        out.print(table)

    _guarded(run)


@app.command()
def preview(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    program: Annotated[Path | None, typer.Argument(help="program written by plan (.json or .srcl); without it the robot stands at home")] = None,
    html: Annotated[Path | None, typer.Option("--html", help="write one self-contained HTML page instead of serving")] = None,
) -> None:
    """Show the cell in meshcat, animated along a program (serves until Ctrl-C, or writes --html)."""

    def run() -> None:
        from robomax_py.cell_io import load_cell, load_cell_robot
        from robomax_py.preview import serve, write_html
        from robomax_py.preview_program import home_program, load_program

        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        shown = home_program(spec) if program is None else load_program(program, spec, robot)
        if html is not None:
            content = write_html(html, spec, robot, shown)
            out.print(f"wrote {html} ({content.frames} animation frames, cycle {content.duration:.3f} s)")
            return
        serve(spec, robot, shown, lambda url: out.print(f"meshcat preview at {url}  (Ctrl-C to stop)"))
        out.print("preview stopped")

    _guarded(run)


@app.command()
def batch(
    cells: Annotated[list[Path], typer.Argument(help="cell files (YAML)")],
    jobs: Annotated[int | None, typer.Option("-j", "--jobs", min=1, help="cells planned at once (default: the number of CPUs)")] = None,
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder for programs and summary.csv / summary.md")] = Path("programs"),
    timeout: Annotated[float | None, typer.Option("--timeout", min=0.0, help="seconds per cell before its worker is killed")] = None,
    ray_address: Annotated[str | None, typer.Option("--ray", metavar="[ADDRESS]",
                                                    help="plan on Ray: a local Ray without ADDRESS (or with `local`), else the cluster at ADDRESS")] = None,
    baseline: Annotated[bool, typer.Option("--baseline", help="the published method: given order, nominal orientation, first branch")] = False,
) -> None:
    """Plan many cells in parallel (one process per cell); write their programs and a summary table.

    Exit 0 all planned; 3 some infeasible, timed out or crashed; 2 a cell file is bad (reported in its
    row, the others still plan) or does not exist (nothing is planned).
    """

    def run() -> int:
        import os

        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        from robomax_py.batch import BAD_INPUT, PLANNED, BatchOptions, CellOutcome, run_batch

        files = [str(c) for c in cells]
        use_ray = ray_address is not None
        address = None if ray_address in (None, "", RAY_LOCAL) else ray_address
        missing = [f for f in files if not Path(f).is_file()]
        if missing:
            for f in missing:
                err.print(f"[bold red]error:[/] {f}: cell file not found", soft_wrap=True)
            return EXIT_BAD_INPUT
        if use_ray:
            try:
                import ray  # noqa: F401
            except ImportError:
                err.print("[bold red]error:[/] --ray needs Ray: pip install 'robomax-py[ray]'", soft_wrap=True)
                return EXIT_BAD_INPUT
        options = BatchOptions(jobs=jobs or os.cpu_count() or 1, timeout=timeout, baseline=baseline)
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
                progress.advance(task)
                return o

            outcomes = run_batch(files, out_dir, options, use_ray=use_ray, ray_address=address, on_done=done)
        table = Table(title=f"batch: {out_dir / 'summary.md'}", title_justify="left")
        for col in ("cell", "status", "cycle (s)", "planning (s)", "spots", "detours"):
            table.add_column(col)
        for o in outcomes:
            table.add_row(o.cell, o.status, "" if o.cycle_time is None else f"{o.cycle_time:.2f}",
                          f"{o.seconds:.1f}", "" if o.spots is None else str(o.spots),
                          "" if o.detours is None else str(o.detours))
        out.print(table)
        if all(o.status == PLANNED for o in outcomes):
            return EXIT_OK
        return EXIT_BAD_INPUT if any(o.status == BAD_INPUT for o in outcomes) else EXIT_INFEASIBLE

    code = _guarded(run)
    raise typer.Exit(code)


@app.command()
def variants(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    n: Annotated[int, typer.Option("--n", "-n", min=1, help="number of variants")] = 20,
    seed: Annotated[int, typer.Option("--seed", min=0, help="seed: the same seed writes the same files")] = 0,
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder")] = Path("variants"),
) -> None:
    """Write seeded perturbed copies of a cell (clamps ±15 mm, part ±5 mm / ±1°, spot order of free seams)."""

    def run() -> None:
        from robomax_py.variants import write_variants

        made = write_variants(cell, n, seed, out_dir)
        out.print(f"wrote {len(made)} variant(s) of {cell}: {made[0].path} ... {made[-1].path}")

    _guarded(run)


RAY_LOCAL = "local"


def _bare_ray_flag(argv: list[str]) -> list[str]:
    """`batch ... --ray` without an address (last, or before an option or a cell file) -> `--ray=local`.

    typer has no options with an optional value, so the console entry point spells the default out.
    """
    if "batch" not in argv:
        return argv
    args = list(argv)
    for k, arg in enumerate(args):
        nxt = args[k + 1] if k + 1 < len(args) else None
        if arg == "--ray" and (nxt is None or nxt.startswith("-") or nxt.endswith((".yaml", ".yml"))):
            args[k] = f"--ray={RAY_LOCAL}"
    return args


def main() -> None:
    """Console entry point."""
    try:
        app(args=_bare_ray_flag(sys.argv[1:]))
    except KeyboardInterrupt:
        err.print("interrupted")
        sys.exit(130)


if __name__ == "__main__":
    main()
