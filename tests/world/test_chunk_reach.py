"""robomax_py.world.chunk_reach: the finer certificate of a cell of two neighbouring pieces, the
moving piece cut into slabs each grown by its own motion.

What must hold: the slabs' spheres cover the piece (every point of its support points' convex hull
is in one); a cell the certificate passes is free throughout by coal's own distance, whatever the
other joints are; every verdict of a world is coal's (a world without the pre-filter); the pairs it
does not apply to (a `<mimic>` joint between them) are left to the first test; and it certifies what
the first test cannot: a UR10's base and upper arm, about 19 mm apart wherever the arm is.
"""

from __future__ import annotations

from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial import ConvexHull

from robomax_py.robot import RobotModel
from robomax_py.world.bounds import support_points
from robomax_py.world.chunk_reach import (
    SLABS,
    chunks_of_pair,
    pair_chunks,
    slab_motion,
    slabs_of,
)
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.collision_core import CollisionWorldCore
from robomax_py.world.pair_cells import CERTIFIED, UNCERTIFIED, CellTable
from tests.world.cell_checks import either_side, free_throughout, undecided_world

REPO = Path(__file__).resolve().parents[2]
UR10_CELL = REPO / "cells" / "ur10_tray.yaml"
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"


@pytest.fixture()
def ur10() -> tuple[RobotModel, CollisionWorld]:
    return undecided_world(UR10_CELL)


def _pair(world: CollisionWorld, first: str, second: str) -> int:
    s = world._s
    gm = s.geom_model
    names = {(gm.geometryObjects[int(a)].name, gm.geometryObjects[int(b)].name): k
             for k, (a, b) in enumerate(zip(s.pair_a, s.pair_b))}
    return names.get((first, second), names.get((second, first), -1))


def _table(world: CollisionWorld, pair: int) -> CellTable:
    assert world._s.prefilter is not None
    table = world._s.prefilter.cells.tables[pair]
    assert table is not None
    return table


@pytest.mark.parametrize("path", [UR10_CELL, REFERENCE_CELL], ids=["ur10", "kr16"])
def test_the_slabs_cover_every_piece(path: Path) -> None:
    """Points of each robot and tool piece's hull (on its faces, and between two of its vertices)
    lie in one of its slabs' spheres; the sphere's own rounding (1e-9 relative) is the tolerance."""
    _, world = undecided_world(path)
    gm = world._s.geom_model
    rng = np.random.default_rng(7)
    covered = 0
    for piece in gm.geometryObjects:
        if piece.parentJoint == 0 and not piece.name.startswith("base"):
            continue                              # the cell's objects: never the moving piece
        placement = piece.placement.homogeneous
        points = support_points(piece.geometry, placement)
        slabs = slabs_of(piece.geometry, placement)
        assert 1 <= len(slabs.radii) <= SLABS
        hull = ConvexHull(points)
        faces = points[hull.simplices]                                  # (f, 3, 3)
        weights = rng.dirichlet(np.ones(3), size=(len(faces), 4))       # 4 points on each face
        on_faces = np.einsum("fkv,fvd->fkd", weights, faces).reshape(-1, 3)
        ends = points[rng.integers(0, len(points), size=(2000, 2))]
        inside = ends[:, 0] + rng.uniform(0, 1, size=(2000, 1)) * (ends[:, 1] - ends[:, 0])
        for x in np.concatenate([on_faces, inside, points]):
            gap = np.linalg.norm(slabs.centres - x, axis=1) - slabs.radii
            assert gap.min() <= 1e-12, (piece.name, x, gap.min())
            covered += 1
    assert covered > 10_000


def _cells_of(robot: RobotModel, world: CollisionWorld, pair: int, rng: np.random.Generator,
              n: int) -> list[np.ndarray]:
    """Configurations whose cells of `pair` hold the arm where a UR10 works: A2 from -180 to 0 deg
    (the upper arm above the base), the others anywhere."""
    lo, hi = robot.limits.lower, robot.limits.upper
    qs = rng.uniform(lo, hi, size=(n, robot.dof))
    qs[:, 1] = rng.uniform(-np.pi, 0.0, size=n)
    return list(qs)


