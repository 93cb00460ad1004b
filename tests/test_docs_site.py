"""The documentation site builds with no warning, and what it publishes from the code is current.

`mkdocs build --strict` fails on a broken link, a missing page or an API object the docstrings no
longer have; the JSON Schemas under docs/schema/ must equal what docs/gen_schema.py makes from the
models that read the files, so an editor's completion never describes keys robomax no longer takes.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

REPO = Path(__file__).resolve().parents[1]


def _gen_schema() -> ModuleType:
    spec = importlib.util.spec_from_file_location("gen_schema", REPO / "docs" / "gen_schema.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("kind", ["cell", "robot", "tool"])
def test_committed_schema_is_current(kind: str) -> None:
    committed = (REPO / "docs" / "schema" / f"{kind}.schema.json").read_text(encoding="utf-8")
    assert committed == _gen_schema().render(kind), f"docs/schema/{kind}.schema.json is stale: run python docs/gen_schema.py"


def test_shipped_cells_validate_against_the_schema() -> None:
    jsonschema = pytest.importorskip("jsonschema")
    import yaml

    schema = _gen_schema().schema("cell")
    cells = sorted((REPO / "cells").glob("*.yaml")) + [REPO / "docs" / "tutorial" / "first_cell.yaml"]
    for cell in cells:
        jsonschema.validate(yaml.safe_load(cell.read_text(encoding="utf-8")), schema)


def test_readme_is_short_and_starts_with_the_two_commands() -> None:
    readme = (REPO / "README.md").read_bytes()
    assert len(readme) <= 8 * 1024
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    test_command = ci.strip().splitlines()[-1]
    assert test_command in readme.decode("utf-8").split("```")[1]


@pytest.mark.slow
def test_site_builds_strict(tmp_path: Path) -> None:
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocstrings_handlers.python")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]),
               NO_MKDOCS_2_WARNING="1")
    # Not -q: mkdocs then logs errors only, and --strict counts the warnings it logs (none).
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-d", str(tmp_path / "site")],
                         check=False, cwd=REPO, env=env, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    cli = (tmp_path / "site" / "cli" / "index.html").read_text(encoding="utf-8")
    assert "robomax plan" in cli and "--format" in cli
    cell_files = (tmp_path / "site" / "cell-files" / "index.html").read_text(encoding="utf-8")
    assert 'id="cell-spotfile"' in cell_files
