"""End to end on every shipped example cell (cells/*.yaml): `robomax plan --format all` writes the
trajectory file and every dialect's program, and `robomax verify` passes on each (its motion
rebuilt from the program's own statements); the frame's seams are all welded and its ordered
pillar seam keeps its order; the programs are byte for byte the committed ones
(tests/golden/shipped: the .srcl text, and the SHA-256 of every other file), so a restructuring
that changes no behaviour is shown to change no program. Slow: each cell plans in 10-40 s."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, app
from robomax_py.export import dialect_for_file
from robomax_py.export.plan_program import identifier

REPO = Path(__file__).resolve().parents[1]
CELLS = sorted((REPO / "cells").glob("*.yaml"))
GOLDEN = REPO / "tests" / "golden" / "shipped"
runner = CliRunner()
MAIN_FILES = (".json", ".srcl", ".src", ".mod", ".ls", ".script")
HASHED = (".json", ".src", ".dat", ".mod", ".ls", ".script")


def test_at_least_three_shipped_cells() -> None:
    assert {p.stem for p in CELLS} >= {"cabin_flange", "frame", "ur10_tray"}


def _file(name: str, ext: str) -> str:
    """A cell's program file: named after the cell, or, for FANUC, after its TP program."""
    dialect = dialect_for_file(ext)
    return f"{dialect.program_name(identifier(name)) if dialect and dialect.program_name else name}{ext}"


def _verified(cell: Path) -> tuple[str, ...]:
    """The files `robomax verify` reads back for a cell: the trajectory file, the SRCL program and one
    controller dialect, a different one for each shipped cell in turn, so that every dialect is
    verified from disk through the command line. (`plan` has already proven every program it wrote:
    read back, rebuilt and verified in-process, before writing.)"""
    dialects = (".src", ".mod", ".ls", ".script")
    return ".json", ".srcl", dialects[CELLS.index(cell) % len(dialects)]


def _plan(cell: Path, out: Path) -> dict[str, object]:
    result = runner.invoke(app, ["plan", str(cell), "-o", str(out), "--format", "all"])
    assert result.exit_code == EXIT_OK, result.output
    name = yaml.safe_load(cell.read_text()).get("name", cell.stem)
    for ext in MAIN_FILES:
        program = out / _file(name, ext)
        assert program.is_file(), f"{program} not written"
        if ext in _verified(cell):
            check = runner.invoke(app, ["verify", str(cell), str(program)])
            assert check.exit_code == EXIT_OK, check.output
    data: dict[str, object] = json.loads((out / f"{name}.json").read_text())
    return data


@pytest.mark.slow
@pytest.mark.parametrize("cell", CELLS, ids=[p.stem for p in CELLS])
def test_shipped_cell_plans_and_verifies(cell: Path, tmp_path: Path, update_golden: bool) -> None:
    data = _plan(cell, tmp_path)
    name = yaml.safe_load(cell.read_text()).get("name", cell.stem)
    srcl = (tmp_path / f"{name}.srcl").read_bytes()
    digests = {_file(name, ext): hashlib.sha256((tmp_path / _file(name, ext)).read_bytes()).hexdigest() for ext in HASHED}
    sums_file = GOLDEN / "SHA256SUMS"
    sums = dict(reversed(line.split("  ")) for line in sums_file.read_text().splitlines() if line)
    if update_golden:
        (GOLDEN / f"{name}.srcl").write_bytes(srcl)
        sums.update(digests)
        sums_file.write_text("".join(f"{v}  {k}\n" for k, v in sorted(sums.items())))
    assert srcl == (GOLDEN / f"{name}.srcl").read_bytes(), f"{name}.srcl differs from tests/golden/shipped"
    for file, digest in digests.items():
        assert digest == sums.get(file), f"{file} differs from tests/golden/shipped/SHA256SUMS"
    spec = yaml.safe_load(cell.read_text())
    if "tending" in spec:                   # the job as one ordered seam of station visits per cycle
        job = spec["tending"]
        visits = job.get("sequence") or [st["name"] for st in job["stations"]]
        spec["seams"] = [{"name": "tending", "ordered": True, "spots": [
            {"name": f"c{c}_{v}"} for c in range(1, job.get("cycles", 1) + 1) for v in visits]}]
    if "pick_place" in spec:                # each transfer a pick where the part lies and a place
        spec["seams"] = [{"name": "transfers", "ordered": True, "spots": [
            {"name": f"t{k}_{visit}_{loc}"} for k, tr in enumerate(spec["pick_place"]["transfers"], start=1)
            for visit, loc in (("pick", tr["from"]), ("place", tr["to"]))]}]
    wanted = {(s["name"], p["name"]) for s in spec["seams"] for p in s["spots"]}
    welded = [(s["seam"], s["name"]) for s in data["spots"]]  # type: ignore[union-attr]
    assert sorted(welded) == sorted(wanted)                      # every spot of every seam, once
    for seam in spec["seams"]:
        if seam.get("ordered"):
            got = [name for s, name in welded if s == seam["name"]]
            assert got == [p["name"] for p in seam["spots"]], f"{seam['name']} welded out of order"


def test_frame_has_an_ordered_seam_and_several_seams() -> None:
    spec = yaml.safe_load((REPO / "cells" / "frame.yaml").read_text())
    assert 3 <= len(spec["seams"]) <= 4
    assert [s["name"] for s in spec["seams"] if s.get("ordered")] == ["pillar"]
