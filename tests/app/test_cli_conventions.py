"""What every `robomax` command shares: --version, -h as --help, help without type placeholders on
flags, the exit-code table under every command's help, --json with a versioned `schema` (and an
error object on bad input), and the example cells shipped inside the package (`robomax examples`,
`robomax bench` without a cell)."""

from __future__ import annotations

import fnmatch
import json
import tomllib
from collections.abc import Callable
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robomax_py._version import __version__
from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_CODES, EXIT_OK, app, json_schema
from robomax_py.app.examples import (
    copy_examples,
    default_bench_cell,
    example_files,
    examples_dir,
)
from robomax_py.errors import OutputError
from robomax_py.io.cell import load_cell

SmallCell = Callable[..., Path]   # conftest.write_small_cell
REPO = Path(__file__).resolve().parents[2]
COMMANDS = ("robots", "check", "plan", "verify", "bench", "cspace", "preview", "batch", "variants",
            "import-urdf", "examples")
runner = CliRunner()


def _help(*args: str) -> str:
    """A help text with its whitespace runs (and rich's line wrapping) made single spaces."""
    result = runner.invoke(app, [*args])
    assert result.exit_code == EXIT_OK, result.output
    return " ".join(result.stdout.split())


def test_version() -> None:
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == EXIT_OK
    assert result.stdout.strip() == f"robomax_py {__version__}"


def test_every_command_is_listed() -> None:
    text = _help("--help")
    assert all(f" {c} " in text for c in COMMANDS)


@pytest.mark.parametrize("command", [None, *COMMANDS])
def test_help_conventions(command: str | None) -> None:
    args = [] if command is None else [command]
    text = _help(*args, "-h")
    assert text == _help(*args, "--help")
    assert "<bool>" not in text and "{" + "cell" not in text
    for code, what in EXIT_CODES:
        assert f"{code} {what}" in text, (code, text)
    if command is not None:
        assert "--json" in text


def test_usage_names_arguments_in_capitals() -> None:
    assert "plan [OPTIONS] CELL" in _help("plan", "-h")
    assert "preview [OPTIONS] CELL [PROGRAM]" in _help("preview", "-h")
    assert "batch [OPTIONS] CELLS..." in _help("batch", "-h")


def _json(args: list[str], code: int = EXIT_OK) -> dict[str, object]:
    result = runner.invoke(app, args)
    assert result.exit_code == code, result.output
    doc = json.loads(result.stdout)
    assert isinstance(doc, dict)
    return doc


def test_json_of_cheap_commands(tmp_path: Path, write_small_cell: SmallCell) -> None:
    doc = _json(["robots", "--json"])
    assert doc["schema"] == json_schema("robots") == "robomax.cli.robots/1" and doc["ok"] is True
    assert "kr125" in {r["name"] for r in doc["robots"]}  # type: ignore[attr-defined]

    cell = write_small_cell(tmp_path, "small")
    doc = _json(["check", str(cell), "--json"])
    assert doc["schema"] == json_schema("check") and doc["ok"] is True and doc["name"] == "small"

    doc = _json(["examples", str(tmp_path / "ex"), "--json"])
    assert doc["schema"] == json_schema("examples") and len(doc["written"]) == len(example_files())  # type: ignore[arg-type]

    doc = _json(["variants", str(cell), "-n", "2", "-o", str(tmp_path / "var"), "--json"])
    assert doc["schema"] == json_schema("variants") and len(doc["files"]) == 2  # type: ignore[arg-type]

    page = tmp_path / "p.html"
    doc = _json(["preview", str(cell), "--html", str(page), "--json"])
    assert doc["schema"] == json_schema("preview") and doc["url"] is None and doc["files"] == [str(page)]


ERROR_ARGS = {
    "check": ["{cell}"], "plan": ["{cell}", "-o", "{tmp}/out"], "verify": ["{cell}", "{tmp}/p.srcl"],
    "bench": ["{cell}"], "cspace": ["{cell}"], "preview": ["{cell}", "--html", "{tmp}/p.html"],
    "batch": ["{cell}", "-o", "{tmp}/out"], "variants": ["{cell}", "-o", "{tmp}/var"],
    "import-urdf": ["{tmp}/none.urdf", "-o", "{tmp}/arm"],
}


@pytest.mark.parametrize("command", sorted(ERROR_ARGS))
def test_json_error_object_on_bad_input(command: str, tmp_path: Path) -> None:
    missing = tmp_path / "missing.yaml"
    args = [a.format(cell=missing, tmp=tmp_path) for a in ERROR_ARGS[command]]
    result = runner.invoke(app, [command, *args, "--json"])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    doc = json.loads(result.stdout)
    assert doc["schema"] == json_schema(command) and doc["ok"] is False
    assert set(doc["error"]) == {"file", "key", "message"} and doc["error"]["message"]
    assert "error:" in result.stderr and "Traceback" not in result.output


