"""How the cell loader reports: an error in what an included file brought is named by that file and
its own key (`_located`), and the errors of a cell file's independent checks are raised together
as one (`_Problems`)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from robomax_py.errors import CellFileError
from robomax_py.io.cell_file_values import T
from robomax_py.io.includes import Expansion
from robomax_py.io.yaml_files import MAX_LISTED_PROBLEMS, several


def _located(expansion: Expansion, build: Callable[..., T], *args: Any) -> T:
    """`build(*args)`, an error in what an included file brought naming that file and its own key."""
    try:
        return build(*args)
    except CellFileError as exc:
        raise expansion.relocated(exc) from None


class _Problems:
    """The CellFileErrors of a cell file's independent checks, raised together as one (`several`)."""

    def __init__(self, path: Path, locate: Callable[[CellFileError], CellFileError]) -> None:
        self.path = path
        self.locate = locate               # an included file's item is named by its file and key there
        self.found: list[CellFileError] = []

    def attempt(self, check: Callable[..., T], *args: Any) -> T | None:
        """`check(*args)`, or None when it refuses the file (its error kept; raised at once when
        MAX_LISTED_PROBLEMS are kept: the rest of the file is not looked at)."""
        try:
            return check(*args)
        except CellFileError as exc:
            self.found.append(self.locate(exc))
            if len(self.found) >= MAX_LISTED_PROBLEMS:
                raise several(list(self.found), self.path, more=True) from None
            return None

    def raise_found(self) -> None:
        if self.found:
            raise several(list(self.found), self.path)
