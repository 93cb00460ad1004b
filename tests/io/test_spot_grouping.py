"""Seams formed from a spot list's geometry (io.spot_grouping, docs/spot-lists.md "Seams"): generated
lists whose rows are known (two parallel rows, an L, a zig-zag polyline, spots zig-zagging across a
flange, a noisy straight row, a gentle arc), placed anywhere in space, in any list order; the
seams formed must be exactly the rows, each in order along its row."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from robomax_py.io.spot_grouping import (
    MAX_TURN_DEG,
    SPACING_RATIO,
    SpotGroup,
    geometric_groups,
)

# Deterministic: the same examples on every run.
CASES = settings(max_examples=60, deadline=None, derandomize=True)
# Noise of a measured or rounded spot list, in pitches: along the row, across it, off the plane.
ALONG, ACROSS, OFF = 0.1, 0.03, 0.03


def _placed(uv: np.ndarray, seed: int, shuffle: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Plane points (n, 2), m, turned and moved to anywhere in space (their normal with them) and,
    when `shuffle`, listed in a random order: (xyz, normals, order), order[k] = the plane point of row k."""
    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=seed).as_matrix()
    xyz = np.c_[uv, np.zeros(len(uv))] @ R.T + rng.uniform(-2, 2, 3)
    normals = np.tile(R[:, 2], (len(uv), 1))
    order = rng.permutation(len(uv)) if shuffle else np.arange(len(uv))
    return xyz[order], normals[order], order


def _as_rows(groups: list[SpotGroup], order: np.ndarray) -> list[list[int]]:
    """The seams formed, each as the plane points it holds in its order."""
    return [[int(order[i]) for i in g.members] for g in groups]


def _same_rows(got: list[list[int]], rows: list[list[int]], free: frozenset[int] = frozenset()) -> None:
    """Each seam is one known row, in the row's order or its reverse; a spot of `free` (a corner
    two rows share) may be in either row sharing it, at that row's end."""
    assert len(got) == len(rows), (got, rows)
    assert sorted(i for g in got for i in g) == sorted({i for r in rows for i in r})
    for seam in got:
        fits = [r for r in rows if set(seam) - free <= set(r) and set(r) - free <= set(seam)]
        assert fits, (seam, rows)
        row = [i for i in fits[0] if i in seam]
        assert seam in (row, row[::-1]), (seam, fits[0])


@CASES
@given(pitch=st.floats(0.02, 0.06), count=st.integers(3, 25), apart=st.floats(0.3, 4.0),
       stagger=st.floats(0.0, 1.0), noisy=st.booleans(), seed=st.integers(0, 2**16), shuffle=st.booleans())
def test_two_parallel_rows_are_two_seams(pitch: float, count: int, apart: float, stagger: float, noisy: bool,
                                         seed: int, shuffle: bool) -> None:
    """Rows `apart` pitches apart (closer than their spots' pitch too), the second shifted along
    by `stagger` pitches, each spot moved by up to ACROSS pitches when `noisy`: a chain of nearest
    neighbours would join them, or zig-zag between them."""
    s = np.arange(count) * pitch
    uv = np.r_[np.c_[s, np.zeros(count)], np.c_[s + stagger * pitch, np.full(count, apart * pitch)]]
    if noisy:
        uv += np.random.default_rng(seed).uniform(-ACROSS, ACROSS, uv.shape) * pitch
    xyz, normals, order = _placed(uv, seed, shuffle)
    _same_rows(_as_rows(geometric_groups(xyz, normals), order),
               [list(range(count)), list(range(count, 2 * count))])


@CASES
@given(pitch=st.floats(0.02, 0.06), first=st.integers(3, 20), second=st.integers(3, 20),
       turn_deg=st.floats(2 * MAX_TURN_DEG + 5, 140.0), corner=st.booleans(), seed=st.integers(0, 2**16),
       shuffle=st.booleans())
def test_an_l_is_two_seams(pitch: float, first: int, second: int, turn_deg: float, corner: bool, seed: int,
                           shuffle: bool) -> None:
    """Two arms meeting at a corner turned by `turn_deg` (90: an L); with `corner` a spot sits on
    the corner and belongs to either arm. (Without one, the chain turns by half the corner at each
    of the two spots beside it: a corner under twice MAX_TURN_DEG is a gentle curve.)"""
    turn = math.radians(turn_deg)
    # The corner at (0, 0): arm1 comes along x and ends on it (or a pitch short of it), arm2 leaves
    # it at `turn_deg` from a pitch beyond it.
    arm1 = np.c_[-(np.arange(first)[::-1] + (0 if corner else 1)) * pitch, np.zeros(first)]
    arm2 = np.arange(1, second + 1)[:, None] * pitch * np.array([[math.cos(turn), math.sin(turn)]])
    uv = np.r_[arm1, arm2]
    xyz, normals, order = _placed(uv, seed, shuffle)
    rows = [list(range(first)), ([first - 1] if corner else []) + list(range(first, len(uv)))]
    _same_rows(_as_rows(geometric_groups(xyz, normals), order), rows,
               frozenset({first - 1}) if corner else frozenset())


@CASES
@given(pitch=st.floats(0.02, 0.06), legs=st.lists(st.integers(4, 12), min_size=2, max_size=5),
       turn_deg=st.floats(45.0, 135.0), seed=st.integers(0, 2**16), shuffle=st.booleans())
