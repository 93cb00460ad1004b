"""robomax_py: offline programming for spot-welding robot cells.

The public API (`load_cell`, `plan_cell`, `write_programs`, `verify_program`, `LoadedCell`,
`CellWarning`; see `robomax_py.app.api`) is imported on first use, so `import robomax_py` and
`robomax --help` stay fast.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from robomax_py.errors import (
    CellFileError,
    ExportError,
    ProgramError,
    RobomaxError,
    RobotModelError,
)

if TYPE_CHECKING:
    from robomax_py.app.api import (
        CellWarning,
        LoadedCell,
        load_cell,
        plan_cell,
        verify_program,
        write_programs,
    )

from robomax_py._version import __version__  # noqa: E402

_API = ("CellWarning", "LoadedCell", "load_cell", "plan_cell", "verify_program", "write_programs")

__all__ = [
    "CellFileError", "CellWarning", "ExportError", "LoadedCell", "ProgramError", "RobomaxError", "RobotModelError",
    "__version__",
    "load_cell", "plan_cell", "verify_program", "write_programs",
]


def __getattr__(name: str) -> Any:
    if name in _API:
        from robomax_py.app import api

        return getattr(api, name)
    raise AttributeError(f"module 'robomax_py' has no attribute {name!r}")
