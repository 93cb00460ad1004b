"""The only exceptions the package raises, and its one warning category.

A user's mistake becomes one of these, carrying a message that names the file, the key path and the
problem; the CLI prints that message and exits 2. Anything else escaping is a bug in robomax_py.
"""

from __future__ import annotations

from pathlib import Path


class RobomaxError(Exception):
    """Base of every error robomax_py raises on purpose."""


class _LocatedError(RobomaxError):
    """An error in a file the user wrote, located by file and key path."""

    def __init__(self, file: str | Path | None, key: str | None, problem: str) -> None:
        self.file = None if file is None else str(file)
        self.key = key
        self.problem = problem
        parts = [p for p in (self.file, key) if p]
        super().__init__(": ".join([*parts, problem]))

    def __reduce__(self) -> tuple[type, tuple[str | None, str | None, str]]:
        # Rebuilt from its parts (an exception pickles its message alone by default, which this
        # constructor does not take): a process pool or a Ray worker passes it back whole.
        return type(self), (self.file, self.key, self.problem)


class CellFileError(_LocatedError):
    """A cell file (or a file it names) is malformed."""


class RobotModelError(_LocatedError):
    """A robot.yaml, tool.yaml, URDF or mesh cannot be used."""


class OutputError(_LocatedError):
    """A command's output cannot be written as asked: a file there holds something else (and
    --force was not given), or the folder cannot be written."""


class ProgramError(_LocatedError):
    """A robot program file cannot be parsed; `key` holds 'line L, column C'."""


class ExportError(RobomaxError):
    """A plan cannot be written in the requested format."""


class ControllerSetupError(ExportError):
    """The cell's `robot.controller` numbers do not fit a dialect (a tool number beyond the
    controller's slots, a signal without the input number the dialect waits on): `key` is the
    cell key, `problem` what is wrong; the caller names the cell file."""

    def __init__(self, key: str, problem: str) -> None:
        self.key = key
        self.problem = problem
        super().__init__(f"{key}: {problem}")

    def __reduce__(self) -> tuple[type, tuple[str, str]]:
        return type(self), (self.key, self.problem)


class PreviewError(RobomaxError):
    """`robomax preview` cannot serve as asked: the host is not an address of this machine, or the
    port is taken."""


class RobomaxWarning(UserWarning):
    """What the user should know that does not stop the work: a robot file's limits defaulted from its
    URDF, a dialect passed over. The CLI prints these as `warning:` lines; the Python API issues them
    with `warnings.warn`, so `warnings.simplefilter("error", RobomaxWarning)` makes them fatal."""


class EventError(_LocatedError):
    """A replanning event (`robomax replan --event`) is malformed or names nothing in the cell:
    `key` is the option, `problem` says which event and what is wrong."""
