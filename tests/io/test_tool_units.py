"""Tool meshes take the keys cell meshes take (docs/cad.md, "Tool meshes"): a gun exported in
millimetres with `units: mm` is the same collision geometry, and collides the same, as the gun in
metres; a STEP body is meshed at its `tolerance`; a gun read 1000 times too large (or too small) is
named with a warning; keys that do not fit are refused naming the tool.yaml and the key."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, app
from robomax_py.errors import RobotModelError
from robomax_py.io.cell import load_cell
from robomax_py.io.robot import load_tool_spec, shipped_robots_dir
from robomax_py.plan.pipeline import plan_cell
from robomax_py.robot import load_robot, mount_tool
from robomax_py.spec import CellSpec
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import REPRESENTATION_BVH, Scene, build_scene

runner = CliRunner()

GUN = shipped_robots_dir() / "tools" / "spot_gun_c"
TCP = {"xyz": [0.2, 0, 0.27], "rpy": [-90, 0, -90]}       # spot_gun_c's, as its tool.yaml gives it
# An STL holds float32 coordinates: the gun's 0.6 m are exact to about 3e-8 m in metres and to
# 3e-5 mm in millimetres, so the two read within this (m) of each other.
SAME_M = 1e-6
# coal's GJK stops within about 1e-6 of a distance, relative: two guns SAME_M apart may differ by
# that much more (2.4e-6 m measured at 2.4 m).
GJK_RTOL = 1e-5
# The two plans are the same motion: sample times (s) and joint values (rad) within these (they
# came out bit-identical on the development machine).
SAME_PLAN_S = 1e-6
SAME_PLAN_RAD = 1e-6
# Configurations compared between the two guns (uniform within the joint limits, seeded).
SAMPLES = 60
# tests/data/cad/block.step (made by make_block.py): 100 x 60 x 20 mm, its flat faces exact.
BLOCK_M = (0.1, 0.06, 0.02)


def _tool(folder: Path, text: dict[str, Any], meshes: dict[str, Path]) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name, source in meshes.items():
        shutil.copy(source, folder / name)
    path = folder / "tool.yaml"
    path.write_text(yaml.safe_dump(text, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def gun_in_mm(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """spot_gun_c's two meshes written in millimetres (as a CAD export writes them), in a folder."""
    folder = tmp_path_factory.mktemp("gun_mm")
    for part in ("body", "tips"):
        mesh = trimesh.load(GUN / f"{part}.stl", force="mesh")
        mesh.apply_scale(1000.0)
        mesh.export(folder / f"{part}_mm.stl")
    return folder


def _cell_with_tool(folder: Path, write_small_cell: Any, tool: str) -> Path:
    path: Path = write_small_cell(folder)
    data = yaml.safe_load(path.read_text())
    data["tool"] = tool
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _piece_boxes(pieces: tuple[Any, ...]) -> np.ndarray:
    """(n, 6) float, m: each collision piece's bounding box (min, max) in the flange frame, sorted."""
    boxes = np.array([[*np.asarray(p.aabb_local.min_), *np.asarray(p.aabb_local.max_)] for p in pieces])
    return boxes[np.lexsort(boxes.T[::-1])]


def _world(cell: CellSpec) -> tuple[CollisionWorld, Scene]:
    robot = load_robot(cell.robot)
    scene = build_scene(cell, robot)
    return CollisionWorld(robot, scene, cell.process.clearance), scene


