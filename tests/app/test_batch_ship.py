"""A cell's files carried with its Ray task: the driver lists every file the cell reads, and the task
plans from copies of them alone, with the driver's robot library, naming the driver's paths.

No Ray here: `plan_unpacked` is the task's body. The copies stand for files that exist on the driver
only: the driver's paths given to the task lie under a folder that does not exist."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import pytest
import yaml

from robomax_py.app.batch import (
    BAD_INPUT,
    PLANNED,
    CellOutcome,
    PlanSettings,
    plan_cell_file,
)
from robomax_py.app.batch_cell import file_digests
from robomax_py.app.batch_ray import plan_unpacked, task_memory_mb
from robomax_py.app.batch_ship import (
    ORPHAN_AGE_S,
    ShippedCell,
    survey,
    sweep_orphans,
    unpacked,
)
from robomax_py.io.robot_paths import ROBOTS_ENV, shipped_robots_dir
from robomax_py.safe_files import recording_reads

SmallCell = Callable[..., Path]
ELSEWHERE = "/nonexistent-driver"          # where the driver's files are, as far as the task can tell


def robot_folder(library: Path, name: str) -> Path:
    """The shipped kr125 copied into a library folder as robot `name` (a user's own robot)."""
    folder = library / name
    shutil.copytree(shipped_robots_dir() / "kr125", folder)
    robot = folder / "robot.yaml"
    robot.write_text(robot.read_text().replace("name: kr125", f"name: {name}"))
    return folder


def cell_with_robot(folder: Path, write_small_cell: SmallCell, stem: str, robot: str) -> Path:
    path = write_small_cell(folder, stem)
    data = yaml.safe_load(path.read_text())
    data["robot"]["model"] = robot
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def elsewhere(cell: ShippedCell) -> tuple[ShippedCell, list[bytes]]:
    """The cell as a driver whose files are under ELSEWHERE would ship it, and the files' bytes."""
    def moved(paths: tuple[str, ...]) -> tuple[str, ...]:
        return tuple(ELSEWHERE + p for p in paths)

    blobs = [Path(p).read_bytes() for p in cell.paths]
    return replace(cell, file=ELSEWHERE + cell.file, paths=moved(cell.paths), robots=moved(cell.robots),
                   ros_packages=moved(cell.ros_packages)), blobs


def probe_worker(file: str, settings: PlanSettings) -> CellOutcome:
    """Loads the cell as the planner would (robot model included) and says which robot.yaml it used."""
    from robomax_py.io.cell import load_cell, load_cell_robot

    with recording_reads() as reads:
        spec = load_cell(file)
        load_cell_robot(spec)
    return CellOutcome(file, spec.name, PLANNED, 0.0, notes=str(spec.robot.source), inputs=file_digests(reads))


@pytest.fixture
def library(tmp_path: Path) -> Path:
    """A robot library folder with robot `robo_x` (a copy of kr125) and `robo_bad`, whose collision
    mesh of link 2 is not a mesh: it passes the driver's checks and fails in the worker."""
    lib = tmp_path / "lib"
    robot_folder(lib, "robo_x")
    bad = robot_folder(lib, "robo_bad")
    (bad / "meshes" / "collision" / "link_2_0.stl").write_bytes(b"\x07 not a mesh " * 100)
    return lib


def test_survey_lists_every_file_the_cell_reads_once(tmp_path: Path, write_small_cell: SmallCell) -> None:
    cell = write_small_cell(tmp_path, "small")
    found = survey(str(cell))
    paths = found.shipped.paths
    assert len(paths) == len(set(paths)) and all(Path(p).is_absolute() for p in paths)
    names = {str(Path(p).relative_to(shipped_robots_dir())) for p in paths if p.startswith(str(shipped_robots_dir()))}
    assert {"kr125/robot.yaml", "kr125/kr125.urdf", "tools/spot_gun_c/tool.yaml", "tools/spot_gun_c/body.stl",
            "tools/spot_gun_c/tips.stl"} <= names
    assert sum(1 for n in names if n.startswith("kr125/meshes/")) > 10          # every link mesh the URDF names
    assert str(cell) in paths and str(tmp_path / "parts" / "cabin_panel.stl") in paths
    # 2 spots, a grid of 3 with gamma fixed: 3 x 3 orientations each.
    assert (found.spots, found.poses) == (2, 18)
    assert task_memory_mb(found.poses) > task_memory_mb(0)


def test_a_shipped_cell_plans_from_its_copies_with_the_drivers_robot_library(
        tmp_path: Path, write_small_cell: SmallCell, library: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cell = cell_with_robot(tmp_path / "cells", write_small_cell, "mine", "robo_x")
    with monkeypatch.context() as m:            # the driver's `--robots`; the task's process never sees it
        m.setenv(ROBOTS_ENV, str(library))
        found = survey(str(cell))
    shipped, blobs = elsewhere(found.shipped)
    got = plan_unpacked(shipped, PlanSettings(), None, probe_worker, blobs)
    assert got.status == PLANNED, got.reasons
    assert got.file == ELSEWHERE + str(cell)
    assert got.notes == f"{ELSEWHERE}{library}/robo_x/robot.yaml"      # found by name, in the copy of --robots
    assert {p for p, _ in got.inputs} == set(shipped.paths)
    assert "robomax-cell-" not in got.notes                               # no path of the copies is left


def test_a_cell_failing_in_the_worker_names_the_drivers_files(
        tmp_path: Path, write_small_cell: SmallCell, library: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cell = cell_with_robot(tmp_path / "cells", write_small_cell, "bad", "robo_bad")
    with monkeypatch.context() as m:
        m.setenv(ROBOTS_ENV, str(library))
        found = survey(str(cell))                # the driver's load does not read link meshes
    shipped, blobs = elsewhere(found.shipped)
    got = plan_unpacked(shipped, PlanSettings(), None, plan_cell_file, blobs)
    assert got.status == BAD_INPUT
    assert f"{ELSEWHERE}{library}/robo_bad/meshes/collision/link_2_0.stl" in got.reasons
    assert "robomax-cell-" not in got.reasons


def test_a_lost_worker_is_submitted_again_and_a_failing_task_is_not(tmp_path: Path,
                                                                     write_small_cell: SmallCell) -> None:
    ray = pytest.importorskip("ray")
    from types import SimpleNamespace

    from robomax_py.app.batch import BatchOptions
    from robomax_py.app.batch_ray import LOST, _received, _Task

    cell = str(write_small_cell(tmp_path, "small"))
    lost_kinds = tuple(getattr(ray.exceptions, n) for n in LOST if hasattr(ray.exceptions, n))

    def received(error: Exception | None, task: _Task) -> object:
        def get(ref: object) -> CellOutcome:
            if error is not None:
                raise error
            return CellOutcome(ELSEWHERE + cell, "small", PLANNED, 1.0)

        fake = SimpleNamespace(get=get, exceptions=ray.exceptions)
        return _received(fake, None, task, cell, BatchOptions(retries=1), lost_kinds)

    task = _Task(0, survey(cell), (), None)
    again = received(ray.exceptions.NodeDiedError("the node died"), task)
    assert isinstance(again, _Task) and again.attempts == 2 and "NodeDiedError: the node died" in again.lost[0]
    done = received(None, again)                       # planned on the second attempt
    assert isinstance(done, CellOutcome) and done.status == PLANNED and done.attempts == 2
    assert done.file == cell and "attempt 1 was lost (NodeDiedError: the node died)" in done.notes
    last = received(ray.exceptions.WorkerCrashedError(), again)          # lost again: retries used up
    assert isinstance(last, CellOutcome) and last.status == "crashed" and "each of 2 attempt(s)" in last.reasons
    failing = received(ray.exceptions.RayTaskError("plan_shipped", "Traceback ...", ValueError("a bug")), task)
    assert isinstance(failing, CellOutcome) and failing.status == "crashed" and failing.attempts == 1


def _gone_pid() -> int:
    """The number of a process that has ended (and been reaped)."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_killed_tasks_folder_is_removed_by_a_later_task_and_nothing_else_is(tmp_path: Path) -> None:
    """A task killed with its node leaves its copies behind; a later task on the node removes them
    once they are older than ORPHAN_AGE_S, and keeps every folder it cannot prove orphaned."""
    gone, old = _gone_pid(), time.time() - ORPHAN_AGE_S - 60
    folders = {
        "orphan": f"robomax-cell-{gone}-a1",                    # process gone, old: removed
        "young": f"robomax-cell-{gone}-b2",                     # process gone, recent: kept
        "live": f"robomax-cell-{os.getpid()}-c3",               # process runs: kept
        "unnumbered": "robomax-cell-d4",                        # made before folders were numbered: kept
        "other": f"other-{gone}-e5",                            # not a task's: kept
    }
    for key, name in folders.items():
        (tmp_path / name / "tmp").mkdir(parents=True)
        if key != "young":
            os.utime(tmp_path / name, (old, old))
    (tmp_path / f"robomax-cell-{gone}-f6").write_text("a file, not a folder")
    os.utime(tmp_path / f"robomax-cell-{gone}-f6", (old, old))
    assert sweep_orphans(str(tmp_path)) == [folders["orphan"]]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [n for k, n in folders.items() if k != "orphan"] + [f"robomax-cell-{gone}-f6"])


def test_a_tasks_folder_is_named_for_its_process_and_removed_when_it_ends(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    cell = ShippedCell(file="/d/cell.yaml", paths=("/d/cell.yaml",), robots=(), ros_packages=())
    with unpacked(cell, [b"name: x\n"]) as box:
        assert Path(box.root).name.startswith(f"robomax-cell-{os.getpid()}-")
        assert Path(box.file).read_bytes() == b"name: x\n"
    assert list(tmp_path.iterdir()) == []
