"""The open-side detour (`Sequencer._open_side_detour`): round a clamp whose lift is blocked by the
clamp above it, off the flange, across in front of the clamp's jaw, back on.

tests/data/boxed_in_clamp.yaml holds two spots either side of a toggle clamp on a flange row and a
second clamp 0.6 m straight above it (stacked rows of flange). Every move between the two spots'
candidates that is blocked is checked with each detour kind: where the lift and the withdrawn
detour fail, the open side finds a way for the first of them; without the clamp above, the lift
finds it.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import PlanOptions, resolved_options
from robomax_py.plan.candidates import seam_candidates
from robomax_py.plan.graph import Sequencer
from robomax_py.plan.graph_detours import OPEN_SIDE_M, WITHDRAW_M
from robomax_py.plan.roadmap import Detour, Roadmap
from robomax_py.plan.sequence import HOME
from robomax_py.robot import fk_tcp
from robomax_py.spec import Box
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.scene import build_scene

CELL = Path(__file__).resolve().parents[1] / "data" / "boxed_in_clamp.yaml"
POS_TOL_M = 1e-4            # the TCP at a waypoint against the offset it was solved for (IK is exact)


def _sequencer(path: Path) -> tuple[Sequencer, Any]:
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    spots, _ = seam_candidates(cell, robot, world, 0)
    options = resolved_options(cell, PlanOptions())
    rng = np.random.default_rng(cell.planner.seed)
    anchors = np.vstack([cell.home, *[c.q_app for c in spots]])
    roadmap = Roadmap(world, robot.limits, anchors, rng, options.roadmap_nodes, options.roadmap_k, seeds=anchors)
    return Sequencer(cell, robot, world, roadmap, spots, options, rng), cell


def _first_blocked(seq: Sequencer) -> tuple[int, int]:
    """The fastest candidate pair of the two spots whose straight move is blocked."""
    est = seq.estimate(0, 1)
    for flat in np.argsort(est, axis=None, kind="stable"):
        a, b = (int(x) for x in np.unravel_index(int(flat), est.shape))
        if np.isfinite(est[a, b]) and not seq._try_straight(0, a, 1, b):
            return a, b
    raise AssertionError("no blocked move between the two spots")


@pytest.fixture(scope="module")
def boxed() -> tuple[Sequencer, Any, tuple[int, int]]:
    seq, cell = _sequencer(CELL)
    assert [c.name for c in seq.spots] == ["p8", "p9"]
    return seq, cell, _first_blocked(seq)


def test_the_open_side_clears_a_clamp_whose_lift_is_blocked_by_a_clamp_above(boxed: tuple[Sequencer, Any, tuple[int, int]]) -> None:
    seq, _, (a, b) = boxed
    assert seq._lift_detour(0, a, 1, b) is None
    assert seq._withdrawn_detour(0, a, 1, b) is None
    # The searched detour's local map repairs its paths (plan.cspace_detour) and may find a way
    # round too; whatever it finds must be free.
    searched = seq._searched_detour(0, seq.q(0)[a], seq.q(1)[b])
    if searched is not None:
        for q0, q1 in itertools.pairwise(searched.waypoints):
            assert seq.world.check_segment(q0, q1).free
    det = seq._open_side_detour(0, a, 1, b)
    assert det is not None
    wp = det.waypoints
    np.testing.assert_array_equal(wp[0], seq.q(0)[a])
    np.testing.assert_array_equal(wp[-1], seq.q(1)[b])
    for q0, q1 in itertools.pairwise(wp):          # checked again here, independently of the search
        assert seq.world.check_segment(q0, q1).free


def test_open_side_detour_geometry(boxed: tuple[Sequencer, Any, tuple[int, int]]) -> None:
    """Off the flange perpendicular to the electrode axis, then against the approach line (-TCP z)
    by one of OPEN_SIDE_M, across, and the same back; the across move runs in front of the jaw."""
    seq, cell, (a, b) = boxed
    det = seq._open_side_detour(0, a, 1, b)
    assert det is not None and len(det.waypoints) == 6
    T = fk_tcp(seq.robot, det.waypoints)
    for start, exit_, side in ((0, 1, 2), (5, 4, 3)):
        z = T[start, :3, 2]
        off = T[exit_, :3, 3] - T[start, :3, 3]
        assert abs(float(off @ z)) < POS_TOL_M
        assert min(abs(float(np.linalg.norm(off)) - w) for w in WITHDRAW_M) < POS_TOL_M
        step = T[side, :3, 3] - T[exit_, :3, 3]
        d = float(-(step @ z))
        assert min(abs(d - s) for s in OPEN_SIDE_M) < POS_TOL_M
        assert float(np.linalg.norm(step + d * z)) < POS_TOL_M
        np.testing.assert_allclose(T[side, :3, :3], T[start, :3, :3], atol=1e-9)   # orientation kept
    # The jaw's face towards the robot (the robot stands at the origin, the jaw box's y axis radial).
    jaw = next(o for o in cell.objects if o.name == "clamp_low_jaw")
    assert isinstance(jaw.shape, Box)
    face = float(np.linalg.norm(jaw.T_world_object[:2, 3])) - jaw.shape.extents[1] / 2
    for k in (2, 3):
        assert float(np.linalg.norm(T[k, :2, 3])) < face
    assert seq._open_side_detour(HOME, 0, 1, b) is None and seq._open_side_detour(0, a, HOME, 0) is None


def test_without_the_clamp_above_the_lift_clears_it(boxed: tuple[Sequencer, Any, tuple[int, int]],
                                                    tmp_path: Path) -> None:
    """The same two configurations, the clamp above taken away: the lift over the clamp is free."""
    seq, _, (a, b) = boxed
    data = yaml.safe_load(CELL.read_text())
    data["objects"] = [o for o in data["objects"] if not o["name"].startswith("clamp_above")]
    path = tmp_path / "one_clamp.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    alone, _ = _sequencer(path)
    # The clamp above rules out some candidates at the spots: find the same two among the others.
    a1 = int(np.flatnonzero((alone.q(0) == seq.q(0)[a]).all(axis=1))[0])
    b1 = int(np.flatnonzero((alone.q(1) == seq.q(1)[b]).all(axis=1))[0])
    assert not alone._try_straight(0, a1, 1, b1)
    assert alone._lift_detour(0, a1, 1, b1) is not None


def test_faster_takes_the_lower_estimate_and_counts_the_other(boxed: tuple[Sequencer, Any, tuple[int, int]]) -> None:
    """Where the lift fails, the open side's and the roadmap's detours are both asked: the faster
    estimate is taken (the second where equal), the other's checks counted as spent."""
    seq, _, _ = boxed
    wp = np.zeros((2, 6))
    slow, fast = Detour(wp, 2.0, 100), Detour(wp, 1.0, 7)
    before = seq.checks
    assert seq._faster(slow, fast) is fast and seq.checks == before + 100
    assert seq._faster(fast, slow) is fast and seq.checks == before + 200
    assert seq._faster(None, slow) is slow and seq._faster(fast, None) is fast and seq._faster(None, None) is None
    equal = Detour(wp, 1.0, 3)
    assert seq._faster(fast, equal) is equal
    assert seq.checks == before + 207


def test_a_lift_asks_each_lifted_end_once(boxed: tuple[Sequencer, Any, tuple[int, int]],
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    # Every pair a candidate ends lifts it the same way: the second lift from the same candidate
    # solves no inverse kinematics and gives the same answer; each cached end sits at its offset.
    from robomax_py.plan import graph_detours

    seq, _, (a, b) = boxed
    solves = 0
    solve = graph_detours.solve_all

    def counted(*args: Any, **kwargs: Any) -> Any:
        nonlocal solves
        solves += 1
        return solve(*args, **kwargs)

    monkeypatch.setattr(graph_detours, "solve_all", counted)
    seq._lift_cache.clear()
    first = seq._lift_detour(0, a, 1, b)
    assert solves > 0
    spent = solves
    assert seq._lift_detour(0, a, 1, b) == first and solves == spent
    up = seq._up()
    for (idx, col, kind, h), q in seq._lift_cache.items():
        if q is None or kind != "up":
            continue
        moved = fk_tcp(seq.robot, q)[:3, 3] - fk_tcp(seq.robot, seq.q(idx)[col])[:3, 3]
        np.testing.assert_allclose(moved, h * up, atol=POS_TOL_M)
