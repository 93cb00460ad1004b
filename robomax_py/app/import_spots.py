"""`robomax import-spots`: a cell file with a CSV spot list's spots added as seams (docs/spot-lists.md).

The list is read by `io.cell.spot_list_seams`, as the cell key `spot_lists` reads it, so the new
cell's spots equal the ones the key would give.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path

from robomax_py.errors import CellFileError, OutputError
from robomax_py.io.cell import (
    dump_cell_file,
    load_cell,
    read_cell_file,
    read_cell_frames,
    spot_list_seams,
)
from robomax_py.io.files import write_atomic
from robomax_py.io.spot_list import DEFAULT_MAX_DISTANCE


@dataclass(frozen=True, slots=True)
class ImportedSpots:
    cell: Path
    seams: tuple[tuple[str, int], ...]        # name, spots
    recovered_normals: int
    recovered_directions: int
    formed: tuple[str, ...]                   # each seam formed, for a person to check
    sides: tuple[str, ...]                    # spots whose side is a guess
    warnings: tuple[str, ...]
    cpu_s: float


def import_spots(cell: Path, spots: Path, part: str, out: Path, units: str | None = None,
                 max_distance: float = DEFAULT_MAX_DISTANCE, force: bool = False,
                 frame: str | None = None, either_side: bool = False) -> ImportedSpots:
    """Write `out`: the cell `cell` with the list's spots added as seams after its own, checked as
    `robomax check` checks it; nothing is written when anything is wrong. The list's coordinates
    are in the part's frame, or in `frame` (a named frame of the cell, an object, or the world).
    `either_side`: the new seams' gun may stand on either side of the sheet (`tolerance.sides:
    either`), and a spot free on both sides is not reported."""
    start = time.process_time()
    if out.resolve() == cell.resolve():
        raise OutputError(out, None, "is the cell read: the new cell is written to another file")
    if out.resolve().parent != cell.resolve().parent:
        # The cell's meshes, robot and tool paths are relative to its folder.
        raise OutputError(out, None, f"write the new cell beside {cell} (its relative paths are to that folder)")
    if os.path.lexists(out) and not force:
        raise OutputError(out, None, "exists; use --force to replace it")
    parsed = read_cell_file(cell)
    taken = {s.name for s in parsed.seams}
    tree = read_cell_frames(cell)[0] if frame is not None else ()    # `parsed` is flat: its named frames are gone
    settings = {"tolerance": {"sides": "either"}} if either_side else None
    seams, result = spot_list_seams(parsed, cell, "", spots, part, units, max_distance, settings, frame, tree)
    clash = next((s.name for s in seams if s.name in taken), None)
    if clash is not None:
        raise CellFileError(spots, None, f"the list's seam '{clash}' is also a seam of {cell}; rename one")
    new = parsed.model_copy(update={"seams": [*parsed.seams, *seams]})
    text = dump_cell_file(new, header=f"{cell.name} with the spots of {spots.name} (robomax import-spots)")
    _check_written(text, out)
    write_atomic(out, text)
    return ImportedSpots(out, tuple((s.name, len(s.spots)) for s in seams), result.recovered_normals,
                         result.recovered_directions, tuple(result.formed), tuple(result.sides),
                         tuple(result.warnings), time.process_time() - start)


def _check_written(text: str, out: Path) -> None:
    """The new cell loads as `robomax check` loads it: checked in a file beside `out` (relative paths
    resolve the same), removed after."""
    trial = out.with_name(f".{out.name}.robomax-check.yaml")
    try:
        trial.write_text(text, encoding="utf-8")
        load_cell(trial)
    except CellFileError as exc:
        raise CellFileError(out, exc.key, exc.problem) from None
    finally:
        trial.unlink(missing_ok=True)
