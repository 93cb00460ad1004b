"""Program names: KRL's DEF and DEFDAT carry the name of their `.src` / `.dat`, RAPID's MODULE that
of its `.mod`, as the controllers' editors name them, and each is a name the controller compiles.
The rules are checked as the vendors state them, not with the writer's code:
- KRL names: at most 24 characters, letters, digits, `_` and `$`, not a digit first (KSS 8.x
  "Names in KRL"; Hungsiu/WtRobotTraining @ c92b8435 03_Syntax.md), so the setup program
  `<name>_frames` must fit as well;
- RAPID identifiers: a letter first, then letters, digits and `_`, at most 32 characters (ABB
  RAPID kernel reference, "Identifiers")."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st
from typer.testing import CliRunner

from robomax_py.app.cli import app
from robomax_py.export import fanuc, krl, rapid
from robomax_py.program import identifier

KRL_NAME = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]{0,23}")
RAPID_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,31}")
KRL_WORDS = {"DEF", "END", "PTP", "LIN", "CIRC", "WAIT", "IF", "FOR", "LOOP", "SPOT_WELD", "GRIP", "RELEASE"}
RAPID_WORDS = {"MODULE", "PROC", "MAIN", "IF", "FOR", "TRUE", "SPOT_WELD", "GRIP", "RELEASE"}


@given(st.text(min_size=0, max_size=60))
def test_krl_names_follow_kss_rules(name: str) -> None:
    ident = krl.program_name(identifier(name))
    assert KRL_NAME.fullmatch(ident) and KRL_NAME.fullmatch(ident + "_frames")
    assert ident.upper() not in KRL_WORDS


@given(st.text(min_size=0, max_size=60))
def test_rapid_names_follow_the_identifier_rules(name: str) -> None:
    ident = rapid.program_name(identifier(name))
    assert RAPID_NAME.fullmatch(ident) and RAPID_NAME.fullmatch(ident + "_frames")
    assert ident.upper() not in RAPID_WORDS


def test_long_names_cut_stay_apart() -> None:
    """Two long names alike in their first characters stay two programs (4 hexadecimal digits of
    each whole name), and a baseline's suffix stays on."""
    a, b = "side_frame_station_robot_left", "side_frame_station_robot_right"
    assert krl.program_name(a) != krl.program_name(b) and rapid.program_name(a) != rapid.program_name(b)
    assert krl.program_name(a + "_teach_in").endswith("_teach_in")


def test_a_station_robots_programs_keep_the_robot_in_their_names() -> None:
    """`<station>_<robot>` cut to fit: the robot's name (the name's last short words) stays on, in
    every dialect that ties its files to the program."""
    station = "2 Seitenrahmen Station links Zelle 4"
    for robot in ("r1", "r2"):
        name = identifier(f"{station}_{robot}")
        assert krl.program_name(name).endswith(f"_4_{robot}")
        assert rapid.program_name(name).endswith(f"_4_{robot}")
        assert fanuc.program_name(name).endswith(f"_4_{robot.upper()}")


def test_short_names_are_kept() -> None:
    assert krl.program_name("small_cell") == "small_cell" and rapid.program_name("small_cell") == "small_cell"


@pytest.fixture(scope="module")
def awkward(tmp_path_factory: pytest.TempPathFactory, write_small_cell) -> tuple[Path, Path]:  # type: ignore[no-untyped-def]
    """The small cell named with spaces, umlauts, a digit first and 44 characters, planned to KRL,
    RAPID and FANUC: (cell file, output folder)."""
    tmp = tmp_path_factory.mktemp("awkward")
    cell = write_small_cell(tmp, name="7 Kabine Flansch Rückwand links Variante 2")
    out = tmp / "out"
    done = CliRunner().invoke(app, ["plan", str(cell), "--out", str(out), "--format", "krl,rapid,fanuc"])
    assert done.exit_code == 0, done.output
    return cell, out


