"""Every arm of the ROS-Industrial support packages, imported as published and planned (a script,
not a test).

    python tests/bench/bench_family.py --quick [--out FILE.md]
    python tests/bench/bench_family.py --packages DIR [--arms a,b,...] [-j N] [--out FILE.md]

Full mode finds every robot file of the support packages under --packages (a folder holding the
packages of the repositories abb, abb_experimental, fanuc, fanuc_experimental, kuka_experimental,
motoman, staubli_experimental and universal_robot, e.g. filled with `git --git-dir=<mirror> archive
HEAD <pkg> | tar -x -C DIR`): each `<pkg>/urdf/<arm>.xacro` that is not a macro or a shared file
(`*_macro.xacro`, `common_*`), with the MoveIt SRDF of the arm where a `*_moveit_config` package
holds one named after it. Quick mode (CI) runs the arms kept in tests/data/rosi.

For every arm: `import-urdf` exactly as the README says (the brand guessed; no --xacro-arg but a
launch argument the package requires without a default, given as a user would:
bench_controller_frames.LAUNCH_CHOICES, named in the import column), the IK
solver chosen and the fit's largest FK difference to the URDF, then the seeded panel cell of
bench_controller_frames (its `arm_shape`, `panel_cell`, `free_home`: four spots on a sheet in front
of the arm, user frame, tool number) planned and its programs written in the robot's native dialect
(proven by robomax's own readers, as `plan` does). The table: arm, package, import result, IK
solver, fit error, plan result, cycle time, import CPU and plan CPU (time.process_time of the worker;
OMP/BLAS pinned to one thread), and the share of arms importing unedited.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import math
import re
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_controller_frames import (
    Row,
    arm_shape,
    free_home,
    import_arm,
    one_line,
    panel_cell,
)

from robomax_py.errors import RobomaxError

# The robot files kept in tests/data/rosi (see SOURCES.md there): name -> (source, SRDF).
QUICK_ARMS: dict[str, tuple[str, str]] = {
    "irb2400": ("rosi:abb_irb2400_support/urdf/irb2400.xacro", "rosi:abb_irb2400_moveit_config/config/abb_irb2400.srdf"),
    "irb6640_185_280": ("rosi:abb_irb6640_support/urdf/irb6640_185_280.xacro",
                        "rosi:abb_irb6640_moveit_config/config/abb_irb6640_185_280.srdf"),
    "m20ia": ("rosi:fanuc_m20ia_support/urdf/m20ia.xacro", ""),
    "m900ia260l": ("rosi:fanuc_m900ia_support/urdf/m900ia260l.xacro", ""),
    "kr120r2500pro": ("rosi:kuka_kr120_support/urdf/kr120r2500pro.xacro", ""),
}
_NOT_ARMS = re.compile(r"(_macro|^common_|_common|materials|colours|colors|transmission|gazebo)", re.IGNORECASE)


@dataclass
class FamilyRow:
    arm: str
    package: str
    imported: str = ""
    solver: str = ""
    fit_mm: float = math.nan
    planned: str = ""
    cycle_s: float = math.nan
    import_cpu_s: float = math.nan
    plan_cpu_s: float = math.nan

    @property
    def unedited(self) -> bool:
        return self.imported.startswith("ok")


def find_arms(packages: Path) -> dict[str, tuple[str, str]]:
    """Every robot file of the support packages below `packages`: name -> (source, SRDF), both
    relative to `packages` (SRDF "" when no MoveIt configuration names the arm)."""
    srdfs = {p.stem: p for p in sorted(packages.glob("**/*_moveit_config/config/*.srdf"))}
    arms: dict[str, tuple[str, str]] = {}
    for xacro in sorted(packages.glob("*/urdf/*.xacro")):
        if _NOT_ARMS.search(xacro.stem) or not xacro.parent.parent.name.endswith(("_support", "_description")):
            continue
        vendor = xacro.parent.parent.name.split("_")[0]
        srdf = srdfs.get(f"{vendor}_{xacro.stem}") or srdfs.get(xacro.stem)
        arms.setdefault(xacro.stem, (str(xacro.relative_to(packages)),
                                     "" if srdf is None else str(srdf.relative_to(packages))))
    return arms


def fit_error_m(robot_yaml: Path) -> tuple[str, float]:
    """The robot's IK solver and, for a closed-form one, the largest FK difference to the URDF (m)."""
    from robomax_py.io.robot import load_robot_spec
    from robomax_py.robot import load_robot
    from robomax_py.robot.ik.fit import fk_agreement

    robot = load_robot(load_robot_spec(robot_yaml))
    if robot.ik_solver not in ("opw", "ur"):
        return robot.ik_solver, math.nan
    return robot.ik_solver, fk_agreement(robot.model, robot.flange_frame_id, robot.ik_params).position_m


