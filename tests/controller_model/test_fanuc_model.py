"""The FANUC TP model on hand-written .ls programs with hand-computed poses (expected rotations from
scipy)."""

from __future__ import annotations

import numpy as np
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from controller_model.common import FanucConfig, FloatArray
from controller_model.fanuc import controller_joints_deg, run_fanuc, urdf_joints_deg

POS_TOL_M = 1e-9
ROT_TOL = 1e-12

HEADER = """/PROG  {name}
/ATTR
OWNER\t\t= MNEDITOR;
DEFAULT_GROUP\t= 1,*,*,*,*;
/MN
"""


def _known(T: FloatArray | None) -> FloatArray:
    assert T is not None, "the model left this frame undefined"
    return T


def _pose(xyz_m: tuple[float, float, float], R: FloatArray) -> FloatArray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = xyz_m
    return T


def _wpr(w: float, p: float, r: float) -> FloatArray:
    """FANUC W, P, R (deg): rotations about the fixed x, y, z axes, in that order."""
    return np.asarray(Rotation.from_euler("xyz", [w, p, r], degrees=True).as_matrix())


def _cartesian(index: int, uf: int, ut: int, xyzwpr: tuple[float, ...], config: str = "N U T, 0, 0, 0") -> str:
    x, y, z, w, p, r = xyzwpr
    return (f"P[{index}]{{\n   GP1:\n\tUF : {uf}, UT : {ut},\t\tCONFIG : '{config}',\n"
            f"\tX = {x:.3f}  mm,\tY = {y:.3f}  mm,\tZ = {z:.3f}  mm,\n"
            f"\tW = {w:.3f} deg,\tP = {p:.3f} deg,\tR = {r:.3f} deg\n}};\n")


def _joint(index: int, uf: int, ut: int, joints: tuple[float, ...]) -> str:
    j = [f"J{i + 1}= {v:.3f} deg" for i, v in enumerate(joints)]
    sep = ",\t"
    return (f"P[{index}]{{\n   GP1:\n\tUF : {uf}, UT : {ut},\n\t{sep.join(j[:3])},\n"
            f"\t{sep.join(j[3:])}\n}};\n")


PROGRAM = HEADER.format(name="CELL") + """   1:  PR[1]=LPOS ;
   2:  PR[1]=PR[1]-PR[1] ;
   3:  PR[1,1]=500.000 ;
   4:  PR[1,3]=100.000 ;
   5:  PR[1,6]=90.0000 ;
   6:  UFRAME[1]=PR[1] ;
   7:  UFRAME_NUM=1 ;
   8:  UTOOL_NUM=2 ;
   9:L P[1] 100mm/sec FINE ;
  10:  CALL SPOT_WELD(1,0.500) ;
  11:  ! flange/s7 ;
  12:J P[2] 100% CNT50 ;
  13:  WAIT   0.50(sec) ;
  14:  WAIT DI[3]=ON ;
  15:J P[3] 100% FINE SPOT[SD=3,P=1,S=1,ED=3] ;
  16:  WAIT (!DI[4]) ;
/POS
""" + _cartesian(1, 1, 2, (10, 0, 0, 0, 0, 0)) + _joint(2, 1, 2, (10, -20, 30, 0, 45, 0)) \
    + _cartesian(3, 1, 2, (0, 0, 0, 10, 20, 30), "F U T, 0, 0, 0") + "/END\n"

T_TOOL = _pose((0.0, 0.0, 0.25), np.eye(3))


