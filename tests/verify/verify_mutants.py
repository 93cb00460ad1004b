"""The process cell's programs and their mutants: a program edited the way a mistaken convention
would write it, verified as `robomax verify` reads it from disk; and what a controller model executes
of a program (`Execution`). The fixtures that plan the cell once are in conftest.py."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from robomax_py.export import DIALECTS
from robomax_py.program import identifier
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.verify import VerifyReport, verify_program

MAIN = {"krl": ".src", "rapid": ".mod", "fanuc": ".ls", "urscript": ".script", "srcl": ".srcl", "inform": ".jbi",
        "as": ".as"}
Edit = Callable[[str], str]


@dataclass(frozen=True)
class Placed:
    """A planned placed cell and its files (name -> text) in `folder`."""

    folder: Path
    cell_path: Path
    cell: CellSpec
    robot: RobotModel
    files: dict[str, str]
    name: str

    def stem(self, fmt: str) -> str:
        """What `fmt`'s files are named after: the cell's name, or the program the dialect names
        (FANUC: PLACED.ls, PLACED_FRAMES.ls)."""
        name_of = DIALECTS[fmt].program_name
        return name_of(identifier(self.name)) if name_of else self.name

    def mutant(self, fmt: str, edits: Mapping[str, Edit], tag: str) -> Path:
        """A folder with every file of `fmt`'s program, those named by `edits` (a file name, or a
        suffix after the program's name such as ".dat" or "_frames.src") edited; its main file.
        An edit that changes nothing fails the test: the mutant must differ from the program."""
        folder = self.folder / f"mutant_{fmt}_{tag}"
        folder.mkdir()
        stem = self.stem(fmt)
        wanted = {k if not k.startswith((".", "_")) else stem + k: edit for k, edit in edits.items()}
        for file, text in self.files.items():
            if file not in wanted:
                (folder / file).write_text(text)
                continue
            new = wanted.pop(file)(text)
            assert new != text, f"the edit of {file} changed nothing"
            (folder / file).write_text(new)
        assert not wanted, f"no such files: {sorted(wanted)}"
        return folder / f"{stem}{MAIN[fmt]}"

    def verify(self, fmt: str, edits: Mapping[str, Edit], tag: str) -> VerifyReport:
        return verify_program(self.cell, self.robot, self.mutant(fmt, edits, tag))


def placement_mm_zyx(cell: CellSpec) -> tuple[list[float], list[float]]:
    """The robot's placement in the cell (robot.base) as a frame is written: mm and ZYX angles (deg,
    R = Rz(A)·Ry(B)·Rx(C)), computed with scipy, not with robomax's conversions."""
    from scipy.spatial.transform import Rotation

    T = cell.T_world_base
    zyx = Rotation.from_matrix(T[:3, :3]).as_euler("ZYX", degrees=True)
    return [float(v) * 1000.0 for v in T[:3, 3]], [float(v) for v in zyx]


def detour_into_the_part(placed: Placed) -> tuple[list[float], list[float]]:
    """Joint values (deg) of the joint target the program reaches the first weld's approach from,
    and the same with A2 turned 10 deg further: a detour that drives the gun into the part (the
    static world says so; a mutant calls a routine that makes it and comes back)."""
    import re

    import numpy as np

    from robomax_py.world.collision import CollisionWorld
    from robomax_py.world.scene import build_scene

    srcl = placed.files[f"{placed.name}.srcl"]
    body = srcl[:srcl.index("MOVE LIN")]
    back = [float(v) for v in re.findall(r"MOVE PTP AXIS\(([^)]*)\)", body)[-1].split(",")]
    detour = [v + (10.0 if i == 1 else 0.0) for i, v in enumerate(back)]
    world = CollisionWorld(placed.robot, build_scene(placed.cell, placed.robot), placed.cell.process.clearance)
    contact = world.first_contact(np.radians(detour))
    assert contact is not None and contact.kind_b == "object", contact
    return detour, back


@dataclass(frozen=True)
class Execution:
    """What a program runs, as robomax's reader has it or as a controller model runs it: the lines
    of the weld calls that run, in order; how many motions run; the line the program ends at
    before its last statement (None: it runs to its end)."""

    welds: tuple[int, ...]
    motions: int
    stopped: int | None


def read_execution(placed: Placed, fmt: str, edits: Mapping[str, Edit], tag: str) -> tuple[Path, Execution]:
    """A mutant's main file and what robomax's reader (as verify reads it) says runs."""
    from robomax_py.program import LinMove, PtpMove, Spot
    from robomax_py.verify import read_program

    main = placed.mutant(fmt, edits, tag)
    _, _, parsed = read_program(placed.robot, main)
    pairs = list(zip(parsed.program.instructions, parsed.lines))
    ends = [line for line, kind, _ in parsed.problems if kind == "flow"]
    return main, Execution(tuple(line for ins, line in pairs if isinstance(ins, Spot)),
                           sum(isinstance(ins, (PtpMove, LinMove)) for ins, _ in pairs), ends[0] if ends else None)


def model_execution(run: object, weld: str) -> Execution:
    """What a controller model's run (`controller_model.common.ProgramRun`) says runs; `weld`: the
    weld routine's name."""
    calls = [c.where.line for c in run.calls if c.name.lower() == weld.lower()]       # type: ignore[attr-defined]
    stopped = run.stopped.line if run.stopped is not None else None                    # type: ignore[attr-defined]
    return Execution(tuple(calls), len(run.motions), stopped)                           # type: ignore[attr-defined]
