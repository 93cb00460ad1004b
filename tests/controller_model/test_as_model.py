"""The Kawasaki AS model on hand-computed values: OAT against scipy's intrinsic ZYZ, LMOVE as
BASE · location with the TOOL in force, ACCURACY ... FINE as a stop, SWAIT on external inputs."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from controller_model.common import Call, Motion, Wait
from controller_model.kawasaki_as import rot_oat_deg, run_as

PROGRAM = """.PROGRAM cell()
  ; a comment
  POINT tool2 = TRANS(0,0,200,0,90,0)
  POINT base3 = TRANS(1000,0,0,90,0,0)
  SPEED 50
  ACCURACY 1 FINE
  JMOVE #[0,-90,90,0,30,0]
  TOOL tool2
  BASE base3
  SPEED 250 MM/S
  ACCURACY 5.0
  LMOVE TRANS(100,20,30,0,180,0)
  ACCURACY 1 FINE
  LMOVE TRANS(100,20,0,0,180,0)
  CALL spot_weld(1,0.300) ; seam/s1
  SWAIT 1005 ; clamp
  TWAIT 0.25
.END
.PROGRAM spot_weld(n,t)
  TWAIT t
.END
"""


def test_oat_is_intrinsic_zyz() -> None:
    for oat in ((10.0, 20.0, 30.0), (-120.0, 170.0, 45.0), (0.0, 0.0, 90.0)):
        want = Rotation.from_euler("ZYZ", oat, degrees=True).as_matrix()
        np.testing.assert_allclose(rot_oat_deg(*oat), want, atol=1e-12)


def test_lmove_is_base_times_location_with_the_tool_in_force() -> None:
    run = run_as(PROGRAM, name="cell.as")
    assert run.clean, run.issues
    first, line, weld = run.motions
    assert first.joints_deg == (0.0, -90.0, 90.0, 0.0, 30.0, 0.0) and first.stops
    assert line.blend == "ACCURACY 5" and weld.stops
    # base3 turns 90 deg about z at x = 1 m: (100, 20, 0) mm lands at (1 - 0.02, 0.1, 0) m
    assert weld.T_base_tcp is not None and weld.T_flange_tcp is not None
    np.testing.assert_allclose(weld.T_base_tcp[:3, 3], [0.98, 0.1, 0.0], atol=1e-12)
    # the tool: 200 mm along the flange's z, turned 90 deg about y (O = 0, A = 90, T = 0)
    np.testing.assert_allclose(weld.T_flange_tcp[:3, 3], [0.0, 0.0, 0.2], atol=1e-12)
    np.testing.assert_allclose(weld.T_flange_tcp[:3, :3] @ [0, 0, 1], [1, 0, 0], atol=1e-12)
    # A = 180: the tool's z points down in the base frame
    np.testing.assert_allclose(weld.T_base_tcp[:3, :3] @ [0, 0, 1], [0, 0, -1], atol=1e-12)


def test_weld_call_and_waits_are_recorded() -> None:
    events = run_as(PROGRAM).events
    calls = [e for e in events if isinstance(e, Call)]
    assert [(c.name, c.args) for c in calls] == [("spot_weld", (1.0, 0.3))]
    assert isinstance(events[events.index(calls[0]) - 1], Motion)
    waits = [e for e in events if isinstance(e, Wait)]
    assert (waits[0].input_number, waits[0].state) == (5, True) and waits[1].seconds == 0.25


def test_outside_the_subset_is_reported() -> None:
    run = run_as(".PROGRAM p()\n  JMOVE here1\n  C1MOVE a\n  LMOVE nowhere\n.END\n")
    assert [i.kind for i in run.issues] == ["unsupported", "unsupported", "undefined"]
