"""robomax_py.world.scene: cell objects and tool -> coal geometry in the robot base frame.

Checks each shape's representation (primitive / convex pieces / exact BVH), the base-frame pose
T_base_obj = inv(T_world_base) @ T_world_object, dynamic windows, and that a missing or unreadable
mesh is reported as a located error (file, key, problem).
"""

from __future__ import annotations

from pathlib import Path

import coal
import numpy as np
import pytest
import trimesh
from numpy.testing import assert_allclose

from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.io.robot import urdf_package_dirs
from robomax_py.robot import RobotModel
from robomax_py.spec import (
    Box,
    Capsule,
    CellSpec,
    Cylinder,
    MeshShape,
    ObjectSpec,
    ProcessSpec,
    RobotSpec,
    Sphere,
    ToolSpec,
    frozen_array,
)
from robomax_py.transforms import invert, pose_matrix
from robomax_py.world.scene import (
    REPRESENTATION_BVH,
    REPRESENTATION_CONVEX,
    REPRESENTATION_PRIMITIVE,
    build_scene,
)

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"
POSE_ATOL = 1e-12  # pose products of a few 4x4 float64 matrices


# ------------------------------------------------------------------------------------ fixtures


def make_cell(
    robot: RobotModel, tool: ToolSpec, objects: tuple[ObjectSpec, ...] = (), dynamic: tuple[ObjectSpec, ...] = (),
    T_world_base: np.ndarray | None = None, source: Path = Path("cells/test.yaml"),
) -> CellSpec:
    spec = RobotSpec(robot.name, robot.source, robot.source, "tool0", "numeric", None, None, None,
                     package_dirs=urdf_package_dirs(robot.source, robot.source))
    return CellSpec(
        name="test", source=source, robot=spec,
        T_world_base=frozen_array(np.eye(4) if T_world_base is None else T_world_base),
        home=frozen_array(np.zeros(robot.dof)), tool=tool, objects=objects, seams=(),
        process=ProcessSpec(), dynamic=dynamic,
    )


def _extrude(polygon: list[tuple[float, float]], height: float) -> tuple[np.ndarray, np.ndarray]:
    """Closed prism over a simple polygon (counter-clockwise), fan-triangulated from vertex 0 (m)."""
    n = len(polygon)
    xy = np.asarray(polygon, dtype=float)
    vertices = np.vstack([np.c_[xy, np.zeros(n)], np.c_[xy, np.full(n, height)]])
    faces = []
    for i in range(n):  # walls
        j = (i + 1) % n
        faces += [[i, j, n + j], [i, n + j, n + i]]
    for i in range(1, n - 1):  # caps (the L is star-shaped from vertex 0)
        faces += [[0, i + 1, i], [n, n + i, n + i + 1]]
    return vertices, np.asarray(faces)


def obj(name: str, shape: object, xyz: list[float], rpy: list[float] | None = None, **kw: object) -> ObjectSpec:
    return ObjectSpec(name, shape, frozen_array(pose_matrix(xyz, rpy or [0.0, 0.0, 0.0])), **kw)  # type: ignore[arg-type]


# --------------------------------------------------------------------------------------- tests


def test_primitives_become_exact_coal_primitives(ur10: RobotModel, gun: ToolSpec) -> None:
    objects = (
        obj("b", Box((0.1, 0.2, 0.3)), [1, 0, 0]),
        obj("c", Cylinder(0.05, 0.4), [0, 1, 0]),
        obj("s", Sphere(0.07), [0, 0, 1]),
        obj("k", Capsule(0.03, 0.2), [1, 1, 0]),
    )
    scene = build_scene(make_cell(ur10, gun, objects), ur10)
    kinds = {o.name: (o.representation, type(o.pieces[0]).__name__, len(o.pieces)) for o in scene.obstacles}
    assert kinds == {
        "b": (REPRESENTATION_PRIMITIVE, "Box", 1),
        "c": (REPRESENTATION_PRIMITIVE, "Cylinder", 1),
        "s": (REPRESENTATION_PRIMITIVE, "Sphere", 1),
        "k": (REPRESENTATION_PRIMITIVE, "Capsule", 1),
    }
    box, cyl, sph, cap = (o.pieces[0] for o in scene.obstacles)
    assert_allclose(box.halfSide, [0.05, 0.1, 0.15])
    assert (cyl.radius, cyl.halfLength) == pytest.approx((0.05, 0.2))
    assert sph.radius == pytest.approx(0.07)
    assert (cap.radius, cap.halfLength) == pytest.approx((0.03, 0.1))
    for o in scene.obstacles:
        assert o.pieces[0].aabb_local.volume() > 0  # computed: Pinocchio's broad phase needs it


