"""robomax_py: offline programming for spot-welding robot cells.

The Python API (`robomax_py.app.api`), imported on first use so that `import robomax_py` and
`robomax --help` stay fast:

Functions
    load_cell(source, *, base_dir=None) -> LoadedCell
        a cell file, or a mapping built in code, checked, and its robot with the tool mounted
    plan_cell(cell, options=None, *, progress=None) -> PlanResult
        plan a loaded cell; `progress` receives a ProgressEvent per stage step
    write_programs(cell, result, out_dir, formats=("srcl",), stamp="") -> WrittenPrograms
        prove and write a complete plan's programs, one dialect per item of `formats`
    verify_program(cell, path) -> VerifyReport
        re-simulate a written program against the cell

Types
    LoadedCell        a checked cell (`spec`) and its robot (`robot`)
    PlanOptions       how to plan, field by field (frozen; `PlanOptions()` plans as `robomax plan`)
    PlanResult        the plan: `status`, `message`, `spots`, `failures`, `transitions`, `cycle_time`
    PlanStatus        `PlanResult.status`: "planned" | "infeasible"
    SpotPlan          one planned spot: where, in which configuration, when
    SpotFailure       why a spot has no candidate (`reason`, a FailureReason)
    FailureReason     "unreachable" | "joint_limit" | "collision" | "approach_blocked" | "pinned_config" | ...
    Transition        the joint path between two stops (`kind`, a TransitionKind)
    TransitionKind    "move" | "detour"
    PlanStage         a progress stage: "candidates" | "sequencing" | "timing" | "verify"
    ProgressEvent     one progress step: `stage`, `done`, `total`, `label`, `fraction`
    WrittenPrograms   the files written: `by_dialect`, `trajectory`, `manifest`; a sequence of paths
    VerifyReport      a program's verification: `clean`, `violations`, `cycle_time`, `clearance`
    Violation         one violation: `kind`, `detail`, `t`, `line`

Errors and warnings
    RobomaxError      base of every error raised on purpose (CellFileError, RobotModelError,
                      ProgramError, ExportError), its message naming file, key and problem
    RobomaxWarning    what the CLI prints as `warning:` (defaulted robot limits, a dialect passed
                      over: FormatSkippedWarning; a cell that is probably wrong: CellWarning),
                      issued with `warnings.warn`

The planner's stage log goes to the `logging` logger "robomax_py" at DEBUG level.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from robomax_py.errors import (
    CellFileError,
    ExportError,
    ProgramError,
    RobomaxError,
    RobomaxWarning,
    RobotModelError,
)

if TYPE_CHECKING:
    from robomax_py.app.api import (
        CellWarning,
        FailureReason,
        FormatSkippedWarning,
        LoadedCell,
        PlanOptions,
        PlanResult,
        PlanStage,
        PlanStatus,
        ProgressEvent,
        SpotFailure,
        SpotPlan,
        Transition,
        TransitionKind,
        VerifyReport,
        Violation,
        WrittenPrograms,
        load_cell,
        plan_cell,
        verify_program,
        write_programs,
    )

from robomax_py._version import __version__

# Names served from robomax_py.app.api on first use (it imports the planner: numpy, Pinocchio, ...).
_API = (
    "CellWarning", "FailureReason", "FormatSkippedWarning", "LoadedCell", "PlanOptions", "PlanResult", "PlanStage", "PlanStatus",
    "ProgressEvent", "SpotFailure", "SpotPlan", "Transition", "TransitionKind", "VerifyReport", "Violation",
    "WrittenPrograms", "load_cell", "plan_cell", "verify_program", "write_programs",
)

__all__ = [
    "CellFileError", "CellWarning", "ExportError", "FailureReason", "FormatSkippedWarning", "LoadedCell", "PlanOptions", "PlanResult",
    "PlanStage", "PlanStatus", "ProgramError", "ProgressEvent", "RobomaxError", "RobomaxWarning", "RobotModelError",
    "SpotFailure", "SpotPlan", "Transition", "TransitionKind", "VerifyReport", "Violation", "WrittenPrograms",
    "__version__", "load_cell", "plan_cell", "verify_program", "write_programs",
]


def __getattr__(name: str) -> Any:
    if name in _API:
        from robomax_py.app import api

        value = getattr(api, name)
        globals()[name] = value          # served from the module's namespace from now on
        return value
    raise AttributeError(f"module 'robomax_py' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_API})