def test_user_frame_from_a_register_composes_before_the_position() -> None:
    run = run_fanuc(PROGRAM, utools={2: T_TOOL})
    assert run.clean, run.issues
    welded, joint, spot = run.motions
    # UFRAME[1] = (500, 0, 100) mm turned 90 deg about z: X 10 mm in it is (500, 10, 100) mm
    assert_allclose(_known(welded.T_base_tcp), _pose((0.5, 0.01, 0.1), _wpr(0, 0, 90)), atol=POS_TOL_M)
    assert_allclose(_known(welded.T_base_user), _pose((0.5, 0.0, 0.1), _wpr(0, 0, 90)), atol=POS_TOL_M)
    assert_allclose(_known(welded.T_flange_tcp), T_TOOL, atol=POS_TOL_M)
    assert welded.config == FanucConfig("N U T, 0, 0, 0", "N", "U", "T", (0, 0, 0))
    assert welded.kind == "linear" and welded.stops and welded.where.line == 14
    assert joint.joints_deg == (10.0, -20.0, 30.0, 0.0, 45.0, 0.0) and joint.blend == "CNT50"
    assert isinstance(spot.config, FanucConfig) and spot.config.flip == "F"


def test_wpr_are_fixed_axis_rotations_x_then_y_then_z() -> None:
    spot = run_fanuc(PROGRAM, utools={2: T_TOOL}).motions[2]
    user = _pose((0.5, 0.0, 0.1), _wpr(0, 0, 90))
    assert_allclose(_known(spot.T_base_tcp), user @ _pose((0, 0, 0), _wpr(10, 20, 30)), atol=ROT_TOL)
    # = Rz(R)·Ry(P)·Rx(W)
    assert_allclose(_wpr(10, 20, 30), Rotation.from_euler("ZYX", [30, 20, 10], degrees=True).as_matrix(),
                    atol=ROT_TOL)


def test_calls_spot_and_waits_in_order() -> None:
    run = run_fanuc(PROGRAM, utools={2: T_TOOL})
    kinds = [type(e).__name__ for e in run.events]
    assert kinds == ["Motion", "Call", "Motion", "Wait", "Wait", "Motion", "Call", "Wait"]
    weld, spot = run.calls
    assert (weld.name, weld.args) == ("SPOT_WELD", (1.0, 0.5))
    assert (spot.name, spot.args) == ("SPOT", ("SD=3", "P=1", "S=1", "ED=3"))
    timed, di, not_di = run.waits
    assert timed.seconds == 0.5
    assert (di.input_number, di.state) == (3, True)
    assert (not_di.input_number, not_di.state) == (4, False)


def test_frames_may_come_from_a_setup_program() -> None:
    setup = HEADER.format(name="CELL_FRAMES") + """   1:  PR[5]=LPOS ;
   2:  PR[5]=PR[5]-PR[5] ;
   3:  PR[5,3]=250.000 ;
   4:  UTOOL[2]=PR[5] ;
/POS
/END
"""
    run = run_fanuc(PROGRAM, setup={"CELL_FRAMES.ls": setup})
    assert run.clean, run.issues
    assert_allclose(_known(run.motions[0].T_flange_tcp), T_TOOL, atol=POS_TOL_M)


def test_frame_numbers_must_match_the_position_and_frames_must_be_known() -> None:
    program = HEADER.format(name="BAD") + """   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=1 ;
   3:L P[1] 100mm/sec FINE ;
   4:  PR[7,1]=3.000 ;
/POS
""" + _cartesian(1, 1, 2, (10, 0, 0, 0, 0, 0)) + "/END\n"
    run = run_fanuc(program)
    kinds = sorted((i.where.line, i.kind) for i in run.issues)
    # line numbers are the file's: /MN starts on line 6
    assert kinds == [(8, "alarm"), (8, "undefined"), (8, "undefined"), (9, "undefined")]
    assert run.motions[0].T_base_tcp is None


