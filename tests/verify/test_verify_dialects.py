"""`robomax verify` on every dialect's program: the written programs verify clean, and programs
edited the ways that matter on a shop floor (a target 1 mm off, another configuration, a blended
weld point, lengths in the wrong unit, a quaternion that is not unit) are rejected, naming the line."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_OK, EXIT_VIOLATIONS, app
from robomax_py.errors import ProgramError
from robomax_py.export import DIALECTS, choose_formats
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.publish import publish
from robomax_py.verify import verify_program

runner = CliRunner()
MAIN = {"krl": ".src", "rapid": ".mod", "fanuc": ".ls", "urscript": ".script", "srcl": ".srcl", "as": ".as"}
# Every dialect but INFORM: the small cell's arm states no encoder pulses per degree, so `all`
# passes INFORM over (its programs are verified on the placed process cell, test_mutants_inform.py).
WRITTEN = sorted(MAIN)


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory, write_small_cell) -> dict[str, Any]:  # type: ignore[no-untyped-def]
    tmp = tmp_path_factory.mktemp("dialects")
    path = write_small_cell(tmp)
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot)
    assert result.status == "planned", result.message
    chosen = choose_formats("all", robot)
    assert sorted(chosen.names) == WRITTEN and [k.format for k in chosen.skipped] == ["inform"]
    files, _ = publish(result, cell, robot, chosen.names)
    for name, text in files.items():
        (tmp / name).write_text(text)
    return {"tmp": tmp, "cell_path": path, "cell": cell, "robot": robot, "files": files}


def _stem(fmt: str) -> str:
    """What the small cell's files of `fmt` are named after (FANUC: the TP program, SMALL_CELL)."""
    name_of = DIALECTS[fmt].program_name
    return name_of("small_cell") if name_of else "small_cell"


def _edited(written: dict[str, Any], fmt: str, edit: Callable[[str], str], tag: str, *, ext: str | None = None) -> Path:
    """A folder with the program, one of its files edited (the main file, or `ext`); its main file."""
    ext = ext or MAIN[fmt]
    folder = written["tmp"] / f"edited_{fmt}_{tag}"
    folder.mkdir()
    for name, text in written["files"].items():
        if name.endswith(tuple(DIALECTS[fmt].extensions)):
            mine = name == f"{_stem(fmt)}{ext}"
            new = edit(text) if mine else text
            if mine:
                assert new != text, "the edit changed nothing"
            (folder / name).write_text(new)
    return folder / f"{_stem(fmt)}{MAIN[fmt]}"


def _verify(written: dict[str, Any], fmt: str, edit: Callable[[str], str], tag: str, *, ext: str | None = None) -> Any:
    return verify_program(written["cell"], written["robot"], _edited(written, fmt, edit, tag, ext=ext))


def _first(pattern: str, text: str, replace: Callable[[re.Match[str]], str]) -> str:
    return re.sub(pattern, replace, text, count=1, flags=re.MULTILINE)


@pytest.mark.parametrize("fmt", WRITTEN)
def test_written_programs_verify_clean_from_the_cli(written: dict[str, Any], fmt: str) -> None:
    result = runner.invoke(app, ["verify", str(written["cell_path"]), str(written["tmp"] / f"{_stem(fmt)}{MAIN[fmt]}")])
    assert result.exit_code == EXIT_OK, result.output
    assert "clean" in result.output


def test_krl_dat_alone_is_read_with_its_src(written: dict[str, Any]) -> None:
    report = verify_program(written["cell"], written["robot"], written["tmp"] / "small_cell.dat")
    assert report.clean, report.violations


# ------------------------------------------------------------------ a target 1 mm off

def _plus_1mm(value: str) -> str:
    return f"{float(value) + 1.0:.3f}"


MOVED: dict[str, tuple[str | None, Callable[[str], str]]] = {
    "krl": (".dat", lambda t: _first(r"(E6POS XP\d+=\{X )(-?[\d.]+)", t, lambda m: m[1] + _plus_1mm(m[2]))),
    "rapid": (None, lambda t: _first(r"(robtarget p\d+ := \[\[)(-?[\d.]+)", t, lambda m: m[1] + _plus_1mm(m[2]))),
    "fanuc": (None, lambda t: _first(r"(X =\s+)(-?[\d.]+)", t, lambda m: m[1] + _plus_1mm(m[2]))),
    "urscript": (None, lambda t: _first(r"(movel\(p\[)(-?[\d.]+)", t, lambda m: m[1] + f"{float(m[2]) + 0.001:.6f}")),
    "srcl": (None, lambda t: _first(r"(MOVE LIN POS\()(-?[\d.]+)", t, lambda m: m[1] + _plus_1mm(m[2]))),
}


@pytest.mark.parametrize("fmt", sorted(MOVED))
def test_a_target_1mm_off_is_rejected_with_its_line(written: dict[str, Any], fmt: str) -> None:
    ext, edit = MOVED[fmt]
    report = _verify(written, fmt, edit, "moved", ext=ext)
    spot = [v for v in report.violations if v.kind == "spot" and "mm from the spot" in v.detail]
    assert spot, report.violations
    assert spot[0].line is not None


