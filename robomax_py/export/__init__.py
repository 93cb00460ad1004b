"""Program formats, both directions, in one registry: a planned result -> program text (pure and
deterministic, fixed float formats), and program files -> what `robomax verify` checks.

`plan_program` turns a plan into the dialect-free `Program` (`planned_program`); each dialect
module owns its adapter, writer and reader (`srcl`, `krl`, `rapid`, `fanuc`, `urscript`,
`inform`, `kawasaki_as`; `dialect` holds what they share), registered as entry points of the group
`robomax_py.dialects` (`shipped`; other packages add dialects the same way); `trajectory_json` is the sampled trajectory file (docs/cell-files.md, "The trajectory file");
`rebuild` turns a parsed program back into motion.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import CellFileError, ExportError
from robomax_py.export import trajectory_json
from robomax_py.export.dialect import (
    Dialect,
    NumberedSignal,
    Parsed,
    SignalNumbers,
    in_controller_joints,
    setup_signals,
)
from robomax_py.export.mount import mount_rotation, robroot
from robomax_py.export.plan_program import frame_defs
from robomax_py.plan import PlanResult
from robomax_py.plan.program_frames import cell_program_frames
from robomax_py.program import FrameDef, identifier
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec
from robomax_py.transforms import invert

if TYPE_CHECKING:
    from robomax_py.export.rebuild.result import Rebuilt

__all__ = ["DIALECTS", "ENTRY_POINT_GROUP", "SHARED_FILES", "Dialect", "FormatChoice", "NumberedSignal", "SignalNumbers", "SkippedFormat",
           "choose_formats", "controller_frames", "controller_rebuild", "controller_world", "dialect_for_file", "format_names",
           "load_dialects", "native_dialect",
           "render_trajectory", "require_calibration", "setup_signals"]

# The entry point group program dialects register under (pyproject.toml): each entry point names a
# `Dialect` object; its name is the `--format` name.
ENTRY_POINT_GROUP = "robomax_py.dialects"


def load_dialects() -> dict[str, Dialect]:
    """Every registered dialect by `--format` name: the shipped ones first, in their order (the
    order files are written in), then the others by name. The shipped dialects come from
    `export.shipped` when the package's own entry points are not installed; an entry point that
    does not load, or names something that is not a Dialect of its own name, is an ExportError."""
    from robomax_py.export.shipped import SHIPPED

    found: dict[str, Dialect] = {d.name: d for d in SHIPPED}
    shipped = set(found)
    others: dict[str, Dialect] = {}
    for ep in metadata.entry_points(group=ENTRY_POINT_GROUP):
        if ep.name in shipped and ep.value.startswith("robomax_py.export.shipped:"):
            continue                      # the package's own registration of a shipped dialect
        try:
            dialect = ep.load()
        except Exception as exc:  # noqa: BLE001 - a plug-in's import fails in its own way
            raise ExportError(f"program dialect plug-in {ep.name} ({ep.value}) does not load: {exc}") from None
        if not isinstance(dialect, Dialect) or dialect.name != ep.name:
            raise ExportError(f"program dialect plug-in {ep.name} ({ep.value}) is not a Dialect named {ep.name!r}")
        if ep.name in found or ep.name in others:
            raise ExportError(f"two program dialects are registered as {ep.name!r}")
        others[ep.name] = dialect
    return {**found, **dict(sorted(others.items()))}


# Registry order is the order files are written in (after the trajectory file).
DIALECTS: dict[str, Dialect] = load_dialects()
# Whole file names every program of a dialect writes alike (FANUC's routines): not one cell's files.
SHARED_FILES: frozenset[str] = frozenset(name for d in DIALECTS.values() for name in d.shared)


def controller_frames(dialect: Dialect, cell: CellSpec) -> tuple[FrameDef, ...]:
    """The frames a controller set up for the cell holds (the integrator has calibrated the cell's
    tool and user frame into it), named as `dialect` refers to them: what a program that selects
    them without stating their values runs with. A dialect whose frames exist only where declared
    (`Dialect.named_frames_only`, RAPID) finds only those the cell names on the controller: a frame
    the program neither declares nor finds there is unknown."""
    frames = frame_defs(cell_program_frames(cell))
    if dialect.named_frames_only:
        setup = cell.controller
        named = {("tool", identifier(setup.tool.name))} if setup.tool is not None and setup.tool.existing else set()
        if setup.frame is not None and setup.frame.frame.existing:
            named.add(("base", identifier(setup.frame.frame.name)))
        frames = tuple(f for f in frames if (f.kind, f.name) in named)
    return tuple(dataclasses.replace(f, name=dialect.frame_name(f)) for f in frames)


def controller_world(dialect: Dialect, cell: CellSpec) -> FloatArray:
    """(4, 4) the controller's world frame in its robot base frame, as the integrator sets the
    controller up for the cell's mounting (`export.mount`): KUKA's $WORLD is inv($ROBROOT), and
    $ROBROOT holds a tilted mount's rotation; every other dialect's frames are the robot base's."""
    if dialect.brand != "kuka":
        return np.eye(4)
    return invert(robroot(mount_rotation(cell.T_world_base, cell.robot.controller.T_root_base)))