def test_meshes_convex_shells_become_pieces_open_sheets_stay_exact(
    ur10: RobotModel, gun: ToolSpec, tmp_path: Path
) -> None:
    shells = trimesh.util.concatenate([
        trimesh.creation.box([0.1, 0.1, 0.1]),
        trimesh.creation.icosphere(radius=0.05).apply_translation([0.3, 0, 0]),
    ])
    shells.export(tmp_path / "shells.stl")
    # A bent open sheet (sheet metal): a 9 x 7 grid, flat then rising at 45 deg.
    x, y = np.meshgrid(np.linspace(0, 0.4, 9), np.linspace(0, 0.3, 7))
    vertices = np.c_[x.ravel(), y.ravel(), np.maximum(x.ravel() - 0.2, 0.0)]
    faces = [[a, a + 1, a + 9] for j in range(6) for a in range(j * 9, j * 9 + 8)]
    faces += [[a + 1, a + 10, a + 9] for j in range(6) for a in range(j * 9, j * 9 + 8)]
    trimesh.Trimesh(vertices, faces).export(tmp_path / "open.stl")
    # One closed but non-convex shell (an L-shaped block): exact too, a hull would fill the corner.
    corner = [(0, 0), (0.2, 0), (0.2, 0.05), (0.05, 0.05), (0.05, 0.2), (0, 0.2)]
    trimesh.Trimesh(*_extrude(corner, 0.05)).export(tmp_path / "L.stl")
    flat = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]])
    flat.export(tmp_path / "flat.stl")
    objects = (
        obj("shells", MeshShape(tmp_path / "shells.stl"), [1, 0, 0]),
        obj("open", MeshShape(tmp_path / "open.stl"), [1, 0, 0], workpiece=True),
        obj("flat", MeshShape(tmp_path / "flat.stl"), [1, 0, 0]),
        obj("L", MeshShape(tmp_path / "L.stl"), [1, 0, 0]),
    )
    scene = build_scene(make_cell(ur10, gun, objects), ur10)
    shells_o, open_o, flat_o, l_o = scene.obstacles
    assert l_o.representation == REPRESENTATION_BVH
    assert shells_o.representation == REPRESENTATION_CONVEX and len(shells_o.pieces) == 2
    assert all(isinstance(p, coal.ConvexBase) for p in shells_o.pieces)
    assert open_o.representation == REPRESENTATION_BVH and len(open_o.pieces) == 1
    assert isinstance(open_o.pieces[0], coal.BVHModelBase) and open_o.workpiece
    # A perfectly flat mesh still gets a bounding box with volume (else the broad phase drops it).
    assert flat_o.representation == REPRESENTATION_BVH
    assert flat_o.pieces[0].aabb_local.volume() > 0


def test_reference_panel_stays_exact_and_gun_is_convex_pieces() -> None:
    assert REFERENCE_CELL.is_file() and (REPO / "robomax_py" / "robots" / "kr125" / "robot.yaml").is_file(), \
        "the reference cell (tests/data/reference) and robots/kr125 are shipped with the repository"
    from robomax_py.io.cell import load_cell, load_cell_robot

    cell = load_cell(REFERENCE_CELL)
    robot = load_cell_robot(cell)
    scene = build_scene(cell, robot)
    panel = scene.object("cabin_panel")
    assert panel.representation == REPRESENTATION_BVH and panel.workpiece
    assert scene.object("table").representation == REPRESENTATION_PRIMITIVE
    assert scene.tool.body_representation == REPRESENTATION_CONVEX
    assert scene.tool.tips_representation == REPRESENTATION_CONVEX
    assert len(scene.tool.body) >= 1 and len(scene.tool.tips) >= 1
    assert_allclose(scene.tool.T_flange_tcp, cell.tool.T_flange_tcp, atol=POSE_ATOL)