def test_examples_equal_the_repository_cells() -> None:
    """The package's copy (what a wheel ships) is cells/ without its generator scripts."""
    cells = REPO / "cells"
    wanted = sorted(p.relative_to(cells) for p in cells.rglob("*")
                    if p.is_file() and p.suffix in (".yaml", ".stl", ".step", ".csv") and "__pycache__" not in p.parts)
    assert example_files() == wanted
    for rel in wanted:
        assert (examples_dir() / rel).read_bytes() == (cells / rel).read_bytes(), (
            f"{rel} differs: copy cells/{rel} to robomax_py/examples/{rel}")


def test_package_data_names_every_example() -> None:
    patterns = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["robomax_py"]
    for rel in example_files():
        name = f"examples/{rel.as_posix()}"
        assert any(fnmatch.fnmatch(name, p) for p in patterns), name


def test_bench_default_cell_is_the_package_copy(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)                     # no cells/ here: the default does not depend on it
    cell = default_bench_cell()
    assert cell.is_absolute() and cell.parent == examples_dir()
    assert load_cell(cell).name == "cabin_flange"


def test_examples_refuse_to_overwrite(tmp_path: Path) -> None:
    folder = tmp_path / "ex"
    first = copy_examples(folder)
    assert {p.relative_to(folder) for p in first.written} == set(example_files())
    again = copy_examples(folder)                   # the same bytes: nothing to do, no complaint
    assert not again.written and len(again.unchanged) == len(example_files())
    edited = folder / "frame.yaml"
    edited.write_text("# mine\n", encoding="utf-8")
    (folder / "tray.yaml").unlink(missing_ok=True)
    with pytest.raises(OutputError, match="frame.yaml: exists with other content; use --force"):
        copy_examples(folder)
    assert edited.read_text(encoding="utf-8") == "# mine\n"
    result = runner.invoke(app, ["examples", str(folder)])
    assert result.exit_code == EXIT_BAD_INPUT and "--force" in result.stderr
    result = runner.invoke(app, ["examples", str(folder), "--force"])
    assert result.exit_code == EXIT_OK, result.output
    assert edited.read_bytes() == (examples_dir() / "frame.yaml").read_bytes()
    assert load_cell(folder / "cabin_flange.yaml").name == "cabin_flange"   # its mesh came along


@pytest.mark.parametrize("program", ["cell.src", "cell.srcl", "cell.json", "cell.ls"])
def test_verify_with_program_and_cell_swapped_says_so(tmp_path: Path, write_small_cell: SmallCell,
                                                      program: str) -> None:
    """The cell comes first; given the other way round, the program would be read as a YAML cell
    and fail on its first statement. The message names the order instead, before any file is read."""
    cell = write_small_cell(tmp_path, "small")
    written = tmp_path / program
    written.write_text("DEF cell( )\nPTP {A1 0}\nEND\n")
    result = runner.invoke(app, ["verify", str(written), str(cell)])
    assert result.exit_code == EXIT_BAD_INPUT
    assert "takes the cell first" in result.output and "Traceback" not in result.output
    assert f"robomax verify {cell} {written}" in " ".join(result.output.split())


@pytest.mark.parametrize("args", [["plan", "{cell}"], ["batch", "{cell}"], ["variants", "{cell}", "-n", "2"],
                                  ["replan", "{cell}", "{cell}"]], ids=lambda a: a[0])
@pytest.mark.parametrize("below", [False, True], ids=["the folder", "a folder above"])
def test_an_output_folder_that_is_a_file_is_refused_before_any_work(tmp_path: Path, args: list[str], below: bool,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    # Before, plan ran to its end and then failed on writing, with an internal fault. Relative
    # paths: rich breaks a long one inside a word.
    monkeypatch.chdir(tmp_path)
    cell = Path("cell.yaml")
    cell.write_text("not read: the option is checked first\n")
    taken = Path("programs")
    taken.write_text("a file\n")
    out = taken / "sub" if below else taken
    result = runner.invoke(app, [a.format(cell=cell) for a in args] + ["-o", str(out)])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    flat = " ".join(result.output.replace("│", " ").split())        # rich's box and line breaks taken out
    assert f"{taken} is a file, not a folder" in flat or f"{taken} (above {out}) is a file, not a folder" in flat, flat
    assert taken.read_text() == "a file\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cell.yaml", "programs"]
