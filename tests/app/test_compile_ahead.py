"""A first plan's kernels compiled side by side (`app.compile_ahead`): the table of kernels is what
a plan compiles, a plan after the processes compiled them compiles none of them and writes the same
program, the share-out is balanced, and a command interrupted meanwhile ends with its processes."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from robomax_py.app.compile_ahead import Compiling, shares
from robomax_py.app.kernel_table import PLAN_KERNELS, SHARED_HELPERS, KernelEntry

HERE = Path(__file__).resolve().parent
REFERENCE_CELL = HERE.parent / "data" / "reference" / "cabin_flange.yaml"
# A hang guard for the planning processes, not a measurement: a first plan takes ~10 s of CPU.
PROCESS_LIMIT_S = 600


def _fresh_env(tmp: Path) -> dict[str, str]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp / "numba"), "ROBOMAX_CACHE": str(tmp / "robomax")}
    env.pop("NUMBA_DISABLE_JIT", None)
    return env


def _recorded_plan(mode: str, tmp: Path) -> dict[str, Any]:
    """compile_record.py's record of one plan of the reference cell in a fresh cache."""
    record = tmp / f"{mode}.json"
    subprocess.run([sys.executable, str(HERE / "compile_record.py"), mode, str(REFERENCE_CELL), str(tmp / mode),
                    str(record)], env=_fresh_env(tmp / f"cache_{mode}"), check=True, capture_output=True,
                   timeout=PROCESS_LIMIT_S)
    found: dict[str, Any] = json.loads(record.read_text())
    return found


def _key(k: KernelEntry) -> tuple[str, str, str]:
    return k.module, k.name, str(tuple(k.args))


@pytest.fixture(scope="module")
def lazy_and_ahead(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, Any], dict[str, Any], Path]:
    tmp = tmp_path_factory.mktemp("compile_ahead")
    return _recorded_plan("lazy", tmp), _recorded_plan("ahead", tmp), tmp


def test_the_table_lists_the_kernels_a_plan_compiles(lazy_and_ahead: tuple[dict[str, Any], dict[str, Any], Path]) -> None:
    lazy, _, _ = lazy_and_ahead
    assert lazy["exit"] == 0 and lazy["cold"] == []
    top = {(c["module"], c["name"], c["args"]) for c in lazy["compiled"] if c["top"]}
    every = {(c["module"], c["name"], c["args"]) for c in lazy["compiled"]}
    listed = {_key(k) for k in PLAN_KERNELS}
    assert top == listed, f"compiled but not listed: {sorted(top - listed)}; listed, not compiled: {sorted(listed - top)}"
    helpers = {_key(k) for k in SHARED_HELPERS}
    assert helpers <= every - top, f"helpers a plan does not compile: {sorted(helpers - every)}"


def test_a_plan_after_the_compiling_processes_compiles_no_kernel_and_writes_the_same_program(
        lazy_and_ahead: tuple[dict[str, Any], dict[str, Any], Path]) -> None:
    _, ahead, tmp = lazy_and_ahead
    assert ahead["exit"] == 0 and ahead["cold"] == []
    # The command's own process compiled nothing: every kernel came from the cache the compiling
    # processes wrote.
    assert ahead["compiled"] == []
    programs = sorted(p.name for p in (tmp / "lazy").glob("*.srcl"))
    assert programs
    for name in programs:
        assert (tmp / "ahead" / name).read_bytes() == (tmp / "lazy" / name).read_bytes()


def _entry(name: str, cost: float) -> KernelEntry:
    return KernelEntry("m", name, (), cost)


def test_the_dearest_kernels_go_to_different_processes() -> None:
    groups = shares([_entry("a", 2.8), _entry("b", 2.3), _entry("c", 0.3), _entry("d", 0.25), _entry("e", 0.15)], 2)
    assert [[k.name for k in g] for g in groups] == [["a", "e"], ["b", "c", "d"]]     # loads 2.95, 2.85
    assert [[k.name for k in g] for g in shares([_entry("a", 1.0)], 4)] == [["a"]]


