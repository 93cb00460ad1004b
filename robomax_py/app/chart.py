"""Cycle-time Gantt chart of a planned trajectory (`robomax plan --plot`), rendered with matplotlib (Agg).

One row per spot in weld order, holding what it takes to get there and weld it: the move or detour
from the previous stop (and any wait before it), the approach, the weld and the retract; a last row
"return home" holds the way back. Bars sit at their times on the program's clock and are coloured by
phase kind (`palette.PHASE_COLOURS`), so the bars together cover the cycle exactly once.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import Any

from robomax_py.app import palette
from robomax_py.errors import ExportError
from robomax_py.plan import PlanResult

RETURN_ROW = "return home"
DPI = 110
# Size in pixels at DPI: fixed width, a fixed base plus one band per row.
WIDTH_PX = 1100
BASE_HEIGHT_PX = 180
ROW_HEIGHT_PX = 34
LEGEND_ORDER = ("move", "detour", "blend", "approach", "weld", "retract", "wait")


@dataclass(frozen=True, slots=True)
class Bar:
    """One phase: its row (index into CycleChart.rows), kind, start and duration, s."""

    row: int
    kind: str
    start: float
    duration: float


@dataclass(frozen=True, slots=True)
class CycleChart:
    """What the chart shows: row labels top to bottom, the bars, and the title's facts."""

    cell: str
    robot: str
    cycle_time: float
    rows: tuple[str, ...]
    bars: tuple[Bar, ...]
    tending: bool = False            # the stops are gripper actions at stations, not welds

    def size_px(self) -> tuple[int, int]:
        """(width, height) of the rendered PNG, pixels."""
        return WIDTH_PX, BASE_HEIGHT_PX + ROW_HEIGHT_PX * max(len(self.rows), 1)


def cycle_chart(result: PlanResult) -> CycleChart:
    """The chart's rows and bars from a planned result's trajectory phases.

    Raises
    ------
    ExportError
        The result has no trajectory (the plan is not complete).
    """
    traj = result.trajectory
    if traj is None:
        raise ExportError(f"{result.cell}: no trajectory to chart (status {result.status})")
    t0 = float(traj.t[0])
    phases = traj.phases
    rows: list[str] = [p.label or f"spot {k + 1}" for k, p in enumerate(traj.phases_of("weld"))]
    bars: list[Bar] = []
    row = 0
    for k, p in enumerate(phases):
        if p.duration > 0.0:
            bars.append(Bar(min(row, len(rows)), p.kind, float(p.t_start) - t0, float(p.duration)))
        following = phases[k + 1].kind if k + 1 < len(phases) else None
        if p.kind == "retract" and following != "retract":
            row += 1                     # the spot is done: what follows leads to the next one
    if any(b.row == len(rows) for b in bars):
        rows.append(RETURN_ROW)
    return CycleChart(result.cell, result.robot, float(traj.duration), tuple(rows), tuple(bars), result.tending)


def chart_figure(chart: CycleChart) -> Any:
    """A matplotlib Figure (Agg canvas, no pyplot state) of the chart; bars are Rectangles with gid "bar"."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    width, height = chart.size_px()
    # Agg truncates the size to whole pixels: a hundredth of a pixel keeps it from losing one.
    fig = Figure(figsize=((width + 0.01) / DPI, (height + 0.01) / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    totals: dict[str, float] = {}
    for bar in chart.bars:
        rect = ax.barh(bar.row, bar.duration, left=bar.start, height=0.62,
                       color=palette.hex_colour(palette.phase_colour(bar.kind)), edgecolor="none")
        for patch in rect.patches:
            patch.set_gid("bar")
        totals[bar.kind] = totals.get(bar.kind, 0.0) + bar.duration
    ax.set_yticks(range(len(chart.rows)), labels=list(chart.rows))
    ax.set_ylim(len(chart.rows) - 0.5, -0.5)             # first spot on top
    ax.set_xlim(0.0, chart.cycle_time)
    ax.set_xlabel("time (s)")
    ax.grid(axis="x", color="#dddddd", linewidth=0.6)
    ax.set_axisbelow(True)
    ax.set_title(f"{chart.cell} ({chart.robot}): cycle time {chart.cycle_time:.2f} s, "
                 f"{sum(1 for r in chart.rows if r != RETURN_ROW)} {'stations' if chart.tending else 'spots'}")
    kinds = [k for k in LEGEND_ORDER if k in totals] + sorted(k for k in totals if k not in LEGEND_ORDER)
    handles = [Patch(color=palette.hex_colour(palette.phase_colour(k)), label=f"{_word(k, chart.tending)} {totals[k]:.2f} s")
               for k in kinds]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), frameon=False, fontsize="small")
    fig.tight_layout(rect=(0.0, 40.0 / height, 1.0, 1.0))
    return fig


def _word(kind: str, tending: bool) -> str:
    """A phase kind as the chart names it: the stop at a tending station is the gripper's action."""
    return "grip/release" if tending and kind == "weld" else kind


def render_png(chart: CycleChart) -> bytes:
    """The chart as PNG bytes, exactly `chart.size_px()` pixels."""
    fig = chart_figure(chart)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI)
    return buf.getvalue()


__all__ = ["Bar", "CycleChart", "chart_figure", "cycle_chart", "render_png"]
