"""The preview's carried parts: where each transfer's part is on the program's clock."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robomax_py.app.preview_parts import carried_parts
from robomax_py.io.cell import load_cell

REPO = Path(__file__).resolve().parents[2]


def test_a_part_lies_is_carried_and_is_handed_over() -> None:
    cell = load_cell(REPO / "cells" / "pick_place.yaml")
    spots = [s for seam in cell.seams for s in seam.spots]
    stops = [{"seam": "transfers", "name": s.name, "t_arrive": 10.0 * k + 1.0, "t_leave": 10.0 * k + 2.0}
             for k, s in enumerate(spots)]
    parts = carried_parts(cell, stops)
    assert len(parts) == 10
    first = parts[0]                                  # t1: housing low_1 -> a_1, gripped at 1 s, released at 12 s
    assert (first.t_grip, first.t_release) == (1.0, 12.0)
    tcp = np.eye(4)
    tcp[:3, 3] = [0.1, 0.2, 0.3]
    np.testing.assert_allclose(first.pose(0.5, tcp)[:3, 3], [0.8, -0.3, 0.5], atol=1e-12)      # on low_1
    np.testing.assert_allclose(first.pose(5.0, tcp), tcp @ cell.part("housing").T_tcp_part)   # in the gripper
    np.testing.assert_allclose(first.pose(20.0, tcp)[:3, 3], [0.25, -0.95, 0.75], atol=1e-12)  # on a_1
    # Transfer 4 picks from a_1 what transfer 1 put there: t1's part is hidden from then on, and
    # t4's object appears only once t1 has released there.
    fourth = parts[3]
    assert fourth.t_shown == first.t_release and first.t_hidden == fourth.t_grip
    assert first.pose(fourth.t_grip + 1.0, tcp) is None
    assert fourth.pose(first.t_release - 0.5, tcp) is None


def test_cells_without_parts_carry_nothing() -> None:
    cell = load_cell(REPO / "cells" / "tending.yaml")
    assert carried_parts(cell, [{"seam": "tending", "name": "c1_conveyor_pick", "t_arrive": 1.0, "t_leave": 2.0}]) == []
