"""A batch writes each cell's programs once: FANUC's default routines are every cell's alike, and a
cell whose TP program names another cell's is refused instead of overwriting its files."""

from __future__ import annotations

from pathlib import Path

from robomax_py.app.batch import BAD_INPUT, PLANNED, CellOutcome, write_outcome_programs


def _outcome(file: str, cell: str, program: str) -> CellOutcome:
    return CellOutcome(file, cell, PLANNED, 1.0, programs=((f"{cell}.json", "{}"), (f"{program}.ls", cell),
                                                             ("SPOT_WELD.ls", "routine")))


def test_fanuc_routines_are_shared_and_program_names_are_owned(tmp_path: Path) -> None:
    taken: dict[str, str] = {}
    first = write_outcome_programs(tmp_path, _outcome("a.yaml", "door-l", "DOOR_L"), taken)
    second = write_outcome_programs(tmp_path, _outcome("b.yaml", "hood", "HOOD"), taken)
    assert first.status == second.status == PLANNED                  # SPOT_WELD.ls written by both
    # "door_l" is another cell name, but its TP program is DOOR_L too (program_name).
    clash = write_outcome_programs(tmp_path, _outcome("c.yaml", "door_l", "DOOR_L"), taken)
    assert clash.status == BAD_INPUT and "a.yaml" in clash.reasons
    assert (tmp_path / "DOOR_L.ls").read_text() == "door-l"
