"""`robomax plan` leaves one plan's files, always: killed (SIGKILL, SIGTERM) at seeded random
instants over a folder holding an older plan's set, the folder holds that set or the new one,
whole (by the manifest's sha256 sums); an interrupt before the writing ends the run non-zero with
nothing written, even while heavy modules are imported; files of dialects not written this time
are removed or named. The kill instants use sleeps; no assertion depends on timing."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

ROBOMAX = [sys.executable, "-m", "robomax_py"]
StateOf = Callable[[Path, str], "str | None"]
# Wide lines, so that a log line is never wrapped by the console.
ENV = {**os.environ, "COLUMNS": "400"}


@dataclass(frozen=True)
class Sets:
    cell: Path
    old: Path            # a folder holding the older plan's set (--speed 0.5)
    old_plan: str
    new_plan: str        # the plan id the runs under test write
    seconds: float       # how long one run took (only to spread the kill instants)


def _plan(cell: Path, out: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*ROBOMAX, "plan", str(cell), "-o", str(out), "--format", "all", *extra],
                          capture_output=True, text=True, check=False, env=ENV)


@pytest.fixture(scope="module")
def sets(tmp_path_factory: pytest.TempPathFactory, write_small_cell: Callable[..., Path],
         plan_set_state: StateOf) -> Sets:
    folder = tmp_path_factory.mktemp("plan_files")
    cell = write_small_cell(folder)
    old = _plan(cell, folder / "old", "--speed", "0.5")
    assert old.returncode == 0, old.stderr
    t0 = time.monotonic()
    new = _plan(cell, folder / "new")
    seconds = time.monotonic() - t0
    assert new.returncode == 0, new.stderr
    old_plan, new_plan = plan_set_state(folder / "old", "small_cell"), plan_set_state(folder / "new", "small_cell")
    assert old_plan and new_plan and old_plan != new_plan
    return Sets(cell, folder / "old", old_plan, new_plan, seconds)


def _snapshot(folder: Path) -> dict[str, bytes | str]:
    """Every entry of a folder: a link's target, a file's bytes (the set folders' files too)."""
    out: dict[str, bytes | str] = {}
    for p in sorted(folder.rglob("*")):
        key = str(p.relative_to(folder))
        out[key] = os.readlink(p) if p.is_symlink() else (p.read_bytes() if p.is_file() else "dir")
    return out


def _trial(sets: Sets, folder: Path, sig: signal.Signals, delay: float, *extra: str) -> tuple[int, str]:
    shutil.copytree(sets.old, folder, symlinks=True)
    proc = subprocess.Popen([*ROBOMAX, "plan", str(sets.cell), "-o", str(folder), "--format", "all", *extra],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=ENV)
    time.sleep(delay)
    proc.send_signal(sig)
    _, stderr = proc.communicate(timeout=600)
    return proc.returncode, stderr


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_plan_killed_at_random_instants_leaves_the_old_set_or_the_new_one(
        sets: Sets, tmp_path: Path, sig: signal.Signals, plan_set_state: StateOf) -> None:
    rng = np.random.default_rng(30 + int(sig))
    outcomes = []
    for k in range(8):
        # Most instants fall in the last third of a run, where the files are proven and written.
        delay = float(rng.uniform(0.3, 1.1)) * sets.seconds
        code, stderr = _trial(sets, tmp_path / f"t{k}", sig, delay)
        state = plan_set_state(tmp_path / f"t{k}", "small_cell")
        assert state in (sets.old_plan, sets.new_plan), (k, state)
        assert "Traceback" not in stderr, stderr
        assert code != 0 or state == sets.new_plan
        outcomes.append((round(delay, 1), code, "new" if state == sets.new_plan else "old"))
    print(f"{sig.name}: (delay s, exit, set) {outcomes}")


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_an_early_interrupt_ends_the_run_non_zero_with_nothing_written(
        sets: Sets, tmp_path: Path, sig: signal.Signals, plan_set_state: StateOf) -> None:
    """Signals in the first seconds, heavy imports and loading included (a dependency's import
    catches BaseException): the run ends with 128 + signum (or is killed by the signal before
    its handler is installed), and a run that had not finished timing its motion wrote nothing."""
    rng = np.random.default_rng(40 + int(sig))
    expected = {128 + int(sig), -int(sig)}
    for k in range(4):
        folder = tmp_path / f"t{k}"
        code, stderr = _trial(sets, folder, sig, float(rng.uniform(0.05, 3.0)), "-v")
        assert code in expected, (code, stderr[-2000:])
        assert "Traceback" not in stderr, stderr
        if "timing: cycle" not in stderr:          # interrupted before the motion was timed
            assert _snapshot(folder) == _snapshot(sets.old)
        assert plan_set_state(folder, "small_cell") in (sets.old_plan, sets.new_plan)


@pytest.mark.slow
def test_dialects_not_written_again_are_removed_and_reported(sets: Sets, tmp_path: Path,
                                                             plan_set_state: StateOf) -> None:
    folder = tmp_path / "out"
    shutil.copytree(sets.old, folder, symlinks=True)
    done = subprocess.run([*ROBOMAX, "plan", str(sets.cell), "-o", str(folder), "--format", "srcl", "--json"],
                          capture_output=True, text=True, check=False, env=ENV)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    removed = sorted(Path(p).name for p in report["removed"])
    # FANUC's program and its setup companion are named as the TP program: the set's all the same.
    assert removed == ["SMALL_CELL.ls", "SMALL_CELL_FRAMES.ls", "small_cell.dat", "small_cell.mod",
                       "small_cell.script", "small_cell.src", "small_cell_frames.mod", "small_cell_frames.src"]
    assert [Path(p).name for p in report["unlisted"]] == ["SPOT_WELD.ls"]
    assert "SPOT_WELD.ls" in done.stderr and "no plan's set there names it" in done.stderr
    plan_set_state(folder, "small_cell")
    listed = {f["name"] for f in json.loads((folder / "small_cell.manifest.json").read_text())["files"]}
    # Every file left is the set's, its manifest, or named by the report.
    for p in folder.iterdir():
        if not p.name.startswith("."):
            assert p.name in listed | {"small_cell.manifest.json"} or p.name in {Path(u).name for u in report["unlisted"]}


@pytest.mark.slow
def test_verify_reads_one_set_and_tells_a_file_that_is_not_the_plan_s(sets: Sets, tmp_path: Path) -> None:
    folder = tmp_path / "out"
    shutil.copytree(sets.old, folder, symlinks=True)
    ok = subprocess.run([*ROBOMAX, "verify", str(sets.cell), str(folder / "small_cell.src")],
                        capture_output=True, text=True, check=False, env=ENV)
    assert ok.returncode == 0 and "lone program" not in ok.stdout, ok.stdout
    # The .dat of another plan beside the .src: the mix is a violation, named.
    dat = folder / "small_cell.dat"
    text = dat.read_text()
    dat.unlink()
    dat.write_text(text.replace("DECL", "DECL ", 1))
    mixed = subprocess.run([*ROBOMAX, "verify", str(sets.cell), str(folder / "small_cell.src")],
                           capture_output=True, text=True, check=False, env=ENV)
    assert mixed.returncode == 1, mixed.stdout
    assert "small_cell.dat is not the file of plan" in mixed.stdout
    # A program without a manifest is verified as a lone program, and said to be one.
    lone = tmp_path / "lone"
    lone.mkdir()
    shutil.copy(folder / "small_cell.srcl", lone / "small_cell.srcl")
    alone = subprocess.run([*ROBOMAX, "verify", str(sets.cell), str(lone / "small_cell.srcl")],
                           capture_output=True, text=True, check=False, env=ENV)
    assert alone.returncode == 0 and "verified as a lone program" in alone.stdout, alone.stdout