def test_objects_are_posed_in_the_robot_base_frame(ur10: RobotModel, gun: ToolSpec) -> None:
    T_world_base = pose_matrix([0.5, -0.2, 0.3], np.radians([0.0, 0.0, 90.0]))
    T_world_obj = pose_matrix([1.0, 1.0, 0.5], np.radians([10.0, 20.0, 30.0]))
    moving = ObjectSpec("door", Box((0.1, 0.1, 0.1)), frozen_array(T_world_obj), present=((1.0, 2.0),))
    cell = make_cell(ur10, gun, (ObjectSpec("b", Box((0.1, 0.1, 0.1)), frozen_array(T_world_obj)),), (moving,),
                     T_world_base=T_world_base)
    scene = build_scene(cell, ur10)
    want = invert(T_world_base) @ T_world_obj
    assert_allclose(scene.obstacles[0].T_base_object, want, atol=POSE_ATOL)
    assert_allclose(scene.dynamic[0].T_base_object, want, atol=POSE_ATOL)
    # The base-frame pose takes a world point to where the robot sees it.
    p_world = T_world_obj @ [0.05, 0.0, 0.0, 1.0]
    assert_allclose(invert(T_world_base) @ p_world, scene.obstacles[0].T_base_object @ [0.05, 0, 0, 1], atol=POSE_ATOL)
    assert scene.flange_frame_id == ur10.flange_frame_id


def test_dynamic_windows(ur10: RobotModel, gun: ToolSpec) -> None:
    door = ObjectSpec("door", Box((0.1, 0.1, 0.1)), frozen_array(np.eye(4)), present=((1.0, 2.0), (5.0, 6.0)))
    scene = build_scene(make_cell(ur10, gun, (), (door,)), ur10)
    (d,) = scene.dynamic
    assert d.dynamic and not scene.obstacles
    assert [d.present_at(t) for t in (0.5, 1.0, 1.5, 2.0, 3.0, 5.5, 7.0)] == [False, True, True, True, False, True, False]
    assert d.present_at(None)  # unknown time: conservatively present


def test_missing_or_unreadable_mesh_is_a_located_cell_error(ur10: RobotModel, gun: ToolSpec, tmp_path: Path) -> None:
    good = obj("ok", Box((0.1, 0.1, 0.1)), [1, 0, 0])
    missing = obj("gone", MeshShape(tmp_path / "nope.stl"), [1, 0, 0])
    with pytest.raises(CellFileError) as err:
        build_scene(make_cell(ur10, gun, (good, missing), source=tmp_path / "cell.yaml"), ur10)
    assert err.value.key == "objects[1].mesh" and err.value.file == str(tmp_path / "cell.yaml")
    assert "not found" in err.value.problem

    (tmp_path / "junk.stl").write_bytes(b"\x00\x01 this is not a mesh")
    junk = obj("junk", MeshShape(tmp_path / "junk.stl"), [1, 0, 0])
    with pytest.raises(CellFileError) as err:
        build_scene(make_cell(ur10, gun, (good,), (junk,)), ur10)
    assert err.value.key == "dynamic[0].mesh" and "cannot read" in err.value.problem


def test_missing_tool_mesh_names_the_tool_file(ur10: RobotModel, gun: ToolSpec, tmp_path: Path) -> None:
    broken = ToolSpec(gun.name, gun.source, MeshShape(tmp_path / "missing_body.stl"), gun.tips, gun.T_flange_tcp)
    with pytest.raises(RobotModelError) as err:
        build_scene(make_cell(ur10, broken), ur10)
    assert err.value.key == "body" and err.value.file == str(gun.source)
