"""Program formats, both directions, in one registry: a planned result -> program text (pure and
deterministic, fixed float formats), and program files -> what `robomax verify` checks.

`plan_program` turns a plan into the dialect-free `Program` (`planned_program`); each dialect
module owns its adapter, writer and reader (`srcl`, `krl`, `rapid`, `fanuc`, `urscript`;
`dialect` holds what they share); `trajectory_json` is the sampled trajectory file (SPEC §5);
`rebuild` turns a parsed program back into motion.
"""

from __future__ import annotations

import dataclasses

from robomax_py.errors import ExportError
from robomax_py.export import fanuc, krl, rapid, srcl, trajectory_json, urscript
from robomax_py.export.dialect import Dialect
from robomax_py.export.plan_program import frame_defs, identifier
from robomax_py.plan import PlanResult
from robomax_py.plan.program_frames import cell_program_frames
from robomax_py.program import FrameDef
from robomax_py.spec import CellSpec

__all__ = ["DIALECTS", "SHARED_FILES", "Dialect", "controller_frames", "dialect_for_file", "format_names", "render_trajectory"]

# Registry order is the order files are written in (after the trajectory file).
DIALECTS: dict[str, Dialect] = {
    "srcl": Dialect("srcl", (".srcl",), "", srcl.adapt, srcl.write, srcl.parse),
    "krl": Dialect("krl", (".src", ".dat"), "kuka", krl.adapt, krl.write, krl.parse, krl.frame_name,
                   (krl.FRAMES_FILE,), krl.FILE_ENCODING),
    "rapid": Dialect("rapid", (".mod",), "abb", rapid.adapt, rapid.write, rapid.parse, companions=(rapid.FRAMES_FILE,),
                     named_frames_only=True),
    "fanuc": Dialect("fanuc", (".ls",), "fanuc", fanuc.adapt, fanuc.write, fanuc.parse, fanuc.frame_name,
                     (fanuc.FRAMES_FILE,), program_name=fanuc.program_name,
                     shared=tuple(f"{name}.ls" for name in fanuc.ROUTINES)),
    "urscript": Dialect("urscript", (".script",), "ur", urscript.adapt, urscript.write, urscript.parse),
}
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
NATIVE = {"kuka": "krl", "abb": "rapid", "fanuc": "fanuc", "ur": "urscript"}


def format_names(spec: str, brand: str) -> tuple[str, ...]:
    """`--format` LIST (SPEC §6): names, `all` or `native` (the robot's brand), comma-separated,
    in registry order without repeats; ExportError for an unknown name."""
    wanted: set[str] = set()
    for part in (p.strip().lower() for p in spec.split(",")):
        if part == "all":
            wanted.update(DIALECTS)
        elif part == "native":
            if brand not in NATIVE:
                raise ExportError("--format native: the robot names no controller brand (controller.brand in robot.yaml)")
            wanted.add(NATIVE[brand])
        elif part in DIALECTS:
            wanted.add(part)
        else:
            known = ", ".join([*DIALECTS, "native", "all"])
            raise ExportError(f"unknown program format '{part}'; known: {known}")
    if not wanted:
        raise ExportError("--format names no program format")
    return tuple(name for name in DIALECTS if name in wanted)


def dialect_for_file(suffix: str) -> Dialect | None:
    """The dialect whose files end in `suffix` (".src" and ".dat" are both KRL)."""
    return next((d for d in DIALECTS.values() if suffix.lower() in d.extensions), None)


def render_trajectory(result: PlanResult) -> str:
    """The trajectory file (SPEC §5) of a planned result."""
    if result.status != "planned" or result.trajectory is None:
        raise ExportError(f"cell {result.cell} is not planned: {result.message}")
    return trajectory_json.render(result)