def test_a_gun_in_millimetres_collides_as_the_gun_in_metres(tmp_path: Path, gun_in_mm: Path,
                                                           write_small_cell: Any) -> None:
    _tool(tmp_path / "gun_mm", {"name": "gun_mm", "body": "body_mm.stl", "tips": "tips_mm.stl", "units": "mm",
                                "tcp": TCP}, {n: gun_in_mm / n for n in ("body_mm.stl", "tips_mm.stl")})
    metres = load_cell(_cell_with_tool(tmp_path / "m", write_small_cell, "spot_gun_c"))
    mm = load_cell(_cell_with_tool(tmp_path / "mm", write_small_cell, "../gun_mm/tool.yaml"))
    # The same warnings (the small cell's zero clearance), none about the tool.
    assert [(n.key, n.message) for n in mm.notices] == [(n.key, n.message) for n in metres.notices]
    assert not any(n.file.endswith("tool.yaml") for n in mm.notices)
    world_m, scene_m = _world(metres)
    world_mm, scene_mm = _world(mm)
    for part in ("body", "tips"):
        got, want = _piece_boxes(getattr(scene_mm.tool, part)), _piece_boxes(getattr(scene_m.tool, part))
        assert got.shape == want.shape
        np.testing.assert_allclose(got, want, rtol=0, atol=SAME_M)
        assert float(np.ptp(want[:, 3:] - want[:, :3])) > 0.01        # a real gun: pieces of some size
    # The same pairs are checked, at the same distances, over configurations across the joint range.
    pairs = np.arange(world_m.n_pairs)
    assert world_mm.n_pairs == world_m.n_pairs
    assert [world_mm.pair_names(int(p)) for p in pairs] == [world_m.pair_names(int(p)) for p in pairs]
    tool_pairs = np.array([p for p in pairs if "tool" in world_m.pair_names(int(p)).kind_a + world_m.pair_names(
        int(p)).kind_b])
    assert len(tool_pairs) > 0
    robot = load_robot(metres.robot)
    rng = np.random.default_rng(7)
    qs = rng.uniform(np.asarray(robot.limits.lower), np.asarray(robot.limits.upper), size=(SAMPLES, robot.model.nq))
    verdicts = set()
    for q in qs:
        np.testing.assert_allclose(world_mm.pair_distances(q, tool_pairs), world_m.pair_distances(q, tool_pairs),
                                   rtol=GJK_RTOL, atol=SAME_M)
        verdicts.add(world_m.is_free(q))
        if abs(world_m.distance(q)) > SAME_M:
            assert world_mm.is_free(q) == world_m.is_free(q)
    assert verdicts == {True, False}                                  # both outcomes were compared


def test_a_gun_in_millimetres_plans_as_the_gun_in_metres(tmp_path: Path, gun_in_mm: Path,
                                                         write_small_cell: Any) -> None:
    _tool(tmp_path / "gun_mm", {"name": "gun_mm", "body": "body_mm.stl", "tips": "tips_mm.stl", "units": "mm",
                                "tcp": TCP}, {n: gun_in_mm / n for n in ("body_mm.stl", "tips_mm.stl")})
    plans = []
    for folder, tool in (("m", "spot_gun_c"), ("mm", "../gun_mm/tool.yaml")):
        cell = load_cell(_cell_with_tool(tmp_path / folder, write_small_cell, tool))
        plans.append(plan_cell(cell, mount_tool(load_robot(cell.robot), cell.tool.T_flange_tcp)))
    metres, mm = plans
    assert metres.status == mm.status == "planned"
    assert [(s.seam, s.name) for s in mm.spots] == [(s.seam, s.name) for s in metres.spots]
    assert metres.trajectory is not None and mm.trajectory is not None
    np.testing.assert_allclose(mm.trajectory.t, metres.trajectory.t, rtol=0, atol=SAME_PLAN_S)
    np.testing.assert_allclose(mm.trajectory.q, metres.trajectory.q, rtol=0, atol=SAME_PLAN_RAD)
    assert metres.clearance is not None and mm.clearance is not None
    assert mm.clearance.between == metres.clearance.between
    assert mm.clearance.distance_m == pytest.approx(metres.clearance.distance_m, rel=GJK_RTOL, abs=SAME_M)


def test_a_gun_of_one_non_convex_mesh_builds_a_collision_world(tmp_path: Path, write_small_cell: Any) -> None:
    """A CAD gun is mostly one non-convex mesh, kept as an exact triangle BVH: the collision world
    (its self-pair analysis, cached by the pieces' geometry) takes it."""
    ring = trimesh.creation.annulus(r_min=0.03, r_max=0.06, height=0.1).apply_translation([0, 0, 0.1])
    ring.apply_scale(1000.0)
    ring.export(tmp_path / "ring_mm.stl")
    _tool(tmp_path / "gun", {"name": "g", "body": "ring_mm.stl", "tips": "tips.stl", "units": "mm", "tcp": TCP},
          {"ring_mm.stl": tmp_path / "ring_mm.stl", "tips.stl": GUN / "tips.stl"})
    cell = load_cell(_cell_with_tool(tmp_path / "c", write_small_cell, "../gun/tool.yaml"))
    world, scene = _world(cell)
    assert scene.tool.body_representation == REPRESENTATION_BVH
    boxes = _piece_boxes(scene.tool.body)
    np.testing.assert_allclose(boxes[0], [-0.06, -0.06, 0.05, 0.06, 0.06, 0.15], rtol=0, atol=SAME_M)
    assert world.n_pairs > 0


