"""The public Python API: the four steps `robomax plan` and `robomax verify` take, as functions.

    import robomax_py as rm
    cell = rm.load_cell("cells/cabin_flange.yaml")
    result = rm.plan_cell(cell, rm.PlanOptions(speed=0.8), progress=lambda e: print(e.stage, e.done, e.total))
    written = rm.write_programs(cell, result, "programs", formats=["srcl", "krl"])
    report = rm.verify_program(cell, written.by_dialect["krl"][0])

Bad input raises a `RobomaxError` (file, key and problem in its message); infeasibility is a
result (`PlanResult.status`, a `PlanStatus`), not an exception. What the CLI prints as `warning:`
lines is issued here with `warnings.warn` as a `RobomaxWarning`; the planner's stage log (what
`robomax plan -v` shows) goes to the `logging` logger "robomax_py" at DEBUG level.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, cast, overload

from robomax_py.errors import ExportError, RobomaxWarning
from robomax_py.plan import (
    FailureReason,
    PlanOptions,
    PlanResult,
    PlanStage,
    PlanStatus,
    SpotFailure,
    SpotPlan,
    Transition,
    TransitionKind,
)
from robomax_py.plan.results import STAGE_LABELS
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.verify import VerifyReport
from robomax_py.world.motion import Violation

if TYPE_CHECKING:
    from robomax_py.app.replan import ReplanOutcome

__all__ = [
    "CellWarning", "FailureReason", "FormatSkippedWarning", "LoadedCell", "PlanOptions", "PlanResult", "PlanStage", "PlanStatus",
    "ProgressEvent", "RobomaxWarning", "SpotFailure", "SpotPlan", "Transition", "TransitionKind", "VerifyReport",
    "Violation", "WrittenPrograms", "load_cell", "plan_cell", "replan_program", "verify_program", "write_programs",
]


class CellWarning(RobomaxWarning):
    """A cell file that loads but probably holds a mistake (`CellSpec.notices`): lengths that look
    like millimetres, a spot inside an object, a home pose in radians, zero clearance to the part.
    The message is the notice's 'file: key: message'."""


class FormatSkippedWarning(RobomaxWarning):
    """`write_programs(formats=["all"])` passed over a dialect the robot file lacks data for."""


@dataclass(frozen=True, slots=True, eq=False)
class LoadedCell:
    """A checked cell and its robot with the tool mounted, ready to plan or verify against."""

    spec: CellSpec
    robot: RobotModel

    @property
    def name(self) -> str:
        return self.spec.name


@dataclass(frozen=True, slots=True)
class ProgressEvent:
    """One step of a long planning stage, as `plan_cell(progress=...)` is told of it.

    `stage` runs through "candidates", "sequencing", "timing", "verify" in that order; within a
    stage `done` never goes back and ends equal to `total`. `total` may grow while a stage runs
    (sequencing rounds are added as repairs need them).
    """

    stage: PlanStage
    done: int
    total: int

    @property
    def label(self) -> str:
        """What the stage does, in a few words (as the CLI's progress bar names it)."""
        return STAGE_LABELS.get(self.stage, self.stage)

    @property
    def fraction(self) -> float:
        """done / total in [0, 1] (1 for an empty stage)."""
        return 1.0 if self.total <= 0 else min(1.0, self.done / self.total)


@dataclass(frozen=True, slots=True, eq=False)
class WrittenPrograms(Sequence[Path]):
    """The files `write_programs` wrote, by dialect.

    `by_dialect` maps each dialect written ("srcl", "krl", ...) to its files, main program first
    (KRL: `.src`, then `.dat` and the frames setup); `trajectory` is the trajectory file
    (`<name>.json`) every set holds; `manifest` lists the set. As a sequence it is every file
    written (not the manifest): the trajectory file, then each dialect's in the order asked.
    """

    paths: tuple[Path, ...]
    by_dialect: Mapping[str, tuple[Path, ...]]
    trajectory: Path
    manifest: Path

    @overload
    def __getitem__(self, index: int) -> Path: ...

    @overload
    def __getitem__(self, index: slice) -> Sequence[Path]: ...

    def __getitem__(self, index: int | slice) -> Path | Sequence[Path]:
        return self.paths[index]

    def __len__(self) -> int:
        return len(self.paths)

    def __iter__(self) -> Iterator[Path]:
        return iter(self.paths)


def load_cell(source: str | Path | Mapping[str, Any], *, base_dir: str | Path | None = None) -> LoadedCell:
    """Read and check a cell (docs/cell-files.md, "A cell file") and build its robot (URDF, meshes, IK checked).

    `source` is a cell file, or a mapping holding what a cell file's YAML parses to (built in
    code; checked as the file would be, errors naming "<mapping>" as the file; `name` required).
    A mapping's relative paths (meshes, a robot or tool file) are relative to `base_dir`, by
    default the current directory; a file's are relative to its folder, and `base_dir` is refused.

    What the robot's loading fell back on (limits not given in robot.yaml and derived from the
    URDF, visual meshes not read) is issued as a `RobomaxWarning`. What is valid but probably a
    mistake in the cell is issued as a `CellWarning` (a `RobomaxWarning`), one per notice (also kept
    in ``cell.spec.notices`` as `Notice(file, key, message)`); ``warnings.simplefilter("error",
    rm.RobomaxWarning)`` makes them errors.
    """
    from robomax_py.io.cell import cell_from_mapping, load_cell_robot
    from robomax_py.io.cell import load_cell as load_spec

    if isinstance(source, Mapping):
        spec = cell_from_mapping(source, Path.cwd() if base_dir is None else Path(base_dir))
    elif base_dir is not None:
        raise TypeError("load_cell: base_dir is for a cell given as a mapping; a cell file's paths are relative "
                        "to its own folder")
    else:
        spec = load_spec(Path(source))
    for notice in spec.notices:
        warnings.warn(str(notice), CellWarning, stacklevel=2)
    robot: RobotModel = load_cell_robot(spec)
    for line in robot.warnings:
        warnings.warn(line, RobomaxWarning, stacklevel=2)
    return LoadedCell(spec, robot)


