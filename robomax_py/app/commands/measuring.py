"""`robomax bench` and `robomax cspace`: figures of this machine and of a cell's configuration space."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import typer
from rich.table import Table

from robomax_py.app.commands.base import (
    JsonFlag,
    _command,
    _guarded,
    _print_json,
    err,
    out,
)

if TYPE_CHECKING:                     # the commands import what they use when they run
    from robomax_py._typing import FloatArray


@_command()
def bench(
    cell: Annotated[Path | None, typer.Argument(help="cell to plan (default: the cabin_flange example shipped "
                                                     "with the package)", show_default=False)] = None,
    runs: Annotated[int, typer.Option("--runs", min=1, help="planning runs (median)")] = 3,
    quick: Annotated[bool, typer.Option("--quick", help="smaller IK and collision batches")] = False,
    as_json: JsonFlag = False,
) -> None:
    """Measure this machine: IK/s, collision checks/s, planning time, cycle vs baseline vs lower bound."""

    def run() -> None:
        from rich.status import Status

        from robomax_py.app.bench import run_bench
        from robomax_py.app.examples import default_bench_cell
        from robomax_py.io.cell import load_cell, load_cell_robot

        path = default_bench_cell() if cell is None else cell
        spec = load_cell(path)
        robot = load_cell_robot(spec)
        with Status("", console=err) as status:
            rows = run_bench(spec, robot, runs=runs, quick=quick, on_step=lambda s: status.update(f"measuring {s}"))
        if as_json:
            _print_json("bench", True, {"cell": str(path), "name": spec.name, "robot": robot.name, "runs": runs,
                                        "quick": quick, "figures": [{"name": r.name, "value": float(r.value), "unit": r.unit,
                                                                     "note": r.note} for r in rows]})
            return
        table = Table(title=f"robomax bench: {spec.name} ({robot.name}), one process", title_justify="left")
        for col, justify in (("figure", "left"), ("value", "right"), ("unit", "left"), ("note", "left")):
            table.add_column(col, justify=justify)  # type: ignore[arg-type]
        for r in rows:
            value = f"{r.value:,.0f}" if r.value >= 1000 else f"{r.value:.3f}"
            table.add_row(r.name, value, r.unit, r.note)
        out.print(table)

    _guarded(run, "bench" if as_json else None)


@_command()
def cspace(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    wrist: Annotated[str, typer.Option("--wrist", help="A4-A6 held at home, or at a spot's nominal-orientation IK (spot or seam/spot)")] = "home",
    resolution: Annotated[int, typer.Option("--resolution", help="samples per axis of A1-A3 (4..400)")] = 50,
    plot: Annotated[Path | None, typer.Option("--plot", help="write a PNG of the blocked cells here")] = None,
    jobs: Annotated[int, typer.Option("-j", "--jobs", min=0, help="processes (0: the cores this process may use)")] = 0,
    as_json: JsonFlag = False,
    learned: Annotated[bool, typer.Option("--learned", help="also the map of the learned point model (trained once per robot, tool and wrist, then cached), compared with the exact one cell by cell")] = False,
    spacing: Annotated[float, typer.Option("--spacing", min=0.005, max=1.0, help="m between the object surface points of the learned map")] = 0.1,
    program: Annotated[Path | None, typer.Option("--program", help="with --plot: draw this trajectory file's A1-A3 path (a .json from plan) over the map")] = None,
    plot_model: Annotated[Path | None, typer.Option("--plot-model", help="with --learned: write a PNG of one point's C-obstacle at three distances")] = None,
    inflation: Annotated[float, typer.Option("--inflation", min=0.0, max=1.0, help="m added to the learned model's sphere radius (safety; 0.06 gave no wrongly free cell on the reference cell)")] = 0.06,
) -> None:
    """The A1-A3 configuration-space map of a cell with the wrist fixed, every cell checked exactly
    (and with --learned, from the learned point model too)."""

    def run() -> None:
        import numpy as np

        from robomax_py.app.cspace_view import map_png, map_summary, spot_wrist
        from robomax_py.cspace import build_map, check_arm, default_workers
        from robomax_py.io.cell import load_cell, load_cell_robot
        from robomax_py.io.files import write_atomic_bytes
        from robomax_py.world.collision import CollisionWorld
        from robomax_py.world.scene import build_scene

        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        check_arm(robot)
        scene = build_scene(spec, robot)             # one world for the wrist's IK check and the map
        world = CollisionWorld(robot, scene, spec.process.clearance)
        values: Literal["home"] | FloatArray = "home" if wrist == "home" else spot_wrist(spec, robot, wrist, world)
        m = build_map(spec, robot, values, resolution, jobs or default_workers(), world)
        path = None
        if program is not None:
            from robomax_py.export.trajectory_json import load_trajectory_file

            path = np.asarray(load_trajectory_file(program, robot)["q"], dtype=float)
        png = map_png(m, f"{spec.name} ({robot.name}): C-space, wrist {wrist}, {resolution}^3", path) if plot else None
        summary = {"cell": spec.name, "robot": robot.name, "wrist": wrist, **map_summary(m)}
        if learned:
            from robomax_py.app.cspace_view import learned_summary

            figures, model = learned_summary(spec, robot, scene, m, spacing, inflation)
            summary.update(figures)
            if plot_model is not None:
                from robomax_py.app.cspace_view import model_png

                reach = model.d_max
                write_atomic_bytes(plot_model, model_png(model, (0.3 * reach, 0.5 * reach, 0.7 * reach),
                                                         f"{robot.name} + {spec.tool.name}: a point's C-obstacle"))
                summary["plot_model"] = str(plot_model)
        if png is not None and plot is not None:
            write_atomic_bytes(plot, png)
            summary["plot"] = str(plot)
        if as_json:
            _print_json("cspace", True, summary)
            return
        table = Table(show_header=False, box=None)
        for key, value in summary.items():
            table.add_row(key, f"{value:,}" if isinstance(value, int) else str(value))
        out.print(table)

    _guarded(run, "cspace" if as_json else None)
