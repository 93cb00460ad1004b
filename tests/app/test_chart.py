"""`robomax plan --plot`: the cycle-time Gantt chart (cycle_chart.py)."""

from __future__ import annotations

import io
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from robomax_py.app import palette
from robomax_py.app.chart import RETURN_ROW, chart_figure, cycle_chart, render_png
from robomax_py.app.cli import EXIT_INFEASIBLE, EXIT_OK, app
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, PlanResult, plan_cell

SmallCell = Callable[..., Path]   # conftest.write_small_cell
CYCLE_TOL_S = 1e-6
runner = CliRunner()


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell) -> PlanResult:
    cell = load_cell(write_small_cell(tmp_path_factory.mktemp("chart"), "small_cell"))
    result = plan_cell(cell, load_cell_robot(cell), PlanOptions())
    assert result.status == "planned", result.message
    return result


def test_rows_are_the_spots_in_weld_order_then_the_way_home(planned: PlanResult) -> None:
    chart = cycle_chart(planned)
    assert chart.rows == tuple(f"{s.seam}/{s.name}" for s in planned.spots) + (RETURN_ROW,)
    for k, spot in enumerate(planned.spots):
        (weld,) = [b for b in chart.bars if b.kind == "weld" and b.row == k]
        assert abs(weld.start - spot.t_arrive) < CYCLE_TOL_S and abs(weld.duration - planned.weld_time) < CYCLE_TOL_S
    assert {b.kind for b in chart.bars if b.row == len(planned.spots)} <= {"move", "detour", "blend", "wait"}


def test_bars_cover_the_cycle_exactly_once(planned: PlanResult) -> None:
    chart = cycle_chart(planned)
    fig = chart_figure(chart)
    widths = [p.get_width() for ax in fig.axes for p in ax.patches if p.get_gid() == "bar"]
    assert len(widths) == len(chart.bars)
    assert abs(sum(widths) - planned.cycle_time) < CYCLE_TOL_S
    starts = np.array([b.start for b in chart.bars])
    ends = starts + np.array([b.duration for b in chart.bars])
    assert np.all(np.abs(starts[1:] - ends[:-1]) < CYCLE_TOL_S)          # end to end, no gap, no overlap
    assert abs(ends[-1] - planned.cycle_time) < CYCLE_TOL_S


def test_png_has_its_size_and_the_kinds_colours(planned: PlanResult) -> None:
    chart = cycle_chart(planned)
    image = np.asarray(Image.open(io.BytesIO(render_png(chart))).convert("RGB"))
    assert (image.shape[1], image.shape[0]) == chart.size_px()
    colours = {tuple(c) for c in image.reshape(-1, 3)}
    for kind in {b.kind for b in chart.bars}:
        c = palette.phase_colour(kind)
        assert ((c >> 16) & 0xFF, (c >> 8) & 0xFF, c & 0xFF) in colours, kind
    assert float(np.mean(np.all(image == 255, axis=2))) < 0.9                # not blank


def test_plan_plot_writes_the_png_beside_the_program(tmp_path: Path, write_small_cell: SmallCell) -> None:
    cell = write_small_cell(tmp_path, "small_cell")
    out = tmp_path / "programs"
    result = runner.invoke(app, ["plan", str(cell), "-o", str(out), "--plot", "--json"])
    assert result.exit_code == EXIT_OK, result.output
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "small_cell.json", "small_cell.manifest.json", "small_cell.png", "small_cell.srcl"]
    assert str(out / "small_cell.png") in json.loads(result.stdout)["files"]
    with Image.open(out / "small_cell.png") as png:
        assert png.format == "PNG" and png.size[0] > 500 and png.size[1] > 150


def test_plot_of_an_infeasible_plan_writes_nothing(tmp_path: Path, write_small_cell: SmallCell) -> None:
    far = {"name": "far", "xyz": [4.0, 0.0, 1.0], "normal": [-1, 0, 0], "direction": [0, 1, 0]}
    cell = write_small_cell(tmp_path, "small", [far])
    out = tmp_path / "out"
    result = runner.invoke(app, ["plan", str(cell), "-o", str(out), "--plot"])
    assert result.exit_code == EXIT_INFEASIBLE, result.output
    assert not out.exists()
