"""Progress reporting, debug logging and the bench figures on the small cell."""

from __future__ import annotations

import io
import logging
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console

from robomax_py.app.bench import lower_bound
from robomax_py.app.progress import configure_logging, stage_bars
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, PlanResult, plan_cell
from robomax_py.timing import ptp_time_estimate
from tests.conftest import SmallCell


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell) -> tuple[PlanResult, list[tuple[str, int, int]]]:
    path = write_small_cell(tmp_path_factory.mktemp("progress"))
    cell = load_cell(path)
    calls: list[tuple[str, int, int]] = []
    result = plan_cell(cell, load_cell_robot(cell), PlanOptions(), lambda *a: calls.append(a))
    assert result.status == "planned", result.message
    return result, calls


def test_stages_report_in_order_and_finish(planned: tuple[PlanResult, list[tuple[str, int, int]]]) -> None:
    result, calls = planned
    stages = list(dict.fromkeys(stage for stage, _, _ in calls))
    assert stages == ["candidates", "sequencing", "timing", "verify"]
    for stage in stages:
        mine = [(d, t) for s, d, t in calls if s == stage]
        assert all(0 <= d <= t for d, t in mine)
        assert [d for d, _ in mine] == sorted(d for d, _ in mine)      # never goes back
        assert mine[-1][0] == mine[-1][1] > 0                           # ends full
    assert [t for s, _, t in calls if s == "candidates"][-1] == len(result.spots)
    assert [t for s, _, t in calls if s == "timing"][-1] == len(result.transitions)


def test_bars_draw_on_a_terminal_and_stay_silent_on_a_pipe() -> None:
    buf = io.StringIO()
    with stage_bars(Console(file=buf, force_terminal=True, width=100)) as progress:
        progress("candidates", 1, 2)
        progress("candidates", 2, 2)
    assert "candidates" in buf.getvalue()
    pipe = io.StringIO()
    with stage_bars(Console(file=pipe, force_terminal=False)) as progress:
        progress("candidates", 1, 2)
    assert pipe.getvalue() == ""


def test_verbose_logs_the_stages(tmp_path: Path, write_small_cell: SmallCell) -> None:
    buf = io.StringIO()
    configure_logging(Console(file=buf, width=200), verbose=True)
    try:
        cell = load_cell(write_small_cell(tmp_path))
        plan_cell(cell, load_cell_robot(cell))
    finally:
        logging.getLogger("robomax_py").handlers.clear()
    text = buf.getvalue()
    for needle in ("candidates", "sequencing:", "timing: cycle", "verify:"):
        assert needle in text


def test_lower_bound_is_below_the_cycle_and_counts_rests_and_the_lines(
    planned: tuple[PlanResult, list[tuple[str, int, int]]],
) -> None:
    result, _ = planned
    robot_limits = load_cell_robot(load_cell(Path(__file__).parent.parent / "data" / "flange_cell" / "cabin_flange.yaml")).limits
    bound = lower_bound(result, robot_limits)
    assert 0 < bound <= result.cycle_time
    spots = result.spots
    first = float(ptp_time_estimate(result.home[None], spots[0].q_spot[None], robot_limits, straight=False)[0])
    assert bound >= first + result.weld_time * len(spots)
    # Half of every approach and of every retract line at the line speed (the halves at the sheet).
    lines = sum(float(np.linalg.norm(s.T_app[:3, 3] - s.T_spot[:3, 3])) for s in spots)
    line_speed = result.options.tcp_speed * result.options.speed
    assert bound >= result.weld_time * len(spots) + lines / line_speed - 1e-9


def test_bench_command_prints_one_table(tmp_path: Path, write_small_cell: SmallCell) -> None:
    from typer.testing import CliRunner

    from robomax_py.app.cli import app

    path = write_small_cell(tmp_path)
    res = CliRunner().invoke(app, ["bench", str(path), "--runs", "1", "--quick"], terminal_width=200)
    assert res.exit_code == 0, res.output
    for needle in ("poses/s", "configs/s", "small_cell", "baseline", "bound ="):
        assert needle in res.output


def test_bench_on_a_missing_cell_is_bad_input(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from robomax_py.app.cli import app

    res = CliRunner().invoke(app, ["bench", str(tmp_path / "nope.yaml")])
    assert res.exit_code == 2
    assert "nope.yaml" in res.output
