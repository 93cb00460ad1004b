"""The process cell's programs in every dialect, written once (the mutants and helpers of
`verify_mutants`, a module of its own: a test imports it by a name no other test folder has)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from verify_mutants import Placed

from robomax_py.export import DIALECTS
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.publish import publish
from tests.conftest import with_pulses


@pytest.fixture(scope="session")
def placed(tmp_path_factory: pytest.TempPathFactory, write_process_cell: Callable[..., Path],
           shared_once: SharedOnce) -> Placed:
    """The process cell (robot off the origin, turned, on a tilted riser; tool 2, user frame 3,
    registers, inputs) planned once per test run, every dialect written."""
    folder = tmp_path_factory.mktemp("placed")
    path = write_process_cell(folder, name="placed")
    return _planned(path, "placed", tuple(DIALECTS), shared_once)


SharedOnce = Callable[[str, Callable[[], Any]], Any]


def _planned(path: Path, name: str, dialects: tuple[str, ...], shared_once: SharedOnce) -> Placed:
    """The cell at `path` planned and published in `dialects` (once per test run: the files are
    shared between test workers by the cell file's bytes), its files written beside it."""
    cell = load_cell(path)
    robot = with_pulses(load_cell_robot(cell))          # INFORM counts joint positions in pulses

    def compute() -> dict[str, str]:
        result = plan_cell(cell, robot)
        assert result.status == "planned", result.message
        files, _ = publish(result, cell, robot, dialects)
        return dict(files)

    files: dict[str, str] = shared_once(f"placed|{name}|{dialects}|{path.read_text()}", compute)
    for file, text in files.items():
        (path.parent / file).write_text(text)
    return Placed(path.parent, path, cell, robot, files, name)


@pytest.fixture(scope="session")
def placed_package(tmp_path_factory: pytest.TempPathFactory, write_process_cell: Callable[..., Path],
                   shared_once: SharedOnce) -> Placed:
    """The placed process cell with `weld: package`: the welds as the controller's process package
    states them (FANUC SpotTool+ SPOT[]), gun 2, s7 with schedule 4 (0.5 s), s8 with 7 (0.8 s)."""
    import yaml

    folder = tmp_path_factory.mktemp("placed_package")
    path = write_process_cell(folder, name="placed_package")
    data = yaml.safe_load(path.read_text())
    data["robot"]["controller"]["weld"] = "package"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return _planned(path, "placed_package", ("fanuc",), shared_once)
