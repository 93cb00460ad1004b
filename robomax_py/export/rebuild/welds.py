"""A program's welds against its cell: the weld time a weld call states, and the gun, schedule and
weld time of a process-package weld (each a problem's detail, or None)."""

from __future__ import annotations

from robomax_py.export.rebuild.result import WELD_TIME_TOL_S
from robomax_py.program import Spot
from robomax_py.spec import CellSpec, SpotSpec


def _spot_of(cell: CellSpec, spot: Spot) -> SpotSpec | None:
    """The cell's spot a weld names (as the program writes names: `identifier`)."""
    from robomax_py.program import identifier

    seam = next((s for s in cell.seams if identifier(s.name) == spot.seam), None)
    return next((p for p in seam.spots if identifier(p.name) == spot.name), None) if seam else None


def weld_time_problem(cell: CellSpec, spot: Spot, label: str) -> str | None:
    """A weld call's time is the cell's weld time of that spot (the weld routine rests or welds
    that long: another time is another weld)."""
    spec = _spot_of(cell, spot)
    if spec is None or spec.action is not None:
        return None
    want = cell.process.weld_time_of(spec)
    if abs(spot.time_s - want) <= WELD_TIME_TOL_S:
        return None
    hint = ""
    if want > 0 and abs(spot.time_s / want - 1000.0) < 1.0:
        hint = " (a thousand times: written in ms?)"
    return f"{label}: the program welds {spot.time_s:.3f} s, the cell's weld time is {want:.3f} s{hint}"


def schedule_time(cell: CellSpec, ins: Spot) -> tuple[float, str | None]:
    """The weld time of a process-package weld: its gun and schedule's, as the cell's spots with
    that schedule take it (the controller's schedule table holds one time each); 0 with a problem
    when the cell has no spot of that schedule or several times for it."""
    process = cell.process
    times = {process.weld_time_of(spot) for seam in cell.seams for spot in seam.spots
             if process.gun == ins.gun and process.schedule_of(spot) == ins.schedule}
    if len(times) != 1:
        what = "no spot of the cell" if not times else f"the cell's spots {sorted(times)} s"
        return 0.0, f"gun {ins.gun} schedule {ins.schedule}: {what} gives its weld time"
    return times.pop(), None


def schedule_problem(cell: CellSpec, spot: Spot, label: str) -> str | None:
    """A process-package weld names the gun and schedule the controller welds with: those of the
    cell's spot (a weld time alone does not tell a schedule's current from another's)."""
    spec = _spot_of(cell, spot)
    if spec is None:
        return None
    want = (cell.process.gun, cell.process.schedule_of(spec))
    if (spot.gun, spot.schedule) != want:
        return (f"{label}: the program welds with gun {spot.gun} schedule {spot.schedule}, the cell with gun "
                f"{want[0]} schedule {want[1]}")
    return None