def bench_arm(name: str, source: str, srdf: str, packages: Path | None, seed: int) -> FamilyRow:
    from robomax_py.export import DIALECTS as WRITERS
    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.plan import plan_cell
    from robomax_py.publish import publish

    row = FamilyRow(name, source.split(":")[-1].split("/")[0])
    with tempfile.TemporaryDirectory(prefix=f"family_{name}_") as scratch:
        tmp = Path(scratch)
        frames_row = Row(name, "", source)
        robot_yaml = import_arm(name, source, srdf, packages, tmp / "robots", frames_row)
        row.imported, row.import_cpu_s = frames_row.imported, frames_row.import_cpu_s
        if robot_yaml is None:
            return row
        t0 = time.process_time()
        try:
            row.solver, fit = fit_error_m(robot_yaml)
            row.fit_mm = fit * 1000
            from robomax_py.io.robot import load_robot_spec
            from robomax_py.robot import load_robot

            robot = load_robot(load_robot_spec(robot_yaml))
            brand = robot.controller.brand
            if robot.dof < 6:
                row.planned = f"not planned: {robot.dof} joints (the panel cell needs six or more)"
                return row
            lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
            shape = arm_shape(robot_yaml, list(robot.joint_names), lower, upper, np.random.default_rng(seed))
            cell_data, _, _ = panel_cell(f"{name}_panel", robot_yaml, shape, name, seed)
            cell_path = tmp / f"{name}_panel.yaml"
            cell_path.write_text(yaml.safe_dump(cell_data, sort_keys=False), encoding="utf-8")
            home = free_home(cell_path, shape.homes_deg)
            if home is None:
                row.planned = f"no collision-free home among {len(shape.homes_deg)} candidates"
                return row
            cell_data["robot"]["home"] = [round(v, 3) for v in home]
            cell_path.write_text(yaml.safe_dump(cell_data, sort_keys=False), encoding="utf-8")
            cell = load_cell(cell_path)
            result = plan_cell(cell, load_cell_robot(cell))
            if result.status != "planned":
                row.planned = f"{result.status}: {one_line(Exception(result.message), 100)}"
                return row
            # The native dialect; SRCL where there is none or it cannot drive the arm (seven axes).
            dialects = tuple(d for d, dialect in WRITERS.items()
                             if d == {"kuka": "krl", "abb": "rapid", "ur": "urscript"}.get(brand, brand)
                             and not dialect.unfit(robot))
            publish(result, cell, load_cell_robot(cell), dialects or ("srcl",))
            row.planned, row.cycle_s = "planned", result.cycle_time
        except RobomaxError as exc:
            row.planned = f"failed: {one_line(exc, 120)}"
        except Exception as exc:  # noqa: BLE001 -- a crash is a finding, reported in the table
            row.planned = f"crashed: {type(exc).__name__}: {one_line(exc, 100)}"
        finally:
            row.plan_cpu_s = time.process_time() - t0
    return row


def _number(v: float, fmt: str) -> str:
    return "—" if math.isnan(v) else format(v, fmt)


