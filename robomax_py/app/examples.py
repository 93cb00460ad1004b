"""The example cells shipped inside the package, and `robomax examples DIR` copying them out.

The cells in the repository's cells/ folder are the ones the README and the tests name; a wheel
carries no file outside the package, so robomax_py/examples/ holds the same files as package data
(the cell files and the part meshes they name, not the generator script), and a test keeps the two
byte for byte equal. Code that needs an example cell (`robomax bench` without a cell) reads the
package's copy, so it works after a plain `pip install` from any working folder.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from robomax_py.errors import OutputError

BENCH_CELL = "cabin_flange.yaml"


def examples_dir() -> Path:
    """The example cells inside the installed package (package data)."""
    return Path(__file__).resolve().parent.parent / "examples"


def example_files() -> list[Path]:
    """Every shipped example file, relative to `examples_dir()`, sorted."""
    root = examples_dir()
    return sorted(p.relative_to(root) for p in root.rglob("*")
                  if p.is_file() and "__pycache__" not in p.parts)


def default_bench_cell() -> Path:
    """The cell `robomax bench` plans when given none: the package's cabin_flange example, found
    next to the installed code rather than in the working folder."""
    return examples_dir() / BENCH_CELL


@dataclass(frozen=True, slots=True)
class CopiedExamples:
    """What `copy_examples` did: files written (new or replaced) and files already equal."""

    folder: Path
    written: tuple[Path, ...]
    unchanged: tuple[Path, ...]


def copy_examples(folder: Path, force: bool = False) -> CopiedExamples:
    """Copy the example cells and their part meshes into `folder` (made if missing), keeping the
    layout (cells at the top, meshes in parts/) so the cells' relative mesh paths hold.

    A file already there with the same bytes is left as it is; one with other content is replaced
    only with `force`. Every file is checked before any is written, so a refusal writes nothing.

    Raises
    ------
    OutputError
        A file in `folder` holds something else and `force` is not set, or a file cannot be written.
    """
    from robomax_py.io.files import write_atomic_bytes

    root = examples_dir()
    folder = Path(folder)
    planned: list[tuple[Path, bytes]] = []
    unchanged: list[Path] = []
    clashes: list[Path] = []
    for rel in example_files():
        data = (root / rel).read_bytes()
        dst = folder / rel
        if dst.is_file() and not dst.is_symlink() and dst.read_bytes() == data:
            unchanged.append(dst)
            continue
        if (dst.exists() or dst.is_symlink()) and not (force and dst.is_file()):
            clashes.append(dst)
        planned.append((dst, data))
    if clashes:
        more = f" (and {len(clashes) - 1} more)" if len(clashes) > 1 else ""
        how = "is not a file" if force else "exists with other content; use --force to replace it"
        raise OutputError(clashes[0], None, f"{how}{more}; nothing was written")
    written: list[Path] = []
    try:
        for dst, data in planned:
            dst.parent.mkdir(parents=True, exist_ok=True)
            write_atomic_bytes(dst, data)
            written.append(dst)
    except OSError as exc:
        raise OutputError(folder, None, f"cannot write the examples: {exc.strerror or exc}") from None
    return CopiedExamples(folder, tuple(written), tuple(unchanged))
