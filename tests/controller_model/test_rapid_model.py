"""The RAPID model on hand-written modules with hand-computed poses (expected rotations from scipy)."""

from __future__ import annotations

import math

import numpy as np
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from controller_model.common import FloatArray, RapidConfig
from controller_model.rapid import run_rapid

POS_TOL_M = 1e-9
ROT_TOL = 1e-9          # quaternions written with 9 decimals


def _known(T: FloatArray | None) -> FloatArray:
    assert T is not None, "the model left this frame undefined"
    return T


def _pose(xyz_m: tuple[float, float, float], R: FloatArray) -> FloatArray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = xyz_m
    return T


def _rz(deg: float) -> FloatArray:
    return np.asarray(Rotation.from_euler("z", deg, degrees=True).as_matrix())


C45, S45 = math.cos(math.pi / 4), math.sin(math.pi / 4)

DATA = f"""MODULE CellData
  PERS tooldata gun := [TRUE, [[200, 0, 270], [0.5, -0.5, 0.5, -0.5]], [1, [0, 0, 0.001], [1, 0, 0, 0], 0, 0, 0]];
  PERS wobjdata fixture := [FALSE, TRUE, "", [[100, 0, 0], [{C45:.12f}, 0, 0, {S45:.12f}]], [[0, 50, 0], [1, 0, 0, 0]]];
  CONST robtarget p10 := [[10, 0, 0], [1, 0, 0, 0], [0, -1, -2, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
ENDMODULE
"""

MAIN = """%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%
MODULE Main
  CONST jointtarget home := [[0, -90, 90, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST zonedata z_stop := [TRUE, 0, 0, 0, 0, 0, 0];
  PROC main()
    MoveAbsJ home, v1000, fine, gun;  ! home
    MoveL p10, v500, fine, gun \\WObj:=fixture;
    spot_weld 1, 0.500;
    MoveJ p10, v500, z10, gun;
    MoveL [[0, 0, 500], [0, 1, 0, 0], [0, 0, 0, 1], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]],
          v500, z_stop, tool0;
    WaitTime \\InPos, 0.5;
    WaitDI part_present, 1;
  ENDPROC

  PROC spot_weld(num n, num weld_time)
    WaitTime \\InPos, weld_time;
  ENDPROC
ENDMODULE
"""


def test_target_is_in_uframe_times_oframe() -> None:
    run = run_rapid({"Main.mod": MAIN, "CellData.mod": DATA}, signals={"part_present": 4})
    assert run.clean, run.issues
    home, welded, free, flat = run.motions
    # uframe: 100 mm along X, turned 90 deg about Z; oframe 50 mm along the user frame's Y -> (50, 0, 0) mm;
    # the target 10 mm along the object frame's X -> (50, 10, 0) mm, turned 90 deg about Z
    assert_allclose(_known(welded.T_base_tcp), _pose((0.05, 0.01, 0.0), _rz(90)), atol=POS_TOL_M)
    assert_allclose(_known(welded.T_base_user), _pose((0.05, 0.0, 0.0), _rz(90)), atol=POS_TOL_M)
    assert welded.config == RapidConfig(0, -1, -2, 0) and welded.kind == "linear" and welded.stops
    # no \\WObj: wobj0, the robot base
    assert_allclose(_known(free.T_base_tcp), _pose((0.01, 0.0, 0.0), np.eye(3)), atol=POS_TOL_M)
    assert free.kind == "joint" and free.blend == "z10"
    assert home.joints_deg == (0.0, -90.0, 90.0, 0.0, 0.0, 0.0) and home.T_base_tcp is None
    # a zonedata with finep TRUE is a stop point; a statement over two lines keeps its first line
    assert flat.stops and flat.where.line == 13
    assert_allclose(_known(flat.T_flange_tcp), np.eye(4), atol=POS_TOL_M)


