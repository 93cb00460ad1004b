"""CAD parts: STEP files (`.step`, `.stp`) tessellated into triangle meshes.

A STEP file holds exact surfaces (planes, cylinders, splines), not triangles. OpenCASCADE, through
the `cascadio` package (the `cad` extra), meshes them so that no triangle is further than the
linear tolerance from the surface it stands for, and writes a glTF binary, which trimesh reads.
Measured with cascadio 0.1 (tests/io/test_cad.py, docs/cad.md):

- the STEP file states its own length unit (`SI_UNIT(.MILLI.,.METRE.)` in nearly every file from
  a body shop's CAD); OpenCASCADE converts the geometry to millimetres on reading, takes the
  tolerance in millimetres whatever the file's unit, and the glTF it writes is in metres, so the
  mesh comes back in metres with no scale to apply;
- trimesh's own STEP loader calls cascadio with cascadio's default tolerance (0.01 mm, many more
  triangles than a collision check needs) and passes no tolerance through `trimesh.load`, so
  cascadio is called here directly.

Tessellating a large part takes seconds, so the result is kept in the cache folder
(`robomax_py.cache_files`), keyed by the file's contents and the tolerances: a STEP is tessellated
once, whichever command reads it next.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import sys
import tempfile
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robomax_py.cache_files import cache_folder, store_arrays

if TYPE_CHECKING:                       # imported where a STEP is read (see geometry)
    import trimesh

STEP_SUFFIXES = (".step", ".stp")

# The tolerance a STEP is meshed at when the cell file states none (mm): well under a weld gun's
# clearances, and about 500 triangles for a 100 mm bracket with a hole (docs/cad.md).
DEFAULT_TOLERANCE_MM = 0.1
# Finer than this the triangle count grows without bound for nothing a collision check can see.
MIN_TOLERANCE_MM = 0.01
# Angular deflection (rad) between neighbouring normals on a curved face: cascadio's default. It
# makes small holes round (at least 13 sides) where the linear tolerance alone would leave them
# triangles; it only adds triangles, never loosens the linear tolerance.
ANGULAR_TOLERANCE_RAD = 0.5

CAD_EXTRA_MESSAGE = "reading STEP needs the cad extra: pip install 'robomax-py[cad]'"

# The length unit a STEP states, in its header: LENGTH_UNIT() ... SI_UNIT(.MILLI.,.METRE.), with
# `$` for no prefix. (Imperial files use CONVERSION_BASED_UNIT, which this does not name.)
_SI_LENGTH = re.compile(rb"LENGTH_UNIT\s*\(\s*\)[^;]*?SI_UNIT\s*\(\s*(\$|\.[A-Z]+\.)\s*,\s*\.METRE\.\s*\)"
                        rb"|SI_UNIT\s*\(\s*(\$|\.[A-Z]+\.)\s*,\s*\.METRE\.\s*\)[^;]*?LENGTH_UNIT\s*\(\s*\)")
_PREFIX_UNITS = {b"$": "m", b".MILLI.": "mm", b".CENTI.": "cm", b".DECI.": "dm", b".KILO.": "km", b".MICRO.": "um"}


class CadExtraMissing(ImportError):
    """cascadio, which reads STEP files, is not installed."""

    def __init__(self) -> None:
        super().__init__(CAD_EXTRA_MESSAGE)


def is_step(path: Path) -> bool:
    return Path(path).suffix.lower() in STEP_SUFFIXES


def step_length_unit(path: Path) -> str | None:
    """The SI length unit a STEP file states ("mm", "m", ...), or None when it states none that
    this recognises (an imperial unit, a file that is not STEP)."""
    with open(path, "rb") as fh:
        data = fh.read()
    found = _SI_LENGTH.search(data)
    if found is None:
        return None
    return _PREFIX_UNITS.get(found.group(1) or found.group(2))


def load_step(path: Path, tolerance_mm: float | None = None) -> trimesh.Trimesh:
    """The STEP file's solids as one triangle mesh in metres, meshed so that no triangle is more
    than `tolerance_mm` (default `DEFAULT_TOLERANCE_MM`) from the exact surface.

    Raises CadExtraMissing without cascadio; ValueError when the file holds no surface.
    """
    import trimesh

    tol = DEFAULT_TOLERANCE_MM if tolerance_mm is None else float(tolerance_mm)
    try:
        import cascadio
    except ImportError:
        raise CadExtraMissing() from None
    data = Path(path).read_bytes()
    version = getattr(cascadio, "__version__", "")
    key = hashlib.sha256(data + f"|{tol!r}|{ANGULAR_TOLERANCE_RAD!r}|{version}".encode()).hexdigest()
    cached = cache_folder("step") / f"{key}.npz"
    try:
        with np.load(cached) as stored:
            return trimesh.Trimesh(vertices=stored["vertices"], faces=stored["faces"], process=False)
    except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile):
        pass                                    # not cached yet, or unreadable: tessellate again
    with tempfile.TemporaryDirectory() as folder:
        glb = Path(folder) / "part.glb"
        log = Path(folder) / "opencascade.log"
        # cascadio reads from a path; the file is read as given (its bytes hashed above).
        with _c_output_to(log):
            cascadio.step_to_glb(str(path), str(glb), tol_linear=tol, tol_angular=ANGULAR_TOLERANCE_RAD,
                                 tol_relative=False)
        if not glb.is_file():
            said = _first_message(log)
            raise ValueError("OpenCASCADE read no shape from the file (not a STEP file, or it holds no solid)"
                             + (f": {said}" if said else ""))
        loaded = trimesh.load(str(glb), force="mesh", process=False)
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise ValueError("the STEP file holds no surface to mesh")
    vertices = np.asarray(loaded.vertices, dtype=float)
    faces = np.asarray(loaded.faces, dtype=np.int64)
    store_arrays(cached, {"vertices": vertices, "faces": faces})
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False)


@contextlib.contextmanager
def _c_output_to(log: Path) -> Iterator[None]:
    """OpenCASCADE's own messages (a STEP syntax error on stdout, "Failed to transfer" on stderr)
    written to `log` instead of the terminal: they would break `--json` output on stdout and come
    without the file and key a message of robomax names. Redirects the process's file descriptors
    1 and 2 for the duration."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(log, "wb") as sink:
            os.dup2(sink.fileno(), 1)
            os.dup2(sink.fileno(), 2)
            yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved:
            os.close(fd)


_ANSI = re.compile(r"\x1b\[[0-9;]*m")


def _first_message(log: Path) -> str:
    """OpenCASCADE's first message in `log`, without colour codes and its `****` frame."""
    try:
        text = log.read_text(errors="replace")
    except OSError:
        return ""
    for line in _ANSI.sub("", text).splitlines():
        line = line.strip(" *\t")
        if line:
            return line
    return ""
