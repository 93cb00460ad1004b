"""robomax_py.world.prefilter: the bounding-volume pre-filter before coal's exact test.

What must hold (its forward kinematics is Pinocchio's: tests/robot/test_forward_kinematics.py): a
pair it clears is farther apart than its margin by coal's own distance (it may never clear a pair
coal would call colliding); and every query of a world gives the same answers with the filter as
without it (verdicts, the state a segment stops at, the contact named).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from urdf_case import six_joint_urdf

from robomax_py.app.import_urdf import import_urdf
from robomax_py.io.cell import load_cell
from robomax_py.io.robot import load_robot_spec
from robomax_py.robot import RobotModel, load_robot
from robomax_py.spec import CellSpec
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.prefilter import SLACK_M, Prefilter
from robomax_py.world.scene import build_scene

REPO = Path(__file__).resolve().parents[2]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"




@pytest.fixture(scope="module")
def reference() -> tuple[CellSpec, RobotModel, CollisionWorld]:
    assert REFERENCE_CELL.is_file(), "the reference cell (tests/data/reference) is shipped with the repository"
    from robomax_py.io.cell import load_cell_robot

    cell = load_cell(REFERENCE_CELL)
    robot = load_cell_robot(cell)
    return cell, robot, CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)


def test_no_filter_for_a_joint_it_does_not_model() -> None:
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelRUBZ(), pin.SE3.Identity(), "continuous")   # cos/sin pair
    model.addJointFrame(j)
    assert Prefilter.of(model, pin.GeometryModel(), [], np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
                        np.zeros(0)) is None


def test_an_arm_whose_root_link_has_no_geometry(tmp_path: Path) -> None:
    """Obstacles hang on the universe joint; an arm whose root link carries no geometry (a track
    left unmodelled, an empty world link) has no robot piece there. Its filter used to look the
    universe up among the robot's joints (a KeyError in every plan of such an arm)."""
    body = '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
    urdf = six_joint_urdf(tmp_path / "bare.urdf", "bare", ["0 0 1", "0 1 0", "0 1 0", "1 0 0", "0 1 0", "1 0 0"],
                          ["0 0 0.4", "0.1 0 0", "0 0 0.5", "0.4 0 0", "0 0 0", "0.1 0 0"],
                          collisions={i: body for i in (1, 2, 3)})
    robot = load_robot(load_robot_spec(import_urdf(urdf, tmp_path / "bare").folder / "robot.yaml"))
    cell = load_cell(REFERENCE_CELL)          # its fixtures as obstacles, in reach of this arm
    world = CollisionWorld(robot, build_scene(cell, robot), 0.0)
    exact = world.copy(prefilter=False)
    rng = np.random.default_rng(5)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, size=(200, robot.dof))
    assert [world.is_free(x) for x in q] == [exact.is_free(x) for x in q]


def _configs(world: CollisionWorld, robot: RobotModel, rng: np.random.Generator, n: int) -> np.ndarray:
    """Uniform samples and samples a few mrad from a contact (bisected between free and colliding)."""
    lo, hi = robot.limits.lower, robot.limits.upper
    out = list(rng.uniform(lo, hi, size=(n, robot.dof)))
    exact = world.copy(prefilter=False)
    while len(out) < 2 * n:
        a, b = rng.uniform(lo, hi, size=(2, robot.dof))
        fa, fb = exact.is_free(a), exact.is_free(b)
        if fa == fb:
            continue
        for _ in range(14):
            mid = (a + b) / 2
            a, b = (mid, b) if exact.is_free(mid) == fa else (a, mid)
        out.extend([a, b])
    return np.asarray(out)


