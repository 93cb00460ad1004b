"""Exporters: a planned result -> program text. Pure and deterministic (fixed float formats)."""

from __future__ import annotations

from collections.abc import Callable

from robomax_py.errors import ExportError
from robomax_py.export import plan_program, trajectory_json
from robomax_py.plan import PlanResult

Exporter = Callable[[PlanResult], str]

# format name -> (file extension, exporter)
EXPORTERS: dict[str, tuple[str, Exporter]] = {
    "json": (".json", trajectory_json.render),
    "srcl": (".srcl", plan_program.render),
}


def render(result: PlanResult, fmt: str) -> str:
    """The program text of a planned result in the named format."""
    if fmt not in EXPORTERS:
        raise ExportError(f"unknown program format '{fmt}'; known: {', '.join(sorted(EXPORTERS))}")
    if result.status != "planned" or result.trajectory is None:
        raise ExportError(f"cell {result.cell} is not planned: {result.message}")
    return EXPORTERS[fmt][1](result)


def render_programs(result: PlanResult) -> dict[str, str]:
    """Every program file of a planned result, all rendered before anything is written.

    Returns
    -------
    dict[str, str]
        File name (``<cell><ext>``, one per exporter, in registry order) -> text.
    """
    return {f"{result.cell}{ext}": render(result, fmt) for fmt, (ext, _) in EXPORTERS.items()}
