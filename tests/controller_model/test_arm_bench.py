"""The arm bench (tests/bench/bench_controller_frames.py) in quick mode on three arms kept in the
repository: imported ROS-Industrial ABB (with its SRDF) and FANUC (J2/J3 coupling) arms and the
shipped KR 16, each planned in a placed panel cell with a user frame, a tool
number and registers; every dialect's program, run by its controller model, within 0.1 mm /
0.01 deg of the plan, with the configuration the plan has."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_quick_bench_finds_nothing(tmp_path: Path) -> None:
    out = tmp_path / "arms.md"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, str(REPO / "tests" / "bench" / "bench_controller_frames.py"), "--quick",
                           "--arms", "irb2400,m20ia,kr16", "--out", str(out)],
                          capture_output=True, text=True, env=env, cwd=tmp_path, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    table = out.read_text()
    rows = [line for line in table.splitlines() if line.startswith(("| irb2400 ", "| m20ia ", "| kr16 "))]
    assert len(rows) == 6, table                      # the main table and the blends table
    assert all(" planned " in row for row in rows[:3]), table
    assert table.rstrip().endswith("- none"), table
