"""`planner.cartesian_moves: spline` end to end on a small cell whose robot stands off the cell's
origin (moved, yawed and raised with everything else), its targets in a user frame on the fixture: the planner flies some junction as a
Bézier spline where that is faster, KRL and SRCL state it as a spline block and rebuild exactly
what was planned, RAPID, FANUC and URScript state it as short lines flown by within the stated
tolerances, and every written program verifies clean against the cell."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from robomax_py.app.report import plan_report
from robomax_py.export import DIALECTS
from robomax_py.export.krl import parse as parse_krl
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.plan.spline_junction import SPLINE_TOL_M
from robomax_py.program import Comment, LinMove
from robomax_py.publish import publish
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.verify import verify_program
from tests.conftest import place_cell, with_pulses

REPO = Path(__file__).resolve().parents[2]
CELL = REPO / "tests" / "data" / "spline_cell" / "spline_cell.yaml"
GOLDEN = REPO / "tests" / "golden" / "spline_cell"
# The robot's placement: 1.5 m, -0.8 m off the origin, on a 0.45 m riser, yawed 35 deg.
PLACEMENT = ((1.5, -0.8, 0.45), 35.0)
FORMATS = ("srcl", "krl", "rapid", "fanuc", "urscript")


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory, shared_once: Any) -> dict[str, Any]:
    data = yaml.safe_load(CELL.read_text())
    place_cell(data, *PLACEMENT)
    # The integrator's numbers: targets relative to user frame 3 on the fixture plate, tool 2.
    data["robot"]["controller"] = {"tool": {"number": 2, "name": "gun2"},
                                   "frame": {"number": 3, "object": "fixture_plate"},
                                   "registers": {"position": [40, 41]}}
    folder = tmp_path_factory.mktemp("spline_cell")
    path = folder / "spline_cell.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    robot = with_pulses(load_cell_robot(cell))

    def compute() -> tuple[Any, Any, Any]:
        result = plan_cell(cell, robot)
        files, checked = publish(result, cell, robot, FORMATS)
        return result, files, checked

    result, files, checked = shared_once(f"spline programs {path.read_text()}", compute)
    return {"folder": folder, "cell": cell, "robot": robot, "result": result, "files": files,
            "checked": {c.format: c for c in checked}}


def test_a_junction_flies_a_spline_where_that_is_faster(planned: dict[str, Any]) -> None:
    result = planned["result"]
    between = result.transitions[1:len(result.spots)]
    assert between and all(t.choice is not None for t in between), "every junction between two spots chooses"
    chosen = [t for t in between if t.choice.chosen == "spline"]
    assert chosen, "no junction of the cell flies a spline"
    for t in between:
        c = t.choice
        if c.chosen == "spline":
            assert t.spline is not None and c.spline_time is not None and c.spline_time < c.flyby_time
            # The spline through the written points keeps to the Bézier path within the points' sagitta.
            assert t.spline.deviation_m <= SPLINE_TOL_M
        else:
            assert t.spline is None and (c.spline_time is None or c.spline_time >= c.flyby_time)
    moves = plan_report(result, 0.0, [])["cartesian_moves"]
    assert [m["between"] for m in moves] == [t.label for t in between]
    assert [m["chosen"] for m in moves] == [t.choice.chosen for t in between]


def test_krl_and_srcl_state_spline_blocks_and_rebuild_the_plan(planned: dict[str, Any]) -> None:
    files, checked = planned["files"], planned["checked"]
    n_splines = sum(t.spline is not None for t in planned["result"].transitions)
    src = files["spline_cell.src"]
    assert src.count("\nSPLINE\n") == src.count("\nENDSPLINE\n") == n_splines
    assert src.count("  SLIN ") == 2 * n_splines
    srcl = files["spline_cell.srcl"]
    assert srcl.count("MOVE SLIN ") == 2 * n_splines and "MOVE SPL " in srcl
    for fmt in ("krl", "srcl"):
        assert checked[fmt].difference.within(), (fmt, checked[fmt].difference)


def test_lin_dialects_follow_the_spline_within_the_stated_tolerance(planned: dict[str, Any]) -> None:
    cycle = planned["result"].trajectory.duration
    for fmt in ("rapid", "fanuc", "urscript"):
        diff = planned["checked"][fmt].difference
        assert not diff.identical, f"{fmt}: the lines should not be the spline sample for sample"
        assert diff.within(cycle), (fmt, diff)
        assert diff.tcp_mm <= TOL.spline_lines_mm


def test_every_written_program_verifies_clean_against_the_placed_cell(planned: dict[str, Any]) -> None:
    folder: Path = planned["folder"] / "out"
    folder.mkdir(exist_ok=True)
    for name, text in planned["files"].items():
        (folder / name).write_bytes(text.encode())
    mains = {"srcl": "spline_cell.srcl", "krl": "spline_cell.src", "rapid": "spline_cell.mod",
             "fanuc": "SPLINE_CELL.ls", "urscript": "spline_cell.script"}
    for fmt, main in mains.items():
        report = verify_program(planned["cell"], planned["robot"], folder / main)
        assert report.clean, (fmt, report.violations[:3])


def test_golden_krl_spline_program(planned: dict[str, Any], update_golden: bool) -> None:
    names = ("spline_cell.src", "spline_cell.dat", "spline_cell_frames.src", "spline_cell.srcl")
    for name in names:
        golden = GOLDEN / name
        text = planned["files"][name]
        if update_golden:
            GOLDEN.mkdir(exist_ok=True)
            golden.write_bytes(text.encode())
        assert golden.is_file(), f"missing {golden}: run pytest --update-golden and review the diff"
        assert text.encode() == golden.read_bytes(), f"spline_cell/{name} changed: review, then pytest --update-golden"


def _texts(planned: dict[str, Any], src: str) -> dict[str, str]:
    return {".src": src, ".dat": planned["files"]["spline_cell.dat"],
            "_frames.src": planned["files"]["spline_cell_frames.src"]}


def test_krl_reads_a_spline_block_as_its_segments(planned: dict[str, Any]) -> None:
    parsed = parse_krl(_texts(planned, planned["files"]["spline_cell.src"]), "spline_cell.src", planned["robot"])
    assert not parsed.problems and not parsed.ignored
    kinds = [m.spline for m in parsed.program.instructions if isinstance(m, LinMove) and m.spline]
    assert kinds and kinds[0] == "slin" and kinds[-1] == "slin" and "spl" in kinds


@pytest.mark.parametrize(("change", "why"), [
    (("ENDSPLINE\n", "ENDSPLINE C_SPL\n"), "an approximated block"),
    (("\nSPLINE\n", "\n"), "segments outside a block"),
])
def test_krl_spline_forms_it_does_not_model_are_not_simulated(planned: dict[str, Any], change: tuple[str, str],
                                                            why: str) -> None:
    src = planned["files"]["spline_cell.src"].replace(*change, 1)
    parsed = parse_krl(_texts(planned, src), "spline_cell.src", planned["robot"])
    assert parsed.ignored, why
    assert any(isinstance(i, Comment) and i.text.startswith("not simulated") for i in parsed.program.instructions), why


def test_every_dialect_has_its_spline_form() -> None:
    assert {name for name, d in DIALECTS.items() if d.splines} == {"srcl", "krl"}


def test_the_report_names_each_junctions_way_and_times(planned: dict[str, Any]) -> None:
    from rich.console import Console

    from robomax_py.app.report import report_tables

    report = plan_report(planned["result"], 0.0, [])
    console = Console(width=200, record=True)
    for table in report_tables(report):
        console.print(table)
    text = console.export_text()
    chosen = [m for m in report["cartesian_moves"] if m["chosen"] == "spline"]
    assert f"{len(chosen)} of {len(report['cartesian_moves'])} junctions" in text
    assert all(m["as_lines_s"] is not None and m["as_lines_s"] > m["spline_s"] for m in chosen)
