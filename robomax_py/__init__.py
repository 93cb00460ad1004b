"""robomax_py: offline programming for spot-welding robot cells."""

from robomax_py.errors import (
    CellFileError,
    ExportError,
    ProgramError,
    RobomaxError,
    RobotModelError,
)

__version__ = "0.1.0"

__all__ = ["CellFileError", "ExportError", "ProgramError", "RobomaxError", "RobotModelError", "__version__"]
