"""A batch worker that plans nothing, for `bench_batch.py --overhead`: a module of its own, light to
import, since every cell's process imports it (the real worker's module is preloaded)."""

from __future__ import annotations

from pathlib import Path

from robomax_py.app.batch_cell import PLANNED, CellOutcome, PlanSettings

# A program of a small plan's length (the small test cell's SRCL is about 30 KB).
PROGRAM = "; a program line of a typical length, repeated as a small plan's program is long\n" * 400


def stand_in_worker(file: str, settings: PlanSettings) -> CellOutcome:
    """A planned outcome with a program of a plan's size, at once."""
    name = Path(file).stem
    return CellOutcome(file, name, PLANNED, 0.0, cycle_time=1.0, spots=2, detours=0,
                       programs=((f"{name}.json", "{}"), (f"{name}.srcl", PROGRAM)), cell_sha256="0" * 64)
