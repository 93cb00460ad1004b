"""`robomax plan CELL --out OUT` as the command's own process runs it, with numba's compile events
recorded; run by test_compile_ahead.py in a fresh cache.

    python compile_record.py lazy|ahead CELL OUT RECORD.json

lazy: nothing compiled ahead (every kernel at its first call, as numba does by itself); ahead: the
kernels compiled side by side as on a machine with two CPUs. RECORD.json gets the exit code, every
robomax_py function this process compiled (module, name, argument types as numba prints them, and
whether it was compiled from Python rather than inside another function's compile) and the table's
entries the cache still lacks at the end.
"""

from __future__ import annotations

import json
import sys
from typing import Any

from numba.core import event

compiled: list[dict[str, Any]] = []
under_way: list[object] = []


class Recorder(event.Listener):
    def on_start(self, ev: event.Event) -> None:
        under_way.append(ev)

    def on_end(self, ev: event.Event) -> None:
        under_way.pop()
        fn = ev.data["dispatcher"].py_func
        if fn.__module__.startswith("robomax_py."):
            compiled.append({"module": fn.__module__, "name": fn.__name__, "args": str(tuple(ev.data["args"])),
                             "top": not under_way})


def main() -> None:
    mode, cell, out, record = sys.argv[1:5]
    event.register("numba:compile", Recorder())      # type: ignore[no-untyped-call]  # numba is untyped
    from robomax_py.app import cli, compile_ahead
    from robomax_py.app.kernel_table import PLAN_KERNELS, SHARED_HELPERS

    if mode == "lazy":
        compile_ahead.start = lambda *a, **k: compile_ahead.Compiling()
    else:
        compile_ahead.usable_cpus = lambda: 2
    sys.argv = ["robomax", "plan", cell, "--out", out]
    code: object = 0
    try:
        cli.main()
    except SystemExit as ended:
        code = ended.code
    left = [f"{k.module}.{k.name}" for k in compile_ahead.cold([*PLAN_KERNELS, *SHARED_HELPERS])]
    with open(record, "w", encoding="utf-8") as fh:
        json.dump({"exit": code, "compiled": compiled, "cold": left}, fh)


if __name__ == "__main__":
    main()