def test_the_mapping_form_and_scale(tmp_path: Path, gun_in_mm: Path) -> None:
    """A mesh given as {mesh, units, scale} overrides the top-level keys for that mesh alone."""
    path = _tool(tmp_path, {"name": "g", "units": "mm",
                            "body": {"mesh": "body.stl", "units": "m", "scale": [1, 1, 2]},
                            "tips": "tips_mm.stl"},
                 {"body.stl": GUN / "body.stl", "tips_mm.stl": gun_in_mm / "tips_mm.stl"})
    tool = load_tool_spec(path)
    assert tool.body.scale == (1.0, 1.0, 2.0)
    assert tool.tips.scale == (0.001, 0.001, 0.001)
    assert tool.body.path == tmp_path / "body.stl" and tool.body.tolerance is None


def test_a_gun_read_1000_times_too_large_or_small_is_named(tmp_path: Path, gun_in_mm: Path,
                                                          write_small_cell: Any) -> None:
    _tool(tmp_path / "big", {"name": "big", "body": "body_mm.stl", "tips": "tips_mm.stl", "tcp": TCP},
          {n: gun_in_mm / n for n in ("body_mm.stl", "tips_mm.stl")})
    _tool(tmp_path / "small", {"name": "small", "body": "body.stl", "tips": "tips.stl", "units": "mm", "tcp": TCP},
          {n: GUN / n for n in ("body.stl", "tips.stl")})
    big = load_cell(_cell_with_tool(tmp_path / "c1", write_small_cell, "../big/tool.yaml")).notices
    big = tuple(n for n in big if n.key != "process.clearance")     # the small cell's own warning
    assert [(n.file, n.key) for n in big] == [(str(tmp_path / "big" / "tool.yaml"), "body")]
    assert "write `units: mm`" in big[0].message and "also 1 more" in big[0].message and "tips" in big[0].message
    small = tuple(n for n in load_cell(_cell_with_tool(tmp_path / "c2", write_small_cell, "../small/tool.yaml")).notices
                  if n.key != "process.clearance")
    assert [n.key for n in small] == ["body"]
    assert "`units: mm` given to a mesh drawn in metres?" in small[0].message


