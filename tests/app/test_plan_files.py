"""`robomax plan` leaves one plan's files, always: killed (SIGKILL, SIGTERM) at seeded random
instants over a folder holding an older plan's set, the folder holds that set or the new one,
whole (by the manifest's sha256 sums); an interrupt before the writing ends the run non-zero with
nothing written, even while heavy modules are imported; files of dialects not written this time
are removed or named. The kill instants use the child's CPU time and sleeps; no assertion depends
on timing.

Run as a script for more trials than the test makes (figures in the notes):
`PYTHONPATH=. python tests/app/test_plan_files.py --trials 30 --seed 1`."""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import app

ROBOMAX = [sys.executable, "-m", "robomax_py"]
StateOf = Callable[[Path, str], "str | None"]
# Wide lines, so that a log line is never wrapped by the console; a run that crashes (a fatal
# signal in native code) prints its Python stack (faulthandler), which the failure shows.
ENV = {**os.environ, "COLUMNS": "400", "PYTHONFAULTHANDLER": "1"}
NAME = "small_cell"
# What `plan --format all` writes for the small cell (the set's own files and FANUC's shared routine).
# No INFORM job: the test arm's robot.yaml states no encoder pulses per degree.
ALL_FILES = ("SMALL_CELL.ls", "SMALL_CELL_FRAMES.ls", "SPOT_WELD.ls", "small_cell.as", "small_cell.dat",
             "small_cell.json", "small_cell.mod", "small_cell.script", "small_cell.src", "small_cell.srcl",
             "small_cell_frames.mod", "small_cell_frames.src")
# Kill instants, CPU seconds of the child: log-uniform over a whole run of the small cell with
# `--format all` (about 3 s of imports, 5 of planning and timing, 4 of proving five dialects,
# 0.1 of writing), so that every stage is hit and the cheap early ones more often.
KILL_CPU_S = (0.05, 13.0)
# A kill aimed at the commit: this long (wall, s) at most after the new set's folder appears.
# Writing and syncing the set takes ~0.1 s here.
COMMIT_WINDOW_S = 0.15


@dataclass(frozen=True)
class Sets:
    cell: Path
    old: Path            # a folder holding the older plan's set (--speed 0.5)
    new: Path            # a folder holding the set the runs under test write
    old_plan: str
    new_plan: str


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
    new = _plan(cell, folder / "new")
    assert new.returncode == 0, new.stderr
    old_plan, new_plan = plan_set_state(folder / "old", NAME), plan_set_state(folder / "new", NAME)
    assert old_plan and new_plan and old_plan != new_plan
    return Sets(cell, folder / "old", folder / "new", old_plan, new_plan)


def _snapshot(folder: Path) -> dict[str, bytes | str]:
    """Every entry of a folder: a link's target, a file's bytes (the set folders' files too)."""
    out: dict[str, bytes | str] = {}
    for p in sorted(folder.rglob("*")):
        key = str(p.relative_to(folder))
        out[key] = os.readlink(p) if p.is_symlink() else (p.read_bytes() if p.is_file() else "dir")
    return out


# `python -m robomax_py` with Ctrl-C as a terminal delivers it: a test run started as a shell's
# background job would hand the command SIGINT ignored, which `robomax` keeps (as for nohup).
ROBOMAX_INTERRUPTIBLE = [sys.executable, "-c", ("import runpy, signal; signal.signal(signal.SIGINT, "
                                                "signal.default_int_handler); runpy.run_module('robomax_py', "
                                                "run_name='__main__', alter_sys=True)")]


def _trial(sets: Sets, folder: Path, sig: signal.Signals, cpu_s: float, *extra: str) -> tuple[int, str, bool]:
    """A plan run sent `sig` once it has used `cpu_s` CPU seconds: (exit code, stderr, whether the
    signal was sent; not when the run had finished first). CPU, not wall time: the small cell
    plans in about 2 s CPU, so a wall delay meets a finished run on a quiet machine and imports
    on a busy one."""
    shutil.copytree(sets.old, folder, symlinks=True)
    proc = subprocess.Popen([*ROBOMAX_INTERRUPTIBLE, "plan", str(sets.cell), "-o", str(folder), "--format", "all",
                             *extra], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=ENV)
    sent = False
    while proc.poll() is None:
        try:
            used = _cpu_s(proc.pid)
        except (FileNotFoundError, ProcessLookupError):
            break                                  # ended between the poll and the read
        if used >= cpu_s:
            proc.send_signal(sig)
            sent = True
            break
        time.sleep(0.005)
    _, stderr = proc.communicate(timeout=600)
    return proc.returncode, stderr, sent


