"""Program exporters on real plans: golden files for every dialect, for the small cell and for a cell
with a dynamic obstacle (a WAIT), a clamp interlock signal and per-spot process overrides; each
written program reads back to the program it was written from (`publish` proves it)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from robomax_py.export import DIALECTS, SHARED_FILES
from robomax_py.export.plan_program import identifier, program_from_plan
from robomax_py.export.srcl import parse_program, write_program
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.program import Spot, WaitFor
from robomax_py.publish import publish
from tests.conftest import with_pulses

REPO = Path(__file__).resolve().parents[2]
GOLDEN = REPO / "tests" / "golden"
ALL = tuple(DIALECTS)


def _planned(path: Path) -> dict[str, Any]:
    cell = load_cell(path)
    robot = with_pulses(load_cell_robot(cell))        # INFORM counts joint positions in pulses
    result = plan_cell(cell, robot)
    assert result.status == "planned", result.message
    files, checked = publish(result, cell, robot, ALL)
    return {"cell": cell, "robot": robot, "result": result, "files": files, "checked": checked}


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory, write_small_cell) -> dict[str, Any]:  # type: ignore[no-untyped-def]
    return _planned(write_small_cell(tmp_path_factory.mktemp("small")))


@pytest.fixture(scope="module")
def process_cell(tmp_path_factory: pytest.TempPathFactory, write_process_cell) -> dict[str, Any]:  # type: ignore[no-untyped-def]
    """The process cell (tests/conftest.py): a door, a clamp input, gun 2, s8 welded longer; placed
    off the origin with the integrator's numbers."""
    return _planned(write_process_cell(tmp_path_factory.mktemp("process")))


def _golden(planned: dict[str, Any], update: bool) -> None:
    name = planned["result"].cell
    folder = GOLDEN / name
    for file, text in planned["files"].items():
        golden = folder / file
        if update:
            folder.mkdir(exist_ok=True)
            golden.write_bytes(text.encode())
        assert golden.is_file(), f"missing {golden}: run pytest --update-golden and review the diff"
        # Bytes: FANUC's lines end in CRLF, which reading as text would hide.
        assert text.encode() == golden.read_bytes(), f"{name}/{file} changed: review, then pytest --update-golden"
    assert sorted(p.name for p in folder.iterdir()) == sorted(planned["files"])
    assert {f for f in planned["files"] if f in SHARED_FILES} == {"SPOT_WELD.ls", "SPOTWELD.jbi"}


def test_golden_small_cell(small: dict[str, Any], update_golden: bool) -> None:
    _golden(small, update_golden)


def test_golden_process_cell(process_cell: dict[str, Any], update_golden: bool) -> None:
    _golden(process_cell, update_golden)


def test_every_dialect_is_proven_and_close_to_the_plan(small: dict[str, Any], process_cell: dict[str, Any]) -> None:
    for planned in (small, process_cell):
        by_format = {c.format: c for c in planned["checked"]}
        assert set(by_format) == set(ALL)
        assert by_format["srcl"].difference.identical            # SRCL states the planned values as they are
        for c in planned["checked"]:
            assert c.difference.within()
            assert c.report is None or c.report.clean


def test_the_process_cell_waits_and_welds_as_asked(process_cell: dict[str, Any]) -> None:
    program = program_from_plan(process_cell["result"], process_cell["cell"].digest)
    waits = [i.signal for i in program.instructions if isinstance(i, WaitFor)]
    # The door is present at the start: the time-aware planner goes round it instead of waiting
    # (tests/plan/test_waiting.py covers the wait at rest and its WAIT FOR door_clear).
    assert "clamp1_closed" in waits and "door_clear" not in waits
    assert not any(t.wait or t.stages for t in process_cell["result"].transitions)
    spots = {i.name: i for i in program.instructions if isinstance(i, Spot)}
    assert (spots["s8"].time_s, spots["s8"].schedule, spots["s8"].gun) == (0.8, 7, 2)
    assert (spots["s7"].time_s, spots["s7"].schedule, spots["s7"].gun) == (0.5, 4, 2)
    first_weld = next(k for k, i in enumerate(program.instructions) if isinstance(i, Spot))
    clamp_wait = next(k for k, i in enumerate(program.instructions) if isinstance(i, WaitFor) and i.signal == "clamp1_closed")
    assert clamp_wait < first_weld
    weld = next(p for p in process_cell["result"].trajectory.phases_of("weld") if p.label.endswith("/s8"))
    assert weld.t_end - weld.t_start == pytest.approx(0.8, abs=1e-9)


