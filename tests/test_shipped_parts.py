"""cells/parts/make_parts.py reproduces the committed part STLs byte for byte, the light gun's generator
its committed files, and every shipped cell passes `robomax check`."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, app

REPO = Path(__file__).resolve().parents[1]
CELLS = sorted((REPO / "cells").glob("*.yaml"))
runner = CliRunner()


def _module(path: Path, name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def test_make_parts_reproduces_committed_stls(tmp_path: Path) -> None:
    make_parts = _module(REPO / "cells" / "parts" / "make_parts.py", "cells_make_parts")
    written = make_parts.generate(tmp_path)
    assert written
    for path in written:
        committed = REPO / "cells" / "parts" / path.name
        assert committed.read_bytes() == path.read_bytes(), f"{path.name} differs: rerun cells/parts/make_parts.py"
    committed_stls = {p.name for p in (REPO / "cells" / "parts").glob("*.stl")}
    assert committed_stls == {p.name for p in written}, "stale or missing STL in cells/parts"


def test_light_gun_generator_reproduces_committed_files(tmp_path: Path) -> None:
    gen = _module(REPO / "robomax_py" / "robots" / "generate_light_gun.py", "robots_generate_light_gun")
    for path in gen.generate(tmp_path):
        rel = path.relative_to(tmp_path)
        assert (REPO / "robomax_py" / "robots" / rel).read_bytes() == path.read_bytes(), f"{rel} differs: rerun the generator"


@pytest.mark.parametrize("cell", CELLS, ids=[p.stem for p in CELLS])
def test_shipped_cell_passes_check(cell: Path) -> None:
    result = runner.invoke(app, ["check", str(cell)])
    assert result.exit_code == EXIT_OK, result.output
