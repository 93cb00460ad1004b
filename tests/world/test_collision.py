"""robomax_py.world.collision: configuration, batch and swept-segment collision queries.

The UR10 of example-robot-data with a synthetic box gun runs everywhere; kr125 (with spot_gun_c,
the reference cell) and kr16 run when robots/ has them. The broad phase and every other shortcut
are compared with an independent exhaustive narrow phase: coal.collide on every enabled pair at
coal's default request, with the pair's margin.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest
import trimesh
from numpy.testing import assert_allclose

from robomax_py.io.robot import load_robot_spec, urdf_package_dirs
from robomax_py.robot import RobotModel, fk_flange, load_robot
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
from robomax_py.transforms import pose_matrix, rot_z
from robomax_py.world.collision import (
    KIND_DYNAMIC,
    KIND_LINK,
    KIND_OBJECT,
    KIND_TOOL_BODY,
    KIND_TOOL_TIPS,
    CollisionOptions,
    CollisionWorld,
    acm_samples,
    bisection_order,
    support_points,
)
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"
PANEL = REFERENCE_CELL.parent / "parts" / "cabin_panel.stl"

# The clearance boundary is tested this far on either side; coal decides it to ~1e-9 m.
CLEARANCE_TOL_M = 1e-4
# GJK's distance tolerance: distances this close to 0 may be called either way.
GJK_TOL_M = 1e-6
UR10_Q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])            # free, gun clear of everything
UR10_FOLDED = np.array([0.0, -1.57, 3.1, 0.0, 0.0, 0.0])          # forearm folded onto the shoulder
KUKA_HOME = np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])
# For tests about obstacles, not about the ACM: no "never close" proof (more pairs checked, same answers).
LIGHT = CollisionOptions(acm_samples=200, acm_proof_joints=0)


# ------------------------------------------------------------------------------------ fixtures


def make_cell(robot: RobotModel, tool: ToolSpec, objects: tuple[ObjectSpec, ...] = (),
              dynamic: tuple[ObjectSpec, ...] = (), clearance: float = 0.0) -> CellSpec:
    spec = RobotSpec(robot.name, robot.source, robot.source, "tool0", "numeric", None, None, None,
                     package_dirs=urdf_package_dirs(robot.source, robot.source))
    return CellSpec(
        name="test", source=Path("cells/test.yaml"), robot=spec, T_world_base=frozen_array(np.eye(4)),
        home=frozen_array(np.zeros(robot.dof)), tool=tool, objects=objects, seams=(),
        process=ProcessSpec(clearance=clearance), dynamic=dynamic,
    )


def world_for(robot: RobotModel, tool: ToolSpec, objects: tuple[ObjectSpec, ...] = (),
              dynamic: tuple[ObjectSpec, ...] = (), clearance: float = 0.0,
              options: CollisionOptions = LIGHT) -> CollisionWorld:
    cell = make_cell(robot, tool, objects, dynamic, clearance)
    return CollisionWorld(robot, build_scene(cell, robot), clearance, options)


def at(T_base: np.ndarray, name: str, shape: object, workpiece: bool = False,
       present: tuple[tuple[float, float], ...] | None = None) -> ObjectSpec:
    return ObjectSpec(name, shape, frozen_array(T_base), workpiece=workpiece, present=present)  # type: ignore[arg-type]


def in_flange(robot: RobotModel, q: np.ndarray, xyz: list[float]) -> np.ndarray:
    """(4, 4) pose in the base frame of a point given in the flange frame at q (flange orientation)."""
    return np.asarray(fk_flange(robot, q) @ pose_matrix(xyz, [0.0, 0.0, 0.0]))


def cabin_objects(dx: float) -> tuple[ObjectSpec, ...]:
    """The reference cell's objects, shifted by dx along x (UR10 reach is shorter than kr125's)."""
    def pose(x: float, y: float, z: float, yaw_deg: float = 0.0) -> np.ndarray:
        return np.asarray(pose_matrix([x + dx, y, z], [0.0, 0.0, math.radians(yaw_deg)]))
    out = [
        at(pose(1.85, 0, 0.31), "table", Box((0.8, 2.0, 0.62))),
        at(pose(1.8, 0, 0.71), "fixture_plate", Box((0.5, 1.6, 0.18))),
        at(pose(1.337, -0.2695, 0.9063, 82.333), "clamp1_jaw", Box((0.05, 0.11, 0.07))),
        at(pose(1.6491, -0.3115, 0.9233, 82.333), "clamp1_arm", Box((0.04, 0.54, 0.04))),
        at(pose(1.337, 0.2695, 0.9347, 97.667), "clamp2_jaw", Box((0.05, 0.11, 0.07))),
        at(pose(1.2, 0.5, 0.9), "post", Cylinder(0.04, 0.3)),
        at(pose(1.2, -0.5, 1.1), "pin", Sphere(0.05)),
        at(pose(1.0, 0.0, 1.3, 90.0), "bar", Capsule(0.02, 0.4)),
    ]
    if PANEL.is_file():
        out.append(at(pose(0.0, 0.0, 0.0), "cabin_panel", MeshShape(PANEL), workpiece=True))
    return tuple(out)


def door() -> ObjectSpec:
    """A dynamic door beside the UR10, present for the first 5 s."""
    return at(np.asarray(pose_matrix([0.7, 0.6, 0.6], [0, 0, 0])), "door", Box((0.6, 0.05, 0.6)),
              present=((0.0, 5.0),))


@pytest.fixture(scope="module")
def ur10_cell_world(ur10: RobotModel, gun: ToolSpec) -> CollisionWorld:
    """UR10 among the (shifted) reference objects, a dynamic door, 1 cm clearance, production ACM."""
    return world_for(ur10, gun, cabin_objects(-0.6), (door(),), clearance=0.01, options=CollisionOptions())


@pytest.fixture(scope="module")
def reference() -> tuple[CellSpec, RobotModel, CollisionWorld]:
    assert REFERENCE_CELL.is_file() and (REPO / "robomax_py" / "robots" / "kr125" / "robot.yaml").is_file(), \
        "the reference cell (tests/data/reference) and robots/kr125 are shipped with the repository"
    from robomax_py.io.cell import load_cell, load_cell_robot

    cell = load_cell(REFERENCE_CELL)
    robot = load_cell_robot(cell)
    return cell, robot, CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)


def library_robot(name: str) -> RobotModel:
    path = REPO / "robomax_py" / "robots" / name / "robot.yaml"
    assert path.is_file(), f"robots/{name} is shipped with the repository"
    return load_robot(load_robot_spec(path))


# ------------------------------------------------------------------ the exhaustive reference


class BruteForce:
    """coal.collide on every enabled pair (default request + the pair's margin): no shortcut at all."""

    def __init__(self, world: CollisionWorld, robot: RobotModel) -> None:
        self.gm = world.geometry_model
        self.model = robot.model
        self.data, self.gd = self.model.createData(), self.gm.createData()
        self.pairs = [(cp.first, cp.second) for cp in self.gm.collisionPairs]
        self.geoms = [g.geometry for g in self.gm.geometryObjects]
        self.margins = world.pair_margins()
        self.dynamic = []
        for p in range(len(self.pairs)):
            names = world.pair_names(p)
            self.dynamic.append(names.body_b if names.kind_b == KIND_DYNAMIC else (
                names.body_a if names.kind_a == KIND_DYNAMIC else None))

    def free(self, q: np.ndarray, absent: frozenset[str] = frozenset()) -> bool:
        pin.updateGeometryPlacements(self.model, self.data, self.gm, self.gd, np.asarray(q, dtype=float))
        tf = [coal.Transform3s(M.rotation, M.translation) for M in self.gd.oMg]
        for (a, b), margin, dyn in zip(self.pairs, self.margins, self.dynamic):
            if dyn is not None and dyn in absent:
                continue
            request, result = coal.CollisionRequest(), coal.CollisionResult()
            request.security_margin = float(margin)
            if coal.collide(self.geoms[a], tf[a], self.geoms[b], tf[b], request, result):
                return False
        return True


def near_boundary_configs(world: CollisionWorld, robot: RobotModel, rng: np.random.Generator, count: int) -> np.ndarray:
    """Configurations a few mrad from a contact: bisect between a free and a colliding sample."""
    out = []
    while len(out) < count:
        a, b = rng.uniform(robot.limits.lower, robot.limits.upper, size=(2, robot.dof))
        fa, fb = world.is_free(a), world.is_free(b)
        if fa == fb:
            continue
        for _ in range(12):
            mid = (a + b) / 2
            if world.is_free(mid) == fa:
                a = mid
            else:
                b = mid
        out.extend([a, b])
    return np.asarray(out[:count])


# --------------------------------------------------------------------------------------- tests


def test_bisection_order_is_coarse_to_fine_permutation() -> None:
    assert bisection_order(8).tolist() == [0, 8, 4, 2, 6, 1, 3, 5, 7]
    assert bisection_order(0).tolist() == [0]
    for m in (1, 2, 7, 100):
        assert sorted(bisection_order(m).tolist()) == list(range(m + 1))


@pytest.mark.parametrize("shape", [
    Box((0.12, 0.12, 0.12)), Cylinder(0.06, 0.15), Sphere(0.07), Capsule(0.04, 0.1), "convex mesh", "open sheet",
], ids=["box", "cylinder", "sphere", "capsule", "convex-mesh", "open-sheet-bvh"])
def test_each_shape_collides_at_the_wrist_and_not_far_away(
    ur10: RobotModel, gun: ToolSpec, shape: object, tmp_path: Path
) -> None:
    if shape == "convex mesh":
        trimesh.creation.icosphere(radius=0.07).export(tmp_path / "ball.stl")
        shape = MeshShape(tmp_path / "ball.stl")
    elif shape == "open sheet":  # a flat 0.3 m square of 8 triangles: exact BVH, cuts through the wrist
        x, y = np.meshgrid(np.linspace(-0.15, 0.15, 3), np.linspace(-0.15, 0.15, 3))
        vertices = np.c_[x.ravel(), y.ravel(), np.zeros(9)]
        faces = [[a, a + 1, a + 3] for a in (0, 1, 3, 4)] + [[a + 1, a + 4, a + 3] for a in (0, 1, 3, 4)]
        trimesh.Trimesh(vertices, faces).export(tmp_path / "sheet.stl")
        shape = MeshShape(tmp_path / "sheet.stl")
    # clearance 0.3 m: "free" below also proves the object is more than 0.3 m away.
    w = world_for(ur10, gun, (at(in_flange(ur10, UR10_Q0, [0, 0, 0.05]), "thing", shape),), clearance=0.3)
    assert not w.is_free(UR10_Q0)
    contact = w.first_contact(UR10_Q0)
    assert contact is not None and contact.body_b == "thing" and contact.kind_b == KIND_OBJECT
    assert contact.kind_a in (KIND_LINK, KIND_TOOL_BODY, KIND_TOOL_TIPS)
    away = UR10_Q0 + np.array([math.pi, 0, 0, 0, 0, 0])
    assert w.is_free(away) and w.first_contact(away) is None


@pytest.mark.parametrize("name", ["ur10", "kr125", "kr16"])
def test_known_colliding_and_free_configurations_against_a_box(
    name: str, ur10: RobotModel, gun: ToolSpec
) -> None:
    robot = ur10 if name == "ur10" else library_robot(name)
    q0 = UR10_Q0 if name == "ur10" else KUKA_HOME
    box = at(in_flange(robot, q0, [0.0, 0.0, 0.0]), "box", Box((0.15, 0.15, 0.15)))
    # clearance 0.5 m: "free" below also proves the box is more than 0.5 m away.
    w = world_for(robot, gun, (box,), clearance=0.5)
    assert not w.is_free(q0) and not w.are_free(q0[None])[0]
    contact = w.first_contact(q0)
    assert contact is not None and "box" in (contact.body_a, contact.body_b)
    turned = q0 + np.array([math.pi, 0, 0, 0, 0, 0])
    assert w.is_free(turned) and w.are_free(turned[None])[0]


def test_self_collision_of_a_folded_arm(ur10: RobotModel, gun: ToolSpec) -> None:
    w = world_for(ur10, gun, options=CollisionOptions())
    assert w.is_free(UR10_Q0)
    contact = w.first_contact(UR10_FOLDED)
    assert contact is not None
    assert contact.kind_a in (KIND_LINK, KIND_TOOL_BODY, KIND_TOOL_TIPS)
    assert contact.kind_b in (KIND_LINK, KIND_TOOL_BODY, KIND_TOOL_TIPS)
    assert w.distance(UR10_FOLDED) < 0


def test_kr125_gun_folded_into_its_base(reference: tuple[CellSpec, RobotModel, CollisionWorld]) -> None:
    _, robot, world = reference
    folded = np.radians([0.0, 0.0, 145.0, 0.0, 0.0, 0.0])   # arm bent back: the gun hits the base
    assert robot.limits.contains(folded)
    contact = world.first_contact(folded)
    assert contact is not None and {contact.kind_a, contact.kind_b} <= {KIND_LINK, KIND_TOOL_BODY, KIND_TOOL_TIPS}
    assert world.is_free(KUKA_HOME)


def test_tips_may_touch_a_workpiece_but_the_body_may_not(ur10: RobotModel, gun: ToolSpec) -> None:
    at_tips = in_flange(ur10, UR10_Q0, [-0.10, 0.0, 0.31])      # inside the tips only
    at_body = in_flange(ur10, UR10_Q0, [0.10, 0.0, 0.25])       # inside the body's upright only
    cube = Box((0.01, 0.01, 0.01))
    assert world_for(ur10, gun, (at(at_tips, "part", cube, workpiece=True),)).is_free(UR10_Q0)
    w = world_for(ur10, gun, (at(at_tips, "fixture", cube, workpiece=False),))
    contact = w.first_contact(UR10_Q0)
    assert contact is not None and (contact.body_a, contact.body_b) == ("tool_tips", "fixture")
    w = world_for(ur10, gun, (at(at_body, "part", cube, workpiece=True),))
    contact = w.first_contact(UR10_Q0)
    assert contact is not None and (contact.body_a, contact.body_b) == ("tool_body", "part")
    allowed = [(d.piece_a, d.piece_b) for d in w.acm.disabled if d.reason == "tips on workpiece"]
    assert allowed == [("tool_tips[0]", "object:part[0]")]


def test_clearance_margin_changes_the_answer_at_the_gap(ur10: RobotModel, gun: ToolSpec) -> None:
    gap = 0.01   # below the arm's own smallest self distance at UR10_Q0 (19 mm)
    # A 1 cm cube whose top face is `gap` below the tips' lower face (flange z = 0.30).
    cube = at(in_flange(ur10, UR10_Q0, [-0.10, 0.0, 0.30 - gap - 0.005]), "cube", Box((0.01, 0.01, 0.01)))
    exact = world_for(ur10, gun, (cube,))
    proximity = exact.closest(UR10_Q0)
    assert proximity.pair is not None and proximity.pair.body_b == "cube"
    assert proximity.distance == pytest.approx(gap, abs=GJK_TOL_M)
    assert world_for(ur10, gun, (cube,), clearance=gap - CLEARANCE_TOL_M).is_free(UR10_Q0)
    near = world_for(ur10, gun, (cube,), clearance=gap + CLEARANCE_TOL_M)
    assert not near.is_free(UR10_Q0)
    contact = near.first_contact(UR10_Q0)
    assert contact is not None and (contact.body_a, contact.body_b) == ("tool_tips", "cube")
    # Self pairs use margin 0: a clearance larger than the self distance changes nothing.
    assert world_for(ur10, gun, clearance=0.5).is_free(UR10_Q0)


def test_dynamic_obstacle_collides_only_inside_its_windows(ur10: RobotModel, gun: ToolSpec) -> None:
    door = at(in_flange(ur10, UR10_Q0, [0.0, 0.0, 0.05]), "door", Box((0.12, 0.12, 0.12)), present=((2.0, 4.0),))
    w = world_for(ur10, gun, dynamic=(door,))
    assert [w.is_free(UR10_Q0, t) for t in (1.0, 2.0, 3.0, 4.0, 5.0)] == [True, False, False, False, True]
    assert not w.is_free(UR10_Q0)                               # unknown time: present
    contact = w.first_contact(UR10_Q0, 3.0)
    assert contact is not None and contact.kind_b == KIND_DYNAMIC and contact.body_b == "door"
    qs = np.stack([UR10_Q0, UR10_Q0 + [math.pi, 0, 0, 0, 0, 0]])
    assert w.are_free(qs, 3.0).tolist() == [False, True]
    assert w.are_free(qs, 5.0).tolist() == [True, True]
    # Dwelling at q while the door comes and goes is caught; dwelling after it left is not.
    assert not w.segment_free(UR10_Q0, UR10_Q0, 0.0, 10.0)
    assert w.segment_free(UR10_Q0, UR10_Q0, 4.5, 10.0)
    assert w.segment_free(UR10_Q0, UR10_Q0, 0.0, 1.9)
    with pytest.raises(ValueError):
        w.segment_free(UR10_Q0, UR10_Q0, 0.0, None)


def test_segment_catches_a_thin_plate_that_a_coarse_check_misses(ur10: RobotModel, gun: ToolSpec) -> None:
    q_a = UR10_Q0 + [-0.8, 0, 0, 0, 0, 0]
    q_b = UR10_Q0 + [0.8, 0, 0, 0, 0, 0]
    theta = -0.8 + 0.3 * 1.6                                    # 30 % of the way, not the middle
    T = np.eye(4)
    T[:3, :3] = rot_z(theta)
    T_plate = T @ in_flange(ur10, UR10_Q0, [0.0, 0.0, 0.05])
    tangent = rot_z(theta) @ np.cross([0, 0, 1], fk_flange(ur10, UR10_Q0)[:3, 3])
    T_plate[:3, :3] = rot_z(math.atan2(tangent[1], tangent[0]))  # plate x = sweep direction
    plate = at(T_plate, "plate", Box((0.002, 0.3, 0.3)))        # 2 mm thick across the sweep
    w = world_for(ur10, gun, (plate,))
    assert w.is_free(q_a) and w.is_free(q_b) and w.is_free((q_a + q_b) / 2)
    coarse = w.check_segment(q_a, q_b, max_step=10.0)            # ends only
    assert coarse.free and coarse.states == 2
    fine = w.check_segment(q_a, q_b)
    assert not fine.free and not w.segment_free(q_a, q_b)
    assert fine.s_contact is not None and 0.15 < fine.s_contact < 0.45
    assert fine.checks < fine.states                             # bisection order stopped early
    assert fine.states == math.ceil(w.sweep_length(q_a, q_b) / 0.002) + 1


def test_segment_asked_again_is_answered_from_memory(ur10: RobotModel, gun: ToolSpec,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    # The same untimed move asked again gives the first answer (checks included) without a scan;
    # other ends, the reverse move, another step or a timed check among dynamic obstacles are checked.
    q_a = UR10_Q0 + [-0.8, 0, 0, 0, 0, 0]
    q_b = UR10_Q0 + [0.8, 0, 0, 0, 0, 0]
    w = world_for(ur10, gun, cabin_objects(-0.6), (door(),))
    scans = 0
    scan = type(w)._scan

    def counted(self: CollisionWorld, *args: object, **kwargs: object) -> object:
        nonlocal scans
        scans += 1
        return scan(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(type(w), "_scan", counted)
    first = w.check_segment(q_a, q_b)
    assert scans == 1
    assert w.check_segment(q_a.copy(), list(q_b)) == first and scans == 1
    w.check_segment(q_b, q_a)
    w.check_segment(q_a, q_b, max_step=0.01)
    w.check_segment(q_a, q_b + 1e-12)
    assert scans == 4
    for _ in range(2):                                           # timed: checked each time
        before = scans
        w.check_segment(q_a, q_b, 0.0, 1.0)
        assert scans > before
    before = scans
    assert w.copy().check_segment(q_a, q_b) == first and scans == before + 1   # a copy remembers its own


def _step_bound_holds(world: CollisionWorld, robot: RobotModel, rng: np.random.Generator,
                      segments: int, max_step: float, max_dq: float) -> float:
    """Largest ratio (path length of any support point between consecutive states) / max_step."""
    gm = world.geometry_model
    moving = [g for g in gm.geometryObjects if g.parentJoint != 0]
    ids = [gm.getGeometryId(g.name) for g in moving]
    local = [support_points(g.geometry) for g in moving]
    model, data, gd = robot.model, robot.model.createData(), gm.createData()
    worst = 0.0
    substeps = 6
    for _ in range(segments):
        q0 = rng.uniform(robot.limits.lower, robot.limits.upper)
        q1 = np.clip(q0 + rng.uniform(-max_dq, max_dq, robot.dof), robot.limits.lower, robot.limits.upper)
        m = world.check_segment(q0, q1, max_step=max_step).states - 1
        s = np.linspace(0.0, 1.0, m * substeps + 1)
        pts = []
        for sk in s:
            pin.updateGeometryPlacements(model, data, gm, gd, q0 + sk * (q1 - q0))
            pts.append(np.vstack([P @ gd.oMg[i].rotation.T + gd.oMg[i].translation for P, i in zip(local, ids)]))
        pts_a = np.asarray(pts)                                   # (m * substeps + 1, points, 3)
        steps = np.linalg.norm(np.diff(pts_a, axis=0), axis=2)    # chord per substep
        per_state = steps.reshape(m, substeps, -1).sum(axis=1)    # path length between states
        worst = max(worst, float(per_state.max()) / max_step)
    return worst


def test_path_check_catches_the_thin_plate_on_its_segment(ur10: RobotModel, gun: ToolSpec) -> None:
    q_a = UR10_Q0 + [-0.8, 0, 0, 0, 0, 0]
    q_b = UR10_Q0 + [0.8, 0, 0, 0, 0, 0]
    theta = -0.8 + 0.3 * 1.6
    T = np.eye(4)
    T[:3, :3] = rot_z(theta)
    T_plate = T @ in_flange(ur10, UR10_Q0, [0.0, 0.0, 0.05])
    tangent = rot_z(theta) @ np.cross([0, 0, 1], fk_flange(ur10, UR10_Q0)[:3, 3])
    T_plate[:3, :3] = rot_z(math.atan2(tangent[1], tangent[0]))
    w = world_for(ur10, gun, (at(T_plate, "plate", Box((0.002, 0.3, 0.3))),))
    q_c = q_b + [0, 0.2, 0, 0, 0, 0]
    free_part = w.check_path(np.array([q_b, q_c]))
    assert free_part.free and free_part.s_contact is None
    blocked = w.check_path(np.array([q_a, q_b, q_c]))            # the plate is on the first segment
    assert not blocked.free and not w.path_free(np.array([q_a, q_b, q_c]))
    states_ab = w.check_segment(q_a, q_b).states
    assert blocked.states == states_ab + free_part.states - 1    # the shared state once
    assert blocked.s_contact is not None and blocked.s_contact < (states_ab - 1) / (blocked.states - 1)
    single = w.check_path(q_a[None, :])
    assert single.free and single.states == 1


def test_path_check_equals_its_segments_checked_one_by_one(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    # Polylines near the flange of the reference cell, free and blocked: the path check must give
    # exactly the verdict of checking every segment with check_segment, on the same states.
    _, robot, world = reference
    q_near = np.radians([0.0, -60.0, 110.0, 0.0, 40.0, 0.0])
    verdicts = set()
    for _ in range(40):
        centre = q_near + rng.uniform(-0.5, 0.5, robot.dof)
        pts = centre + rng.uniform(-0.15, 0.15, size=(4, robot.dof))
        pts[1] = pts[0]                                          # a zero-length segment too
        segs = [world.check_segment(a, b) for a, b in itertools.pairwise(pts)]
        res = world.check_path(pts)
        assert res.free == all(seg.free for seg in segs)
        assert res.states == 1 + sum(seg.states - 1 for seg in segs if seg.states > 1)
        verdicts.add(res.free)
    assert verdicts == {True, False}                             # both cases were exercised


def test_a_polylines_sweep_lengths_are_its_segments_to_the_last_bit(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    # check_path subdivides every segment at once: it must find the step counts check_segment finds
    # one by one, so the two check the same states (a last-bit difference can change a count).
    _, robot, world = reference
    pts = rng.uniform(-3.0, 3.0, size=(2000, robot.dof)) * 10.0 ** rng.integers(-6, 1, size=(2000, 1))
    assert world.sweep_lengths(pts[:-1], pts[1:]).tolist() == [world.sweep_length(a, b) for a, b in itertools.pairwise(pts)]


def test_step_bound_no_point_moves_more_than_max_step(ur10: RobotModel, gun: ToolSpec, rng: np.random.Generator) -> None:
    w = world_for(ur10, gun, options=CollisionOptions())
    ratio = _step_bound_holds(w, ur10, rng, segments=6, max_step=0.05, max_dq=0.5)
    assert ratio <= 1.0 + 1e-9
    assert ratio > 0.2  # and the bound is not absurdly loose


def test_kr125_step_bound(reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator) -> None:
    _, robot, world = reference
    ratio = _step_bound_holds(world, robot, rng, segments=4, max_step=0.05, max_dq=0.3)
    assert 0.2 < ratio <= 1.0 + 1e-9


def _compare_with_brute_force(world: CollisionWorld, robot: RobotModel, qs: np.ndarray) -> np.ndarray:
    """Broad phase (batch and single), exhaustive narrow phase and first_contact vs brute force."""
    brute_force = BruteForce(world, robot)
    brute = np.array([brute_force.free(q) for q in qs])
    batch = world.are_free(qs)
    assert (batch == brute).all(), np.flatnonzero(batch != brute)
    assert (np.array([world.is_free(q) for q in qs]) == brute).all()
    assert (world.copy(broad_phase=False).are_free(qs) == brute).all()
    assert (world.copy(prefilter=False).are_free(qs) == brute).all()
    for q, free in zip(qs[:200], brute[:200]):
        assert (world.first_contact(q) is None) == free
    return brute


def test_broad_phase_equals_brute_force_ur10(
    ur10_cell_world: CollisionWorld, ur10: RobotModel, rng: np.random.Generator
) -> None:
    qs = np.vstack([
        rng.uniform(ur10.limits.lower, ur10.limits.upper, size=(700, ur10.dof)),
        near_boundary_configs(ur10_cell_world, ur10, rng, 200),
    ])
    brute = _compare_with_brute_force(ur10_cell_world, ur10, qs)
    assert 0.05 < brute.mean() < 0.95          # both answers well represented
    # Dynamic door absent (t outside its window) vs brute force without it.
    w = ur10_cell_world
    brute_force = BruteForce(w, ur10)
    brute_late = np.array([brute_force.free(q, frozenset({"door"})) for q in qs[:300]])
    assert (w.are_free(qs[:300], t=6.0) == brute_late).all()
    assert (w.copy(broad_phase=False).are_free(qs[:300], t=6.0) == brute_late).all()


def test_broad_phase_equals_brute_force_kr125(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    _, robot, world = reference
    qs = np.vstack([
        rng.uniform(robot.limits.lower, robot.limits.upper, size=(120, robot.dof)),
        near_boundary_configs(world, robot, rng, 80),
    ])
    _compare_with_brute_force(world, robot, qs)


@pytest.mark.slow
def test_broad_phase_equals_brute_force_kr125_many(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    _, robot, world = reference
    qs = np.vstack([
        # 2,000 configurations, a fifth near the boundary (it ran 5,000, which cost CI 2.5 times as
        # much; the fast test above and the pre-filter's own tests hold the same answers).
        rng.uniform(robot.limits.lower, robot.limits.upper, size=(1600, robot.dof)),
        near_boundary_configs(world, robot, rng, 400),
    ])
    _compare_with_brute_force(world, robot, qs)


def test_distance_agrees_with_is_free(ur10: RobotModel, gun: ToolSpec, rng: np.random.Generator) -> None:
    w = world_for(ur10, gun, cabin_objects(-0.6))
    for q in rng.uniform(ur10.limits.lower, ur10.limits.upper, size=(120, ur10.dof)):
        d = w.distance(q)
        if abs(d) > GJK_TOL_M:
            assert w.is_free(q) == (d > 0)


def test_acm_structure_and_determinism(ur10_cell_world: CollisionWorld, ur10: RobotModel, gun: ToolSpec) -> None:
    a = ur10_cell_world
    b = world_for(ur10, gun, cabin_objects(-0.6), (door(),), clearance=0.01, options=CollisionOptions())
    assert a.acm == b.acm and a.n_pairs == b.n_pairs
    reasons = {(d.piece_a, d.piece_b): d.reason for d in a.acm.disabled}
    assert reasons[("shoulder_link_0", "upper_arm_link_0")] == "adjacent"
    assert reasons[("wrist_3_link_0", "ee_link_0")] == "rigid"
    assert reasons[("tool_body[0]", "tool_tips[0]")] == "rigid"
    enabled = set(a.acm.enabled)
    assert ("shoulder_link_0", "forearm_link_0") in enabled      # they fold onto each other
    assert ("wrist_3_link_0", "object:table[0]") in enabled
    if PANEL.is_file():
        assert reasons[("tool_tips[0]", "object:cabin_panel[0]")] == "tips on workpiece"
        assert any(p == ("tool_body[0]", "object:cabin_panel[0]") for p in enabled)
    assert all(r != "fixed base" or k[0].startswith("base_link") for k, r in reasons.items())


def test_gun_mounting_block_may_touch_the_wrist_at_the_flange(
    ur10: RobotModel, gun: ToolSpec, tmp_path: Path
) -> None:
    """A tool piece reaching back over the flange into the link before it touches it in every
    configuration: allowed ("tool touches flange link"), and the arm is not reported colliding."""
    body = trimesh.load(gun.body.path, force="mesh")
    mount = trimesh.creation.box([0.09, 0.09, 0.2]).apply_translation([0.0, 0.0, -0.05])
    trimesh.util.concatenate([body, mount]).export(tmp_path / "body.stl")
    mounted = ToolSpec(gun.name, gun.source, MeshShape(tmp_path / "body.stl"), gun.tips, gun.T_flange_tcp)
    w = world_for(ur10, mounted, options=CollisionOptions())
    allowed = [(d.piece_a, d.piece_b) for d in w.acm.disabled if d.reason == "tool touches flange link"]
    assert allowed == [("wrist_2_link_0", "tool_body[3]")]
    assert w.is_free(UR10_Q0)
    assert not w.is_free(UR10_FOLDED)


def _never_close_holds(world: CollisionWorld, robot: RobotModel, samples: int, seed: int) -> float:
    """Smallest distance over `samples` fresh random configurations of every 'never close' pair."""
    gm = world.geometry_model
    names = [g.name for g in gm.geometryObjects]
    pairs = [(names.index(d.piece_a), names.index(d.piece_b)) for d in world.acm.disabled if d.reason == "never close"]
    if not pairs:
        return math.inf
    tmp = pin.GeometryModel()
    for g in gm.geometryObjects:
        tmp.addGeometryObject(pin.GeometryObject(g))
    for a, b in pairs:
        tmp.addCollisionPair(pin.CollisionPair(a, b))
    gd, data = tmp.createData(), robot.model.createData()
    low = math.inf
    for q in acm_samples(robot, samples, seed):
        pin.computeDistances(robot.model, data, tmp, gd, q)
        low = min(low, min(r.min_distance for r in gd.distanceResults))
    return low


def test_never_close_pairs_stay_apart_ur10(ur10_cell_world: CollisionWorld, ur10: RobotModel) -> None:
    assert _never_close_holds(ur10_cell_world, ur10, 3000, seed=99) > ur10_cell_world.options.acm_proof_margin


@pytest.mark.slow
def test_never_close_pairs_stay_apart_kr125(reference: tuple[CellSpec, RobotModel, CollisionWorld]) -> None:
    _, robot, world = reference
    assert _never_close_holds(world, robot, 12000, seed=99) > world.options.acm_proof_margin


def test_reference_cell_home_is_free_with_its_clearance(reference: tuple[CellSpec, RobotModel, CollisionWorld]) -> None:
    cell, _, world = reference
    assert world.is_free(cell.home)
    assert world.distance(cell.home) > cell.process.clearance
    assert not world.layout_contacts and not world.acm.always_in_contact


def test_copy_answers_the_same(ur10_cell_world: CollisionWorld, ur10: RobotModel, rng: np.random.Generator) -> None:
    qs = rng.uniform(ur10.limits.lower, ur10.limits.upper, size=(300, ur10.dof))
    other = ur10_cell_world.copy()
    assert other.acm is ur10_cell_world.acm
    assert (other.are_free(qs, 1.0) == ur10_cell_world.are_free(qs, 1.0)).all()
    check = other.check(qs[0])
    assert check.free == ur10_cell_world.is_free(qs[0]) and check.narrow_phase_tests >= 0
    assert_allclose(other.lever_arms, ur10_cell_world.lever_arms)