def test_srcl_of_a_plan_parses_back_byte_identical(small: dict[str, Any]) -> None:
    text = small["files"][f"{small['result'].cell}.srcl"]
    program = parse_program(text, "small_cell.srcl")
    assert write_program(program) == text
    assert program.header.joints == small["result"].joint_names
    assert program.header.cell_sha256 == small["cell"].digest
    spots = [i for i in program.instructions if type(i).__name__ == "Spot"]
    assert [s.name for s in spots] == [s.name for s in small["result"].spots]


def test_stamp_only_when_asked(small: dict[str, Any]) -> None:
    files, _ = publish(small["result"], small["cell"], small["robot"], ALL, stamp="2026-12-02")
    for file, text in files.items():
        if file.endswith(".json") or file in SHARED_FILES:       # the default routines, alike in every set
            continue
        assert "written 2026-12-02" in text, file
        assert "written " not in small["files"][file], file


def test_baseline_files_are_named_apart(small: dict[str, Any]) -> None:
    for method, suffix in (("published", "_published"), ("teach-in", "_teach_in")):
        files, _ = publish(small["result"], small["cell"], small["robot"], ("srcl", "krl"), method=method)
        name = "small_cell" + suffix
        # KRL's files carry the DEF's name, a KRL name of 24 characters at most with `_frames`
        # after it: "small_cell_published" is cut, the baseline's suffix kept.
        krl = next(f[:-4] for f in files if f.endswith(".src") and not f.endswith("_frames.src"))
        assert krl.endswith(suffix) and len(krl + "_frames") <= 24 and krl != name
        assert sorted(files) == [f"{krl}.dat", f"{krl}.src", f"{krl}_frames.src", f"{name}.json", f"{name}.srcl"]
        assert f"DEF {krl}( )" in files[f"{krl}.src"] and f"DEFDAT  {krl}" in files[f"{krl}.dat"]


@pytest.mark.parametrize(("name", "ident"), [("door-L 2", "door_L_2"), ("7up", "_7up"), ("s1", "s1")])
def test_identifier(name: str, ident: str) -> None:
    assert identifier(name) == ident


def test_a_format_whose_program_does_not_prove_says_how_to_have_the_others(small: dict[str, Any],
                                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """A dialect writing a program that runs otherwise than planned (here RAPID's with the first
    joint move's A1 0.5 deg off) stops the whole publication, nothing written: the message names
    the format, and when others were asked for, how to have them alone."""
    import dataclasses

    from robomax_py import publish as publishing
    from robomax_py.errors import ExportError
    from robomax_py.program import PtpMove

    rapid = DIALECTS["rapid"]

    def nudged(planned, robot):  # type: ignore[no-untyped-def]
        program = rapid.adapt(planned, robot)
        at = next(k for k, ins in enumerate(program.instructions) if isinstance(ins, PtpMove))
        move = program.instructions[at]
        moved = dataclasses.replace(move, target_deg=(move.target_deg[0] + 0.5, *move.target_deg[1:]))
        return dataclasses.replace(program, instructions=(*program.instructions[:at], moved,
                                                          *program.instructions[at + 1:]))

    monkeypatch.setitem(publishing.DIALECTS, "rapid", dataclasses.replace(rapid, adapt=nudged))
    with pytest.raises(ExportError, match=r"^rapid: the rebuilt motion differs .*; nothing was written "
                                          r"\(--format srcl,krl asks for the other formats alone\)$"):
        publish(small["result"], small["cell"], small["robot"], ("srcl", "rapid", "krl"))
    with pytest.raises(ExportError, match=r"^rapid: the rebuilt motion differs [^;]*$"):
        publish(small["result"], small["cell"], small["robot"], ("rapid",))
