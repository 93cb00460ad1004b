"""The Yaskawa INFORM model on hand-computed values: pulses to degrees, a rectangular position in a
user frame with the tool the controller holds, PL=0 as a stop, the weld job call and the waits."""

from __future__ import annotations

import numpy as np
import pytest

from controller_model.common import Call, Wait, homogeneous, rot_z_deg
from controller_model.inform import run_inform

PPD = (1000.0, 1000.0, 1000.0, 500.0, 500.0, 250.0)
JOB = """/JOB
//NAME CELL
//POS
///NPOS 2,0,0,0,0,0
///TOOL 2
///POSTYPE PULSE
///PULSE
C00000=10000,-90000,90000,0,15000,-2500
///USER 3
///TOOL 2
///POSTYPE USER
///RECTAN
///RCONF 0,0,0,0,0,0,0,0
C00001=100.000,20.000,0.000,180.0000,0.0000,90.0000
//INST
///DATE 2000/01/01 00:00
///ATTR SC,RW
///GROUP1 RB1
NOP
MOVJ C00000 VJ=50.00 PL=3
MOVL C00001 V=250.0 PL=0
CALL JOB:SPOTWELD ARGF1 ARGF0.300
'seam/s1 gun 1 schedule 1
WAIT IN#(5)=ON
TIMER T=0.25
END
"""
TOOL = homogeneous(np.eye(3), (0.0, 0.0, 0.2))
USER = homogeneous(rot_z_deg(90.0), (1.0, 0.0, 0.0))


def test_pulses_rectangular_positions_and_frames() -> None:
    run = run_inform(JOB, name="CELL.JBI", pulses_per_degree=PPD, tools={2: TOOL}, users={3: USER})
    assert run.clean, run.issues
    joint, line = run.motions
    assert joint.joints_deg == (10.0, -90.0, 90.0, 0.0, 30.0, -10.0) and not joint.stops
    assert line.stops and line.T_flange_tcp is TOOL
    assert line.T_base_tcp is not None
    # user frame 3 turns 90 deg about z at x = 1 m: (100, 20, 0) mm lands at (0.98, 0.1, 0) m
    np.testing.assert_allclose(line.T_base_tcp[:3, 3], [0.98, 0.1, 0.0], atol=1e-12)
    # Rx = 180, Rz = 90 (R = Rz·Ry·Rx): the tool's z points down, its x along the user frame's y
    np.testing.assert_allclose(line.T_base_tcp[:3, :3] @ [0, 0, 1], [0, 0, -1], atol=1e-12)
    np.testing.assert_allclose(line.T_base_tcp[:3, :3] @ [1, 0, 0], [-1, 0, 0], atol=1e-12)
    calls = [e for e in run.events if isinstance(e, Call)]
    assert [(c.name, c.args) for c in calls] == [("SPOTWELD", (1.0, 0.3))]
    waits = [e for e in run.events if isinstance(e, Wait)]
    assert (waits[0].input_number, waits[0].state) == (5, True) and waits[1].seconds == 0.25


@pytest.mark.parametrize("held", [{"tools": {}, "users": {3: USER}}, {"tools": {2: TOOL}, "users": {}}])
def test_a_frame_the_controller_does_not_hold_is_undefined(held: dict[str, dict[int, np.ndarray]]) -> None:
    run = run_inform(JOB, pulses_per_degree=PPD, **held)   # type: ignore[arg-type]
    assert [i.kind for i in run.issues] == ["undefined"]
