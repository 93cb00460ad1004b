"""Gantt chart of a station's replay (`verify_station`): one row per robot, its timeline on the
station clock as bars (moving, welding, waiting), each wait labelled with the signal and the robot
it waits for, a wait that never ends hatched; the title gives the makespan and each robot's idle
share. Rendered with matplotlib (Agg), as the single-robot cycle chart (`app.chart`)."""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import Any

from robomax_py.app import palette
from robomax_py.app.chart import DPI, WIDTH_PX
from robomax_py.verify_station import StationReport

BASE_HEIGHT_PX = 200
ROW_HEIGHT_PX = 48
# The replay's activities in the cycle chart's colours: moving as a move, welding as a weld,
# waiting as a wait.
KIND_PHASE = {"moving": "move", "welding": "weld", "waiting": "wait"}
# A label is drawn on a wait bar at least this long (s); shorter ones are left to the legend.
LABEL_MIN_S = 0.4


@dataclass(frozen=True, slots=True)
class StationBar:
    """One activity: its robot's row, kind, start and duration (s), and for a wait what it waits
    for ("r1_z1_clear of r1"); `forever` when it never ends."""

    row: int
    kind: str
    start: float
    duration: float
    label: str = ""
    forever: bool = False


@dataclass(frozen=True, slots=True)
class StationChart:
    station: str
    rows: tuple[str, ...]             # "r1 (idle 12 %)"
    bars: tuple[StationBar, ...]
    makespan: float
    end: float                        # the clock's right edge, s (>= makespan: waits that never end)

    def size_px(self) -> tuple[int, int]:
        return WIDTH_PX, BASE_HEIGHT_PX + ROW_HEIGHT_PX * max(len(self.rows), 1)


def station_chart(name: str, report: StationReport) -> StationChart:
    """The chart's rows and bars from a station's replay."""
    rows, bars = [], []
    end = max([report.makespan, *(a.t_end for m in report.members for a in m.timeline)])
    for i, member in enumerate(report.members):
        rows.append(f"{member.name} (idle {100.0 * report.idle_share(member.name):.0f} %)")
        for a in member.timeline:
            label = ""
            if a.kind == "waiting" and a.signal:
                label = f"{a.signal} of {a.other}" if a.other else (f"{a.signal}: never set" if a.forever else a.signal)
            duration = max(a.t_end - a.t_start, 0.0)
            if a.forever and duration <= 0.0:
                duration = max(end, 1.0) * 0.02          # a sliver to show where it stopped
            bars.append(StationBar(i, a.kind, a.t_start, duration, label, a.forever))
    return StationChart(name, tuple(rows), tuple(bars), report.makespan, max(end, report.makespan))


def station_figure(chart: StationChart) -> Any:
    """A matplotlib Figure (Agg canvas, no pyplot state); bars are Rectangles with gid "bar"."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    width, height = chart.size_px()
    fig = Figure(figsize=((width + 0.01) / DPI, (height + 0.01) / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    right = max(chart.end, 1e-3)
    for bar in chart.bars:
        colour = palette.hex_colour(palette.phase_colour(KIND_PHASE.get(bar.kind, "move")))
        rect = ax.barh(bar.row, bar.duration, left=bar.start, height=0.6, color=colour, edgecolor="none",
                       hatch="//" if bar.forever else None)
        for patch in rect.patches:
            patch.set_gid("bar")
        if bar.label and (bar.duration >= LABEL_MIN_S or bar.forever):
            ax.text(bar.start + 0.05 * min(bar.duration, 1.0), bar.row, bar.label, va="center", ha="left",
                    fontsize="small", clip_on=True)
    ax.set_yticks(range(len(chart.rows)), labels=list(chart.rows))
    ax.set_ylim(len(chart.rows) - 0.5, -0.5)
    ax.set_xlim(0.0, right * 1.02)
    if chart.makespan > 0:
        ax.axvline(chart.makespan, color="#444444", linewidth=0.8, linestyle="--")
    ax.set_xlabel("time (s)")
    ax.grid(axis="x", color="#dddddd", linewidth=0.6)
    ax.set_axisbelow(True)
    ax.set_title(f"station {chart.station}: makespan {chart.makespan:.2f} s, {len(chart.rows)} robots")
    handles = [Patch(color=palette.hex_colour(palette.phase_colour(KIND_PHASE[k])), label=k)
               for k in ("moving", "welding", "waiting")]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), frameon=False, fontsize="small")
    fig.tight_layout(rect=(0.0, 40.0 / height, 1.0, 1.0))
    return fig


def render_station_png(chart: StationChart) -> bytes:
    """The chart as PNG bytes, exactly `chart.size_px()` pixels."""
    buf = io.BytesIO()
    station_figure(chart).savefig(buf, format="png", dpi=DPI)
    return buf.getvalue()


__all__ = ["StationBar", "StationChart", "render_station_png", "station_chart", "station_figure"]