@given(st.lists(st.floats(0.01, 5.0), min_size=1, max_size=12), st.integers(1, 6))
def test_each_kernel_goes_to_one_process_and_none_waits_for_more_than_its_share(costs: list[float], count: int) -> None:
    entries = [_entry(f"k{i}", c) for i, c in enumerate(costs)]
    groups = shares(entries, count)
    assert sorted(k.name for g in groups for k in g) == sorted(k.name for k in entries)
    assert 1 <= len(groups) <= count and all(groups)
    # Graham's bound for list scheduling: no group ends later than the mean load plus one kernel.
    loads = [sum(k.cost_s for k in g) for g in groups]
    assert max(loads) <= sum(costs) / len(groups) + max(costs) + 1e-9


def test_a_process_past_the_limit_is_stopped() -> None:
    p = get_context("fork").Process(target=time.sleep, args=(60,), daemon=True)
    p.start()
    checks: list[int] = []
    assert Compiling((p,)).wait(lambda: checks.append(1), limit_s=0.3) == 0
    assert not p.is_alive() and p.exitcode == -signal.SIGTERM
    assert checks                               # the signal check ran while it waited


def _plain(x: float) -> float:
    return x + 1.0


def test_nothing_is_compiled_ahead_where_no_folder_keeps_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """A kernel without a cache (no folder could be written: numba's own NullCache) or not compiled
    at all (NUMBA_DISABLE_JIT): another process's compile would be lost, so none is started."""
    import numba

    from robomax_py.app import compile_ahead

    module = sys.modules[__name__]
    monkeypatch.setattr(module, "uncached", numba.njit(_plain), raising=False)
    monkeypatch.setattr(module, "not_compiled", _plain, raising=False)
    for name in ("uncached", "not_compiled"):
        entry = KernelEntry(__name__, name, (numba.float64,), 1.0)
        assert compile_ahead.cold([entry]) == []
        assert compile_ahead.start([entry], [], cpus=4) == Compiling()
    # One such kernel among cached ones: none is compiled ahead (the command compiles them all).
    entries = [*PLAN_KERNELS, KernelEntry(__name__, "uncached", (numba.float64,), 1.0)]
    assert compile_ahead.cold(entries) == []


def _mistyped(x: float) -> float:
    return x.no_such_attribute  # type: ignore[attr-defined,no-any-return]  # fails numba's typing


def test_a_kernel_that_fails_to_compile_ends_its_process_without_a_traceback(
        monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]) -> None:
    """The command then compiles it at its first call and reports the failure as it always did."""
    import numba

    monkeypatch.setattr(sys.modules[__name__], "mistyped", numba.njit(_mistyped), raising=False)
    bad = KernelEntry(__name__, "mistyped", (numba.float64,), 1.0)
    assert Compiling((), ((bad,),)).wait() == 0
    assert "Traceback" not in capfd.readouterr().err


def _children(pid: int) -> list[int]:
    found = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        found += [int(c) for c in (task / "children").read_text().split()]
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the process tree from /proc")
def test_ctrl_c_while_the_kernels_compile_ends_the_command_and_its_processes(tmp_path: Path) -> None:
    # Ctrl-C answered as at a terminal even where this test runs with SIGINT ignored (a job started
    # in the background: the command then rightly ignores it too).
    command = ("import runpy, signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
               "sys.argv = ['robomax', *sys.argv[1:]]; runpy.run_module('robomax_py', run_name='__main__')")
    run = subprocess.Popen([sys.executable, "-c", command, "plan", str(REFERENCE_CELL), "--out", str(tmp_path / "out")],
                           env=_fresh_env(tmp_path), start_new_session=True, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + PROCESS_LIMIT_S
    while not _children(run.pid) and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    if run.poll() is not None or not _children(run.pid):
        run.kill()
        pytest.skip("no compiling process was started (one CPU)")
    time.sleep(0.5)                             # into their compile (about 2 s), the last one started
    compiling = _children(run.pid)
    os.killpg(run.pid, signal.SIGINT)            # what the terminal sends on Ctrl-C: the whole group
    _, stderr = run.communicate(timeout=PROCESS_LIMIT_S)
    assert run.returncode == 130, stderr
    assert "Traceback" not in stderr, stderr
    for pid in compiling:
        assert not Path(f"/proc/{pid}").exists() or "Z" in Path(f"/proc/{pid}/stat").read_text().split()[2]
    assert not (tmp_path / "out").exists()
