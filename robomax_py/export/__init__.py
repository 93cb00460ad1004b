"""Program formats, both directions, in one registry: a planned result -> program text (pure and
deterministic, fixed float formats), and a program file -> what `robomax verify` checks.

Each format is one module owning its writer and its reader (`srcl`, `trajectory_json`);
`plan_program` turns a plan into the dialect-free `Program` the dialects write, `rebuild` turns a
parsed `Program` back into motion.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from robomax_py.errors import ExportError
from robomax_py.export import plan_program, srcl, trajectory_json
from robomax_py.plan import PlanResult

Exporter = Callable[[PlanResult], str]


@dataclass(frozen=True, slots=True)
class Format:
    """A program format: its file extension, its writer and (where it has one) its parser."""

    name: str
    extension: str
    render: Exporter
    parse: Callable[..., object]


# Registry order is the order files are written in (the trajectory file first).
FORMATS: dict[str, Format] = {
    "json": Format("json", ".json", trajectory_json.render, trajectory_json.load_trajectory_file),
    "srcl": Format("srcl", ".srcl", plan_program.render, srcl.parse_program),
}




def render(result: PlanResult, fmt: str) -> str:
    """The program text of a planned result in the named format."""
    if fmt not in FORMATS:
        raise ExportError(f"unknown program format '{fmt}'; known: {', '.join(sorted(FORMATS))}")
    if result.status != "planned" or result.trajectory is None:
        raise ExportError(f"cell {result.cell} is not planned: {result.message}")
    return FORMATS[fmt].render(result)


def render_programs(result: PlanResult) -> dict[str, str]:
    """Every program file of a planned result, all rendered before anything is written.

    Returns
    -------
    dict[str, str]
        File name (``<cell><ext>``, one per format, in registry order) -> text.
    """
    return {f"{result.cell}{f.extension}": render(result, name) for name, f in FORMATS.items()}
