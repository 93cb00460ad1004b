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
    plot: Annotated[bool, typer.Option("--plot", help="also write DIR/<name>.png: a cycle-time Gantt chart, one row per spot")] = False,
) -> None:
    """Plan a cell and write its program files (only when the plan is complete and verified)."""

    def run() -> int:
        import json as _json
        import time

        from robomax_py.cell_io import load_cell, load_cell_robot
        from robomax_py.export import EXPORTERS, render
        from robomax_py.files import write_atomic
        from robomax_py.plan import PlanOptions, plan_cell
        from robomax_py.report import plan_report, report_tables

        t0 = time.perf_counter()
        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        result = plan_cell(spec, robot, PlanOptions(baseline=baseline, speed=speed))
        seconds = time.perf_counter() - t0
        written: list[Path] = []
        if result.status == "planned":
            texts = {fmt: render(result, fmt) for fmt in EXPORTERS}   # all rendered before any write
            png = None
            if plot:
                from robomax_py.cycle_chart import cycle_chart, render_png

                png = render_png(cycle_chart(result))
            for fmt, text in texts.items():
                path = out_dir / f"{spec.name}{EXPORTERS[fmt][0]}"
                write_atomic(path, text)
                written.append(path)
            if png is not None:
                from robomax_py.files import write_atomic_bytes

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


def main() -> None:
    """Console entry point."""
    try:
        app()
    except KeyboardInterrupt:
        err.print("interrupted")
        sys.exit(130)


if __name__ == "__main__":
    main()