# ------------------------------------------------------------------ another configuration

FLIPPED: dict[str, tuple[str | None, Callable[[str], str]]] = {
    "krl": (".dat", lambda t: _first(r"(E6POS XP\d+=\{[^}]*S )(\d)", t, lambda m: m[1] + str(int(m[2]) ^ 1))),
    "rapid": (None, lambda t: _first(r"(robtarget p\d+ := \[\[[^\]]*\], \[[^\]]*\], \[[^\]]*, )(-?\d)\]",
                                      t, lambda m: m[1] + str(int(m[2]) ^ 4) + "]")),
    "fanuc": (None, lambda t: _first(r"CONFIG : '([FN])", t, lambda m: "CONFIG : '" + ("N" if m[1] == "F" else "F"))),
    "srcl": (None, lambda t: _first(r"CONFIG 'S(\d)", t, lambda m: f"CONFIG 'S{int(m[1]) ^ 1}")),
}


@pytest.mark.parametrize("fmt", sorted(FLIPPED))
def test_another_configuration_is_rejected_with_its_line(written: dict[str, Any], fmt: str) -> None:
    ext, edit = FLIPPED[fmt]
    report = _verify(written, fmt, edit, "flipped", ext=ext)
    config = [v for v in report.violations if v.kind in ("config", "spot") and "onfiguration" in v.detail or v.kind == "config"]
    assert config, report.violations
    assert all(v.line is not None for v in config)


# ------------------------------------------------------------------ a blended weld point

def _krl_cont(fold: re.Match[str]) -> str:
    """An exact-stop LIN fold made CONT, as the smartPAD's inline form writes it."""
    text = fold[0].replace(" Vel=", " CONT Vel=", 1).replace("3:, ", "3:C_DIS C_DIS, ", 1)
    return text[:-len(" \n")] + " C_DIS C_DIS\n"


BLENDED: dict[str, Callable[[str], str]] = {
    "krl": lambda t: re.sub(r"^;FOLD LIN (P\d+) Vel=.*?\nLIN X\1 \n", _krl_cont, t, count=1,
                             flags=re.MULTILINE | re.DOTALL),
    "rapid": lambda t: _first(r"^(\s*MoveL p\d+, v_lin\d+, )fine", t, lambda m: m[1] + "z10"),
    "fanuc": lambda t: _first(r"^(\s*\d+:\s*L P\[\d+:\w+\] \d+mm/sec )FINE", t, lambda m: m[1] + "CNT50"),
    "urscript": lambda t: _first(r"^(\s*movel\(.*)r=0\.000000000\)(  # approach)", t, lambda m: m[1] + "r=0.010000000)" + m[2]),
    "srcl": lambda t: _first(r"^(\s*MOVE LIN .* MM/S)( \{ approach \})", t, lambda m: m[1] + " FLYBY 1.0000" + m[2]),
}


@pytest.mark.parametrize("fmt", sorted(BLENDED))
def test_a_blended_weld_point_is_rejected_with_its_line(written: dict[str, Any], fmt: str) -> None:
    report = _verify(written, fmt, BLENDED[fmt], "blended")
    flyby = [v for v in report.violations if v.kind == "flyby"]
    assert flyby, report.violations
    assert flyby[0].line is not None


# ------------------------------------------------------------------ lengths in the wrong unit

def _in_metres(pattern: str) -> Callable[[str], str]:
    return lambda t: re.sub(pattern, lambda m: m[1] + f"{float(m[2]) / 1000:.6f}", t)


SCALED: dict[str, tuple[str | None, Callable[[str], str]]] = {
    "krl": (".dat", _in_metres(r"(\b[XYZ] )(-?\d+\.\d{3})(?=,)")),
    "rapid": (None, _in_metres(r"(robtarget p\d+ := \[\[|, )(-?\d+\.\d{3})(?=[,\]])")),
    "fanuc": (None, _in_metres(r"(\b[XYZ] =\s+)(-?\d*\.\d{3})(?=  mm)")),
    "urscript": (None, lambda t: re.sub(r"(movel\(p\[)(-?[\d.]+), (-?[\d.]+), (-?[\d.]+)",
                                        lambda m: m[1] + ", ".join(f"{float(v) * 1000:.3f}" for v in m.groups()[1:]), t)),
}


@pytest.mark.parametrize("fmt", sorted(SCALED))
def test_lengths_in_another_unit_are_rejected(written: dict[str, Any], fmt: str) -> None:
    ext, edit = SCALED[fmt]
    report = _verify(written, fmt, edit, "scaled", ext=ext)
    assert not report.clean
    assert any(v.line is not None for v in report.violations), report.violations


