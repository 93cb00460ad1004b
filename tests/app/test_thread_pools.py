"""The command's own process runs one thread per linear algebra library where the user set no
number: set before numpy loads (the command's entry imports no numpy), kept where the user gave
one, left alone once numpy is loaded (too late) and in a caller's process."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
POOLS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def _run(code: str, **given: str) -> str:
    env = {k: v for k, v in os.environ.items() if k not in POOLS}
    env.update(given, PYTHONPATH=str(REPO))
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True,
                          cwd=REPO).stdout.strip()


def test_the_entry_imports_no_numpy() -> None:
    # Else the pools would be running before `main` could size them.
    assert _run("import sys, robomax_py.app.cli; print('numpy' in sys.modules)") == "False"


@pytest.mark.parametrize(("given", "expected"), [({}, "1 1 1"), ({"OPENBLAS_NUM_THREADS": "4"}, "4 1 1")],
                         ids=["none given", "one given"])
def test_one_thread_each_where_the_user_set_none(given: dict[str, str], expected: str) -> None:
    code = ("import os\nfrom robomax_py.app.cli import _one_thread_per_library\n_one_thread_per_library()\n"
            f"print(' '.join(os.environ.get(k, '-') for k in {POOLS!r}))")
    assert _run(code, **given) == expected


def test_left_alone_once_numpy_is_loaded() -> None:
    code = ("import os, numpy\nfrom robomax_py.app.cli import _one_thread_per_library\n_one_thread_per_library()\n"
            f"print(' '.join(os.environ.get(k, '-') for k in {POOLS!r}))")
    assert _run(code) == "- - -"
