"""The cell a program's continuation runs in (`robomax replan`; the cell key `continuation`,
docs/cell-files.md, "Continuations").

A continuation's program takes up another program's work at a time `at` of that program's clock,
where the robot came to rest: the actions done by then are left out, and every time window moves
to the continuation's clock, which starts at `at` (windows over before it are dropped, one in
progress then starts at 0; a moving object's timed poses move with them). `robomax replan` plans
in this cell, and the cell file it writes beside the programs says the same with `continuation:`
(`at` and the actions `done`) and `robot.start`, so that `robomax verify` checks the programs
against the cell they run in, from another folder or machine alike.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection
from pathlib import Path

from robomax_py.errors import CellFileError
from robomax_py.io.cell_file import ContinuationFile
from robomax_py.spec import CellSpec, MachineSpec, ObjectSpec, frozen_array

__all__ = ["continued", "file_continuation", "shifted_windows", "spot_label"]


def spot_label(seam: str, spot: str) -> str:
    """`seam/spot`, as `continuation.done` and `robomax replan` name an action."""
    return f"{seam}/{spot}"


def shifted_windows(windows: tuple[tuple[float, float], ...], t0: float) -> tuple[tuple[float, float], ...]:
    """Windows (s from program start) in a clock starting at t0: those over before t0 dropped, one
    in progress at t0 starting at 0."""
    return tuple((max(0.0, a - t0), b - t0) for a, b in windows if b - t0 >= 0.0)


def _shifted(d: ObjectSpec, t0: float) -> ObjectSpec | None:
    """A dynamic object in the clock starting at t0; None when it is never there again."""
    if d.present is None:
        return d
    moved = shifted_windows(d.present, t0)
    if not moved:
        return None
    motion = d.motion if d.motion is None else dataclasses.replace(d.motion, t=frozen_array(d.motion.t - t0))
    return dataclasses.replace(d, present=moved, motion=motion)


def continued(cell: CellSpec, at: float, done: Collection[tuple[str, str]]) -> CellSpec:
    """The cell with the actions `done` ((seam, spot) pairs) left out, a seam with none left
    dropped, and every window in the clock starting at `at` (s of the cell's clock). Its seams may
    be empty: the caller says why that is wrong."""
    seams = []
    for seam in cell.seams:
        left = tuple(s for s in seam.spots if (seam.name, s.name) not in done)
        if left:
            seams.append(dataclasses.replace(seam, spots=left))
    dynamic = tuple(m for m in (_shifted(d, at) for d in cell.dynamic) if m is not None)
    machines = tuple(MachineSpec(m.name, m.door, shifted_windows(m.windows, at)) for m in cell.machines)
    return dataclasses.replace(cell, seams=tuple(seams), dynamic=dynamic, machines=machines)


def file_continuation(cell: CellSpec, given: ContinuationFile, path: Path) -> CellSpec:
    """A cell file's `continuation:` applied to its cell: each action in `done` one of the cell's,
    named once, and some action left."""
    labels = {spot_label(seam.name, s.name): (seam.name, s.name) for seam in cell.seams for s in seam.spots}
    done: set[tuple[str, str]] = set()
    for i, label in enumerate(given.done):
        if label not in labels:
            shown = ", ".join(list(labels)[:6]) + (", ..." if len(labels) > 6 else "")
            raise CellFileError(path, f"continuation.done[{i}]", f"{label!r} is not an action of the cell "
                                                                 f"(seam/spot, e.g. {shown})")
        if labels[label] in done:
            raise CellFileError(path, f"continuation.done[{i}]", f"{label!r} is listed twice")
        done.add(labels[label])
    out = continued(cell, given.at, done)
    if not out.seams:
        raise CellFileError(path, "continuation.done", "every action of the cell is done: nothing is left to program")
    return out