def old_set(folder: Path) -> str:
    """A stand-in for an older plan's `--format all` set in `folder` (its files' bytes are not a
    plan's: only the manifest's sums are judged); its plan id."""
    from robomax_py.io.files import commit_set

    files = {n: f"an older plan's {n}\n" * 200 for n in ALL_FILES}
    return commit_set(folder, NAME, files, "older cell", {"SPOT_WELD.ls"}).plan


def _cpu_s(pid: int) -> float:
    """CPU seconds (user + system) a running process has used so far (Linux /proc)."""
    with open(f"/proc/{pid}/stat") as fh:
        fields = fh.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _staging(folder: Path, before: set[str]) -> bool:
    """Whether a new set's folder has appeared (the run is writing its set)."""
    return any(e.name.startswith(f".{NAME}.robomax-set-") and e.name not in before and e.is_dir()
               for e in os.scandir(folder))


@dataclass(frozen=True)
class Outcome:
    signal: str
    aim: str             # "cpu 3.2 s" or "commit +0.041 s": where the kill was aimed
    code: int            # the exit status (-n: ended by signal n)
    state: str           # "old", "new" or what else the folder held
    plan: str | None     # the plan id of the set the folder holds
    cpu_s: float         # CPU seconds the run had used when signalled
    stderr: str


