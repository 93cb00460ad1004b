"""A cell file as its schema, for tools that rewrite cells (`import-spots`, `variants`): read flat,
its includes merged and its poses in the world, and written back as cell-file text."""

from __future__ import annotations

from pathlib import Path

from pydantic import ValidationError

from robomax_py.errors import CellFileError
from robomax_py.io.cell_file import CellFile, IncludeFile
from robomax_py.io.cell_problems import _located
from robomax_py.io.frames import FrameNode, resolve_frames
from robomax_py.io.includes import expand_includes
from robomax_py.io.yaml_files import read_yaml_mapping, validation_error
from robomax_py.safe_files import LIMITS


def read_cell_file(path: str | Path) -> CellFile:
    """A cell file as its checked schema (file units), for tools that rewrite cells: flat, its
    includes merged (their paths relative to the cell) and every pose in world coordinates
    (docs/frames.md), so what is written from it stands alone.

    Only the files themselves are checked here; `load_cell` checks what they name (robot, tool, meshes).
    """
    flat = _read_resolved(Path(path))[0].model_copy(update={"frames": [], "include": []})
    flat.__pydantic_fields_set__.difference_update({"frames", "include"})   # resolved: not written back
    return flat


def read_cell_frames(path: str | Path) -> tuple[tuple[FrameNode, ...], tuple[Path, ...]]:
    """The cell's frame tree (`io.frames.FrameNode`, file order) and the files it includes (reading order)."""
    _, tree, files = _read_resolved(Path(path))
    return tree, files


def _read_resolved(path: Path) -> tuple[CellFile, tuple[FrameNode, ...], tuple[Path, ...]]:
    data = read_yaml_mapping(path, CellFileError, "cell file", LIMITS.cell)
    expansion = expand_includes(data, path, IncludeFile)

    def parse() -> tuple[CellFile, tuple[FrameNode, ...]]:
        try:
            parsed = CellFile.model_validate(expansion.data)
        except ValidationError as exc:
            raise validation_error(exc, CellFile, path, CellFileError) from None
        return resolve_frames(parsed, path)

    parsed, tree = _located(expansion, parse)
    return parsed, tree, tuple(file for file, _ in expansion.files)


def dump_cell_file(cell: CellFile, header: str = "") -> str:
    """Cell-file text of a schema object: the keys that were set, in schema order; `header` as comments.

    Deterministic: the same object gives the same bytes. Lists of numbers are written inline.
    """
    import yaml

    data = cell.model_dump(mode="json", exclude_unset=True)
    comment = "".join(f"# {line}\n" if line else "#\n" for line in header.splitlines())
    text: str = yaml.safe_dump(data, sort_keys=False, default_flow_style=None, allow_unicode=True, width=120)
    return comment + text
