"""The public Python API: the four steps `robomax plan` and `robomax verify` take, as functions.

    import robomax_py as rm
    cell = rm.load_cell("cells/cabin_flange.yaml")
    result = rm.plan_cell(cell)
    files = rm.write_programs(cell, result, "programs", formats="srcl,krl")
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

__all__ = ["CellWarning", "FormatSkippedWarning", "LoadedCell", "load_cell", "plan_cell", "verify_program", "write_programs"]


class CellWarning(UserWarning):
    """A cell file that loads but probably holds a mistake (`CellSpec.notices`): lengths that look
    like millimetres, a spot inside an object, a home pose in radians, zero clearance to the part.
    The message is the notice's 'file: key: message'."""


class FormatSkippedWarning(UserWarning):
    """`write_programs(formats="all")` passed over a dialect the robot file lacks data for."""


@dataclass(frozen=True, slots=True, eq=False)
class LoadedCell:
    """A checked cell file and its robot with the tool mounted, ready to plan or verify against."""

    spec: CellSpec
    robot: RobotModel

    @property
    def name(self) -> str:
        return self.spec.name


def load_cell(path: str | Path) -> LoadedCell:
    """Read and check a cell file (SPEC §3) and build its robot (URDF, meshes, IK checked).

    What is valid but probably a mistake is reported through Python's `warnings` module, one
    `CellWarning` per notice (also kept in ``cell.spec.notices`` as `Notice(file, key, message)`);
    ``warnings.simplefilter("error", rm.CellWarning)`` makes them errors.
    """
    import warnings

    from robomax_py.io.cell import load_cell as load_spec
    from robomax_py.io.cell import load_cell_robot

    spec = load_spec(Path(path))
    for notice in spec.notices:
        warnings.warn(str(notice), CellWarning, stacklevel=2)
    return LoadedCell(spec, load_cell_robot(spec))


def plan_cell(cell: LoadedCell, options: PlanOptions | None = None, **overrides: object) -> PlanResult:
    """Plan a loaded cell. `overrides` are `PlanOptions` fields (e.g. ``given_order=True``, the published method)."""
    from robomax_py.plan import plan_cell as plan

    opts = dataclasses.replace(options or PlanOptions(), **overrides)  # type: ignore[arg-type]
    return plan(cell.spec, cell.robot, opts)


def write_programs(cell: LoadedCell, result: PlanResult, out_dir: str | Path, formats: str = "srcl",
                   stamp: str = "") -> list[Path]:
    """Render the program files of a complete plan (the trajectory file and each of `formats`, as
    `plan --format` takes them), prove each (read back, rebuilt, compared and verified), then
    write them as one set with its manifest, as `plan` does (`io.files.commit_set`); the paths
    written (the manifest, `<name>.manifest.json`, beside them).

    `all` is every dialect the robot file has the data for: one it lacks a key for (INFORM without
    `controller.pulses_per_degree`) is passed over with a `FormatSkippedWarning` naming the file,
    the key and the dialect.

    Raises ExportError for a plan that is not complete, a dialect named that the robot file lacks
    data for, or a program that does not prove: nothing is written then.
    """
    import warnings

    from robomax_py.export import SHARED_FILES, choose_formats
    from robomax_py.io.files import commit_set
    from robomax_py.plan import method_suffix
    from robomax_py.publish import publish

    chosen = choose_formats(formats, cell.robot)
    for skipped in chosen.skipped:
        warnings.warn(skipped.message, FormatSkippedWarning, stacklevel=2)
    files, _ = publish(result, cell.spec, cell.robot, chosen.names, stamp=stamp, method=result.method)
    name = result.cell + method_suffix(result.method)
    return list(commit_set(Path(out_dir), name, files, cell.spec.digest, SHARED_FILES).paths)


def verify_program(cell: LoadedCell, path: str | Path) -> VerifyReport:
    """Re-simulate a program file (.srcl rebuilt from its statements, or .json) against the cell."""
    from robomax_py.verify import verify_program as verify

    return verify(cell.spec, cell.robot, Path(path))
