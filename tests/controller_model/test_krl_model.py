"""The KRL model on hand-written snippets with hand-computed poses (expected rotations from scipy's
`Rotation`, an implementation independent of the model's own matrices)."""

from __future__ import annotations

import numpy as np
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from controller_model.common import FloatArray, KrlConfig, Motion
from controller_model.krl import run_krl

POS_TOL_M = 1e-9        # exact arithmetic on short decimals
ROT_TOL = 1e-12


def _known(T: FloatArray | None) -> FloatArray:
    """A frame the model must have determined."""
    assert T is not None, "the model left this frame undefined"
    return T


def _pose(xyz_m: tuple[float, float, float], R: FloatArray) -> FloatArray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = xyz_m
    return T


def _zyx(a: float, b: float, c: float) -> FloatArray:
    """KUKA A, B, C (deg): rotate about Z by A, then about the new Y by B, then about the new X by C."""
    return np.asarray(Rotation.from_euler("ZYX", [a, b, c], degrees=True).as_matrix())


def test_base_composes_before_the_target() -> None:
    src = """DEF t()
$TOOL = {X 0, Y 0, Z 200, A 0, B 0, C 0}
$BASE = {X 100, Y 0, Z 0, A 90, B 0, C 0}
LIN {X 10, Y 0, Z 0, A 0, B 0, C 0}
END
"""
    run = run_krl(src)
    assert run.clean, run.issues
    (m,) = run.motions
    # $BASE turned 90 deg about Z at X 100 mm: a target 10 mm along the base's X is at (100, 10, 0) mm
    assert_allclose(_known(m.T_base_tcp), _pose((0.1, 0.01, 0.0), _zyx(90, 0, 0)), atol=POS_TOL_M)
    assert_allclose(_known(m.T_flange_tcp), _pose((0.0, 0.0, 0.2), np.eye(3)), atol=POS_TOL_M)
    assert_allclose(_known(m.T_base_user), _pose((0.1, 0.0, 0.0), _zyx(90, 0, 0)), atol=POS_TOL_M)
    assert m.kind == "linear" and m.stops and m.where.line == 4


def test_abc_is_z_then_y_then_x() -> None:
    src = """DEF t()
$BASE = $NULLFRAME
$TOOL = $NULLFRAME
PTP {X 1, Y 2, Z 3, A 30, B 20, C 10, S 'B010', T 'B101010'}
END
"""
    (m,) = run_krl(src).motions
    assert_allclose(_known(m.T_base_tcp)[:3, :3], _zyx(30, 20, 10), atol=ROT_TOL)
    # extrinsic x, y, z (fixed axes) is the same rotation
    assert_allclose(_known(m.T_base_tcp)[:3, :3], Rotation.from_euler("xyz", [10, 20, 30], degrees=True).as_matrix(),
                    atol=ROT_TOL)
    assert_allclose(_known(m.T_base_tcp)[:3, 3], [0.001, 0.002, 0.003], atol=POS_TOL_M)
    assert m.config == KrlConfig(status=2, turn=42)
    assert m.kind == "joint"


SETUP = """DEF cell_frames()
TOOL_DATA[2] = {X 200, Y 0, Z 270, A -90, B 0, C -90}
BASE_DATA[3] = {X 1000, Y -500, Z 300, A 45, B 0, C 0}
END
"""

INLINE_SRC = """DEF cell()
;FOLD INI
  ;FOLD BASISTECH INI
    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )
    INTERRUPT ON 3
    BAS (#INITMOV,0 )
  ;ENDFOLD (BASISTECH INI)
;ENDFOLD (INI)
;FOLD PTP P1 Vel=100 % PDAT1 Tool[2] Base[3];%{PE}%R 8.3.48,%MKUKATPBASIS,%CMOVE,%VPTP,%P 1:PTP, 2:P1, 3:, 5:100, 7:PDAT1
$BWDSTART=FALSE
PDAT_ACT=PPDAT1
FDAT_ACT=FP1
BAS(#PTP_PARAMS,100)
PTP XP1
;ENDFOLD
;FOLD LIN P2 CONT Vel=2 m/s CPDAT1 Tool[2] Base[0];%{PE}%R 8.3.48,%MKUKATPBASIS,%CMOVE,%VLIN,%P 1:LIN, 2:P2, 3:C_DIS C_DIS, 5:2, 7:CPDAT1
$BWDSTART=FALSE
LDAT_ACT=LCPDAT1
FDAT_ACT=FP2
BAS(#CP_PARAMS,2)
LIN XP2 C_DIS C_DIS
;ENDFOLD
END
"""

