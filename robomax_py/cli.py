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


def main() -> None:
    """Console entry point."""
    try:
        app()
    except KeyboardInterrupt:
        err.print("interrupted")
        sys.exit(130)


if __name__ == "__main__":
    main()
