"""`--format all` on a station of two brands: each robot's controller section numbers its I/O as
its own vendor does (the KR 125-class arm's clamp inputs 11 and 12 and interlock I/O from 101, the
UR10's 0..7), so the dialects that cannot address a robot's numbers are passed over for that robot,
named with the station key, and the others written and replayed together clean. Named, such a
dialect is refused before anything is planned (it used to fail after the plan, naming a cell key
the station file does not have)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_OK, app
from tests.bench.station_cells import station, write

runner = CliRunner()


@pytest.fixture(scope="module")
def two_brands(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write(tmp_path_factory.mktemp("format_all"), station(2, 8, 0, ["kr125", "ur10"], name="two_brands"))


@pytest.mark.slow
def test_all_writes_what_each_controller_can_address(two_brands: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    planned = runner.invoke(app, ["plan", str(two_brands), "-o", str(out), "--format", "all"])
    assert planned.exit_code == EXIT_OK, planned.output
    written = {p.name for p in out.iterdir()}
    assert {"two_brands_r1.srcl", "two_brands_r1.src", "two_brands_r1.mod", "two_brands_r2.script",
            "two_brands_r2.mod"} <= written
    assert "two_brands_r1.script" not in written and "two_brands_r2.src" not in written
    text = " ".join(planned.output.split())
    assert "robots[0].controller.inputs.clamp_left_closed: input 11 is outside URScript's inputs 0..7: " \
           "no urscript program written" in text
    assert "robots[1].controller.inputs.clamp_left_closed: input 0 is outside KRL's inputs 1..4096: " \
           "no krl program written" in text
    checked = runner.invoke(app, ["verify", str(two_brands), str(out)])
    assert checked.exit_code == EXIT_OK, checked.output


def test_a_named_dialect_that_cannot_address_a_robots_io_is_refused_before_planning(two_brands: Path,
                                                                                     tmp_path: Path) -> None:
    out = tmp_path / "out"
    refused = runner.invoke(app, ["plan", str(two_brands), "-o", str(out), "--format", "urscript"])
    assert refused.exit_code == EXIT_BAD_INPUT, refused.output
    text = " ".join(refused.output.split())
    assert "robots[0].controller.inputs.clamp_left_closed: input 11 is outside URScript's inputs 0..7 " \
           "(--format urscript)" in text
    assert "Traceback" not in refused.output and "sequencing" not in text
    assert not out.exists()


@pytest.mark.slow
def test_the_json_report_names_what_was_passed_over(two_brands: Path, tmp_path: Path) -> None:
    planned = runner.invoke(app, ["plan", str(two_brands), "-o", str(tmp_path / "out"), "--format", "srcl,rapid,krl",
                                  "--json"])
    assert planned.exit_code == EXIT_BAD_INPUT                      # KRL named: the UR10's inputs 0 and 1
    planned = runner.invoke(app, ["plan", str(two_brands), "-o", str(tmp_path / "out"), "--format", "all", "--json"])
    assert planned.exit_code == EXIT_OK, planned.output
    report = json.loads(planned.stdout)
    skipped = {(k["robot"], k["format"]): k for k in report["skipped_formats"]}
    assert skipped[("r1", "urscript")]["key"] == "robots[0].controller.inputs.clamp_left_closed"
    assert skipped[("r2", "krl")]["why"] == "input 0 is outside KRL's inputs 1..4096"
    assert ("r1", "krl") not in skipped and ("r2", "urscript") not in skipped
