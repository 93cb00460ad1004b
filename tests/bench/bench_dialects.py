"""Controller programs per shipped cell and dialect: size, CPU time to write (adapt + render), to
prove (read back, rebuild, compare, verify, as `plan` does before writing) and to verify the
written file (`robomax verify`), and the largest difference between the rebuilt and the planned
motion.

    .venv/bin/python tests/bench/bench_dialects.py [--runs 3] [CELL ...]

CPU seconds of this process (time.process_time), median of --runs; the plan itself is made once
per cell and not counted. The SRCL row is the baseline the other dialects are compared against
(`x srcl`: ratio of their verify time to SRCL's in the same run).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from robomax_py.export import DIALECTS, SHARED_FILES, choose_formats
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.publish import publish
from robomax_py.verify import verify_program

REPO = Path(__file__).resolve().parents[2]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cells", nargs="*", type=Path)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    cells = args.cells or sorted((REPO / "cells").glob("*.yaml"))
    print("| cell | dialect | bytes | write CPU s | prove CPU s | verify CPU s | x srcl | rebuilt vs planned |")
    print("|---|---|---|---|---|---|---|---|")
    for path in cells:
        cell = load_cell(path)
        robot = load_cell_robot(cell)
        result = plan_cell(cell, robot)
        if result.status != "planned":
            print(f"| {cell.name} | — | infeasible: {result.message} |")
            continue
        rows = {}
        with tempfile.TemporaryDirectory() as tmp:
            for fmt in choose_formats("all", robot).names:
                write, prove, verify = [], [], []
                checked = None
                for _ in range(args.runs):
                    files, (checked,) = publish(result, cell, robot, (fmt,))
                    write.append(checked.write_seconds)
                    prove.append(checked.check_seconds)
                    for name, text in files.items():
                        (Path(tmp) / name).write_text(text)
                    # The main program: a dialect that names programs its way (FANUC) names it so.
                    ext = DIALECTS[fmt].extensions[0]
                    main_file = Path(tmp) / next(n for n in checked.files if n.endswith(ext)
                                                 and not n.endswith("_frames" + ext) and n not in SHARED_FILES)
                    t0 = time.process_time()
                    report = verify_program(cell, robot, main_file)
                    verify.append(time.process_time() - t0)
                    assert report.clean, (fmt, report.violations[:3])
                assert checked is not None
                size = sum(len(t.encode()) for t in checked.files.values())
                rows[fmt] = (size, statistics.median(write), statistics.median(prove), statistics.median(verify),
                             checked.difference)
        base = rows["srcl"][3]
        for fmt, (size, w, p, v, d) in rows.items():
            print(f"| {cell.name} | {fmt} | {size:,} | {w:.3f} | {p:.2f} | {v:.2f} | {v / base:.2f} | "
                  f"{d.tcp_mm:.4f} mm, {d.joint_deg:.5f} deg, {d.time_s * 1000:.2f} ms |", flush=True)


if __name__ == "__main__":
    main()