def kill_trial(cell: Path, folder: Path, sig: signal.Signals, rng: np.random.Generator, at_commit: bool,
               state_of: StateOf) -> Outcome:
    """One `plan --format all` over an older set in `folder`, signalled at a random instant: a CPU
    time drawn log-uniformly from KILL_CPU_S, or (at_commit) a moment within COMMIT_WINDOW_S of the
    new set's folder appearing. The folder's state afterwards."""
    old = old_set(folder)
    before = {e.name for e in os.scandir(folder)}
    proc = subprocess.Popen([*ROBOMAX, "plan", str(cell), "-o", str(folder), "--format", "all"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=ENV)
    if at_commit:
        offset = float(rng.uniform(0.0, COMMIT_WINDOW_S))
        aim = f"commit +{offset:.3f} s"
        while proc.poll() is None and _cpu_s(proc.pid) < 0.5 * KILL_CPU_S[1]:    # long before it writes
            time.sleep(0.02)
        while proc.poll() is None and not _staging(folder, before):
            time.sleep(0.001)
        time.sleep(offset)
    else:
        target = math.exp(float(rng.uniform(math.log(KILL_CPU_S[0]), math.log(KILL_CPU_S[1]))))
        aim = f"cpu {target:.2f} s"
        while proc.poll() is None and _cpu_s(proc.pid) < target:
            time.sleep(0.005)
    cpu = _cpu_s(proc.pid) if proc.poll() is None else float("nan")
    if proc.poll() is None:
        proc.send_signal(sig)
    _, stderr = proc.communicate(timeout=600)
    try:
        plan = state_of(folder, NAME)
        state = "old" if plan == old else "new"
    except AssertionError as exc:          # a mix: what the test must never see
        plan, state = None, f"mixed: {exc}"
    return Outcome(sig.name, aim, proc.returncode, state, plan, cpu, stderr)


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_plan_killed_at_random_instants_leaves_the_old_set_or_the_new_one(
        write_small_cell: Callable[..., Path], tmp_path: Path, sig: signal.Signals, plan_set_state: StateOf) -> None:
    """Four runs per signal, signalled at seeded CPU instants over the whole run; the last SIGKILL
    inside the commit (a run that gets that far costs ~13 s of CPU: SIGTERM during the commit, held
    until the set is whole, is tried in tests/io/test_plan_set.py and by the script). Each leaves
    the older set or the new one whole; a run that ends 0 wrote the new one; every new set is the
    same plan. About 30 s of CPU in all; `python tests/app/test_plan_files.py` runs more."""
    cell = write_small_cell(tmp_path)
    rng = np.random.default_rng(30 + int(sig))
    outcomes = [kill_trial(cell, tmp_path / f"t{k}", sig, rng, k == 3 and sig == signal.SIGKILL, plan_set_state)
                for k in range(4)]
    print(f"\n{sig.name}: " + "; ".join(f"{o.aim} -> exit {o.code}, {o.state}" for o in outcomes))
    for o in outcomes:
        assert o.state in ("old", "new"), o
        assert "Traceback" not in o.stderr, o.stderr[-3000:]
        assert o.code != 0 or o.state == "new", o
        assert o.code in (0, -int(sig), 128 + int(sig)), o
    assert len({o.plan for o in outcomes if o.state == "new"}) <= 1


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_an_early_interrupt_ends_the_run_non_zero_with_nothing_written(
        sets: Sets, tmp_path: Path, sig: signal.Signals, plan_set_state: StateOf) -> None:
    """Signals in the first seconds, heavy imports and loading included (a dependency's import
    catches BaseException): the run ends with 128 + signum (or is killed by the signal before
    its handler is installed), and a run that had not finished timing its motion wrote nothing."""
    rng = np.random.default_rng(40 + int(sig))
    expected = {128 + int(sig), -int(sig)}
    interrupted = 0
    for k in range(4):
        folder = tmp_path / f"t{k}"
        # Early: a whole warm run is now about 1.9-2.0 s CPU (-v, --format all); a signal at its
        # end, the programs written and the process exiting, ends it 0, as it should.
        sent_at = float(rng.uniform(0.05, 1.2))
        code, stderr, sent = _trial(sets, folder, sig, sent_at, "-v")
        assert "Traceback" not in stderr, stderr
        if not sent:                               # the run finished first: a plain run
            assert code == 0 and plan_set_state(folder, "small_cell") == sets.new_plan, stderr[-2000:]
            continue
        interrupted += 1
        if code not in expected:                  # pytest.fail: its message is shown whole, not cut short
            pytest.fail(f"signal at {sent_at:.3f} s CPU: exit {code}\n{stderr[-4000:]}")
        if "timing: cycle" not in stderr:          # interrupted before the motion was timed
            assert _snapshot(folder) == _snapshot(sets.old)
        assert plan_set_state(folder, "small_cell") in (sets.old_plan, sets.new_plan)
    assert interrupted, "every run finished before its signal: the test shows nothing"


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
    assert removed == ["SMALL_CELL.ls", "SMALL_CELL_FRAMES.ls", "small_cell.as", "small_cell.dat", "small_cell.mod",
                       "small_cell.script", "small_cell.src", "small_cell_frames.mod", "small_cell_frames.src"]
    assert [Path(p).name for p in report["unlisted"]] == ["SPOT_WELD.ls"]
    assert "SPOT_WELD.ls" in done.stderr and "no plan's set there names it" in done.stderr
    plan_set_state(folder, "small_cell")
    listed = {f["name"] for f in json.loads((folder / "small_cell.manifest.json").read_text())["files"]}
    # Every file left is the set's, its manifest, or named by the report.
    for p in folder.iterdir():
        if not p.name.startswith("."):
            assert p.name in listed | {"small_cell.manifest.json"} or p.name in {Path(u).name for u in report["unlisted"]}


def _verify(cell: Path, program: Path) -> tuple[int, list[str]]:
    result = CliRunner().invoke(app, ["verify", str(cell), str(program)], env={"COLUMNS": "400"})
    return result.exit_code, result.output.splitlines()


@pytest.mark.slow
def test_verify_reads_one_set_and_tells_a_file_that_is_not_the_plan_s(sets: Sets, tmp_path: Path) -> None:
    """A program beside its plan's manifest must be the file that plan wrote: another plan's file,
    an edited one or one the manifest does not list is one `set` violation naming it (exit 1, the
    motion still judged); without a manifest a program is a lone program, and said to be one."""
    folder = tmp_path / "out"
    shutil.copytree(sets.old, folder, symlinks=True)
    for program in ("small_cell.src", "SMALL_CELL.ls", "small_cell.json"):
        code, lines = _verify(sets.cell, folder / program)
        assert code == 0 and not any("lone program" in line or "set:" in line for line in lines), lines
    # The .dat edited beside the .src: the mix is a violation, naming the file.
    dat = folder / "small_cell.dat"
    text = dat.read_text()
    dat.unlink()
    dat.write_text(text.replace("DECL", "DECL ", 1))
    code, lines = _verify(sets.cell, folder / "small_cell.src")
    found = [line for line in lines if "set:" in line]
    assert code == 1 and len(found) == 1, lines
    assert f"small_cell.dat is not the file of plan {sets.old_plan[:12]} that small_cell.manifest.json lists" in found[0]
    # The manifest of another plan (the new one) beside the old plan's files.
    manifest = folder / "small_cell.manifest.json"
    manifest.unlink()
    shutil.copy(sets.new / "small_cell.manifest.json", manifest)
    code, lines = _verify(sets.cell, folder / "SMALL_CELL.ls")
    found = [line for line in lines if "set:" in line]
    # One line per file read that differs (the frames companion is the same in both plans).
    assert code == 1 and found, lines
    assert f"SMALL_CELL.ls is not the file of plan {sets.new_plan[:12]} that small_cell.manifest.json lists" in found[0]
    assert all(line.split("set: ")[1].startswith(("SMALL_CELL.ls ", "SMALL_CELL_FRAMES.ls ")) for line in found)
    assert "clean" not in lines[-1] and "violation(s)" in lines[-1]
    # A file the manifest does not list (an older dialect's, put back by hand beside an srcl plan).
    srcl_only = tmp_path / "srcl_only"
    done = subprocess.run([*ROBOMAX, "plan", str(sets.cell), "-o", str(srcl_only)], capture_output=True, text=True,
                          check=False, env=ENV)
    assert done.returncode == 0, done.stderr
    shutil.copy(sets.new / "small_cell.script", srcl_only / "small_cell.script")
    code, lines = _verify(sets.cell, srcl_only / "small_cell.script")
    found = [line for line in lines if "set:" in line]
    assert code == 1 and len(found) == 1, lines
    assert "small_cell.script is not one of the files of plan" in found[0], found
    # A program without a manifest is verified as a lone program, and said to be one.
    lone = tmp_path / "lone"
    lone.mkdir()
    shutil.copy(folder / "small_cell.srcl", lone / "small_cell.srcl")
    code, lines = _verify(sets.cell, lone / "small_cell.srcl")
    assert code == 0 and any("verified as a lone program" in line for line in lines), lines


def main() -> None:
    """More kill trials than the test makes, for the figures: a table of outcomes per signal."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=30, help="runs per signal (a quarter aimed at the commit)")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    from tests.conftest import _plan_set_state, _write_small_cell

    with tempfile.TemporaryDirectory() as tmp:
        cell = _write_small_cell(Path(tmp))
        for sig in (signal.SIGKILL, signal.SIGTERM):
            rng = np.random.default_rng([args.seed, int(sig)])
            outcomes = []
            for k in range(args.trials):
                o = kill_trial(cell, Path(tmp) / f"{sig.name}{k}", sig, rng, k % 4 == 3, _plan_set_state)
                outcomes.append(o)
                print(f"{sig.name} {k:2d} {o.aim:>18}  cpu at signal {o.cpu_s:5.2f} s  exit {o.code:4d}  {o.state}"
                      f"{'  TRACEBACK' if 'Traceback' in o.stderr else ''}", flush=True)
            counts = Counter((o.aim.split()[0], o.state, o.code) for o in outcomes)
            print(f"{sig.name}: " + ", ".join(f"{n} x {aim} -> {state} (exit {code})"
                                            for (aim, state, code), n in sorted(counts.items())), flush=True)
            print(f"{sig.name}: new plans {sorted({o.plan[:12] for o in outcomes if o.plan and o.state == 'new'})}")


if __name__ == "__main__":
    main()
