"""The zone the preview draws for an interlock (`station.zones.meeting_box`) holds the places the
two robots would meet there: on random postures of two KR 125-class arms set close enough to come
near often, the midpoint of the nearest points of every pair of pieces that come within the margin
without overlapping (coal's distance, a second answer to the boxes the zone is made of: the midpoint
is within half the margin of both pieces) lies inside it; and `plan STATION` writes the zones it
orders, which the preview then draws."""

from __future__ import annotations

import json
from pathlib import Path

import coal
import numpy as np
import pytest

from robomax_py.station.bodies import clash_map
from robomax_py.station.zones import meeting_box

# coal's nearest points are exact to its own distance tolerance; overlapping pieces are not judged
# by them (their witness points need not lie in the overlap).
POINT_TOL_M = 1e-4


@pytest.mark.parametrize("margin", [0.05, 0.2])
def test_the_zone_holds_every_contact(bodies, random_poses, margin: float) -> None:  # type: ignore[no-untyped-def]
    a, b = bodies
    pa, pb = random_poses(7, 14)
    clash = clash_map(a, pa, b, pb, margin)
    rows, cols = slice(0, 10), slice(2, 14)
    inside = clash[rows, cols]
    assert 0 < inside.sum() < inside.size       # both answers occur
    box = meeting_box(a, pa, rows, b, pb, cols, clash, margin, np.zeros(14), np.zeros(14))
    assert box is not None
    lo, hi = np.asarray(box.lo) - POINT_TOL_M, np.asarray(box.hi) + POINT_TOL_M
    request = coal.DistanceRequest()
    found = 0
    for i, j in np.argwhere(clash):
        for u, ga in enumerate(a.pieces):
            for v, gb in enumerate(b.pieces):
                Ta, Tb = pa[i, u], pb[j, v]
                result = coal.DistanceResult()
                d = coal.distance(ga, coal.Transform3s(Ta[:3, :3], Ta[:3, 3]), gb,
                                  coal.Transform3s(Tb[:3, :3], Tb[:3, 3]), request, result)
                if not 0.0 <= d < margin or not (rows.start <= i < rows.stop and cols.start <= j < cols.stop):
                    continue
                point = (np.asarray(result.getNearestPoint1()) + np.asarray(result.getNearestPoint2())) / 2
                found += 1
                assert np.all((point >= lo) & (point <= hi)), (i, j, u, v, point, box)
    assert found > 0
    # Cells outside the two spans do not count: none of them, nor no cell at all, makes a zone.
    assert meeting_box(a, pa, slice(0, 0), b, pb, cols, clash, margin, np.zeros(14), np.zeros(14)) is None


@pytest.mark.slow
def test_plan_writes_each_interlocks_zone_and_the_preview_draws_it(crossing_station_plan: dict[str, str],
                                                                   tmp_path: Path) -> None:
    from robomax_py.app.preview_station import read_zones

    summary = json.loads(crossing_station_plan["crossing.station.json"])
    assert summary["interlocks"]
    for lock in summary["interlocks"]:
        lo, hi = np.asarray(lock["region"]["min"]), np.asarray(lock["region"]["max"])
        assert np.all(lo < hi)
        # Where two arms reaching across the part's rails meet: above the table (x 1.35-2.05 m).
        assert lo[0] < 2.05 and hi[0] > 1.35 and hi[2] > 0.7
    path = tmp_path / "crossing.station.json"
    path.write_text(crossing_station_plan["crossing.station.json"])
    zones = read_zones(path)
    assert len(zones) == len(summary["interlocks"])
    for zone, lock in zip(zones, summary["interlocks"], strict=True):
        centre = (np.asarray(lock["region"]["min"]) + np.asarray(lock["region"]["max"])) / 2
        np.testing.assert_allclose(zone.T_world_zone[:3, 3], centre, atol=1e-9)
