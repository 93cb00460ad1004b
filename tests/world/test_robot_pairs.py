"""Robot against robot (`world.robot_pairs`) against an exact answer of its own: two robots touch
when the convex hulls of some piece of each (every link and tool piece is convex) share a point,
which is a linear program (weights on each hull's vertices, summing to one, reaching the same
point), solved by scipy for every pair whose vertex boxes overlap. The robots stand apart from
the origin (on a riser, yawed), posed at random around a shared zone."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.optimize import linprog

from robomax_py.world.robot_pairs import (
    RobotBody,
    piece_poses,
    robot_body,
    robots_contact,
)
from robomax_py.world.scene import build_scene

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "verify"))
from station_case import ZONE_DEG, station_cells

# Configurations this close to touching (by coal's distance) are left out: the LP's and GJK's
# tolerances (~1e-9 m) could differ there, and a 0.1 mm band is far wider than both.
BORDER_M = 1e-4


def _hulls_meet(P: np.ndarray, Q: np.ndarray) -> bool:
    m, k = len(P), len(Q)
    A_eq = np.zeros((5, m + k))
    A_eq[:3, :m], A_eq[:3, m:] = P.T, -Q.T
    A_eq[3, :m], A_eq[4, m:] = 1.0, 1.0
    b_eq = np.array([0.0, 0.0, 0.0, 1.0, 1.0])
    res = linprog(np.zeros(m + k), A_eq=A_eq, b_eq=b_eq, bounds=(0, None), method="highs")
    return bool(res.status == 0)


def _vertices(body: RobotBody, poses: np.ndarray) -> list[np.ndarray]:
    return [np.asarray(g.points()) @ T[:3, :3].T + T[:3, 3] for g, T in zip(body.geometries, poses)]


def _brute_force(a: RobotBody, qa: np.ndarray, b: RobotBody, qb: np.ndarray) -> bool:
    va, vb = _vertices(a, piece_poses(a, qa)), _vertices(b, piece_poses(b, qb))
    for P in va:
        for Q in vb:
            if np.all(P.min(0) <= Q.max(0)) and np.all(Q.min(0) <= P.max(0)) and _hulls_meet(P, Q):
                return True
    return False


def _distance(a: RobotBody, qa: np.ndarray, b: RobotBody, qb: np.ndarray) -> float:
    import coal

    pa, pb = piece_poses(a, qa), piece_poses(b, qb)
    best = np.inf
    for ga, Ta in zip(a.geometries, pa):
        for gb, Tb in zip(b.geometries, pb):
            res = coal.DistanceResult()
            d = coal.distance(ga, coal.Transform3s(Ta[:3, :3], Ta[:3, 3]), gb, coal.Transform3s(Tb[:3, :3], Tb[:3, 3]),
                              coal.DistanceRequest(), res)
            best = min(best, d)
    return float(best)


@pytest.fixture(scope="module")
def bodies(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    cells = station_cells(tmp_path_factory.mktemp("pairs"))
    return {n: robot_body(n, r, build_scene(c, r)) for n, (c, r) in cells.items()}


def test_contact_agrees_with_the_hulls_linear_program(bodies: dict[str, Any]) -> None:
    rng = np.random.default_rng(7)
    a, b = bodies["r1"], bodies["r2"]
    verdicts = []
    for _ in range(16):
        # Around the zone, leaning further in (A2 forward) or back, so that some poses touch.
        qa = np.radians(np.asarray(ZONE_DEG) + rng.uniform(-12.0, 12.0, 6) + [0, rng.uniform(-5, 15), 0, 0, 0, 0])
        qb = np.radians(np.asarray(ZONE_DEG) + rng.uniform(-12.0, 12.0, 6) + [0, rng.uniform(-5, 15), 0, 0, 0, 0])
        if abs(_distance(a, qa, b, qb)) < BORDER_M:
            continue
        got = robots_contact(a, qa, b, qb) is not None
        assert got == _brute_force(a, qa, b, qb), (np.degrees(qa), np.degrees(qb))
        verdicts.append(got)
    assert any(verdicts) and not all(verdicts), "the sample must hold touching and apart poses"


def test_a_margin_counts_near_as_touching(bodies: dict[str, Any]) -> None:
    a, b = bodies["r1"], bodies["r2"]
    home = np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])
    gap = _distance(a, home, b, home)
    assert gap > 0.1 and robots_contact(a, home, b, home) is None
    assert robots_contact(a, home, b, home, margin=gap + 0.01) is not None
    assert robots_contact(a, home, b, home, margin=gap - 0.01) is None


def test_a_contact_between_two_free_poses_is_found_by_the_sweep(bodies: dict[str, Any]) -> None:
    """r1 swings A1 through r2's arm in one step: apart at both ends, touching on the way, where a
    dense scan of the same joint-space line (0.1 % steps) first touches."""
    from robomax_py.world.robot_pairs import swept_contact

    a, b = bodies["r1"], bodies["r2"]
    zone = np.radians(np.asarray(ZONE_DEG))
    qb = zone + np.radians([0, 8, 0, 0, 0, 0])         # r2 leans into the zone
    qa0, qa1 = zone + np.radians([-70, 8, 0, 0, 0, 0]), zone + np.radians([70, 8, 0, 0, 0, 0])
    assert robots_contact(a, qa0, b, qb) is None and robots_contact(a, qa1, b, qb) is None
    dense = [s for s in np.linspace(0.0, 1.0, 1001) if robots_contact(a, qa0 + s * (qa1 - qa0), b, qb) is not None]
    assert dense, "the swing must pass through r2"
    found = swept_contact(a, (qa0, qa1), b, (qb, qb), 0.0, 0.002)
    assert found is not None
    s, _ = found
    assert min(dense) - 1e-3 <= s <= max(dense) + 1e-3
    assert robots_contact(a, qa0 + s * (qa1 - qa0), b, qb) is not None
    # r2 turned away (A1 120 deg): the same swing touches nothing on the dense scan, nor in the sweep.
    away = np.radians([120.0, -90.0, 90.0, 0.0, 0.0, 0.0])
    assert not [s for s in np.linspace(0.0, 1.0, 1001) if robots_contact(a, qa0 + s * (qa1 - qa0), b, away)]
    assert swept_contact(a, (qa0, qa1), b, (away, away), 0.0, 0.002) is None
