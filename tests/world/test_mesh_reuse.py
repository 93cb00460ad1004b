"""A cell's mesh split into collision pieces once per process while its file is unchanged: the same
pieces for a second scene, new ones (the new shape) once the file is rewritten."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
import trimesh

from robomax_py.errors import CellFileError
from robomax_py.world import scene


def _extent(pieces: tuple[object, ...]) -> np.ndarray:
    points = np.vstack([np.asarray(p.points()) for p in pieces])  # type: ignore[attr-defined]
    return np.ptp(points, axis=0)


def test_unchanged_file_reused_rewritten_file_read_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(scene, "_MESH_PIECES", {})
    path = tmp_path / "block.stl"
    trimesh.creation.box((0.2, 0.3, 0.4)).export(path)
    first, kind = scene._mesh_pieces(path, CellFileError, tmp_path / "cell.yaml", "objects[0].mesh")
    assert kind == scene.REPRESENTATION_CONVEX
    np.testing.assert_allclose(_extent(first), [0.2, 0.3, 0.4], atol=1e-9)
    again, _ = scene._mesh_pieces(path, CellFileError, tmp_path / "cell.yaml", "objects[0].mesh")
    assert again is first
    trimesh.creation.box((0.5, 0.3, 0.4)).export(path)
    st = path.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))     # a coarse clock's same-second rewrite
    new, _ = scene._mesh_pieces(path, CellFileError, tmp_path / "cell.yaml", "objects[0].mesh")
    np.testing.assert_allclose(_extent(new), [0.5, 0.3, 0.4], atol=1e-9)
