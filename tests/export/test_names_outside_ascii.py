"""Names a German or Chinese integrator writes (`Schweißpunkt_1`, `Naht_ÄÖÜ`, `点1`): every program
names things with letters, digits and '_' only, German letters spelled out (`Schweisspunkt_1`) and
other characters made '_'; each dialect's program of such a cell is written, read back and
verified clean. Two names that would be written
alike are refused when the cell is read (tests/io/test_cell.py)."""

from __future__ import annotations

from pathlib import Path

import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import app

runner = CliRunner()


def test_a_cell_named_in_german_and_chinese_is_written_in_every_dialect(tmp_path: Path, write_small_cell) -> None:  # type: ignore[no-untyped-def]
    path = write_small_cell(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["name"] = "Kabine_Außen"
    for i, seam in enumerate(data["seams"]):
        seam["name"] = ["Naht_ÄÖÜ", "焊缝"][i % 2] + str(i)
        for j, spot in enumerate(seam["spots"]):
            spot["name"] = f"Schweißpunkt_{j + 1}" if j % 2 else f"点{j + 1}"
    path.write_text(yaml.safe_dump(data, allow_unicode=True, sort_keys=False), encoding="utf-8")
    out = tmp_path / "out"
    done = runner.invoke(app, ["plan", str(path), "--out", str(out), "--format", "all"])
    assert done.exit_code == 0, done.output
    programs = [p for p in out.iterdir() if p.suffix.lower() in {".srcl", ".src", ".mod", ".ls", ".script", ".jbi", ".as"}
                and "frames" not in p.name.lower() and p.name != "SPOT_WELD.ls"]
    # SRCL, KRL, RAPID, FANUC TP, URScript, AS (INFORM needs the arm's pulses per degree).
    assert len(programs) == 6, sorted(p.name for p in out.iterdir())
    srcl = next(p for p in programs if p.suffix == ".srcl").read_text()
    assert "SPOT Schweisspunkt_2 SEAM Naht_AeOeUe0" in srcl and "SPOT _1 SEAM Naht_AeOeUe0" in srcl
    # KSS reads its files in Windows-1252, RAPID's in a code page of the controller: their comments
    # are written in ASCII, German letters spelled out.
    for program in programs:
        if program.suffix in (".src", ".mod"):
            text = program.read_text(encoding="utf-8")
            assert text.isascii() and "Naht_AeOeUe0/Schweisspunkt_2" in text, program.name
    for program in programs:
        checked = runner.invoke(app, ["verify", str(path), str(program)])
        assert checked.exit_code == 0 and "clean" in checked.output, (program.name, checked.output)
