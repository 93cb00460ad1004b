"""Every benchmark script in tests/bench runs in CI at its smallest (a smoke run: the script must
finish with exit 0; no figure or timing is asserted), so that none rots while the code it measures
changes. The corpus, family and arm benches have their own smoke tests (test_bench_corpus.py,
test_bench_family.py, tests/controller_model/test_arm_bench.py).

Each script runs in its own process as a user runs it, on the small 2-spot test cell where it
takes a cell; the reference cell where the script is about that cell."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import SmallCell

BENCH = Path(__file__).resolve().parent
REPO = BENCH.parents[1]
SMALL = "{small}"               # replaced by the small test cell's path
OUT = "{out}"                   # replaced by a folder of the test's own

# script -> the cheapest arguments it takes.
SMOKE: dict[str, list[str]] = {
    "bench_batch.py": ["--quick", "--n", "2", "--runs", "1", "--no-ray"],
    "bench_bezier.py": ["--repeat", "1"],
    "bench_bezier_paper.py": ["--quick", "--out", OUT],
    "bench_cartesian_splines.py": ["--quick"],
    "bench_ceiling.py": [SMALL, "--pairs", "2"],
    "bench_collision.py": ["--cell", SMALL, "--quick"],
    "bench_dialects.py": ["--runs", "1", SMALL],
    "bench_ik.py": ["--quick"],
    "bench_jit_compile.py": [SMALL],
    "bench_learned_cspace.py": [SMALL, "--quick"],
    "bench_import.py": ["--runs", "1", "--poses", "20"],
    "bench_pick_place.py": ["--quick", "--out", OUT],
    "bench_plan.py": ["--runs", "1", "--resolutions", "20"],
    "bench_paper_001.py": ["--runs", "1", "--cycles", "1", "--figures", OUT],
    "bench_replan.py": ["--quick"],
    "bench_scale.py": ["--sizes", "8", "--families", "open", "--runs", "1"],
    "bench_station.py": ["--quick"],
    "bench_startup.py": [SMALL, "--runs", "1"],
    "bench_table_ik.py": ["--quick", "--figures", OUT],
    "bench_tcp_detours.py": ["--quick", "--png", f"{OUT}/orientations.png"],
    "bench_tending.py": ["--cycles", "1"],
    "bench_transfers.py": ["--transfers", "1", "--runs", "1", "--out", OUT],
    "bench_timing.py": [SMALL, "--runs", "1"],
    "bench_voxels.py": [SMALL],
}
OWN_TESTS = {"bench_corpus.py", "bench_controller_frames.py", "bench_family.py"}


def test_every_bench_script_has_a_smoke_run() -> None:
    scripts = {p.name for p in BENCH.glob("bench_*.py")}
    assert scripts - OWN_TESTS == set(SMOKE), "give each bench script its cheapest arguments in SMOKE"


@pytest.mark.slow
@pytest.mark.parametrize("script", sorted(SMOKE))
def test_bench_script_runs(script: str, tmp_path: Path, write_small_cell: SmallCell) -> None:
    small = write_small_cell(tmp_path, "small")
    out = tmp_path / "out"
    args = [a.replace(SMALL, str(small)).replace(OUT, str(out)) for a in SMOKE[script]]
    # TMPDIR: a script that keeps its output in a temporary folder for the user to look at
    # (bench_batch, bench_transfers) leaves it in the test's own folder, not in the system's.
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]),
           "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "TMPDIR": str(tmp_path)}
    done = subprocess.run([sys.executable, str(BENCH / script), *args], capture_output=True, text=True,
                          env=env, cwd=tmp_path, check=False)
    assert done.returncode == 0, (done.stdout[-2000:] + done.stderr[-3000:])