def test_a_quaternion_that_is_not_unit_is_bad_input_with_its_line(written: dict[str, Any]) -> None:
    edit: Callable[[str], str] = lambda t: _first(r"(robtarget p\d+ := \[\[[^\]]*\], \[)(-?[\d.]+)", t,
                                                  lambda m: m[1] + f"{float(m[2]) + 0.1:.9f}")
    program = _edited(written, "rapid", edit, "quaternion")
    with pytest.raises(ProgramError, match=r"line \d+.*not unit"):
        verify_program(written["cell"], written["robot"], program)
    result = runner.invoke(app, ["verify", str(written["cell_path"]), str(program)])
    assert result.exit_code in (EXIT_BAD_INPUT, EXIT_VIOLATIONS), result.output


def test_violations_exit_one_from_the_cli(written: dict[str, Any]) -> None:
    ext, edit = MOVED["fanuc"]
    program = _edited(written, "fanuc", edit, "cli", ext=ext)
    result = runner.invoke(app, ["verify", str(written["cell_path"]), str(program)])
    assert result.exit_code == EXIT_VIOLATIONS, result.output
    assert re.search(r"line \d+", result.output), result.output


def test_an_unknown_extension_is_bad_input(written: dict[str, Any], tmp_path: Path) -> None:
    other = tmp_path / "small_cell.txt"
    other.write_text("PTP HOME\n")
    result = runner.invoke(app, ["verify", str(written["cell_path"]), str(other)])
    assert result.exit_code == EXIT_BAD_INPUT
    assert ".src" in result.output and ".script" in result.output


# A block before the first motion, in each dialect's words: a loop (an endless one here, or one on an
# input: how often it runs decides whether the program ever goes on) and a condition, both empty.
_BLOCKS: dict[str, tuple[str, str, str]] = {
    # (what the first motion's line starts with, the loop, the condition)
    "krl": (r"^(\s*)(PTP )", "{0}LOOP\n{0}ENDLOOP\n", "{0}IF $IN[1] THEN\n{0}ENDIF\n"),
    "rapid": (r"^(\s*)(MoveAbsJ )", "{0}WHILE TRUE DO\n{0}ENDWHILE\n", "{0}IF DInput(di1) = 1 THEN\n{0}ENDIF\n"),
    "fanuc": (r"^(\s*)(\d+:J P\[1\])", "{0}  0:  FOR R[1]=1 TO 3 ;\n{0}  0:  ENDFOR ;\n",
              "{0}  0:  IF (DI[1]=ON) THEN ;\n{0}  0:  ENDIF ;\n"),
    "urscript": (r"^(\s*)(movej\()", "{0}while get_standard_digital_in(0):\n{0}  sync()\n{0}end\n",
                 "{0}if get_standard_digital_in(0):\n{0}  sync()\n{0}end\n"),
}


@pytest.mark.parametrize("fmt", sorted(_BLOCKS))
def test_a_loop_is_reported_and_a_condition_passed(written: dict[str, Any], fmt: str) -> None:
    # Before, an empty `LOOP ... ENDLOOP` verified clean: the controller never gets past it.
    first, loop, condition = _BLOCKS[fmt]

    def inserted(block: str) -> Callable[[str], str]:
        return lambda text: _first(first, text, lambda m: block.format(m[1]) + m[1] + m[2])

    looped = _verify(written, fmt, inserted(loop), "loop")
    unsupported = [v for v in looped.violations if v.kind == "unsupported"]
    opening = loop.format("").splitlines()[0].split(":  ")[-1].rstrip(" ;")    # FANUC's line number off
    assert len(unsupported) == 1 and opening in unsupported[0].detail, looped.violations
    assert unsupported[0].line is not None
    conditioned = _verify(written, fmt, inserted(condition), "condition")
    if fmt == "fanuc":          # its reader reads no statement of an IF ... THEN block: it reports the opening
        assert [v.kind for v in conditioned.violations] == ["unsupported"], conditioned.violations
    else:
        assert conditioned.clean, conditioned.violations


# The first Cartesian target's x, as each dialect writes it, and where (KRL: the .dat).
_FIRST_X: dict[str, tuple[str, str | None]] = {
    "krl": (r"(\{X )[-0-9.]+", ".dat"),
    "rapid": (r"(robtarget \w+ := \[\[)[-0-9.]+", None),
    "urscript": (r"(movel\(p\[)[-0-9.]+", None),
    "srcl": (r"(MOVE LIN POS\()[-0-9.]+", None),
    "as": (r"(LMOVE TRANS\()[-0-9.]+", None),
}


@pytest.mark.parametrize("value", ["nan", "1E300"])
@pytest.mark.parametrize("fmt", sorted(_FIRST_X))
def test_a_target_that_is_no_number_is_bad_input_with_its_line(written: dict[str, Any], fmt: str, value: str) -> None:
    # Before, 1E300 mm passed the readers and overflowed the rebuild (an internal fault), and a KRL
    # `nan` became a line "that cannot be followed".
    pattern, ext = _FIRST_X[fmt]
    edited = _edited(written, fmt, lambda text: _first(pattern, text, lambda m: m[1] + value), f"x_{value}", ext=ext)
    # Some readers refuse the number themselves ("expected numbers, got nan"), the rest when it is read.
    with pytest.raises(ProgramError, match=r"line \d+(, column \d+)?: .*(nan|1e\+30\d|1E300)"):
        verify_program(written["cell"], written["robot"], edited)