def plan_cell(cell: LoadedCell, options: PlanOptions | None = None, *,
              progress: Callable[[ProgressEvent], None] | None = None) -> PlanResult:
    """Plan a loaded cell with `options` (default `PlanOptions()`, as `robomax plan` plans).

    `progress`, when given, is called with a `ProgressEvent` as each long stage advances; an
    exception it raises stops the planning and propagates (a way to cancel).
    """
    from robomax_py.plan import plan_cell as plan

    if progress is None:
        return plan(cell.spec, cell.robot, options or PlanOptions())
    report = progress

    def on_stage(stage: str, done: int, total: int) -> None:
        report(ProgressEvent(cast(PlanStage, stage), done, total))

    return plan(cell.spec, cell.robot, options or PlanOptions(), on_stage)


def write_programs(cell: LoadedCell, result: PlanResult, out_dir: str | Path,
                   formats: Sequence[str] = ("srcl",), stamp: str = "") -> WrittenPrograms:
    """Render the program files of a complete plan (the trajectory file and each dialect of
    `formats`), prove each (read back, rebuilt, compared and verified), then write them as one set
    with its manifest, as `robomax plan` does; what was written, by dialect.

    `formats` names dialects as `plan --format` does, one per item: "srcl", "krl", "rapid",
    "fanuc", "urscript", "inform", "as", "native" (the robot's controller brand) or "all" (every
    dialect the robot file has the data for; one it lacks a key for, e.g. INFORM without
    `controller.pulses_per_degree`, is passed over with a `FormatSkippedWarning` naming the file,
    the key and the dialect). A comma-separated string ("srcl,krl") is still accepted but
    deprecated (DeprecationWarning).

    Raises ExportError for a plan that is not complete, a dialect named that the robot file lacks
    data for, or a program that does not prove: nothing is written then.
    """
    from robomax_py.export import SHARED_FILES, choose_formats, setup_signals
    from robomax_py.io.files import MANIFEST_SUFFIX, commit_set
    from robomax_py.plan import method_suffix
    from robomax_py.publish import publish

    if isinstance(formats, str):
        warnings.warn("write_programs(formats=...) as a comma-separated string is deprecated; pass a sequence, "
                      f"e.g. formats={[f.strip() for f in formats.split(',') if f.strip()]!r}",
                      DeprecationWarning, stacklevel=2)
        asked = formats
    else:
        if not formats or any(not isinstance(f, str) or not f.strip() or "," in f for f in formats):
            raise ExportError(f"formats: expected one dialect name per item (e.g. ['srcl', 'krl']), got {formats!r}")
        asked = ",".join(formats)
    chosen = choose_formats(asked, cell.robot, setup_signals(cell.spec.controller), cell.spec.source)
    for skipped in chosen.skipped:
        warnings.warn(skipped.message, FormatSkippedWarning, stacklevel=2)
    files, checked = publish(result, cell.spec, cell.robot, chosen.names, stamp=stamp, method=result.method)
    name = result.cell + method_suffix(result.method)
    out = Path(out_dir)
    paths = tuple(commit_set(out, name, files, cell.spec.digest, SHARED_FILES).paths)
    return WrittenPrograms(
        paths=paths,
        by_dialect=MappingProxyType({one.format: tuple(out / n for n in one.files) for one in checked}),
        trajectory=out / f"{name}.json",
        manifest=out / f"{name}{MANIFEST_SUFFIX}",
    )


def replan_program(cell: LoadedCell, program: str | Path, at: float, events: Sequence[str],
                   options: PlanOptions | None = None) -> ReplanOutcome:
    """The continuation of a running program after its cell changed, as `robomax replan` plans it:
    the robot stops on its planned path after `at` s (an action in progress completed), and the
    work left is planned from there with `events` applied (the grammar of `--event`,
    docs/cli.md); nothing is written.

    The outcome's `cell` is the continuation's cell (events applied, its clock from the stop, its
    `start` the stop configuration): write with
    ``write_programs(LoadedCell(outcome.cell, cell.robot), outcome.result, out_dir)`` and verify
    against that same cell. Bad input (an event, the program, a time outside it) raises a
    `RobomaxError`; an infeasible continuation is `outcome.status == "infeasible"`, its
    `message` naming the cause.
    """
    from robomax_py.app.replan import replan

    if isinstance(events, str):
        raise TypeError("events: expected a sequence of event strings, got one string")
    return replan(cell.spec, cell.robot, Path(program), float(at), tuple(events), options or PlanOptions())


def verify_program(cell: LoadedCell, path: str | Path) -> VerifyReport:
    """Re-simulate a program file (any dialect robomax writes, rebuilt from its statements, or a
    trajectory .json) against the cell; its `violations` are empty (`clean`) when it holds."""
    from robomax_py.verify import verify_program as verify

    return verify(cell.spec, cell.robot, Path(path))
