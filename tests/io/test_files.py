"""Output that never half-exists: atomic replace, one complete set of programs when two
writers share a folder, temporary files of a killed writer removed by the next one."""

from __future__ import annotations

import json
import multiprocessing
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from robomax_py.export.srcl import parse_program
from robomax_py.io.files import TMP_SUFFIX, write_programs


def test_stale_temporary_files_are_removed_by_the_next_writer(tmp_path: Path) -> None:
    stale = tmp_path / f".cell.json.abc123{TMP_SUFFIX}"
    stale.write_text("half a file")
    written = write_programs(tmp_path, {"cell.json": "{}\n", "cell.srcl": "x\n"})
    assert [p.name for p in written] == ["cell.json", "cell.srcl"]
    assert not stale.exists()
    # Besides the set's links and manifest, only the set's hidden pointer and folder.
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == [
        "cell.json", "cell.manifest.json", "cell.srcl"]
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(TMP_SUFFIX)]


def _writer(folder: str, letter: str, rounds: int) -> None:
    for _ in range(rounds):
        write_programs(Path(folder), {"cell.json": letter * 200_000, "cell.srcl": letter * 200_000})


def test_two_writers_never_leave_a_mixed_set(tmp_path: Path) -> None:
    ctx = multiprocessing.get_context("spawn")
    for attempt in range(3):
        procs = [ctx.Process(target=_writer, args=(str(tmp_path), letter, 40)) for letter in "AB"]
        for p in procs:
            p.start()
        for p in procs:
            p.join(60)
            assert p.exitcode == 0
        json_text = (tmp_path / "cell.json").read_text()
        srcl_text = (tmp_path / "cell.srcl").read_text()
        assert len(json_text) == len(srcl_text) == 200_000
        assert json_text[0] == srcl_text[0], f"attempt {attempt}: a mixed set"
    assert not list(tmp_path.glob(f".*{TMP_SUFFIX}"))


@pytest.mark.slow
def test_plan_killed_mid_run_leaves_no_partial_program(tmp_path: Path, write_small_cell) -> None:  # type: ignore[no-untyped-def]
    cell = write_small_cell(tmp_path)
    out = tmp_path / "programs"
    robomax = [sys.executable, "-m", "robomax_py"]
    for k, delay in enumerate((0.5, 4.0)):
        proc = subprocess.Popen([*robomax, "plan", str(cell), "-o", str(out)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(delay)
        proc.send_signal(signal.SIGKILL if k % 2 else signal.SIGTERM)
        proc.wait(60)
        for program in out.glob("small_cell.*") if out.exists() else []:
            text = program.read_text()
            if program.name.endswith(".manifest.json"):      # the run finished before the signal
                assert json.loads(text)["format"] == "robomax.manifest/1"
            elif program.suffix == ".json":
                assert json.loads(text)["format"] == "robomax.trajectory/1"
            else:
                parse_program(text, program)
    done = subprocess.run([*robomax, "plan", str(cell), "-o", str(out)], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    names = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert names == ["small_cell.json", "small_cell.manifest.json", "small_cell.srcl"], names
    assert os.stat(out / "small_cell.json").st_size > 1000
