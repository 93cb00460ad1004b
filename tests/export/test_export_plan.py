"""Program exporters on a real plan: golden files, and the SRCL text parses back to the same bytes."""

from __future__ import annotations

from pathlib import Path

import pytest

from robomax_py.export import FORMATS, render
from robomax_py.export.plan_program import identifier
from robomax_py.export.srcl import parse_program, write_program
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell

REPO = Path(__file__).resolve().parents[2]
GOLDEN = REPO / "tests" / "golden"


@pytest.fixture(scope="module")
def small_plan(tmp_path_factory: pytest.TempPathFactory, write_small_cell):  # type: ignore[no-untyped-def]
    """The plan of the small test cell (conftest.write_small_cell)."""
    cell = load_cell(write_small_cell(tmp_path_factory.mktemp("small")))
    result = plan_cell(cell, load_cell_robot(cell))
    assert result.status == "planned", result.message
    return result


@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_golden(small_plan, fmt: str, update_golden: bool) -> None:  # type: ignore[no-untyped-def]
    text = render(small_plan, fmt)
    golden = GOLDEN / f"small_cell{FORMATS[fmt].extension}"
    if update_golden:
        golden.write_text(text)
    assert golden.is_file(), f"missing {golden}: run pytest --update-golden and review the diff"
    assert text == golden.read_text(), f"{golden.name} changed: review, then pytest --update-golden"


def test_srcl_of_a_plan_parses_back_byte_identical(small_plan) -> None:  # type: ignore[no-untyped-def]
    text = render(small_plan, "srcl")
    program = parse_program(text, "small_cell.srcl")
    assert write_program(program) == text
    assert program.header.joints == small_plan.joint_names
    spots = [i for i in program.instructions if type(i).__name__ == "Spot"]
    assert [s.name for s in spots] == [s.name for s in small_plan.spots]


@pytest.mark.parametrize(("name", "ident"), [("door-L 2", "door_L_2"), ("7up", "_7up"), ("s1", "s1")])
def test_identifier(name: str, ident: str) -> None:
    assert identifier(name) == ident