def test_a_cleared_pair_is_farther_than_its_margin(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    _, robot, world = reference
    filt = world._s.prefilter
    assert filt is not None
    margins = world.pair_margins()
    everything = np.arange(world.n_pairs)
    active = np.ones(world.n_pairs, dtype=bool)
    qs = _configs(world, robot, rng, 150)
    offsets, pairs = filt.uncleared(qs, active)
    assert offsets[0] == 0 and offsets[-1] == len(pairs) and len(offsets) == len(qs) + 1
    cleared_total = 0
    for i, q in enumerate(qs):
        left = pairs[offsets[i]:offsets[i + 1]]
        assert (np.diff(left) > 0).all()                      # in pair order, once each
        cleared = np.setdiff1d(everything, left)
        cleared_total += len(cleared)
        d = world.pair_distances(q, cleared)
        assert (d > margins[cleared] + SLACK_M - 1e-9).all(), (i, cleared[d <= margins[cleared] + SLACK_M])
    assert cleared_total > 0.9 * len(qs) * world.n_pairs      # and it does clear most pairs


def test_answers_are_the_same_with_and_without_the_filter(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    _, robot, world = reference
    plain = world.copy(prefilter=False)
    qs = _configs(world, robot, rng, 100)
    assert (world.are_free(qs) == plain.are_free(qs)).all()
    for q in qs[:80]:
        assert world.is_free(q) == plain.is_free(q)
        assert world.check(q).contact == plain.check(q).contact
    for a, b in zip(qs[:-1:2], qs[1::2]):
        mine, theirs = world.check_segment(a, b), plain.check_segment(a, b)
        assert (mine.free, mine.checks, mine.states, mine.s_contact) == \
            (theirs.free, theirs.checks, theirs.states, theirs.s_contact)
    path = qs[:12]
    mine, theirs = world.check_path(path), plain.check_path(path)
    assert (mine.free, mine.checks, mine.states, mine.s_contact) == \
        (theirs.free, theirs.checks, theirs.states, theirs.s_contact)


def test_a_pieces_volumes_are_reused_only_for_the_same_geometry_at_the_same_placement(
        reference: tuple[CellSpec, RobotModel, CollisionWorld]) -> None:
    """The per-piece volumes are kept per process; a rebuilt world's filter is the fresh one, and a
    piece moved or replaced gets volumes of its own."""
    from robomax_py.world import prefilter
    from robomax_py.world.acm import OBSTACLE_KINDS

    _, _, world = reference
    s = world._s
    obstacle = [p.kind in OBSTACLE_KINDS for p in s.pieces]
    args = (s.model, s.geom_model, obstacle, s.pair_a, s.pair_b, s.pair_margin)
    prefilter._BOUNDS.clear()
    fresh = Prefilter.of(*args)
    reused = Prefilter.of(*args)
    assert fresh is not None and reused is not None
    np.testing.assert_array_equal(fresh.floats, reused.floats)      # vectors and matrices are views of floats
    np.testing.assert_array_equal(fresh.ints, reused.ints)

    gm = s.geom_model.copy()
    g = next(k for k, o in enumerate(obstacle) if o)
    moved = gm.geometryObjects[g]
    moved.placement = pin.SE3(np.eye(3), np.asarray(moved.placement.translation) + [0.5, 0.0, 0.0])
    shifted = Prefilter.of(s.model, gm, *args[2:])
    prefilter._BOUNDS.clear()
    shifted_fresh = Prefilter.of(s.model, gm, *args[2:])
    assert shifted is not None and shifted_fresh is not None
    np.testing.assert_array_equal(shifted.floats, shifted_fresh.floats)
    assert not np.array_equal(shifted.floats, fresh.floats)


def test_the_kept_volumes_hold_no_chunk_points(reference: tuple[CellSpec, RobotModel, CollisionWorld]) -> None:
    """The per-process table keeps each obstacle's chunk tree by its volumes and their count, not
    the chunks' point sets (71 MB a placement for a 790,000-triangle part): the panel mesh's tree
    has as many spheres, boxes and subtree ends as its count."""
    from robomax_py.world import prefilter
    from robomax_py.world.acm import OBSTACLE_KINDS

    _, _, world = reference
    s = world._s
    prefilter._BOUNDS.clear()
    Prefilter.of(s.model, s.geom_model, [p.kind in OBSTACLE_KINDS for p in s.pieces], s.pair_a, s.pair_b,
                 s.pair_margin)
    trees = [e for e in prefilter._BOUNDS.values() if e.chunk_count > 1]
    assert trees, "the reference panel is a mesh of more than one chunk"
    for e in prefilter._BOUNDS.values():
        assert isinstance(e.chunk_count, int)
        assert e.chunk_count == len(e.chunk_spheres) == len(e.chunk_boxes) == len(e.skip)


def test_timed_segments_are_the_same_with_and_without_the_filter(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    """With an obstacle that comes and goes (a box where the arm passes, present in two windows),
    timed segments give the same verdict, states checked and contact with and without the filter."""
    import dataclasses

    from robomax_py.robot.model import fk_flange
    from robomax_py.spec import Box, ObjectSpec
    from robomax_py.transforms import pose_matrix

    cell, robot, _ = reference
    home = np.asarray(cell.home)
    near = np.asarray(fk_flange(robot, home))[:3, 3] + [0.0, 0.0, 0.3]
    box = ObjectSpec("door", Box((0.4, 0.4, 0.1)), np.asarray(cell.T_world_base) @ pose_matrix(near, [0.0, 0.0, 0.0]),
                     present=((0.3, 0.6), (0.9, 1.0)))
    timed = dataclasses.replace(cell, dynamic=(box,))
    world = CollisionWorld(robot, build_scene(timed, robot), cell.process.clearance)
    plain = world.copy(prefilter=False)
    outcomes = set()
    for _ in range(40):
        a = home + rng.uniform(-0.3, 0.3, robot.dof)
        b = home + rng.uniform(-0.6, 0.6, robot.dof)
        t0 = float(rng.uniform(0.0, 1.0))
        t1 = t0 + float(rng.uniform(0.0, 0.8))
        mine, theirs = world.check_segment(a, b, t0, t1), plain.check_segment(a, b, t0, t1)
        assert (mine.free, mine.checks, mine.states, mine.s_contact) == \
            (theirs.free, theirs.checks, theirs.states, theirs.s_contact)
        outcomes.add(mine.free)
    assert outcomes == {True, False}          # both verdicts were exercised


def test_pairs_cleared_near_a_short_path_are_cleared_at_each_of_its_states(
    reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator
) -> None:
    """`near` of a short path's states (an approach line: a few cm of TCP motion, here random
    steps near a contact and near nothing) leaves out only pairs every state clears: each state's
    uncleared pairs are the same with and without it, and a near check_path gives the same result.
    It does leave out most of the blocks of pairs."""
    _, robot, world = reference
    filt = world._s.prefilter
    assert filt is not None
    active = np.ones(world.n_pairs, dtype=bool)
    starts = _configs(world, robot, rng, 40)
    left_out = 0
    for start in starts:
        path = start + np.cumsum(rng.normal(0.0, 0.01, size=(6, robot.dof)), axis=0)
        path = np.clip(path, robot.limits.lower, robot.limits.upper)
        blocks, live = filt.near(path, active)
        assert not (live & ~active).any()
        plain = filt.uncleared(path, active)
        near = filt.uncleared(path, live, blocks)
        np.testing.assert_array_equal(plain[0], near[0])
        np.testing.assert_array_equal(plain[1], near[1])
        mine, theirs = world.check_path(path, near=True), world.check_path(path)
        assert (mine.free, mine.checks, mine.states, mine.s_contact) == \
            (theirs.free, theirs.checks, theirs.states, theirs.s_contact)
        left_out += int((~blocks).sum())
    assert left_out > 0.5 * len(starts) * len(filt.every_block)
    nan_path = np.vstack([starts[0], np.full(robot.dof, np.nan)])
    assert filt.near(nan_path, active)[0].all()                    # no box, no bound: every block kept


def test_each_kernel_compiles_one_specialisation(reference: tuple[CellSpec, RobotModel, CollisionWorld],
                                                 rng: np.random.Generator) -> None:
    """Every way the filter is called (one configuration, a batch, a batch by rows of `near`, the
    near tests, the joint placements) reaches each compiled function with the same argument types:
    numba compiles a function again for each new type (a literal int, a read-only or a differently
    laid out array, an omitted argument), a first plan's compile paid twice."""
    from numba.core.dispatcher import Dispatcher

    from robomax_py.world import prefilter_kernels, prefilter_reach

    _, robot, world = reference
    filt = world._s.prefilter
    assert filt is not None
    active = np.ones(world.n_pairs, dtype=bool)
    qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(8, robot.dof))
    blocks, live = filt.near(qs, active)
    filt.near_reach(qs, active)
    filt.uncleared(qs[:1], active)
    filt.uncleared(qs, active)
    filt.uncleared(qs[::2], live, blocks)
    filt.uncleared(qs, np.array([live, active]), np.array([blocks, filt.every_block]), np.arange(8) % 2)
    filt.joint_placements(qs[0])
    kernels = [f for m in (prefilter_kernels, prefilter_reach) for f in vars(m).values()
               if isinstance(f, Dispatcher) and f.py_func.__module__ == m.__name__]
    assert len(kernels) >= 10
    for kernel in kernels:   # none when its callers were loaded from numba's cache
        assert len(kernel.signatures) <= 1, (kernel.py_func.__name__, kernel.signatures)


def test_the_block_tree_leaves_out_only_blocks_their_own_test_clears(
        reference: tuple[CellSpec, RobotModel, CollisionWorld], rng: np.random.Generator) -> None:
    """A world of many scattered obstacles (60 boxes around the arm, each pair with its own margin):
    walked by its box tree (every group's blocks), the filter gives the same uncleared pairs, and
    the same `near` and `near_reach`, as walked block by block; and a row of `near`'s few blocks,
    walked by its list, what the whole walk gives."""
    import coal

    _, robot, world = reference
    s = world._s
    gm = s.geom_model.copy()
    robot_pieces = [g for g, o in enumerate(gm.geometryObjects) if int(o.parentJoint) > 0]
    n_old = gm.ngeoms
    for n in range(60):
        centre = rng.uniform([-1.6, -1.6, -0.2], [1.6, 1.6, 1.8])
        box = coal.Box(*rng.uniform(0.03, 0.4, size=3))
        gm.addGeometryObject(pin.GeometryObject(f"clutter{n}", 0, pin.SE3(pin.rpy.rpyToMatrix(*rng.uniform(-3, 3, 3)),
                                                                         centre), box))
    new_a = np.array([a for a in robot_pieces for _ in range(60)], dtype=np.int64)
    new_b = np.array([n_old + n for _ in robot_pieces for n in range(60)], dtype=np.int64)
    pair_a = np.concatenate([s.pair_a, new_a])
    pair_b = np.concatenate([s.pair_b, new_b])
    margin = np.concatenate([s.pair_margin, rng.choice([0.0, 0.01, 0.05, 0.2], size=len(new_a))])
    from robomax_py.world.acm import OBSTACLE_KINDS

    obstacle = [p.kind in OBSTACLE_KINDS for p in s.pieces] + [True] * 60
    plain = Prefilter.of(s.model, gm, obstacle, pair_a, pair_b, margin, tree_min_blocks=10**9)
    tree = Prefilter.of(s.model, gm, obstacle, pair_a, pair_b, margin, tree_min_blocks=1)
    assert plain is not None and tree is not None
    assert len(tree.ints) > len(plain.ints)                 # the tree has inner nodes, the plain walk none
    lo, hi = robot.limits.lower, robot.limits.upper
    qs = rng.uniform(lo, hi, size=(20000, robot.dof))
    listed = 0
    for active in (np.ones(len(pair_a), dtype=bool), rng.random(len(pair_a)) < 0.7):
        expected, got = plain.uncleared(qs, active), tree.uncleared(qs, active)
        np.testing.assert_array_equal(expected[0], got[0])
        np.testing.assert_array_equal(expected[1], got[1])
        assert np.isin(expected[1], np.arange(len(s.pair_a), len(pair_a))).sum() > len(qs)   # clutter is met
        for start in qs[:60]:
            path = np.clip(start + np.cumsum(rng.normal(0.0, 0.02, size=(5, robot.dof)), axis=0), lo, hi)
            tree_all = tree.uncleared(path, active)
            for mine, theirs in ((tree.near(path, active), plain.near(path, active)),
                                 (tree.near_reach(path, active), plain.near_reach(path, active))):
                for x, y in zip(mine, theirs):
                    np.testing.assert_array_equal(x, y)
            blocks, live = tree.near(path, active)
            listed += 4 * int(blocks.sum()) < len(blocks)        # a row of few blocks: walked by its list
            for got in (plain.uncleared(path, live, blocks), tree.uncleared(path, live, blocks)):
                np.testing.assert_array_equal(got[0], tree_all[0])
                np.testing.assert_array_equal(got[1], tree_all[1])
    assert listed > 10


def test_piece_bounds_find_each_point_sets_box_once(monkeypatch: Any) -> None:
    """A piece's (and each chunk's) sphere is centred on the box found for it: one principal-axes
    box per point set, and the volumes those of `_enclosing_sphere` on its own."""
    import coal

    from robomax_py.world import prefilter

    boxes: list[int] = []
    real_box = prefilter._enclosing_box

    def counted(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        boxes.append(len(points))
        return real_box(points)

    monkeypatch.setattr(prefilter, "_enclosing_box", counted)
    geom = coal.Box(0.3, 0.2, 0.1)
    got = prefilter._piece_bounds(geom, np.eye(4), True)       # an obstacle: with its chunk
    assert got is not None and got.chunk_count == 1 and len(boxes) == 2
    monkeypatch.setattr(prefilter, "_enclosing_box", real_box)
    c, r = prefilter._enclosing_sphere(got.placed)
    assert np.array_equal(got.sphere[0], c) and got.sphere[1] == r


def test_each_packed_table_has_one_name() -> None:
    """The kernels read every table at the start `prefilter_layout` names: two names for one slot (or a
    slot without a name) would read one table as another."""
    from robomax_py.world import prefilter_layout as layout

    counts = {"N_HEADER", "N_FLOAT_TABLES", "N_INT_TABLES"}
    slots = sorted(v for k, v in vars(layout).items() if k.isupper() and not k.startswith("_") and k not in counts)
    first = layout.N_HEADER
    assert slots == list(range(first, first + layout.N_FLOAT_TABLES + layout.N_INT_TABLES))
