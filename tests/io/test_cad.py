"""CAD parts and mesh units (docs/cad.md): a STEP file made by the project's own script with
build123d (OpenCASCADE; tests/data/cad/make_block.py, its output committed so the tests need no CAD
kernel beyond cascadio), in millimetres, read through a cell with `units: mm`; its mesh checked against the exact solid it was
made from; an STL in millimetres read with `units: mm` equals the same STL in metres; no cascadio
gives one clear message."""

from __future__ import annotations

import builtins
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import app
from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell
from robomax_py.robot import cad
from robomax_py.robot.geometry import mesh_shape_trimesh
from robomax_py.spec import MeshShape

runner = CliRunner()

# The test part, mm: a block LENGTH x WIDTH x HEIGHT centred on its origin with a through hole of
# radius HOLE_R along z.
LENGTH, WIDTH, HEIGHT, HOLE_R = 100.0, 60.0, 20.0, 15.0
# glTF stores float32 coordinates: 0.05 m is exact to about 4e-9 m; a vertex of the mesh lies on the
# exact surface within this (m).
VERTEX_ON_SURFACE_M = 1e-6
# Where the part stands in the reference cell: on the table, clear of the panel and the clamps.
PART_XYZ = [1.85, -0.8, 0.631]


@pytest.fixture(scope="module")
def step_part(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The test part as a STEP file in millimetres (tests/data/cad/block.step, written by
    make_block.py from the dimensions above), copied so a test may not change the original."""
    path = tmp_path_factory.mktemp("cad") / "block.step"
    shutil.copy(Path(__file__).resolve().parents[1] / "data" / "cad" / "block.step", path)
    return path


@pytest.fixture(autouse=True)
def _own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each test tessellates afresh into its own cache folder."""
    monkeypatch.setenv("ROBOMAX_CACHE", str(tmp_path / "cache"))


def surface_distance_m(points: np.ndarray) -> np.ndarray:
    """Distance (m) of points (m) to the surface of the exact test part: |signed distance| of the
    block minus the (infinite) cylinder of the hole."""
    half = np.array([LENGTH, WIDTH, HEIGHT]) / 2000.0
    q = np.abs(points) - half
    box = np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
    hole = HOLE_R / 1000.0 - np.hypot(points[:, 0], points[:, 1])   # > 0 inside the hole's cylinder
    return np.asarray(np.abs(np.maximum(box, hole)))


def cell_with(tmp_path: Path, reference: Path, obj: dict[str, Any], extra: dict[str, Path] | None = None) -> Path:
    """The reference cell with one more object; `extra` files copied beside it by name."""
    shutil.copytree(reference.parent / "parts", tmp_path / "parts")
    for name, source in (extra or {}).items():
        shutil.copy(source, tmp_path / "parts" / name)
    data = yaml.safe_load(reference.read_text())
    data["objects"].append(obj)
    path = tmp_path / "cell.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_step_read_through_a_cell_matches_the_solid(tmp_path: Path, step_part: Path,
                                                    reference_cell_path: Path) -> None:
    pytest.importorskip("cascadio")
    tolerance_mm = 0.2
    path = cell_with(tmp_path, reference_cell_path,
                     {"name": "block", "mesh": "parts/block.step", "units": "mm", "tolerance": tolerance_mm,
                      "pose": {"xyz": PART_XYZ}}, {"block.step": step_part})
    cell = load_cell(path)
    block = next(o for o in cell.objects if o.name == "block")
    assert isinstance(block.shape, MeshShape)
    assert block.shape.tolerance == pytest.approx(tolerance_mm / 1000.0)
    mesh = mesh_shape_trimesh(block.shape)
    # Bounding box: the block's own, in metres (its flat faces are meshed exactly).
    np.testing.assert_allclose(mesh.bounds, [[-0.05, -0.03, -0.01], [0.05, 0.03, 0.01]], atol=VERTEX_ON_SURFACE_M)
    assert mesh.is_watertight
    # Every vertex lies on the exact surface; every point of every triangle within the tolerance.
    assert surface_distance_m(np.asarray(mesh.vertices)).max() < VERTEX_ON_SURFACE_M
    samples, _ = trimesh.sample.sample_surface_even(mesh, 20000, seed=0)
    edge_midpoints = np.asarray(mesh.vertices)[mesh.edges_unique].mean(axis=1)
    worst = surface_distance_m(np.vstack([samples, edge_midpoints])).max()
    assert worst <= tolerance_mm / 1000.0
    # The hole is meshed (not capped): its chord midpoints are off the cylinder by the sagitta.
    assert worst > 0.0
    # Its volume: the block less the hole, within what the tessellation takes off the hole.
    exact = (LENGTH * WIDTH * HEIGHT - np.pi * HOLE_R**2 * HEIGHT) / 1e9
    assert mesh.volume == pytest.approx(exact, abs=2 * np.pi * HOLE_R / 1000 * HEIGHT / 1000 * tolerance_mm / 1000)

    result = runner.invoke(app, ["check", str(path)])
    assert result.exit_code == 0, result.output
    assert "objects[9]" not in result.output, result.output