def render(rows: list[FamilyRow], command: str) -> str:
    ok = sum(r.unedited for r in rows)
    planned = sum(r.planned == "planned" for r in rows)
    imports = [r.import_cpu_s for r in rows if not math.isnan(r.import_cpu_s)]
    solvers: dict[str, int] = {}
    for r in rows:
        if r.solver:
            solvers[r.solver] = solvers.get(r.solver, 0) + 1
    lines = [
        f"Command: `{command}`", "",
        (f"Arms: {len(rows)}; imported unedited: {ok} ({100 * ok / max(len(rows), 1):.0f} %); planned: {planned}; "
         f"IK solvers: {', '.join(f'{k} {v}' for k, v in sorted(solvers.items()))}."),
        (f"Import CPU: total {sum(imports):.1f} s, median {float(np.median(imports)) if imports else math.nan:.1f} s, "
         f"max {max(imports, default=math.nan):.1f} s (time.process_time of the worker: fit, load-back and "
         "meshes; the xacro child process not counted). Fit error: the closed-form solver's largest FK "
         "difference to the URDF over 300 random configurations."), "",
        "| arm | package | import | IK solver | fit error mm | plan | cycle s | import CPU s | plan CPU s |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        cells = [r.arm, r.package, r.imported, r.solver or "—", _number(r.fit_mm, ".1e"), r.planned or "—",
                 _number(r.cycle_s, ".2f"), _number(r.import_cpu_s, ".1f"), _number(r.plan_cpu_s, ".1f")]
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="only the arms kept in the repository (CI)")
    parser.add_argument("--packages", type=Path, help="folder of ROS-Industrial support packages (full mode)")
    parser.add_argument("--arms", help="comma-separated arm names to run (default: all of the mode)")
    parser.add_argument("--first", help="comma-separated arm names to run before the others")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("-j", "--jobs", type=int, default=1, help="arms benched in parallel processes")
    parser.add_argument("--out", type=Path, help="also write the table as markdown here")
    args = parser.parse_args()
    if not args.quick and args.packages is None:
        parser.error("give --packages DIR (full mode) or --quick")
    arms = dict(QUICK_ARMS) if args.quick else find_arms(args.packages)
    if args.arms:
        wanted = [a.strip() for a in args.arms.split(",") if a.strip()]
        unknown = [a for a in wanted if a not in arms]
        if unknown:
            parser.error(f"unknown arms: {', '.join(unknown)} (known: {', '.join(arms)})")
        arms = {a: arms[a] for a in wanted}
    if args.first:
        first = [a.strip() for a in args.first.split(",") if a.strip() in arms]
        arms = {**{a: arms[a] for a in first}, **arms}
    packages = None if args.quick else args.packages.resolve()
    command = "python tests/bench/bench_family.py " + " ".join(sys.argv[1:])
    jobs = [(name, src, srdf, packages, args.seed) for name, (src, srdf) in arms.items()]
    rows: list[FamilyRow] = []

    def done(row: FamilyRow) -> None:
        # The table so far is rewritten after every arm: a long run stopped early keeps its rows.
        print(f"{row.arm}: {row.imported} | {row.solver} | {row.planned}", flush=True)
        rows.append(row)
        if args.out:
            args.out.write_text(render(rows, command), encoding="utf-8")

    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            for row in pool.map(_bench_job, jobs):
                done(row)
    else:
        for job in jobs:
            done(_bench_job(job))
    print(render(rows, command))


def _bench_job(job: tuple[str, str, str, Path | None, int]) -> FamilyRow:
    name, source, srdf, packages, seed = job
    try:
        return bench_arm(name, source, srdf, packages, seed)
    except Exception as exc:  # noqa: BLE001 -- one arm's failure is a row of the table, not the end of the run
        row = FamilyRow(name, source.split(":")[-1].split("/")[0])
        row.imported = f"crashed: {type(exc).__name__}: {one_line(exc, 100)}"
        return row


if __name__ == "__main__":
    main()
