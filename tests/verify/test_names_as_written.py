"""Names that a controller program cannot carry as they are: a seam called `seam` (an SRCL keyword,
written `seam_`) and a spot called `door-L 2` (written `door_L_2`). The programs name them by their
identifiers; `verify` reads those back as the cell's own spots, in every dialect."""

from __future__ import annotations

from pathlib import Path

import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, EXIT_VIOLATIONS, app
from tests.conftest import SmallCell

runner = CliRunner()


def test_a_keyword_seam_and_a_spaced_spot_name_plan_and_verify_in_every_dialect(
        tmp_path: Path, write_small_cell: SmallCell) -> None:
    path = write_small_cell(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["seams"][0]["name"] = "seam"
    data["seams"][0]["spots"][1]["name"] = "door-L 2"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    out = tmp_path / "out"
    done = runner.invoke(app, ["plan", str(path), "-o", str(out), "--format", "srcl,krl,rapid,fanuc,urscript"])
    assert done.exit_code == EXIT_OK, done.output
    programs = [out / "small_cell.srcl", out / "small_cell.src", out / "small_cell.mod", out / "SMALL_CELL.ls",
                out / "small_cell.script"]
    srcl = programs[0].read_text()
    assert "seam_" in srcl and "door_L_2" in srcl
    for program in programs:
        check = runner.invoke(app, ["verify", str(path), str(program)])
        assert check.exit_code == EXIT_OK, (program.name, check.output)
    # A spot the cell does not have is still one: renamed in the program, it is refused.
    programs[0].write_text(srcl.replace("door_L_2", "door_L_3"))
    check = runner.invoke(app, ["verify", str(path), str(programs[0])])
    assert check.exit_code == EXIT_VIOLATIONS and "door_L_3 is not a spot of the cell" in check.output, check.output