INLINE_DAT = """DEFDAT cell
DECL E6POS XP1={X 100.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0,S 2,T 42,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
DECL FDAT FP1={TOOL_NO 2,BASE_NO 3,IPO_FRAME #BASE,POINT2[] " ",TQ_STATE FALSE}
DECL PDAT PPDAT1={VEL 100.000,ACC 100.000,APO_DIST 100.000,APO_MODE #CDIS,GEAR_JERK 50.0000,EXAX_IGN 0}
DECL E6POS XP2={X 500.0,Y 0.0,Z 800.0,A 0.0,B 90.0,C 0.0,S 2,T 2}
DECL FDAT FP2={TOOL_NO 2,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " ",TQ_STATE FALSE}
DECL LDAT LCPDAT1={VEL 2.00000,ACC 100.000,APO_DIST 100.000,APO_FAC 50.0000,ORI_TYP #VAR,CIRC_TYP #BASE}
ENDDAT
"""


def test_inline_forms_take_their_frames_from_fdat_and_the_stored_frames() -> None:
    run = run_krl(INLINE_SRC, INLINE_DAT, setup={"cell_frames.src": SETUP})
    assert run.clean, run.issues
    first, second = run.motions
    base = _pose((1.0, -0.5, 0.3), _zyx(45, 0, 0))
    tool = _pose((0.2, 0.0, 0.27), _zyx(-90, 0, -90))
    # BAS(#PTP_PARAMS): $BASE = BASE_DATA[3], $TOOL = TOOL_DATA[2]; 100 mm along the base's X
    assert_allclose(_known(first.T_base_user), base, atol=POS_TOL_M)
    assert_allclose(_known(first.T_flange_tcp), tool, atol=POS_TOL_M)
    assert_allclose(_known(first.T_base_tcp)[:3, 3], [1.0 + 0.1 * np.cos(np.pi / 4), -0.5 + 0.1 * np.sin(np.pi / 4), 0.3],
                    atol=POS_TOL_M)
    assert first.stops and first.config == KrlConfig(2, 42)
    # BASE_NO 0: $BASE = $WORLD
    assert_allclose(_known(second.T_base_user), np.eye(4), atol=POS_TOL_M)
    assert_allclose(_known(second.T_base_tcp), _pose((0.5, 0.0, 0.8), _zyx(0, 90, 0)), atol=POS_TOL_M)
    assert second.blend == "C_DIS C_DIS" and not second.stops


def test_stored_frames_may_come_from_the_caller() -> None:
    T_base = _pose((0.0, 0.0, 0.5), _zyx(0, 0, 180))
    run = run_krl(INLINE_SRC, INLINE_DAT, tool_data={2: np.eye(4)}, base_data={3: T_base})
    assert run.clean, run.issues
    assert_allclose(_known(run.motions[0].T_base_tcp), T_base @ _pose((0.1, 0.0, 0.0), np.eye(3)), atol=POS_TOL_M)


def test_an_unknown_stored_frame_is_reported_not_guessed() -> None:
    run = run_krl(INLINE_SRC, INLINE_DAT)
    undefined = [i for i in run.issues if i.kind == "undefined"]
    assert {i.where.line for i in undefined} == {13, 14, 20, 21}   # the BAS lines and the Cartesian targets
    assert run.motions[0].T_base_tcp is None       # BASE_DATA[3] unknown
    assert run.motions[1].T_base_tcp is not None   # BASE_NO 0 needs no stored frame


def test_initmov_activates_world_base_and_tool_one() -> None:
    src = """DEF t()
BAS (#INITMOV,0 )
LIN {X 1, Y 0, Z 0, A 0, B 0, C 0}
END
"""
    run = run_krl(src, tool_data={1: _pose((0.0, 0.0, 0.1), np.eye(3))}, base=_pose((5.0, 0, 0), np.eye(3)))
    assert run.clean, run.issues
    (m,) = run.motions
    assert_allclose(_known(m.T_base_user), np.eye(4), atol=POS_TOL_M)
    assert_allclose(_known(m.T_flange_tcp), _pose((0.0, 0.0, 0.1), np.eye(3)), atol=POS_TOL_M)


