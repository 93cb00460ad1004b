"""The family bench (tests/bench/bench_family.py) in quick mode on the two arms with passive
(`<mimic>`) joints kept in the repository: both import unedited, fit OPW, and plan their panel cell
with the native program written and proven."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_quick_family_bench_plans_the_mimic_arms(tmp_path: Path) -> None:
    out = tmp_path / "family.md"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, str(REPO / "tests" / "bench" / "bench_family.py"), "--quick",
                           "--arms", "irb6640_185_280,m900ia260l", "--out", str(out)],
                          capture_output=True, text=True, env=env, cwd=tmp_path, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    table = out.read_text()
    rows = [line for line in table.splitlines() if line.startswith(("| irb6640_185_280 ", "| m900ia260l "))]
    assert len(rows) == 2, table
    assert all(" ok" in row and " opw " in row and " planned " in row for row in rows), table
    assert "imported unedited: 2 (100 %)" in table, table