def test_a_zig_zag_polyline_is_one_seam_per_leg(pitch: float, legs: list[int], turn_deg: float, seed: int,
                                                shuffle: bool) -> None:
    """Legs of spots turning left and right by `turn_deg` in turn, sharing the spot at each vertex.
    (Legs of at least 4 spots: with 3, turns near 120 deg put every other spot on a line of its own,
    as straight and as evenly spaced as the legs.)"""
    points, rows, at, heading = [np.zeros(2)], [], np.zeros(2), 0.0
    for n, spots in enumerate(legs):
        step = pitch * np.array([math.cos(heading), math.sin(heading)])
        row = [len(points) - 1]
        for _ in range(spots - 1):
            at = at + step
            points.append(at)
            row.append(len(points) - 1)
        rows.append(row)
        heading += math.radians(turn_deg) * (1 if n % 2 == 0 else -1)
    vertices = frozenset(r[0] for r in rows[1:])
    xyz, normals, order = _placed(np.array(points), seed, shuffle)
    _same_rows(_as_rows(geometric_groups(xyz, normals), order), rows, vertices)


@CASES
@given(pitch=st.floats(0.015, 0.04), count=st.integers(3, 30), width=st.floats(0.5, 3.0),
       seed=st.integers(0, 2**16), shuffle=st.booleans())
def test_spots_zig_zagging_across_a_flange_are_its_two_rows(pitch: float, count: int, width: float, seed: int,
                                                            shuffle: bool) -> None:
    """Spots listed alternately on the two edges of a flange `width` x their pitch apart: each spot's
    nearest neighbours are on the other edge, and a chain of them zig-zags across the flange."""
    k = np.arange(2 * count)
    uv = np.c_[k * pitch, (k % 2) * width * pitch]
    xyz, normals, order = _placed(uv, seed, shuffle)
    _same_rows(_as_rows(geometric_groups(xyz, normals), order),
               [list(range(0, 2 * count, 2)), list(range(1, 2 * count, 2))])


@CASES
@given(pitch=st.floats(0.015, 0.06), count=st.integers(2, 60), seed=st.integers(0, 2**16),
       shuffle=st.booleans())
def test_a_noisy_straight_row_is_one_seam(pitch: float, count: int, seed: int, shuffle: bool) -> None:
    """Spots moved by up to ALONG, ACROSS and OFF pitches and their normals tilted by up to 3 deg: the
    row turns by under 9 deg at a spot and its steps differ by under 1.5x, within MAX_TURN_DEG and
    SPACING_RATIO."""
    assert MAX_TURN_DEG >= 9 and SPACING_RATIO >= 1.5
    rng = np.random.default_rng(seed)
    uv = np.c_[np.arange(count) * pitch + rng.uniform(-ALONG, ALONG, count) * pitch,
               rng.uniform(-ACROSS, ACROSS, count) * pitch]
    xyz, normals, order = _placed(uv, seed, shuffle)
    R = Rotation.random(random_state=seed).as_matrix()
    xyz += np.outer(rng.uniform(-OFF, OFF, count)[order] * pitch, R[:, 2])
    tilt = Rotation.from_rotvec(rng.normal(size=(count, 3)) * math.radians(3) / math.sqrt(3) / 1.8)
    _same_rows(_as_rows(geometric_groups(xyz, tilt.apply(normals)), order), [list(range(count))])


@CASES
@given(pitch=st.floats(0.02, 0.05), step_deg=st.floats(2.0, 15.0), count=st.integers(3, 40),
       seed=st.integers(0, 2**16), shuffle=st.booleans())
def test_a_gentle_arc_is_one_seam(pitch: float, step_deg: float, count: int, seed: int, shuffle: bool) -> None:
    """Spots on a circle turning `step_deg` (under MAX_TURN_DEG) from one to the next: a flange's
    curve; short of closing the circle."""
    count = min(count, int(300 / step_deg))
    radius = pitch / (2 * math.sin(math.radians(step_deg) / 2))
    angle = np.radians(step_deg) * np.arange(count)
    xyz, normals, order = _placed(radius * np.c_[np.cos(angle), np.sin(angle)], seed, shuffle)
    _same_rows(_as_rows(geometric_groups(xyz, normals), order), [list(range(count))])


def test_a_missing_spot_keeps_a_row_a_gap_splits_it() -> None:
    """A spot left out (a step twice the pitch, within SPACING_RATIO) keeps one seam; a gap of six
    pitches (beyond GAP_FACTOR x the spacing) starts another; a lone spot is a seam of its own."""
    pitch = 0.03
    row = [k for k in range(20) if k != 7]
    xyz = np.c_[np.array(row) * pitch, np.zeros((len(row), 2))]
    normals = np.tile([0.0, 0.0, 1.0], (len(row), 1))
    assert [g.members for g in geometric_groups(xyz, normals)] == [tuple(range(len(row)))]
    split = np.r_[xyz[:10], xyz[10:] + [0.15, 0.0, 0.0]]
    assert [g.members for g in geometric_groups(split, normals)] == [tuple(range(10)), tuple(range(10, len(row)))]
    alone = np.r_[xyz, [[0.3, 0.5, 0.0]]]
    groups = geometric_groups(alone, np.r_[normals, [[0.0, 0.0, 1.0]]])
    assert [(g.name, g.members) for g in groups] == [("seam1", tuple(range(len(row)))), ("seam2", (len(row),))]


def test_spots_on_two_faces_are_two_seams() -> None:
    """A row running over a bend between two faces (normals 90 deg apart) splits at the bend."""
    pitch = 0.03
    xyz = np.c_[np.arange(10) * pitch, np.zeros((10, 2))]
    normals = np.array([[0.0, 0.0, 1.0]] * 5 + [[0.0, 1.0, 0.0]] * 5)
    assert [g.members for g in geometric_groups(xyz, normals)] == [tuple(range(5)), tuple(range(5, 10))]