def test_a_step_gun_body_is_meshed_at_its_tolerance(tmp_path: Path, write_small_cell: Any,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("cascadio")
    monkeypatch.setenv("ROBOMAX_CACHE", str(tmp_path / "cache"))
    block = Path(__file__).resolve().parents[1] / "data" / "cad" / "block.step"
    path = _tool(tmp_path / "gun", {"name": "g", "body": {"mesh": "block.step", "tolerance": 0.2},
                                    "tips": "tips.stl", "tcp": TCP}, {"block.step": block, "tips.stl": GUN / "tips.stl"})
    tool = load_tool_spec(path)
    assert tool.body.scale == (1.0, 1.0, 1.0)
    assert tool.body.tolerance == pytest.approx(0.2e-3, rel=1e-12)   # mm: the unit the STEP states
    cell = load_cell(_cell_with_tool(tmp_path / "c", write_small_cell, "../gun/tool.yaml"))
    _, scene = _world(cell)
    boxes = _piece_boxes(scene.tool.body)
    extents = boxes[:, 3:].max(axis=0) - boxes[:, :3].min(axis=0)
    np.testing.assert_allclose(extents, BLOCK_M, rtol=0, atol=SAME_M)
    # For a STEP, units says what the tolerance is written in and must be the unit the file states.
    data = yaml.safe_load(path.read_text())
    data["units"] = "m"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(RobotModelError) as err:
        load_tool_spec(path)
    assert (err.value.file, err.value.key) == (str(path), "units")
    assert "block.step states its lengths in mm" in err.value.problem


@pytest.mark.parametrize(("keys", "key", "problem"), [
    ({"units": "cm"}, "units", "input should be 'm' or 'mm'"),
    ({"scale": -1}, "scale", "greater than 0"),
    ({"scale": [1, 2]}, "scale", "at least 3 items"),
    ({"tolerance": 0.1}, "tolerance", "body.stl is already triangles"),
    ({"tolerance": 0}, "tolerance", "greater than 0"),
    ({"unit": "mm"}, "unit", "did you mean 'units'?"),
    ({"body": {"mesh": "body.stl", "unit": "mm"}}, "body.unit", "did you mean 'units'?"),
    ({"body": {"mesh": "body.stl", "units": "inch"}}, "body.units", "input should be 'm' or 'mm'"),
    ({"body": {"units": "mm"}}, "body.mesh", "required key is missing"),
    ({"tips": {"mesh": "tips.stl", "tolerance": 0.1}}, "tips.tolerance", "tips.stl is already triangles"),
    ({"tips": {"mesh": "gone.stl"}}, "tips.mesh", "not found"),
    ({"body": 3}, "body", "valid string"),
])
def test_tool_mesh_keys_that_do_not_fit_are_refused(tmp_path: Path, keys: dict[str, Any], key: str,
                                                   problem: str) -> None:
    path = _tool(tmp_path, {"name": "g", "body": "body.stl", "tips": "tips.stl", **keys},
                 {n: GUN / n for n in ("body.stl", "tips.stl")})
    with pytest.raises(RobotModelError) as err:
        load_tool_spec(path)
    assert (err.value.file, err.value.key) == (str(path), key)
    assert problem in err.value.problem


def test_check_names_the_tool_file_and_key(tmp_path: Path, write_small_cell: Any) -> None:
    tool = _tool(tmp_path / "gun", {"name": "g", "body": "body.stl", "tips": "tips.stl", "units": "inch"},
                 {n: GUN / n for n in ("body.stl", "tips.stl")})
    cell = _cell_with_tool(tmp_path / "c", write_small_cell, "../gun/tool.yaml")
    done = runner.invoke(app, ["check", str(cell)])
    assert done.exit_code == EXIT_BAD_INPUT
    assert f"{tool}: units: input should be 'm' or 'mm', got 'inch'" in done.output
    assert "Traceback" not in done.output


def test_a_tool_mesh_that_does_not_read_is_named_by_its_path(tmp_path: Path, write_small_cell: Any) -> None:
    """A tool body that is not a mesh: the message names the file's path (not the program's own
    record of the mesh) and the key."""
    broken = tmp_path / "broken.stl"
    broken.write_text("solid broken\n  this is not an STL facet\nendsolid broken\n")
    tool = _tool(tmp_path / "gun", {"name": "g", "body": "body.stl", "tips": "tips.stl"},
                 {"body.stl": broken, "tips.stl": GUN / "tips.stl"})
    cell = _cell_with_tool(tmp_path / "c", write_small_cell, "../gun/tool.yaml")
    done = runner.invoke(app, ["check", str(cell)])
    said = " ".join(done.output.split())
    assert done.exit_code == EXIT_BAD_INPUT and "Traceback" not in done.output
    assert f"{tool}: body: cannot read mesh {tool.parent / 'body.stl'}" in said and "MeshShape(" not in said


def test_a_tcp_in_millimetres_is_refused_with_its_metres(tmp_path: Path) -> None:
    # tcp.xyz is metres even where the meshes are millimetres: a TCP 336 m from the flange was taken
    # as given, and every spot came out "out of reach by 332 m".
    text = {"name": "gun_mm", "body": "body.stl", "tips": "tips.stl", "units": "mm",
            "tcp": {"xyz": [200, 0, 270], "rpy": [-90, 0, -90]}}
    path = _tool(tmp_path / "gun_mm", text, {"body.stl": GUN / "body.stl", "tips.stl": GUN / "tips.stl"})
    with pytest.raises(RobotModelError, match=r"tool\.yaml: tcp\.xyz: \[200\.0, 0\.0, 270\.0\] puts the TCP 336\.006 m "
                                              r"from the flange.*in mm\? \[0\.2, 0\.0, 0\.27\]"):
        load_tool_spec(path)
    text["tcp"] = {"xyz": [0, 0, 4.9], "rpy": [0, 0, 0]}                     # long, but a tool's
    assert load_tool_spec(_tool(tmp_path / "long", text, {"body.stl": GUN / "body.stl",
                                                          "tips.stl": GUN / "tips.stl"})).T_flange_tcp[2, 3] == 4.9
