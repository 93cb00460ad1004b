"""Replanning a running tending program (a script, not a test):

    python tests/bench/bench_replan.py [PROGRAM] [--runs 3] [--quick]

On the shipped tending cell (`cells/tending.yaml`) and its program (default: the shipped one,
tests/golden/shipped/tending.srcl, read back from its statements), for each event and replanning
time T of a fixed list, prints:
- where the robot stops (how, when) and the work left;
- the CPU seconds of `robomax replan` (reading the program, the stop, planning the continuation;
  median of --runs runs in one process, the first paying numba's compilation; not the proof and
  writing of the files);
- the finish (program clock) of (a) the original plan, as planned, without the event; (b) the
  original program run as it stands in the changed cell: its `WAIT FOR <door>_open` statements
  hold until the late door opens, everything after them later (rebuilt from the statements with the
  changed windows, verified against the changed cell: a move that has no wait before it and meets
  the door collides, and the row says so); (c) the continuation planned waiting at rest
  (`planner.dynamic: rest`); (d) the continuation, time-aware (what `robomax replan` writes).
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import statistics
import time
from pathlib import Path

from robomax_py.app.replan import continuation_name, replan
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.io.replan_events import apply_events, parse_event
from robomax_py.plan import PlanOptions
from robomax_py.verify import verify_program

REPO = Path(__file__).resolve().parents[2]
CASES = (
    ("late:cnc1=+4", 2.5), ("late:cnc1=+4", 8.0), ("late:cnc1=+4", 24.0), ("late:cnc1=+4", 36.0),
    ("late:cnc2=+4", 10.0), ("late:cnc2=+4", 26.0),
    ("late:cnc1=+8", 35.0),
    ("window:cnc1_door=32-38", 30.0),
    ("window:cnc1_door=0-9,9.6-12,16-25,32-41", 8.0),
)
QUICK = (("late:cnc1=+4", 36.0),)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("program", nargs="?", type=Path, default=REPO / "tests" / "golden" / "shipped" / "tending.srcl")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="one case, one run (a smoke run)")
    ap.add_argument("--case", type=int, action="append", help="only the case of this index (repeatable)")
    args = ap.parse_args()
    cell = load_cell(REPO / "cells" / "tending.yaml")
    robot = load_cell_robot(cell)
    runs = 1 if args.quick else args.runs
    print("| event | T (s) | stop | left | CPU (s, median) | (a) planned | (b) program as it stands | "
          "(c) continuation, waiting at rest | (d) continuation, time-aware |")
    print("|---|---|---|---|---|---|---|---|---|")
    cases = QUICK if args.quick else tuple(CASES[i] for i in args.case) if args.case else CASES
    for event, at in cases:
        cpu = []
        outcome = None
        for _ in range(runs):
            t0 = time.process_time()
            outcome = replan(cell, robot, args.program, at, (event,), compare=False)
            cpu.append(time.process_time() - t0)
        assert outcome is not None
        rest = replan(cell, robot, args.program, at, (event,), PlanOptions(dynamic="rest"), compare=False)
        changed = apply_events(cell, (parse_event(event, cell),), at)
        as_is = verify_program(changed, robot, args.program)
        kinds = sorted({v.kind for v in as_is.violations})
        b = f"{as_is.cycle_time:.3f} s" + ("" if as_is.clean else f" ({', '.join(kinds)}: unsafe)")
        s = outcome.stop
        stop = f"{s.how} at {s.t_stop:.3f} s"
        c = "infeasible" if rest.new_finish is None else f"{rest.new_finish:.3f} s"
        d = f"infeasible: {outcome.message}" if outcome.new_finish is None else f"{outcome.new_finish:.3f} s"
        print(f"| `{event}` | {at:g} | {stop} | {len(outcome.left)} | {statistics.median(cpu):.1f} | "
              f"{outcome.old_finish:.3f} s | {b} | {c} | {d} |", flush=True)
    print(f"\n(continuations named as `robomax replan` names them, e.g. {continuation_name(cell, 8.0)})")


if __name__ == "__main__":
    main()