def test_step_is_tessellated_once_per_tolerance(tmp_path: Path, step_part: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    cascadio = pytest.importorskip("cascadio")
    calls: list[float] = []
    real = cascadio.step_to_glb

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls.append(kwargs["tol_linear"])
        return real(*args, **kwargs)

    monkeypatch.setattr(cascadio, "step_to_glb", counted)
    fine = cad.load_step(step_part, 0.1)
    again = cad.load_step(step_part, 0.1)
    coarse = cad.load_step(step_part, 1.0)
    assert calls == [0.1, 1.0]
    np.testing.assert_array_equal(fine.faces, again.faces)
    assert len(coarse.faces) < len(fine.faces)


def test_step_units_are_the_files_own(tmp_path: Path, step_part: Path, reference_cell_path: Path) -> None:
    assert cad.step_length_unit(step_part) == "mm"
    path = cell_with(tmp_path, reference_cell_path,
                     {"name": "block", "mesh": "parts/block.step", "units": "m", "pose": {"xyz": PART_XYZ}},
                     {"block.step": step_part})
    with pytest.raises(CellFileError, match=r"objects\[9\]\.units: block\.step states its lengths in mm"):
        load_cell(path)


def test_stl_in_millimetres_equals_the_stl_in_metres(tmp_path: Path, reference_cell_path: Path) -> None:
    metres = trimesh.creation.annulus(r_min=0.015, r_max=0.04, height=0.02)
    millimetres = metres.copy()
    millimetres.apply_scale(1000.0)
    folder = tmp_path / "files"
    folder.mkdir()
    metres.export(folder / "ring_m.stl")
    millimetres.export(folder / "ring_mm.stl")
    path = cell_with(tmp_path, reference_cell_path,
                     {"name": "ring", "mesh": "parts/ring_mm.stl", "units": "mm", "scale": [1, 1, 2],
                      "pose": {"xyz": PART_XYZ}},
                     {"ring_m.stl": folder / "ring_m.stl", "ring_mm.stl": folder / "ring_mm.stl"})
    ring = next(o for o in load_cell(path).objects if o.name == "ring")
    assert isinstance(ring.shape, MeshShape)
    read = mesh_shape_trimesh(ring.shape)
    expected = trimesh.load(str(tmp_path / "parts" / "ring_m.stl"), force="mesh")
    expected.apply_scale([1.0, 1.0, 2.0])
    np.testing.assert_allclose(read.bounds, expected.bounds, atol=1e-9)
    np.testing.assert_allclose(np.sort(read.vertices, axis=0), np.sort(expected.vertices, axis=0), atol=1e-9)


def test_a_mesh_in_millimetres_read_as_metres_is_named(tmp_path: Path, reference_cell_path: Path) -> None:
    big = trimesh.creation.box(extents=[1200.0, 800.0, 20.0])   # a door panel written in mm
    folder = tmp_path / "files"
    folder.mkdir()
    big.export(folder / "block_mm.stl")
    path = cell_with(tmp_path, reference_cell_path,
                     {"name": "block", "mesh": "parts/block_mm.stl", "pose": {"xyz": PART_XYZ}},
                     {"block_mm.stl": folder / "block_mm.stl"})
    notices = [n for n in load_cell(path).notices if n.key == "objects[9].mesh"]
    assert len(notices) == 1 and "`units: mm`" in notices[0].message, notices


def test_mesh_keys_that_do_not_fit_are_refused(tmp_path: Path, reference_cell_path: Path) -> None:
    path = cell_with(tmp_path, reference_cell_path,
                     {"name": "plate", "box": [0.1, 0.1, 0.01], "units": "mm", "pose": {"xyz": PART_XYZ}})
    with pytest.raises(CellFileError, match=r"objects\[9\]: .*units belongs to a mesh"):
        load_cell(path)
    path = cell_with(tmp_path / "stl", reference_cell_path,
                     {"name": "panel2", "mesh": "parts/cabin_panel.stl", "tolerance": 0.1,
                      "pose": {"xyz": PART_XYZ}})
    with pytest.raises(CellFileError, match=r"objects\[9\]\.tolerance: cabin_panel\.stl is already triangles"):
        load_cell(path)
    # A scale fits neither member of its union (a number, or three): named at its own key.
    for scale, problem in ((-1, "greater than 0"), ([1, 2], "at least 3 items")):
        path = cell_with(tmp_path / f"scale{len(str(scale))}", reference_cell_path,
                         {"name": "panel2", "mesh": "parts/cabin_panel.stl", "scale": scale, "pose": {"xyz": PART_XYZ}})
        with pytest.raises(CellFileError) as err:
            load_cell(path)
        assert err.value.key == "objects[9].scale" and problem in err.value.problem, err.value


def test_a_step_that_does_not_read_is_one_message(tmp_path: Path, reference_cell_path: Path,
                                                  capfd: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("cascadio")
    folder = tmp_path / "files"
    folder.mkdir()
    (folder / "broken.step").write_text("ISO-10303-21;\nHEADER;\nnot a step file\n")
    path = cell_with(tmp_path, reference_cell_path,
                     {"name": "broken", "mesh": "parts/broken.step", "pose": {"xyz": PART_XYZ}},
                     {"broken.step": folder / "broken.step"})
    capfd.readouterr()
    with pytest.raises(CellFileError, match=r"objects\[9\]\.mesh: cannot read mesh .*broken\.step: OpenCASCADE "
                                            r"read no shape from the file"):
        load_cell(path)
    # OpenCASCADE's own messages (on the process's stdout and stderr) are kept off the terminal.
    out, err = capfd.readouterr()
    assert out == "" and err == "", (out, err)


def test_a_corrupt_cache_entry_is_made_again(tmp_path: Path, step_part: Path) -> None:
    pytest.importorskip("cascadio")
    first = cad.load_step(step_part, 0.5)
    for entry in (tmp_path / "cache" / "step").glob("*.npz"):
        entry.write_bytes(b"PK\x03\x04 not a zip")
    again = cad.load_step(step_part, 0.5)
    np.testing.assert_array_equal(first.faces, again.faces)


def test_no_cascadio_gives_the_cad_extra(tmp_path: Path, step_part: Path, reference_cell_path: Path,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    real_import = builtins.__import__

    def without_cascadio(name: str, *args: Any, **kwargs: Any) -> Any:
        if name == "cascadio":
            raise ImportError("No module named 'cascadio'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", without_cascadio)
    path = cell_with(tmp_path, reference_cell_path,
                     {"name": "block", "mesh": "parts/block.step", "units": "mm", "pose": {"xyz": PART_XYZ}},
                     {"block.step": step_part})
    with pytest.raises(CellFileError) as caught:
        load_cell(path)
    assert caught.value.key == "objects[9].mesh"
    assert "reading STEP needs the cad extra: pip install 'robomax-py[cad]'" in str(caught.value)
    result = runner.invoke(app, ["check", str(path)])
    assert result.exit_code != 0 and "robomax-py[cad]" in result.output and "Traceback" not in result.output
