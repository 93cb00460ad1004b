"""What a run needs of a mesh file kept in the cache folder: the same arrays read back, a changed
file or parameter computed again, a failure never kept; the collision pieces and link hulls built
from kept arrays are the ones built from the mesh; a cell loaded again imports no trimesh."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

from robomax_py.errors import CellFileError
from robomax_py.robot.geometry import (
    collision_piece_arrays,
    collision_shapes_of,
    load_mesh,
    mesh_collision_shapes,
)
from robomax_py.robot.mesh_cache import kept_arrays
from robomax_py.world import scene

REPO = Path(__file__).resolve().parents[2]
PANEL = REPO / "tests" / "data" / "reference" / "parts" / "cabin_panel.stl"


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv("ROBOMAX_CACHE", str(folder))
    return folder


def _counted(calls: list[int], value: float) -> dict[str, np.ndarray]:
    calls.append(1)
    return {"a": np.array([value, 1.0 / 3.0]), "b": np.arange(4, dtype=np.int64)}


def test_kept_arrays_are_read_back_bit_for_bit(cache: Path, tmp_path: Path) -> None:
    mesh = tmp_path / "m.stl"
    mesh.write_bytes(b"solid x\nendsolid x\n")
    calls: list[int] = []
    first = kept_arrays("test", mesh, ("p", 1.0), lambda: _counted(calls, np.pi))
    again = kept_arrays("test", mesh, ("p", 1.0), lambda: _counted(calls, np.e))
    assert len(calls) == 1
    assert sorted(again) == ["a", "b"]
    for name in first:
        assert again[name].dtype == first[name].dtype
        assert again[name].tobytes() == first[name].tobytes()


def test_another_content_or_parameter_is_computed_again(cache: Path, tmp_path: Path) -> None:
    mesh = tmp_path / "m.stl"
    mesh.write_bytes(b"one")
    calls: list[int] = []
    kept_arrays("test", mesh, ("p", 1.0), lambda: _counted(calls, 1.0))
    kept_arrays("test", mesh, ("p", 2.0), lambda: _counted(calls, 2.0))
    mesh.write_bytes(b"a longer one")      # another size: a same-size rewrite in one clock tick looks unchanged
    got = kept_arrays("test", mesh, ("p", 1.0), lambda: _counted(calls, 3.0))
    assert len(calls) == 3
    assert got["a"][0] == 3.0


def test_a_failure_is_never_kept(cache: Path, tmp_path: Path) -> None:
    mesh = tmp_path / "m.stl"
    mesh.write_bytes(b"not a mesh")

    def fails() -> dict[str, np.ndarray]:
        raise ValueError("cannot read")

    for _ in range(2):
        with pytest.raises(ValueError, match="cannot read"):
            kept_arrays("test", mesh, (), fails)
    assert not list(cache.rglob("*.npz"))


def test_an_unwritable_cache_still_computes(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("ROBOMAX_CACHE", str(blocker))
    mesh = tmp_path / "m.stl"
    mesh.write_bytes(b"x")
    calls: list[int] = []
    for _ in range(2):
        assert kept_arrays("test", mesh, (), lambda: _counted(calls, 1.0))["a"][0] == 1.0
    assert len(calls) == 2


def _points(pieces: object) -> list[np.ndarray]:
    return [np.asarray(p.points()) if hasattr(p, "points") else np.asarray(p.vertices())  # type: ignore[attr-defined]
            for p in pieces]  # type: ignore[attr-defined]


@pytest.mark.parametrize("make", [lambda p: trimesh.util.concatenate([trimesh.creation.box((0.2, 0.3, 0.4)),
                                                                       trimesh.creation.icosphere(radius=0.1)
                                                                       .apply_translation((1, 0, 0))]).export(p),
                                  lambda p: p.write_bytes(PANEL.read_bytes())],
                         ids=["convex pieces", "open sheet (BVH)"])
def test_collision_pieces_from_kept_arrays_are_the_mesh_s(cache: Path, tmp_path: Path, make: object,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "part.stl"
    make(path)  # type: ignore[operator]
    direct = mesh_collision_shapes(load_mesh(path))
    monkeypatch.setattr(scene, "_MESH_PIECES", {})
    built, kind = scene._mesh_pieces(path, CellFileError, None, None)
    assert list(cache.rglob("pieces-*.npz"))
    monkeypatch.setattr(scene, "_MESH_PIECES", {})
    kept, kept_kind = scene._mesh_pieces(path, CellFileError, None, None)
    assert kind == kept_kind
    assert [type(p) for p in direct] == [type(p) for p in built] == [type(p) for p in kept]
    for a, b, c in zip(_points(direct), _points(built), _points(kept), strict=True):
        assert a.tobytes() == b.tobytes() == c.tobytes()
    arrays = collision_piece_arrays(load_mesh(path))
    assert len(collision_shapes_of(arrays)) == len(direct)


def test_a_cell_loaded_again_imports_no_trimesh(cache: Path) -> None:
    script = ("import sys\n"
              "from robomax_py.io.cell import load_cell, load_cell_robot\n"
              "from robomax_py.world.scene import build_scene\n"
              f"cell = load_cell({str(REPO / 'tests/data/reference/cabin_flange.yaml')!r})\n"
              "build_scene(cell, load_cell_robot(cell))\n"
              "print('trimesh' in sys.modules)\n")
    env = {**os.environ, "ROBOMAX_CACHE": str(cache), "PYTHONPATH": str(REPO)}
    runs = [subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, check=True,
                           cwd=REPO).stdout.strip() for _ in range(2)]
    assert runs == ["True", "False"]
