"""`_lazy.defer`: toppra's `import matplotlib.pyplot` runs neither pyplot nor the matplotlib package,
and a later real use of either (a chart) still gets the real modules. Each case runs in a fresh
interpreter, since what it checks is what sys.modules holds."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

PROLOGUE = """
import sys, types
from robomax_py._lazy import defer
defer("matplotlib.pyplot")
import toppra.algorithm
real = lambda name: type(sys.modules[name]) is types.ModuleType
"""


def _run(code: str) -> None:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]),
           "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, "-c", PROLOGUE + code], capture_output=True, text=True,
                          env=env, check=False)
    assert done.returncode == 0, done.stderr[-3000:]


def test_toppra_import_leaves_matplotlib_unloaded() -> None:
    _run("assert not real('matplotlib') and not real('matplotlib.pyplot')\n"
         "assert 'matplotlib.figure' not in sys.modules")


def test_a_submodule_import_after_defer_gets_the_real_package() -> None:
    _run("from matplotlib.figure import Figure\n"
         "assert real('matplotlib') and Figure.__module__ == 'matplotlib.figure'\n"
         "import matplotlib.pyplot as plt\n"
         "assert callable(plt.subplots)")


def test_the_stand_in_bound_by_toppra_forwards_to_pyplot() -> None:
    _run("from toppra.algorithm import algorithm\n"
         "assert algorithm.plt.figure.__module__ == 'matplotlib.pyplot'\n"
         "assert real('matplotlib') and real('matplotlib.pyplot')")
