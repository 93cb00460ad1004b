"""Moving dynamic objects (world.moving, io.cell_moving): the path's interpolation, the file's
checks, and the spans' windows against a fine-step exact answer."""

from __future__ import annotations

import math
from pathlib import Path

import coal
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.spec import Box, ObjectSpec, PathMotion, frozen_array
from robomax_py.transforms import pose_matrix, rotation_angle
from robomax_py.world.moving import path_body, path_poses, spans
from robomax_py.world.scene import build_scene

DATA = Path(__file__).resolve().parents[1] / "data" / "moving"
POS_TOL_M = 1e-9
# The exact answer is sampled this finely (s): far finer than any span (tens of ms).
FINE_STEP_S = 1e-3


def _path(t: list[float], xyz: list[list[float]], rpy_deg: list[list[float]], sweep: float = 0.02) -> PathMotion:
    poses = np.stack([pose_matrix(p, np.radians(r)) for p, r in zip(xyz, rpy_deg)])
    return PathMotion(frozen_array(t), frozen_array(poses), sweep=sweep)


def test_path_poses_interpolate_linearly_and_slerp_and_hold_at_the_ends() -> None:
    motion = _path([1.0, 3.0], [[0, 0, 0], [2, 0, 0]], [[0, 0, 0], [0, 0, 90]])
    got = path_poses(motion, np.array([0.0, 1.0, 2.0, 3.0, 5.0]))
    np.testing.assert_allclose(got[:, 0, 3], [0, 0, 1, 2, 2], atol=POS_TOL_M)
    angles = [math.degrees(float(rotation_angle(got[0, :3, :3], g[:3, :3]))) for g in got]
    np.testing.assert_allclose(angles, [0, 0, 45, 90, 90], atol=1e-7)


CELL = """robomax: 1
robot: {model: kr16, home: [0, -90, 90, 0, 0, 0]}
tool: gripper_2f
tending:
  stations:
    - {name: a, xyz: [1.0, -0.5, 0.5], action: grip}
dynamic:
"""


@pytest.mark.parametrize(("entry", "key", "words"), [
    ("  - {name: p, box: [0.1, 0.1, 0.1], path: [{t: 0, xyz: [1, 0, 1]}, {t: 0, xyz: [1, 1, 1]}]}",
     "dynamic[0].path", "increase strictly"),
    ("  - {name: p, box: [0.1, 0.1, 0.1], path: [{t: 0, xyz: [1, 0, 1]}, {t: .nan, xyz: [1, 1, 1]}]}",
     "dynamic[0].path", "finite"),
    ("  - {name: p, box: [0.1, 0.1, 0.1]}", "dynamic[0]", "present: required"),
    ("  - {name: p, box: [0.1, 0.1, 0.1], pose: {xyz: [1, 0, 0]}, path: [{t: 0, xyz: [1, 0, 1]}, {t: 1, xyz: [1, 1, 1]}]}",
     "dynamic[0]", "not with path"),
    ("  - {name: p, box: [0.1, 0.1, 0.1], count: 3, path: [{t: 0, xyz: [1, 0, 1]}, {t: 1, xyz: [1, 1, 1]}]}",
     "dynamic[0]", "only with repeat"),
    ("  - {name: r, box: [0.1, 0.1, 0.1], robot: {model: kr16}, trajectory: sweep.json}", "dynamic[0]", "a robot has no box"),
    ("  - {name: r, robot: {model: kr16}}", "dynamic[0]", "trajectory: required"),
    ("  - {name: r, robot: {model: kr16}, trajectory: missing.json}", "dynamic[0].trajectory", "missing.json"),
    ("  - {name: r, robot: {model: kr16}, trajectory: bad.json}", "dynamic[0].trajectory", "increase strictly"),
])
def test_bad_moving_objects_are_named_by_file_and_key(tmp_path: Path, entry: str, key: str, words: str) -> None:
    (tmp_path / "sweep.json").write_bytes((DATA / "sweep.json").read_bytes())
    (tmp_path / "bad.json").write_text('{"format": "robomax.trajectory/1", "joints": ["a"], "t": [0, 0], "q": [[0], [1]]}')
    path = tmp_path / "cell.yaml"
    path.write_text(CELL + entry + "\n")
    with pytest.raises(CellFileError) as err:
        load_cell(path)
    assert "cell.yaml" in str(err.value) and key in str(err.value) and words in str(err.value), str(err.value)


@pytest.mark.parametrize(("old", "new", "words"), [('"joint_a1"', '"shoulder"', "shoulder"),
                                                    ("1.2217304763960306", "12.0", "outside kr16's limits")])
def test_a_trajectory_not_for_the_robot_is_refused_at_load(tmp_path: Path, old: str, new: str, words: str) -> None:
    text = (DATA / "sweep.json").read_text()
    assert old in text
    (tmp_path / "other.json").write_text(text.replace(old, new, 1))
    path = tmp_path / "cell.yaml"
    path.write_text(CELL + "  - {name: r2, robot: {model: kr16, base: {xyz: [2.45, 0, 0], rpy: [0, 0, 180]}}, "
                           "trajectory: other.json}\n")
    with pytest.raises(CellFileError) as err:
        load_cell(path)
    assert "dynamic[0].trajectory" in str(err.value) and words in str(err.value), str(err.value)


def test_a_repeated_path_is_there_in_every_pass(tmp_path: Path) -> None:
    path = tmp_path / "cell.yaml"
    path.write_text(CELL + "  - {name: p, box: [0.1, 0.1, 0.1], repeat: 5, count: 3, "
                           "path: [{t: 1, xyz: [1, -1, 1]}, {t: 3, xyz: [1, 1, 1]}]}\n")
    cell = load_cell(path)
    assert cell.dynamic[0].present == ((1.0, 3.0), (6.0, 8.0), (11.0, 13.0))
    scene = build_scene(cell, load_cell_robot(cell))
    first = scene.dynamic[0]
    assert first.present is not None and len(first.present) == 3
    assert first.present[1][0] == pytest.approx(first.present[0][0] + 5.0)