def test_quaternion_is_scalar_first_and_tframe_is_the_tool() -> None:
    run = run_rapid({"Main.mod": MAIN, "CellData.mod": DATA}, signals={"part_present": 4})
    welded, flat = run.motions[1], run.motions[3]
    want_tool = np.asarray(Rotation.from_quat([-0.5, 0.5, -0.5, 0.5]).as_matrix())   # scipy: x, y, z, w
    assert_allclose(_known(welded.T_flange_tcp)[:3, :3], want_tool, atol=ROT_TOL)
    assert_allclose(_known(welded.T_flange_tcp)[:3, 3], [0.2, 0.0, 0.27], atol=POS_TOL_M)
    # [0, 1, 0, 0]: half a turn about X
    assert_allclose(_known(flat.T_base_tcp), _pose((0.0, 0.0, 0.5), np.diag([1.0, -1.0, -1.0])), atol=POS_TOL_M)


def test_calls_and_waits_in_order() -> None:
    run = run_rapid({"Main.mod": MAIN, "CellData.mod": DATA}, signals={"part_present": 4})
    (call,) = run.calls
    assert (call.name, call.args) == ("spot_weld", (1.0, 0.5))
    timed, di = run.waits
    assert timed.seconds == 0.5
    assert (di.signal, di.input_number, di.state) == ("part_present", 4, True)
    kinds = [type(e).__name__ for e in run.events]
    assert kinds == ["Motion", "Motion", "Call", "Motion", "Motion", "Wait", "Wait"]


def test_what_may_change_motion_is_reported() -> None:
    module = """MODULE M
  PERS tooldata fixed_gun := [FALSE, [[0, 0, 0], [1, 0, 0, 0]], [1, [0, 0, 0.001], [1, 0, 0, 0], 0, 0, 0]];
  PERS wobjdata moving := [FALSE, FALSE, "STN1", [[0, 0, 0], [1, 0, 0, 0]], [[0, 0, 0], [1, 0, 0, 0]]];
  CONST robtarget p1 := [[0, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST robtarget skew := [[0, 0, 0], [0.9, 0, 0, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  PROC main()
    MoveL Offs(p1, 0, 0, 10), v100, fine, tool0;
    MoveL p1, v100, fine, fixed_gun;
    MoveL p1, v100, fine, tool0 \\WObj:=moving;
    MoveC p1, p1, v100, fine, tool0;
    ConfL \\Off;
    IF di1 = 1 THEN
      MoveL \\Conc, p1, v100, fine, tool0;
    ENDIF
    MoveL skew, v100, fine, tool0;
    MoveL p2, v100, fine, tool0;
    p1 := CRobT();
  ENDPROC
ENDMODULE
"""
    run = run_rapid([module])
    by_line = {i.where.line: i.kind for i in run.issues}
    assert by_line == {7: "unsupported", 8: "unsupported", 9: "unsupported", 10: "unsupported", 11: "unsupported",
                       12: "unsupported", 13: "unsupported", 14: "unsupported", 15: "alarm", 16: "undefined",
                       17: "unsupported"}


def test_spot_instruction_moves_and_welds() -> None:
    module = """MODULE M
  CONST robtarget s1 := [[1000, 0, 800], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  PROC main()
    SpotL s1, vmax, spot1, gun1, tool0;
  ENDPROC
ENDMODULE
"""
    run = run_rapid([module])
    assert run.clean, run.issues
    (m,) = run.motions
    assert m.kind == "linear" and m.stops
    assert_allclose(_known(m.T_base_tcp), _pose((1.0, 0.0, 0.8), np.diag([-1.0, 1.0, -1.0])), atol=POS_TOL_M)
    (call,) = run.calls
    assert (call.name, call.args) == ("SpotL", ("spot1", "gun1"))


def test_external_axis_values_are_reported() -> None:
    module = """MODULE M
  PROC main()
    MoveL [[0, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]], v100, fine, tool0;
    MoveL [[0, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0], [1500, 9E9, 9E9, 9E9, 9E9, 9E9]], v100, fine, tool0;
  ENDPROC
ENDMODULE
"""
    run = run_rapid([module])
    assert len(run.motions) == 2
    assert [(i.where.line, i.kind) for i in run.issues] == [(4, "unsupported")]