def controller_rebuild(dialect: Dialect, cell: CellSpec, robot: RobotModel, main: Path | str, parsed: Parsed,
                       station: frozenset[str] | None = None) -> Rebuilt:
    """The motion of a parsed program as its controller runs it (`export.rebuild.rebuild`): its
    joint targets counted the controller's way (robot.yaml controller.joint_signs/zeros), its
    frames those the controller composes (`controller_frames`) on its world frame
    (`controller_world`). One place for plan's proof, verify and replan alike."""
    from robomax_py.export.rebuild import rebuild

    program = in_controller_joints(parsed.program, robot, inverse=True) if dialect.brand else parsed.program
    rebuilt = rebuild(program, cell, robot, main, parsed.lines, parsed.brand, controller_frames(dialect, cell),
                      controller=bool(dialect.brand), station=station, T_base_world=controller_world(dialect, cell))
    rebuilt.joint_step = parsed.joint_step
    return rebuilt


def native_dialect(brand: str, dialects: dict[str, Dialect] | None = None) -> str | None:
    """The `--format` name of a controller brand's own dialect (the first registered for it), or
    None for a brand robomax has no dialect for."""
    return next((name for name, d in (dialects or DIALECTS).items() if d.brand and d.brand == brand), None)


def _requested(spec: str, brand: str, robot_file: object) -> tuple[set[str], set[str]]:
    """The dialects `--format` names one by one (a name, `native`) and those it takes in with `all`."""
    named: set[str] = set()
    every: set[str] = set()
    for part in (p.strip().lower() for p in spec.split(",")):
        if part == "all":
            every.update(name for name, d in DIALECTS.items() if d.in_all)
        elif part == "native":
            native = native_dialect(brand)
            if native is None:
                where = f"{robot_file}: " if robot_file else ""
                having = ", ".join(sorted({d.brand for d in DIALECTS.values() if d.brand}))
                raise ExportError(f"--format native: {where}controller.brand: robomax writes no program for "
                                  f"brand {brand!r} (native programs for {having}); name a format instead")
            named.add(native)
        elif part in DIALECTS:
            named.add(part)
        else:
            known = ", ".join([*DIALECTS, "native", "all"])
            raise ExportError(f"unknown program format '{part}'; known: {known}")
    if not named and not every:
        raise ExportError("--format names no program format")
    return named, every


def format_names(spec: str, brand: str, robot_file: object = None) -> tuple[str, ...]:
    """`--format` LIST (docs/cell-files.md, "Controller programs"): names, `all` or `native` (the robot's brand), comma-separated,
    in registry order without repeats; ExportError for an unknown name, and for `native` when the
    robot's brand has no dialect (naming the robot file and its key, never another brand's).
    What the robot lacks for a dialect is not looked at here (`choose_formats`)."""
    named, every = _requested(spec, brand, robot_file)
    return tuple(name for name in DIALECTS if name in named | every)