def test_the_base_and_upper_arm_of_a_ur10_certify(ur10: tuple[RobotModel, CollisionWorld],
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """The first test alone certifies none of these cells (its bound, about 37 mm, is more than the
    pieces' gap); with the slabs most are certified."""
    robot, world = ur10
    pair = _pair(world, "base_link_0", "upper_arm_link_0")
    assert pair >= 0
    table = _table(world, pair)
    qs = _cells_of(robot, world, pair, np.random.default_rng(1), 60)
    decided = world._s.prefilter.cells.decided  # type: ignore[union-attr]

    def decide_all() -> list[int]:
        decided[:] = 0
        return [world._decide(q, pair, table, table.cell(q)) for q in qs]

    with monkeypatch.context() as patch:
        patch.setattr(CollisionWorldCore, "_certified_by_slabs", lambda self, p, lo, hi, distance: False)
        assert set(decide_all()) == {UNCERTIFIED}
    verdicts = decide_all()
    assert verdicts.count(CERTIFIED) >= 0.5 * len(qs), verdicts.count(CERTIFIED)


def test_a_cell_certified_by_slabs_is_free_throughout(ur10: tuple[RobotModel, CollisionWorld]) -> None:
    """coal's distance at configurations spread over each cell the slabs certified (the other joints
    anywhere) exceeds the pair's margin: the definition the certificate stands for."""
    robot, world = ur10
    s = world._s
    tables = [(k, t) for k, t in enumerate(s.prefilter.cells.tables) if t is not None]  # type: ignore[union-attr]
    rng = np.random.default_rng(5)
    scratch = (s.model.createData(), s.geom_model.createData())
    checked = 0
    for pair, table in tables:
        assert chunks_of_pair(s.model, s.geom_model, int(s.pair_a[pair]), int(s.pair_b[pair])) is not None
        for q in _cells_of(robot, world, pair, rng, 40):
            lo, hi = table.box(q, table.cell(q))
            centre = world.pair_distances((lo + hi) / 2, np.array([pair]))[0]
            if world._certified_by_slabs(pair, lo, hi, float(centre)):
                checked += free_throughout(world, robot, pair, table, lo, hi, rng, scratch)
    assert checked >= 100


def test_the_same_verdicts_as_coal_alone(ur10: tuple[RobotModel, CollisionWorld]) -> None:
    """Configurations a few microradians either side of a contact between the upper arm and the
    base (A2 bisected), others in the same cells, and the arm anywhere: every verdict, deciding the
    cells and then clearing by them, is a world's without the pre-filter."""
    robot, world = ur10
    exact = world.copy(prefilter=False)
    rng = np.random.default_rng(11)
    lo, hi = robot.limits.lower, robot.limits.upper
    near: list[np.ndarray] = []
    while len(near) < 60:
        q = rng.uniform(lo, hi)
        contact = exact.check(q).contact
        if contact is None or {contact.body_a, contact.body_b} != {"base_link", "upper_arm_link"}:
            continue
        free = q.copy()
        free[1] = -np.pi / 2                      # the upper arm upright: clear of the base
        if not exact.is_free(free):
            continue
        a, b = either_side(exact, q, free)
        near.extend([a, b])
        for _ in range(3):
            other = b.copy()
            other[2:] = rng.uniform(lo[2:], hi[2:])
            near.append(other)
    qs = np.concatenate([np.asarray(near), np.asarray(_cells_of(robot, world, 0, rng, 300))])
    expected = np.array([exact.is_free(q) for q in qs])
    assert 0 < expected.sum() < len(qs)
    first = world.are_free(qs)
    second = world.are_free(qs)
    np.testing.assert_array_equal(first, expected)
    np.testing.assert_array_equal(second, expected)
    for q, free in zip(qs[:40], expected[:40]):
        assert world.check(q).free == free


def test_not_across_a_passive_joint() -> None:
    """A `<mimic>` joint between two pieces follows another: the cell's box, over the joints' own
    values, would not hold its motion, so the certificate does not apply."""
    model = pin.Model()
    first = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "a1")
    second = model.addJoint(first, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.5])), "a2")
    passive = model.addJoint(second, pin.JointModelMimic(model.joints[second], 1.0, 0.0),
                             pin.SE3(np.eye(3), np.array([0.5, 0.0, 0.0])), "a3")
    assert model.joints[passive].nq == 0
    gm = pin.GeometryModel()
    for joint, name in ((0, "base"), (second, "upper"), (passive, "follower")):
        gm.addGeometryObject(pin.GeometryObject(name, joint, pin.SE3.Identity(), coal.Box(0.1, 0.1, 0.1)))
    assert pair_chunks(model, gm, 0, 1) is not None
    assert pair_chunks(model, gm, 0, 2) is None


def test_no_point_of_a_slab_moves_farther_than_its_bound(ur10: tuple[RobotModel, CollisionWorld]) -> None:
    """Points on and in each slab's sphere (at the cell's centre, riding on the moving piece's joint)
    move relative to the other piece's joint by no more than `slab_motion` says, over configurations
    spread through the cell, its corners included; for every pair with cells."""
    robot, world = ur10
    s = world._s
    model, gm = s.model, s.geom_model
    data, other = model.createData(), model.createData()
    rng = np.random.default_rng(3)
    checked = 0
    for pair, table in enumerate(s.prefilter.cells.tables):  # type: ignore[union-attr]
        if table is None:
            continue
        chunks = chunks_of_pair(model, gm, int(s.pair_a[pair]), int(s.pair_b[pair]))
        assert chunks is not None
        joints = list(table.q_index)
        for q in _cells_of(robot, world, pair, rng, 10):
            lo, hi = table.box(q, table.cell(q))
            centre = (lo + hi) / 2
            pin.computeJointJacobians(model, data, centre)
            _, moved = slab_motion(chunks, data, (hi - lo) / 2)
            direction = rng.normal(size=(len(moved), 20, 3))
            direction /= np.linalg.norm(direction, axis=2, keepdims=True)
            depth = np.where(rng.uniform(size=(len(moved), 20, 1)) < 0.5, 1.0, rng.uniform(size=(len(moved), 20, 1)))
            local = chunks.slabs.centres[:, None, :] + direction * depth * chunks.slabs.radii[:, None, None]

            start = _relative(data, chunks.fixed_joint, chunks.moving_joint, local)
            corners = [[(hi if (c >> i) & 1 else lo)[j] for i, j in enumerate(joints)] for c in range(1 << len(joints))]
            inside = [rng.uniform(lo, hi)[joints] for _ in range(12)]
            for x in [*corners, *inside]:
                y = centre.copy()
                y[joints] = x
                pin.forwardKinematics(model, other, y)
                moved_to = _relative(other, chunks.fixed_joint, chunks.moving_joint, local)
                shift = np.linalg.norm(moved_to - start, axis=2).max(axis=1)
                assert (shift <= moved).all(), (pair, shift - moved)
                checked += 1
    assert checked >= 100


def _relative(data: pin.Data, fixed: int, moving: int, local: np.ndarray) -> np.ndarray:
    """Points given in joint `moving`'s frame, in joint `fixed`'s frame (as `data` places them)."""
    pose = data.oMi[fixed].actInv(data.oMi[moving])
    out: np.ndarray = local @ pose.rotation.T + pose.translation
    return out