def test_what_may_change_motion_is_reported() -> None:
    program = HEADER.format(name="ODD") + """   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=0 ;
   3:  LBL[1] ;
   4:J P[1] 100% FINE Offset,PR[2] ;
   5:J PR[3] 100% FINE ;
   6:  IF DI[1]=ON,JMP LBL[1] ;
   7:L P[1] 100mm/sec FINE TB .10sec,P-SPS ;
      1:  DO[1]=ON ;
       ------ ;
   8:C P[1]
    :  P[1] 100mm/sec FINE ;
   9:  //L P[1] 100mm/sec FINE ;
  10:  CALL MOVER(1) ;
  11:  JMP LBL[1] ;
/POS
""" + _joint(1, 0, 0, (0, 0, 0, 0, -90, 0)) + "/END\n"
    mover = HEADER.format(name="MOVER") + "   1:J P[1] 100% FINE ;\n/POS\n" + _joint(1, 0, 0, (0,) * 6) + "/END\n"
    run = run_fanuc(program, called={"mover.ls": mover})
    # the call with an argument is not followed; the jump back to LBL[1] repeats without end
    assert {i.where.line for i in run.unsupported} == {9, 10, 11, 12, 13, 15, 18, 19}
    assert [c.name for c in run.calls] == ["MOVER"]
    assert len(run.motions) == 1     # the L with TB is read (its point logic is reported)
    assert run.stopped is not None and run.stopped.line == 19


def test_the_flow_is_followed() -> None:
    """A CALL of a given program runs it (its positions its own), JMP LBL[n] skips to LBL[n], END
    and PAUSE stop the program; a JMP under an IF ... THEN is reported, not taken."""
    program = HEADER.format(name="FLOW") + """   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=0 ;
   3:  CALL MOVER ;
   4:  JMP LBL[2] ;
   5:J P[1] 100% FINE ;
   6:  LBL[2:after] ;
   7:  IF (DI[1]=ON) THEN ;
   8:  JMP LBL[3] ;
   9:  ENDIF ;
  10:J P[1] 50% FINE ;
  11:  LBL[3] ;
  12:  PAUSE ;
  13:J P[1] 100% FINE ;
/POS
""" + _joint(1, 0, 0, (0, 0, 0, 0, -90, 0)) + "/END\n"
    mover = HEADER.format(name="MOVER") + "   1:J P[1] 100% FINE ;\n   2:  END ;\n   3:J P[1] 100% FINE ;\n/POS\n" \
        + _joint(1, 0, 0, (10, 0, 0, 0, 0, 0)) + "/END\n"
    run = run_fanuc(program, called={"mover.ls": mover})
    assert [(m.where.source, m.joints_deg) for m in run.motions] == [("mover.ls", (10.0, 0.0, 0.0, 0.0, 0.0, 0.0)),
                                                                      ("program.ls", (0.0, 0.0, 0.0, 0.0, -90.0, 0.0))]
    assert {i.where.line for i in run.unsupported} == {12, 13, 14}     # IF ... THEN, the JMP under it, ENDIF
    assert run.stopped is not None and run.stopped.line == 17        # PAUSE


def test_j2_j3_coupling_counts_j3_from_the_horizontal() -> None:
    urdf = (5.0, 20.0, -30.0, 1.0, 2.0, 3.0)
    controller = controller_joints_deg(urdf, j23_coupling=True)
    assert controller == (5.0, 20.0, -50.0, 1.0, 2.0, 3.0)     # J3 - J2 of the URDF
    assert urdf_joints_deg(controller, j23_coupling=True) == urdf
    assert controller_joints_deg(urdf, j23_coupling=False) == urdf
    assert run_fanuc(PROGRAM, utools={2: T_TOOL}, j23_coupling=True).j23_coupling


def test_extended_axes_are_reported() -> None:
    position = _joint(1, 0, 0, (0, 0, 0, 0, -90, 0)).replace("\n};", ",\tE1= 350.000  mm\n};")
    program = HEADER.format(name="RAIL") + "   1:  UFRAME_NUM=0 ;\n   2:  UTOOL_NUM=0 ;\n   3:J P[1] 100% FINE ;\n" \
        + "/POS\n" + position + "/END\n"
    run = run_fanuc(program)
    assert len(run.motions) == 1
    assert [(i.where.line, i.kind) for i in run.issues] == [(8, "unsupported")]