def test_axis_targets_calls_and_waits() -> None:
    src = """&ACCESS RVP
DEF t()
SIGNAL part_ok $IN[5]
DECL E6AXIS HOME_AX={A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0, E1 0, E2 0, E3 0, E4 0, E5 0, E6 0}
PTP HOME_AX
PTP {A1 10, A2 -80, A3 70, A4 5, A5 30, A6 -40} C_PTP
$VEL.CP = 0.5
$APO.CDIS = 12.5
spot_weld(1, 0.500) ; flange/s7
WAIT SEC 0.25
WAIT FOR $IN[3]
WAIT FOR NOT part_ok
WAIT FOR $IN[7]==FALSE
END

DEF spot_weld(n:IN, weld_time:IN)
  INT n
  REAL weld_time
  WAIT SEC weld_time
END
"""
    run = run_krl(src)
    assert run.clean, run.issues
    a, b = run.motions
    assert a.joints_deg == (0.0, -90.0, 90.0, 0.0, 0.0, 0.0) and a.stops and a.T_base_tcp is None
    assert b.joints_deg == (10.0, -80.0, 70.0, 5.0, 30.0, -40.0) and b.blend == "C_PTP"
    (call,) = run.calls
    assert (call.name, call.args, call.where.line) == ("spot_weld", (1.0, 0.5), 9)
    waits = run.waits
    assert waits[0].seconds == 0.25
    assert (waits[1].input_number, waits[1].state) == (3, True)
    assert (waits[2].input_number, waits[2].state, waits[2].signal) == (5, False, "part_ok")
    assert (waits[3].input_number, waits[3].state) == (7, False)
    kinds = [type(e).__name__ for e in run.events]
    assert kinds == ["Motion", "Motion", "Call", "Wait", "Wait", "Wait", "Wait"]


def test_what_may_change_motion_is_reported_with_its_line() -> None:
    src = """DEF t()
$BASE = $NULLFRAME
$TOOL = $NULLFRAME
IF $IN[1] THEN
  LIN {X 1, Y 0, Z 0, A 0, B 0, C 0}
ENDIF
LIN {X 5}
CIRC {X 1, Y 1, Z 0}, {X 2, Y 0, Z 0}
PTP_REL {A1 10}
LIN XP1:{X 0, Y 0, Z 10, A 0, B 0, C 0}
$ROBROOT = {X 0, Y 0, Z 100, A 0, B 0, C 0}
mover(1)
HALT
END

DEF mover(n:IN)
  INT n
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
END
"""
    run = run_krl(src)
    assert {i.where.line for i in run.unsupported} == {4, 6, 7, 8, 9, 10, 11, 12}
    assert len(run.motions) == 1          # the LIN inside IF is still read, and reported via the IF
    assert [c.name for c in run.calls] == ["mover"]
    assert run.stopped is not None and run.stopped.line == 13     # HALT: the program waits for a restart


def test_the_flow_is_followed() -> None:
    """A call of a DEF without parameters runs it (its RETURN back to the caller), GOTO skips to
    its label, RETURN ends the main program; a GOTO under a condition is reported, not taken."""
    src = """DEF t()
mover()
GOTO after
PTP {A1 1, A2 -90, A3 90, A4 0, A5 0, A6 0}
after:
IF $IN[1] THEN
  GOTO later
ENDIF
PTP {A1 2, A2 -90, A3 90, A4 0, A5 0, A6 0}
later:
RETURN
PTP {A1 3, A2 -90, A3 90, A4 0, A5 0, A6 0}
END

DEF mover()
  PTP {A1 4, A2 -90, A3 90, A4 0, A5 0, A6 0}
  RETURN
  PTP {A1 5, A2 -90, A3 90, A4 0, A5 0, A6 0}
END
"""
    run = run_krl(src)
    assert [m.joints_deg[0] for m in run.motions if m.joints_deg] == [4.0, 2.0]
    assert {i.where.line for i in run.unsupported} == {6, 7, 8}     # IF, the GOTO under it, ENDIF
    assert run.stopped is not None and run.stopped.line == 11


def _motion_at(motions: tuple[Motion, ...], line: int) -> Motion:
    return next(m for m in motions if m.where.line == line)


