"""A mesh file is parsed once per process while it is unchanged, each caller getting a mesh of its
own; a mesh with an open piece becomes one exact BVH without being split, and every mesh gets the
collision pieces the definition gives ("convex pieces when the mesh is a set of closed convex
shells, else one exact BVH"), computed here from that definition piece by piece."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.robot import geometry
from robomax_py.robot.geometry import collision_piece_arrays, load_mesh


@pytest.fixture
def parses(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """An empty parse table, and the files trimesh parsed, as they happen."""
    geometry._parsed_mesh.cache_clear()
    seen: list[str] = []
    load = trimesh.load

    def counted(path, *args, **kwargs):  # type: ignore[no-untyped-def]
        seen.append(str(path))
        return load(path, *args, **kwargs)

    monkeypatch.setattr(trimesh, "load", counted)
    return seen


def test_a_mesh_is_parsed_once_and_each_caller_gets_its_own(tmp_path: Path, parses: list[str]) -> None:
    path = tmp_path / "box.stl"
    trimesh.creation.box(extents=[0.1, 0.2, 0.3]).export(path)
    first = load_mesh(path)
    first.apply_translation([5.0, 0.0, 0.0])                   # a caller moving its copy
    second = load_mesh(path)
    assert parses == [str(path.resolve())]
    assert np.allclose(second.bounds, [[-0.05, -0.1, -0.15], [0.05, 0.1, 0.15]])
    scaled = load_mesh(path, np.array([2.0, 2.0, 2.0]))         # another scale: its own entry
    assert np.allclose(scaled.extents, [0.2, 0.4, 0.6])
    assert len(parses) == 2


def test_a_rewritten_mesh_is_read_again(tmp_path: Path, parses: list[str]) -> None:
    path = tmp_path / "part.stl"
    trimesh.creation.box(extents=[0.1, 0.1, 0.1]).export(path)
    assert np.allclose(load_mesh(path).extents, 0.1)
    trimesh.creation.box(extents=[0.4, 0.1, 0.1]).export(path)
    os.utime(path, ns=(1, 1))                                  # a new stamp, whatever the clock's grain
    assert np.allclose(load_mesh(path).extents, [0.4, 0.1, 0.1])
    assert len(parses) == 2


def test_a_failed_read_is_not_kept(tmp_path: Path, parses: list[str]) -> None:
    path = tmp_path / "empty.stl"
    path.write_bytes(b"")
    for _ in range(2):
        with pytest.raises(ValueError):
            load_mesh(path)
    trimesh.creation.box(extents=[0.1, 0.1, 0.1]).export(path)
    assert len(load_mesh(path).faces) == 12


def test_splitting_stops_at_the_first_open_piece(monkeypatch: pytest.MonkeyPatch) -> None:
    # A soup of 40 flat patches of two triangles, like a tessellated CAD part's faces: one piece
    # is built.
    patch = trimesh.Trimesh([[0, 0, 0], [0.1, 0, 0], [0.1, 0.1, 0], [0, 0.1, 0]], [[0, 1, 2], [0, 2, 3]], process=False)
    soup = trimesh.util.concatenate([patch.copy().apply_translation([float(i), 0.0, 0.0]) for i in range(40)])
    built: list[int] = []
    submesh = trimesh.Trimesh.submesh

    def counted(self, faces, *args, **kwargs):  # type: ignore[no-untyped-def]
        built.append(len(faces))
        return submesh(self, faces, *args, **kwargs)

    monkeypatch.setattr(trimesh.Trimesh, "submesh", counted)
    arrays = collision_piece_arrays(soup)
    assert sorted(arrays) == ["faces", "vertices"]
    assert len(arrays["faces"]) == 40 * 2
    assert built == [1]


def _pieces_by_definition(mesh: trimesh.Trimesh) -> list[trimesh.Trimesh] | None:
    """The closed convex shells of `mesh` (each piece of trimesh's `split`, which fills holes of a
    triangle or a quad, closed and its volume its hull's), None when some piece is not one: all
    pieces split first, then judged."""
    pieces = mesh.split(only_watertight=False)
    for p in pieces:
        if not p.is_watertight or p.volume <= 0:
            return None
        if abs(p.convex_hull.volume - p.volume) > geometry.CONVEX_VOLUME_RTOL * p.convex_hull.volume + 1e-12:
            return None
    return list(pieces)


_SHAPES = st.sampled_from(["box", "box with a quad hole", "open box", "sphere", "ring"])


def _shape(kind: str, at: float) -> trimesh.Trimesh:
    if kind == "sphere":
        made = trimesh.creation.icosphere(subdivisions=1, radius=0.2)
    elif kind == "ring":                                        # closed, not convex
        made = trimesh.creation.annulus(r_min=0.1, r_max=0.2, height=0.1)
    else:
        made = trimesh.creation.box(extents=[0.2, 0.3, 0.1])
        if kind != "box":                                       # two triangles out, or four
            made = trimesh.Trimesh(made.vertices, made.faces[:-2 if kind == "box with a quad hole" else -4],
                                   process=False)
    return made.apply_translation([at, 0.0, 0.0])


@settings(max_examples=40, deadline=None)
@given(st.lists(_SHAPES, min_size=1, max_size=5))
def test_collision_pieces_are_the_definition_s(kinds: list[str]) -> None:
    # Shapes 1 m apart, so no edge joins two of them.
    mesh = trimesh.util.concatenate([_shape(k, float(i)) for i, k in enumerate(kinds)])
    arrays = collision_piece_arrays(mesh)
    expected = _pieces_by_definition(mesh)
    if expected is None:
        assert sorted(arrays) == ["faces", "vertices"]
        assert np.array_equal(arrays["faces"], mesh.faces)
        assert np.array_equal(arrays["vertices"], mesh.vertices)
    else:
        assert len(arrays) == len(expected)
        for i, piece in enumerate(expected):
            hull = trimesh.convex.convex_hull(arrays[f"hull_{i}"])
            assert np.isclose(hull.volume, piece.convex_hull.volume, rtol=1e-9)
