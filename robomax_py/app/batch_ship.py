"""A cell's files carried with its Ray task, for nodes that share no folder with the driver.

The driver loads each cell once (`survey`) while `safe_files.recording_reads` lists every file the
loader reads: the cell file, the files it includes, spot lists, meshes, the robot's robot.yaml, URDF,
SRDF and meshes (the URDF's are all checked at load), the tool's tool.yaml and meshes, wherever they
lie (a `--robots` folder, the shipped library, a ROS package). Their bytes travel through Ray's
object store; the task writes them into a fresh folder (`unpacked`) at `<folder>/<absolute path on
the driver>`, so every relative path between them (a mesh beside its URDF, `../parts/panel.stl`)
leads where it led on the driver, and points the child process's robot library path
(ROBOMAX_ROBOTS) and ROS_PACKAGE_PATH at the copies of the driver's folders: a robot named by its
folder name is found as on the driver. Messages name the driver's paths again (`Sandbox.outside`).
A file the cell names by an absolute path is carried too, but read from there only where that path
exists: an absolute path is the one thing a cell must not use on a cluster that shares nothing.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

from robomax_py.app.process_ended import process_ended
from robomax_py.io.robot_paths import ROBOTS_ENV, ROS_PACKAGE_PATH_ENV, robot_library

# A task's folder is named for the process that made it: `robomax-cell-<pid>-<random>`.
_PREFIX = "robomax-cell-"
_OWNED = re.compile(re.escape(_PREFIX) + r"(\d+)-")
# A folder whose process is gone is removed by the node's next task once it is this old (s). Its
# process was killed (a lost node, an out-of-memory kill), so its own clean-up never ran; the age
# keeps the folder of a live task that this process cannot see (another PID namespace sharing the
# temporary folder) for longer than any task runs.
ORPHAN_AGE_S = 6 * 3600.0


@dataclass(frozen=True, slots=True)
class ShippedCell:
    """What a task needs to plan a cell on a node that has none of its files."""

    file: str                        # the cell file, absolute path on the driver
    paths: tuple[str, ...]           # every file the cell reads, absolute on the driver; the task's blobs in this order
    robots: tuple[str, ...]          # the driver's robot library path, absolute (ROBOMAX_ROBOTS, then the shipped library)
    ros_packages: tuple[str, ...]    # the driver's ROS_PACKAGE_PATH entries, absolute


@dataclass(frozen=True, slots=True)
class Survey:
    """A cell loaded by the driver: what to ship, and its size for the memory model."""

    shipped: ShippedCell
    name: str                        # the cell's name
    spots: int
    poses: int                       # TCP orientations to solve: spots x orientation samples, summed over seams


def survey(file: str) -> Survey:
    """Load the cell as a worker would, listing the files it reads; RobomaxError for a bad cell
    (the message the worker would give: the same loader, the same path)."""
    from robomax_py.io.cell import load_cell
    from robomax_py.plan.poses import orientation_grid
    from robomax_py.safe_files import recording_reads

    with recording_reads() as reads:
        spec = load_cell(file)
    ros = [os.path.abspath(p) for p in os.environ.get(ROS_PACKAGE_PATH_ENV, "").split(os.pathsep) if p.strip()]
    shipped = ShippedCell(file=os.path.abspath(file), paths=tuple(dict.fromkeys(reads)),
                          robots=tuple(os.path.abspath(p) for p in robot_library()), ros_packages=tuple(ros))
    poses = sum(len(seam.spots) * len(orientation_grid(seam).angles) for seam in spec.seams)
    return Survey(shipped, spec.name, sum(len(seam.spots) for seam in spec.seams), poses)


@dataclass(frozen=True, slots=True)
class Sandbox:
    """A cell's files written out on a node: the folder, the cell file in it, and the environment
    its worker process plans with."""

    root: str                        # the folder; the driver's absolute paths continue below it
    file: str                        # the cell file in it
    env: dict[str, str]              # ROBOMAX_ROBOTS and ROS_PACKAGE_PATH pointing into it

    def outside(self, text: str) -> str:
        """`text` naming the driver's paths where it names the copies."""
        return text.replace(self.root, "")


@contextmanager
def unpacked(cell: ShippedCell, blobs: Sequence[bytes]) -> Iterator[Sandbox]:
    """The cell's files (`blobs`, in the order of `cell.paths`) written into a fresh temporary
    folder, removed when the block ends."""
    if len(blobs) != len(cell.paths):
        raise ValueError(f"{len(cell.paths)} files to ship, {len(blobs)} given")
    sweep_orphans(tempfile.gettempdir())
    # The real path: messages name files as the loader reaches them, through /tmp's link if it is one.
    root = os.path.realpath(tempfile.mkdtemp(prefix=f"{_PREFIX}{os.getpid()}-"))
    try:
        for path, data in zip(cell.paths, blobs, strict=True):
            target = root + path
            os.makedirs(os.path.dirname(target), exist_ok=True)
            with open(target, "wb") as fh:
                fh.write(data)

        def inside(paths: tuple[str, ...]) -> str:
            return os.pathsep.join(root + p for p in paths)

        yield Sandbox(root, root + cell.file, {ROBOTS_ENV: inside(cell.robots), ROS_PACKAGE_PATH_ENV: inside(cell.ros_packages)})
    finally:
        shutil.rmtree(root, ignore_errors=True)


def sweep_orphans(folder: str, now: float | None = None) -> list[str]:
    """Remove the task folders in `folder` whose process no longer runs and that are older than
    ORPHAN_AGE_S; returns the names removed. A folder that cannot be judged (another user's
    process, a name without a process number) is kept. POSIX only (`process_ended`): elsewhere
    nothing is removed."""
    removed: list[str] = []
    now = time.time() if now is None else now
    with os.scandir(folder) as entries:
        found = list(entries)
    for entry in found:
        owner = _OWNED.match(entry.name)
        if owner is None or not entry.is_dir(follow_symlinks=False) or not process_ended(int(owner.group(1))):
            continue
        try:
            if now - entry.stat(follow_symlinks=False).st_mtime < ORPHAN_AGE_S:
                continue
        except OSError:
            continue
        shutil.rmtree(entry.path, ignore_errors=True)
        removed.append(entry.name)
    return removed
