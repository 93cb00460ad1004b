"""The public Python API: the four steps `robomax plan` and `robomax verify` take, as functions.

    import robomax_py as rm
    cell = rm.load_cell("cells/cabin_flange.yaml")
    result = rm.plan_cell(cell)
    files = rm.write_programs(result, "programs")
    report = rm.verify_program(cell, files[-1])

Bad input raises a `RobomaxError` (file, key and problem in its message); infeasibility is a
result (`PlanResult.status`), not an exception.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from robomax_py.plan import PlanOptions, PlanResult
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.verify import VerifyReport

__all__ = ["LoadedCell", "load_cell", "plan_cell", "verify_program", "write_programs"]


@dataclass(frozen=True, slots=True, eq=False)
class LoadedCell:
    """A checked cell file and its robot with the tool mounted, ready to plan or verify against."""

    spec: CellSpec
    robot: RobotModel

    @property
    def name(self) -> str:
        return self.spec.name


def load_cell(path: str | Path) -> LoadedCell:
    """Read and check a cell file (SPEC §3) and build its robot (URDF, meshes, IK checked)."""
    from robomax_py.io.cell import load_cell as load_spec
    from robomax_py.io.cell import load_cell_robot

    spec = load_spec(Path(path))
    return LoadedCell(spec, load_cell_robot(spec))


def plan_cell(cell: LoadedCell, options: PlanOptions | None = None, **overrides: object) -> PlanResult:
    """Plan a loaded cell. `overrides` are `PlanOptions` fields (e.g. ``baseline=True``)."""
    from robomax_py.plan import plan_cell as plan

    opts = dataclasses.replace(options or PlanOptions(), **overrides)  # type: ignore[arg-type]
    return plan(cell.spec, cell.robot, opts)


def write_programs(result: PlanResult, out_dir: str | Path) -> list[Path]:
    """Render every program file of a complete plan, then write each atomically; the paths written.

    Raises ExportError for a plan that is not complete: nothing is written then.
    """
    from robomax_py.export import render_programs
    from robomax_py.io.files import write_programs as write

    return write(Path(out_dir), render_programs(result))


def verify_program(cell: LoadedCell, path: str | Path) -> VerifyReport:
    """Re-simulate a program file (.srcl rebuilt from its statements, or .json) against the cell."""
    from robomax_py.verify import verify_program as verify

    return verify(cell.spec, cell.robot, Path(path))
