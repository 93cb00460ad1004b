"""CI's smoke run of the corpus bench (tests/bench/bench_corpus.py --quick): two small generated
cells (one the planner and the oracle refuse, one both plan) planned, judged by the oracle and
re-planned by both baselines; no timing asserted."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parent / "bench_corpus.py"


@pytest.mark.slow
def test_corpus_bench_quick_mode_runs(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, str(BENCH), "--quick", "--jobs", "1", "--out", str(tmp_path),
                           "--json", str(tmp_path / "rows.json")], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "cells 2: planned 1" in done.stdout and "planning CPU per cell: median" in done.stdout
    rows = json.loads((tmp_path / "rows.json").read_text())
    assert len(rows) == 2 and all(r.get("finished") and "error" not in r for r in rows)
    for r in rows:
        assert r["oracle"]["verdict"] in ("feasible", "infeasible", "unknown")
        if r["status"] == "planned":
            assert r["cycle"] >= r["bound"] > 0
            assert {"published", "teach_in"} <= set(r)
