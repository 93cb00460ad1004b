"""The public API: the example of docs/api.md runs as written, in a copy of the repository's
cells, and the API's names are exported from the package."""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import pytest

import robomax_py

REPO = Path(__file__).resolve().parents[2]


def test_api_names_are_exported() -> None:
    for name in ("load_cell", "plan_cell", "write_programs", "verify_program", "LoadedCell"):
        assert name in robomax_py.__all__
        assert callable(getattr(robomax_py, name))
    with pytest.raises(AttributeError):
        robomax_py.no_such_thing  # noqa: B018


def test_bad_cell_raises_a_located_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("robomax: 1\nrobot: {model: kr125}\n")
    with pytest.raises(robomax_py.CellFileError, match="bad.yaml"):
        robomax_py.load_cell(bad)


@pytest.mark.slow
def test_documented_example_runs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    page = (REPO / "docs" / "api.md").read_text()
    block = re.search(r"<!-- api-example -->\n```python\n(.*?)```\n<!-- /api-example -->", page, re.DOTALL)
    assert block is not None, "docs/api.md has no api-example block"
    shutil.copytree(REPO / "cells", tmp_path / "cells")
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        exec(compile(block.group(1), "docs/api.md", "exec"), {})  # noqa: S102 - the documented example, run as written
    finally:
        os.chdir(cwd)
    assert "clean: True" in capsys.readouterr().out
    assert (tmp_path / "programs" / "cabin_flange.srcl").is_file()