def test_a_cell_named_as_people_name_it_gives_files_its_controllers_load(awkward: tuple[Path, Path]) -> None:
    """The KRL and RAPID files are named as their DEF / DEFDAT / MODULE, each a valid name; the
    trajectory file keeps the cell's name; `verify` of each program is clean."""
    cell, out = awkward
    runner = CliRunner()
    src = [p for p in out.glob("*.src") if not p.stem.endswith("_frames")]
    mod = [p for p in out.glob("*.mod") if not p.stem.endswith("_frames")]
    assert len(src) == 1 and len(mod) == 1
    stem = src[0].stem
    text = src[0].read_text(encoding="cp1252")
    assert KRL_NAME.fullmatch(stem) and KRL_NAME.fullmatch(stem + "_frames")
    assert re.search(rf"^DEF {re.escape(stem)}\(", text, re.MULTILINE)
    assert re.search(rf"^DEFDAT\s+{re.escape(stem)}\s*$", (out / f"{stem}.dat").read_text(encoding="cp1252"),
                     re.MULTILINE)
    frames = (out / f"{stem}_frames.src").read_text(encoding="cp1252")
    assert re.search(rf"^DEF {re.escape(stem)}_frames\(", frames, re.MULTILINE)
    module = mod[0].stem
    assert RAPID_NAME.fullmatch(module) and RAPID_NAME.fullmatch(module + "_frames")
    assert re.search(rf"^MODULE {re.escape(module)}\s*$", mod[0].read_text(), re.MULTILINE)
    assert re.search(rf"^MODULE {re.escape(module)}_frames\s*$", (out / f"{module}_frames.mod").read_text(),
                     re.MULTILINE)
    assert (out / "7 Kabine Flansch Rückwand links Variante 2.json").is_file()
    for program in (src[0], mod[0]):
        verified = runner.invoke(app, ["verify", str(cell), str(program)])
        assert verified.exit_code == 0 and "clean" in verified.output, verified.output


def test_verify_of_a_setup_file_names_the_program(awkward: tuple[Path, Path]) -> None:
    """A frames setup program or the weld routine given to verify: one message naming the program
    to verify, exit 2 (verified alone it would report every spot unwelded)."""
    cell, out = awkward
    setups = [p for p in out.iterdir() if p.stem.lower().endswith("_frames")] + [out / "SPOT_WELD.ls"]
    assert len(setups) == 4
    for setup in setups:
        got = CliRunner().invoke(app, ["verify", str(cell), str(setup)])
        text = " ".join(got.output.split())
        assert got.exit_code == 2 and "verify" in text and ("setup program of" in text or "at each weld" in text), text
        if "setup program of" in text:
            main = setup.name[:-len("_frames") - len(setup.suffix)] + setup.suffix
            assert f"verify {main}" in text
    # The plan's manifest ends in .json as a trajectory file does: named for what it is, not a format error.
    [manifest] = out.glob("*.manifest.json")
    got = CliRunner().invoke(app, ["verify", str(cell), str(manifest)])
    text = " ".join(got.output.split())
    assert got.exit_code == 2 and "is the manifest of the set of programs" in text and "Traceback" not in text, text


def test_verify_reports_a_def_name_krl_does_not_compile(awkward: tuple[Path, Path], tmp_path: Path) -> None:
    """A program's DEF renamed to 30 characters (file and DEFDAT with it): verify reports it at the
    DEF line, as a controller that will not compile it."""
    cell, out = awkward
    src = next(p for p in out.glob("*.src") if not p.stem.endswith("_frames"))
    long = "a_weld_program_named_30_chars_"
    assert len(long) == 30
    for p in out.iterdir():
        if p.suffix in (".src", ".dat") and not p.stem.endswith("_frames"):
            text = p.read_text(encoding="cp1252").replace(src.stem, long)
            (tmp_path / f"{long}{p.suffix}").write_text(text, encoding="cp1252")
    got = CliRunner().invoke(app, ["verify", str(cell), str(tmp_path / f"{long}.src")])
    text = " ".join(got.output.split())
    assert got.exit_code != 0 and f"DEF {long}: 30 characters" in text, text