def test_frames_in_force_follow_the_statements() -> None:
    src = """DEF t()
$TOOL = TOOL_DATA[1]
$BASE = BASE_DATA[2]
LIN {X 0, Y 0, Z 0, A 0, B 0, C 0}
$BASE = $NULLFRAME
LIN {X 0, Y 0, Z 0, A 0, B 0, C 0}
END
"""
    T1 = _pose((0.0, 0.0, 0.3), np.eye(3))
    T2 = _pose((0.4, 0.0, 0.0), _zyx(0, 0, 90))
    run = run_krl(src, tool_data={1: T1}, base_data={2: T2})
    assert run.clean, run.issues
    assert_allclose(_known(_motion_at(run.motions, 4).T_base_tcp), T2, atol=POS_TOL_M)
    assert_allclose(_known(_motion_at(run.motions, 6).T_base_tcp), np.eye(4), atol=POS_TOL_M)
    assert_allclose(_known(_motion_at(run.motions, 6).T_flange_tcp), T1, atol=POS_TOL_M)


def test_a_spline_block_passes_its_points_and_stops_at_its_last() -> None:
    src = """DEF t()
$TOOL = {X 0, Y 0, Z 200, A 0, B 0, C 0}
$BASE = {X 100, Y 0, Z 0, A 90, B 0, C 0}
SPLINE
  SLIN {X 0, Y 0, Z 30, A 0, B 0, C 0} WITH $VEL.CP = 0.5
  SPL {X 10, Y 5, Z 40, A 0, B 0, C 0} WITH $VEL.CP = 1
  SPL {X 20, Y 0, Z 30, A 0, B 0, C 0}
  SLIN {X 20, Y 0, Z 0, A 0, B 0, C 0} WITH $VEL.CP = 0.5
ENDSPLINE
END
"""
    run = run_krl(src)
    assert run.clean, run.issues
    motions = run.motions
    assert [m.statement for m in motions] == ["SLIN", "SPL", "SPL", "SLIN"]
    assert [m.stops for m in motions] == [False, False, False, True]
    # Each point composed with $BASE as a LIN's: 10 mm along the base's X at (100, 10, 0) mm, turned 90 deg.
    assert_allclose(_known(motions[1].T_base_tcp), _pose((0.095, 0.01, 0.04), _zyx(90, 0, 0)), atol=POS_TOL_M)


def test_spline_forms_outside_the_model_are_reported() -> None:
    head = "DEF t()\n$TOOL = $NULLFRAME\n$BASE = $NULLFRAME\n"
    point = "{X 0, Y 0, Z 30, A 0, B 0, C 0}"
    for body, why in ((f"SPLINE\nSLIN {point}\nENDSPLINE C_SPL\n", "C_SPL"),
                      (f"SPL {point}\n", "outside"),
                      (f"SPLINE WITH $ACC = {{CP 2.0, ORI1 200, ORI2 200}}\nSLIN {point}\nENDSPLINE\n", "WITH"),
                      (f"SPLINE\nSLIN {point} WITH $ORI_TYPE = #JOINT\nENDSPLINE\n", "other variables")):
        run = run_krl(head + body + "END\n")
        assert any(i.kind == "unsupported" for i in run.issues), why


def test_robomax_spline_program_welds_at_the_spots() -> None:
    """The planner's KRL spline program (tests/golden/spline_cell, a cell moved, yawed and raised with
    its robot, targets in user frame 3 on the fixture, stored by the frames program: in the robot
    base they are where the unmoved cell's spots are in the world) runs cleanly, every block stops
    where a weld follows, and each weld is at its spot within 0.1 mm."""
    from pathlib import Path

    import yaml

    repo = Path(__file__).resolve().parents[2]
    golden = repo / "tests" / "golden" / "spline_cell"
    src, dat = ((golden / f"spline_cell{k}").read_text(encoding="cp1252") for k in (".src", ".dat"))
    setup = {"spline_cell_frames.src": (golden / "spline_cell_frames.src").read_text(encoding="cp1252")}
    run = run_krl(src, dat, setup=setup)
    assert run.clean, run.issues
    assert any(m.statement == "SPL" for m in run.motions)
    cell = yaml.safe_load((repo / "tests" / "data" / "spline_cell" / "spline_cell.yaml").read_text())
    spots = {s["name"]: np.array(s["xyz"], dtype=float) for s in cell["seams"][0]["spots"]}
    events = list(run.events)
    welds = [k for k, e in enumerate(events) if getattr(e, "name", "") == "spot_weld"]
    assert len(welds) == len(spots)
    for k in welds:
        before = next(e for e in reversed(events[:k]) if isinstance(e, Motion))
        assert before.stops, f"the motion before the weld at {events[k].where} flies by"
        tcp = _known(before.T_base_tcp)[:3, 3]
        assert min(float(np.linalg.norm(tcp - p)) for p in spots.values()) <= 1e-4