def _blocked(ghosts: list[tuple[float, float, FloatPose, float]], piece: coal.CollisionGeometry,
             probe: coal.Sphere, at: FloatPose) -> list[tuple[float, float]]:
    """The windows of the spans within their margin of the probe: what the timed search blocks."""
    out = []
    for t0, t1, T, margin in ghosts:
        if _distance(piece, T, probe, at) <= margin:
            out.append((t0, t1))
    return out


FloatPose = np.ndarray


def _distance(piece: coal.CollisionGeometry, T: FloatPose, probe: coal.Sphere, at: FloatPose) -> float:
    result = coal.DistanceResult()
    coal.distance(piece, coal.Transform3s(T[:3, :3], T[:3, 3]), probe, coal.Transform3s(np.eye(3), at),
                  coal.DistanceRequest(), result)
    return float(result.min_distance)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    knots=st.integers(2, 4),
    seed=st.integers(0, 10_000),
    sweep=st.sampled_from([0.01, 0.02, 0.05]),
)
def test_the_spans_block_every_time_a_fine_step_exact_check_finds_contact(knots: int, seed: int, sweep: float) -> None:
    """A box carried along a random path (positions, turns and times drawn) and a probe sphere
    near it: every time of a 1 ms grid at which the box at its exact pose touches the probe lies in
    the window of a span within its margin of the probe (the spans are conservative, exact in time)."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.2, 2.0, knots))
    xyz = rng.uniform(-0.5, 0.5, (knots, 3))
    rpy = rng.uniform(-180, 180, (knots, 3))
    motion = _path(list(t), xyz.tolist(), rpy.tolist(), sweep)
    shape = Box(extents=tuple(rng.uniform(0.05, 0.4, 3)))
    obj = ObjectSpec("box", shape, frozen_array(motion.T_world_object[0]), motion=motion)
    piece = coal.Box(*shape.extents)
    body = path_body(obj, (piece,))
    cut = spans(body, (float(t[0]), float(t[-1])), sweep)
    assert all(s.margin <= sweep + 1e-12 for s in cut)
    ghosts = [(s.t0, s.t1, np.asarray(s.T_world_body), s.margin) for s in cut]
    probe = coal.Sphere(0.02)
    fine = np.arange(t[0], t[-1], FINE_STEP_S)
    exact = path_poses(motion, fine)
    centre = exact[rng.integers(len(fine)), :3, 3]            # touched at that time at least
    for at in (centre, *(xyz[rng.integers(knots)] + rng.uniform(-0.3, 0.3, (2, 3)))):
        windows = _blocked(ghosts, piece, probe, at)
        touching = [tk for tk, T in zip(fine, exact) if _distance(piece, T, probe, at) <= 0.0]
        assert touching or at is not centre
        missed = [tk for tk in touching if not any(w0 <= tk <= w1 for w0, w1 in windows)]
        assert not missed, (missed[:3], windows)


# A link's point may leave the chord between two grid times by a second-order amount the margin
# does not count (world.moving): contacts deeper than this must lie in a blocked window.
ROBOT_CHORD_TOL_M = 1e-4


def test_another_robots_spans_block_every_time_a_fine_step_exact_check_finds_contact(tmp_path: Path) -> None:
    """A KR 16-class arm sweeping its axis 1 through 140 deg in 4 s (tests/data/moving/sweep.json):
    probes where its tool passes, and every 1 ms of the sweep at which a link or the tool at its
    exact pose (linear in joint space) touches one lies in a window of a span within its margin."""
    from robomax_py.world.bounds import support_points
    from robomax_py.world.moving import robot_bodies
    from robomax_py.world.scene import shape_pieces

    (tmp_path / "sweep.json").write_bytes((DATA / "sweep.json").read_bytes())
    path = tmp_path / "cell.yaml"
    path.write_text(CELL + "  - {name: r2, robot: {model: kr16, base: {xyz: [2.45, 0, 0], rpy: [0, 0, 180]}, "
                           "tool: gripper_2f}, trajectory: sweep.json}\n")
    cell = load_cell(path)
    obj = cell.dynamic[0]
    bodies = robot_bodies(obj, path, lambda mesh, part: shape_pieces(mesh)[0])
    fine = np.arange(2.0, 6.0, FINE_STEP_S)
    probe = coal.Sphere(0.005)
    tool = bodies[-1]
    # The tool's leading corner at three times: touched then, and only briefly (it moves on).
    probes = []
    for t in (3.03, 4.07, 5.21):
        T0, T1 = tool.poses(np.array([t - 1e-3, t]))
        corners = np.vstack([support_points(p, T1) for p in tool.pieces])
        probes.append(corners[int(np.argmax(corners @ (T1[:3, 3] - T0[:3, 3])))])
    checked = 0
    for body in bodies:
        cut = spans(body, (0.0, math.inf), 0.05)
        exact = body.poses(fine)
        for at in probes:
            windows = [(s.t0, s.t1) for s in cut
                       if min(_distance(p, np.asarray(s.T_world_body), probe, at) for p in body.pieces) <= s.margin]
            touching = [tk for tk, T in zip(fine, exact)
                        if min(_distance(p, T, probe, at) for p in body.pieces) <= -ROBOT_CHORD_TOL_M]
            checked += len(touching)
            missed = [tk for tk in touching if not any(w0 <= tk <= w1 for w0, w1 in windows)]
            assert not missed, (body.label, missed[:3], windows)
    assert checked > 0