@dataclasses.dataclass(frozen=True, slots=True)
class SkippedFormat:
    """A dialect `--format all` passes over: the robot file does not state `key`, which it needs;
    or (`unfit`) the dialect cannot state the robot's programs at all, for `why`; or (`signal`) the
    cell file (`robot_file` then names it) gives `key` a controller input or output number the
    dialect's programs cannot address."""

    format: str
    robot_file: str
    key: str
    why: str
    unfit: bool = False
    signal: bool = False

    @property
    def message(self) -> str:
        if self.unfit:
            return f"{self.robot_file}: no {self.format} program written ({self.why})"
        if self.signal:
            return f"{self.robot_file}: {self.key}: {self.why}: no {self.format} program written"
        return (f"{self.robot_file}: {self.key} is not given: no {self.format} program written ({self.why}); "
                f"state it to have one")


@dataclasses.dataclass(frozen=True, slots=True)
class FormatChoice:
    """The dialects to write for a robot, in registry order, and those `all` passed over."""

    names: tuple[str, ...]
    skipped: tuple[SkippedFormat, ...] = ()


def require_calibration(fmt: str, robot: RobotModel) -> None:
    """ExportError naming the robot file and the key when `robot` lacks what dialect `fmt` needs."""
    lacking = DIALECTS[fmt].needs(robot)
    if lacking:
        key, why = lacking[0]
        raise ExportError(f"--format {fmt}: {robot.source}: {key} is not given for {robot.name}: {why}")


def choose_formats(spec: str, robot: RobotModel, signals: Sequence[NumberedSignal] = (),
                   cell_file: Path | None = None) -> FormatChoice:
    """`--format` LIST for `robot` (`format_names`): a dialect named (or `native`) that needs data
    the robot file lacks is an ExportError naming the file and the key, and one whose programs
    cannot address an input or output number of `signals` (the cell file's, `setup_signals`) a
    CellFileError naming `cell_file` and the key (both checked before anything is planned or
    written); `all` means every dialect the robot can be written in, the others skipped with the
    reason (`FormatChoice.skipped`), so that a whole set never fails for a missing calibration or a
    vendor's I/O numbering."""
    named, every = _requested(spec, robot.controller.brand, robot.source)
    names: list[str] = []
    skipped: list[SkippedFormat] = []
    for name, dialect in DIALECTS.items():
        unfit = dialect.unfit(robot)
        io = dialect.signal_problem(signals)
        if name in named:
            if unfit:
                raise ExportError(f"--format {name}: {robot.source}: {unfit}")
            require_calibration(name, robot)
            if io is not None:
                raise CellFileError(cell_file or Path("<cell>"), io[0], f"{io[1]} (--format {name})")
            names.append(name)
        elif name in every:
            if unfit:
                skipped.append(SkippedFormat(name, str(robot.source), "urdf", unfit, unfit=True))
                continue
            if io is not None:
                skipped.append(SkippedFormat(name, str(cell_file or "<cell>"), io[0], io[1], signal=True))
                continue
            lacking = dialect.needs(robot)
            if lacking:
                skipped.extend(SkippedFormat(name, str(robot.source), key, why) for key, why in lacking)
            else:
                names.append(name)
    return FormatChoice(tuple(names), tuple(skipped))


def dialect_for_file(suffix: str) -> Dialect | None:
    """The dialect whose files end in `suffix` (".src" and ".dat" are both KRL)."""
    return next((d for d in DIALECTS.values() if suffix.lower() in d.extensions), None)


def render_trajectory(result: PlanResult) -> str:
    """The trajectory file (docs/cell-files.md, "The trajectory file") of a planned result."""
    if result.status != "planned" or result.trajectory is None:
        raise ExportError(f"cell {result.cell} is not planned: {result.message}")
    return trajectory_json.render(result)
