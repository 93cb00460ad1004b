"""`robomax plan` as a user runs it: one process from start to exit, its CPU (user + sys, of the
process and any it waits for: the processes that compile a first plan's kernels side by side
included) and its wall time, on the cell of the README's quick start unless given another.

    python tests/bench/bench_startup.py [CELL] [--runs 3]

Cold is the first plan after an install: empty caches (a fresh ROBOMAX_CACHE and NUMBA_CACHE_DIR,
so numba compiles every kernel the plan calls: robomax keeps its kernels under a set
NUMBA_CACHE_DIR, else in the cache folder). Warm is the next plan with the caches the cold one left.
Python reads and writes its bytecode (`__pycache__`, ignored by git) whatever the calling
environment says, as an installed package has it: with PYTHONDONTWRITEBYTECODE set, every run
compiled robomax's ~190 modules again, ~0.2 s of CPU that a user's run never pays.
Each run has its own cache folder and output folder. The figures are medians over --runs; the
ratio cold / warm is of the same run, so a busy machine shifts both alike. Wall time is what the
user waits: on an idle machine with two CPUs or more the first plan's compile is shared out
(`app.compile_ahead`), so cold wall is below cold CPU; on a loaded machine it swings. The split of a warm
run (imports, the command's own work) comes from `python -X importtime` and a profile.

The floor is what no change to robomax can take off a plan: a process that only imports the
third-party modules a warm plan of the cell loads (read from that plan's own `sys.modules`, the
packages robomax defers left deferred) and exits. warm - floor is robomax's share: its own modules,
reading the cell, planning, writing and proving the program.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
QUICK_START_CELL = REPO / "cells" / "cabin_flange.yaml"


def plan_cpu(cell: Path, cache: Path, out: Path) -> tuple[float, float]:
    """(CPU seconds (user + sys), wall seconds) of one `python -m robomax_py plan cell --out out`
    with its caches in `cache`; raises when the command fails."""
    env = {**os.environ,
           "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]),
           "ROBOMAX_CACHE": str(cache / "robomax"), "NUMBA_CACHE_DIR": str(cache / "numba")}
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        env.pop(name, None)                 # the command sets its own, as for a user
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "robomax_py", "plan", str(cell), "--out", str(out)],
                          capture_output=True, text=True, env=env, check=False)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"robomax plan {cell} failed ({done.returncode}):\n{done.stderr[-3000:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


# A plan, then the third-party modules it loaded (not the standard
# library's, not robomax's, not a deferred stand-in), one per line.
_LOADED = """
import sys, types
from robomax_py.app.cli import app
app(["plan", sys.argv[1], "--out", sys.argv[2]], standalone_mode=False)   # in-process: the command's own exit skips what follows
skip = set(sys.stdlib_module_names) | {"robomax_py", "__main__", "_virtualenv"}
names = [m for m, mod in sys.modules.items() if m.split(".")[0] not in skip and not m.startswith("_")
         and type(mod) is types.ModuleType]
print("\\n".join(sorted(names)), file=open(sys.argv[3], "w"))
"""

# Imports the listed modules as the plan had them, the packages robomax defers deferred.
_FLOOR = """
import importlib, sys
from robomax_py._lazy import defer
defer("matplotlib.pyplot")
for name in open(sys.argv[1]).read().split():
    try:
        importlib.import_module(name)
    except Exception:
        pass
"""


def import_floor(cell: Path, cache: Path, out: Path) -> float:
    """CPU seconds (user + sys) of a process importing the third-party modules a warm plan of
    `cell` loads (caches in `cache`, which a plan has warmed)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]),
           "ROBOMAX_CACHE": str(cache / "robomax"), "NUMBA_CACHE_DIR": str(cache / "numba")}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    listed = out.with_suffix(".modules")
    subprocess.run([sys.executable, "-c", _LOADED, str(cell), str(out), str(listed)], capture_output=True, env=env,
                   check=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-c", _FLOOR, str(listed)], capture_output=True, env=env, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("cell", nargs="?", type=Path, default=QUICK_START_CELL)
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    cold, warm, ratio, cold_wall, warm_wall, extra_wall, floor = [], [], [], [], [], [], []
    for _ in range(args.runs):
        with tempfile.TemporaryDirectory() as tmp:
            root = Path(tmp)
            c, cw = plan_cpu(args.cell, root / "cache", root / "out_cold")
            w, ww = plan_cpu(args.cell, root / "cache", root / "out_warm")
            floor.append(import_floor(args.cell, root / "cache", root / "out_floor"))
        cold.append(c)
        warm.append(w)
        ratio.append(c / w)
        cold_wall.append(cw)
        warm_wall.append(ww)
        extra_wall.append(cw - ww)
    m = statistics.median
    print(f"robomax plan {args.cell.name}: median of {args.runs}")
    print(f"{'':>22} {'CPU s':>8} {'wall s':>8}")
    print(f"{'cold (empty caches)':>22} {m(cold):8.2f} {m(cold_wall):8.2f}")
    print(f"{'warm':>22} {m(warm):8.2f} {m(warm_wall):8.2f}")
    print(f"{'cold / warm':>22} {m(ratio):8.2f}")
    print(f"{'cold - warm':>22} {m(cold) - m(warm):8.2f} {m(extra_wall):8.2f}")
    print(f"{'import floor':>22} {m(floor):8.2f}")
    print(f"{'warm - floor':>22} {m(warm) - m(floor):8.2f}")


if __name__ == "__main__":
    main()
