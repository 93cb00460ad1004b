"""The static checks the project holds itself to, run as tests so that CI runs them: `mypy --strict`
on the package (settings in pyproject's [tool.mypy]) and ruff on the package, the tests and the
docs' scripts (pyproject's [tool.ruff]). Both tools are pinned to a minor version in the test extra:
a newer release adds checks, and adopting them is a change of its own.

Each runs in its own process as a developer runs it; mypy writes its cache under pytest's temporary
folder, so a run never depends on what an earlier one left.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _run(args: list[str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", *args], cwd=REPO, capture_output=True, text=True, check=False)


@pytest.mark.slow
def test_mypy_strict_finds_nothing(tmp_path: Path) -> None:
    done = _run(["mypy", "--cache-dir", str(tmp_path / "mypy"), "robomax_py"])
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]


def test_ruff_finds_nothing() -> None:
    done = _run(["ruff", "check", "--no-cache", "robomax_py", "tests", "docs"])
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
