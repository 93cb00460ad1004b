"""Configuration data against values published with joint values (or their signs), per brand.

FANUC: RoboGuide's own configuration letters for CRX-10iA joint solutions, on a CRX-10iA built here
from the same source's kinematic table. KUKA: Status and Turn written by a KSS 8.3 controller into
real .dat files (their joint values are not published, their signs are: T). ABB: confdata RoboDK
wrote for an IRB 1200 target, and the quadrant numbering of ABB's RAPID reference.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from robomax_py.app.import_urdf import import_urdf
from robomax_py.io.robot import load_robot_spec
from robomax_py.robot import JointLimits, RobotModel, fk_flange, load_robot
from robomax_py.robot.ik.config import brand_text
from robomax_py.robot.solve import brand_text_of, config_texts_near
from robomax_py.spec import ControllerSpec
from tests.robot.vendor_config import arm_geometry, fanuc_text, posture, wrist_point

ROSI = Path(__file__).parent.parent / "data" / "rosi"
IMPORTED = {
    "irb2400": ROSI / "abb_irb2400_support/urdf/irb2400.xacro",
    "m20ia": ROSI / "fanuc_m20ia_support/urdf/m20ia.xacro",
    "kr120r2500pro": ROSI / "kuka_kr120_support/urdf/kr120r2500pro.xacro",
}
# The CRX fixture's positions are rounded to 0.01 mm.
CSV_POSITION_TOL_M = 2e-5
CONFIG_TOL_RAD = math.radians(0.01)


@pytest.fixture(scope="module")
def rosi(tmp_path_factory: pytest.TempPathFactory) -> dict[str, RobotModel]:
    """The ROS-Industrial arms of tests/data/rosi, imported as `robomax import-urdf` does."""
    root = tmp_path_factory.mktemp("robots")
    return {name: load_robot(load_robot_spec(import_urdf(source, root / name, (ROSI,)).folder / "robot.yaml"))
            for name, source in IMPORTED.items()}

# ------------------------------------------------------------------------------------- FANUC

# frfournier/robodk_crx_kinematics@2dde7c7e01158546ae4800e1e27e0a4268940a23 (Apache-2.0):
# tests/conftest.py lines 125-131, the CRX-10iA's modified DH rows (alpha, a, theta, d), mm and rad,
# line 105 the joint senses (1, 1, -1, -1, -1, -1), and src/crx_solver.cpp lines 106-128: DH
# angle = theta + sense * J, except J3's = theta - J2 + sense3 * J3 (J3 counted from the
# horizontal, as the controller counts it). The base frame is FANUC's world, at the J2 height.
CRX_DH = [(0.0, 0.0, 0.0, 0.245), (-math.pi / 2, 0.0, -math.pi / 2, 0.0), (0.0, 0.540, 0.0, 0.0),
          (-math.pi / 2, 0.0, 0.0, 0.540), (math.pi / 2, 0.0, 0.0, -0.150), (-math.pi / 2, 0.0, 0.0, 0.160)]
# DH angle per URDF joint value: +J1, +J2, -(J3 + J2) = -J3 of the URDF (robomax's J3 with
# j23_coupling: URDF J3 = controller J3 + J2), -J4, -J5, -J6.
CRX_AXIS_SIGN = [1, 1, -1, -1, -1, -1]

# tests/fixtures/CRX10iA-solutions.csv of the same commit ("FANUC RoboGuide simulation results",
# tests/README.md): csv line, X, Y, Z (mm), J1..J6 (deg, as the controller counts them), letters.
# Test case 11 ("ALL8") has one solution in each of the eight configurations.
CRX_ROWS = [
    (11, (700, 150, 0), (0, 28.797, -35.453, -180, 54.547, 0), "F U T"),
    (12, (700, 150, 0), (-155.811, -125.453, 118.797, -180, -151.203, 155.811), "N U B"),
    (13, (700, 150, 0), (0, 125.453, 61.203, -180, 151.203, 0), "F D T"),
    (14, (700, 150, 0), (-155.811, -28.797, 215.453, -180, -54.547, 155.811), "N D B"),
    (16, (700, -150, 540), (0, 90, 90, 0, -90, 0), "N D T"),
    (19, (120.93, -304.29, 523.66), (-53.304, -41.707, -3.066, 94.105, -36.806, 84.878), "N U T"),
    (20, (120.93, -304.29, 523.66), (-94.524, -46.154, 8.411, 151.588, 9.543, 28.079), "F U T"),
    (21, (120.93, -304.29, 523.66), (-29.111, 79.789, 115.78, 63.37, -102.215, -157.121), "N D T"),
    (22, (120.93, -304.29, 523.66), (-100.556, 73.206, 133.278, 165.642, 132.372, -9.788), "F D T"),
    (23, (120.93, -304.29, 523.66), (150.889, -79.789, 64.22, -116.63, -102.215, -157.121), "N U B"),
    (24, (120.93, -304.29, 523.66), (79.444, -73.206, 46.722, -14.358, 132.372, -9.788), "F U B"),
    (25, (120.93, -304.29, 523.66), (85.476, 46.154, 171.589, -28.412, 9.543, 28.079), "F D B"),
    (26, (120.93, -304.29, 523.66), (126.696, 41.707, 183.066, -85.895, -36.806, 84.878), "N D B"),
]
# Line 15: all joints 0, J5 = 0 exactly, the wrist singularity: RoboGuide writes N there.
CRX_SINGULAR_ROW = (15, (700, -150, 540), (0, 0, 0, 0, 0, 0), "N U T")


def crx10ia() -> RobotModel:
    parts = ['<robot name="crx10ia">', '<link name="world"/>']
    for k, ((alpha, a, theta, d), sign) in enumerate(zip(CRX_DH, CRX_AXIS_SIGN, strict=True)):
        # Modified DH: Rx(alpha) Tx(a) Rz(theta) Tz(d), then the joint's turn about z. The first row's
        # d is undone by the base frame (FANUC's world at the J2 height).
        T = (pin.SE3(pin.utils.rotate("x", alpha), np.zeros(3)) * pin.SE3(np.eye(3), np.array([a, 0, 0]))
             * pin.SE3(pin.utils.rotate("z", theta), np.array([0, 0, 0 if k == 0 else d])))
        xyz = " ".join(repr(float(v)) for v in T.translation)
        rpy = " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(T.rotation))
        parent = "world" if k == 0 else f"link_{k}"
        parts.append(
            f'<joint name="joint_{k + 1}" type="revolute"><parent link="{parent}"/><child link="link_{k + 1}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/>'
            f'<axis xyz="0 0 {sign}"/><limit lower="-6.3" upper="6.3" velocity="1" effort="1"/></joint>'
            f'<link name="link_{k + 1}"/>')
    parts.append('<joint name="flange" type="fixed"><parent link="link_6"/><child link="tool0"/></joint>'
                 '<link name="tool0"/></robot>')
    model = pin.buildModelFromXML("".join(parts))
    n = model.nq
    limits = JointLimits(model.lowerPositionLimit.copy(), model.upperPositionLimit.copy(),
                         np.ones(n), np.ones(n), np.ones(n))
    return RobotModel("crx10ia", Path("crx10ia"), model, pin.GeometryModel(), pin.GeometryModel(),
                      tuple(model.names[1:]), model.getFrameId("tool0"), limits, "numeric", None, np.eye(4),
                      ControllerSpec(brand="fanuc", j23_coupling=True))


def urdf_joints(j_deg: tuple[float, ...]) -> np.ndarray:
    """FANUC J1..J6 (deg, J3 from the horizontal) -> the URDF's joint values, rad."""
    j = np.array(np.radians(j_deg), dtype=float)
    j[2] = j[2] + j[1]
    return j


@pytest.mark.parametrize(("line", "xyz_mm", "j_deg", "letters"), CRX_ROWS, ids=[f"csv{r[0]}" for r in CRX_ROWS])
def test_fanuc_letters_equal_roboguides(line: int, xyz_mm: tuple[float, ...], j_deg: tuple[float, ...],
                                        letters: str) -> None:
    """RoboGuide's F/N, U/D and T/B for CRX-10iA solutions: the arm built here reproduces the
    fixture's TCP positions (so the joints mean what RoboGuide meant), then robomax's letters and
    the second implementation's equal RoboGuide's. The CRX wrist is not spherical (axes 4-5 and
    5-6 meet 0.15 m apart); for these postures either meeting point gives the same letters."""
    robot = crx10ia()
    q = urdf_joints(j_deg)
    np.testing.assert_allclose(fk_flange(robot, q)[:3, 3], np.asarray(xyz_mm) / 1000.0, atol=CSV_POSITION_TOL_M)
    assert brand_text_of(robot, q, "fanuc").split(",")[0] == letters
    geom = arm_geometry(robot.model, q)
    for axes in ((3, 4), (4, 5)):
        assert fanuc_text(posture(geom, wrist_point(geom, axes)[0]), np.asarray(j_deg)).split(",")[0] == letters


def test_fanuc_letters_at_the_wrist_singularity_are_accepted() -> None:
    """At J5 = 0 exactly RoboGuide writes N (CSV line 15); SPEC §6 writes F (J5 >= 0). Both name
    the same joints, and a program written either way passes the 0.01 deg check verify makes."""
    _line, xyz_mm, j_deg, letters = CRX_SINGULAR_ROW
    robot = crx10ia()
    q = urdf_joints(j_deg)
    np.testing.assert_allclose(fk_flange(robot, q)[:3, 3], np.asarray(xyz_mm) / 1000.0, atol=CSV_POSITION_TOL_M)
    assert brand_text_of(robot, q, "fanuc") == "F U T, 0, 0, 0"
    assert f"{letters}, 0, 0, 0" in config_texts_near(robot, q, "fanuc", CONFIG_TOL_RAD)


def test_fanuc_flip_follows_j5_on_the_rosi_m20ia(rosi: dict[str, RobotModel]) -> None:
    """The same rule on an arm whose J3 turns about -y and whose controller counts J3 from the
    horizontal: CRX lines 11 and 14 have J5 = +54.5 (F) and -54.5 (N) deg; J5 is not coupled."""
    robot = rosi["m20ia"]
    assert robot.controller.j23_coupling
    for j5, letter in ((54.547, "F"), (-54.547, "N")):
        q = urdf_joints((0.0, 20.0, -10.0, 30.0, j5, 40.0))
        assert brand_text_of(robot, q, "fanuc")[0] == letter


# -------------------------------------------------------------------------------------- KUKA

# HugoDanielson/ChinaMilling@04c963fece86c21dd117b7228a9f8dfd7158cfa2, a KR C4 backup (KSS 8.3):
# (file, line, S, T) of points the controller wrote. Their joint values are not stored; the Turn
# bits give their signs (bit i: A(i+1) < 0), and Status bit 2 must follow A5's sign. KSS 8.3 also
# sets Status bit 4 (16) on taught points; its meaning is not configuration, so S is read mod 8.
KSS_POINTS = [
    ("KRC/R1/TP/Milling/spindle_main.dat", 18, 2, 34),
    ("KRC/R1/TP/Milling/spindle_main.dat", 24, 22, 26),
    ("KRC/R1/TP/Milling/spindle_main.dat", 28, 22, 50),
    ("KRC/R1/TP/Milling/amm_periphery.dat", 14, 18, 35),
]


@pytest.mark.parametrize(("path", "line", "s", "t"), KSS_POINTS, ids=[f"{p.rsplit('/', 1)[1]}:{ln}" for p, ln, _, _ in KSS_POINTS])
def test_kuka_status_and_turn_written_by_a_controller(rosi: dict[str, RobotModel], path: str, line: int, s: int,
                                                      t: int) -> None:
    """On the ROS-Industrial KR 120 R2500 pro: a posture with the signs T states, elbow up and in
    the basic area as S bits 0 and 1 state (A2 = -60 deg, A3 = +100 deg: wrist point in front of
    A1 and of the line through A2 and A3), reads back as the controller's S (mod 8) and T."""
    robot = rosi["kr120r2500pro"]
    assert s & 0b011 == 0b010                      # every point here: basic area, elbow up
    magnitude_deg = np.array([30.0, 60.0, 100.0, 40.0, 50.0, 60.0])
    sign = np.array([-1.0 if t >> i & 1 else 1.0 for i in range(6)])
    q = np.radians(sign * magnitude_deg)
    assert brand_text_of(robot, q, "kuka") == f"S{s & 7:03b} T{t:06b}"


# --------------------------------------------------------------------------------------- ABB


def test_abb_quadrants_as_the_rapid_reference_numbers_them() -> None:
    """RAPID reference, confdata: "quadrant 0 is the first quarter revolution, 0-90°, in a positive
    direction from the zero position; quadrant 1 is the next revolution, 90-180°, etc. Quadrant -1
    is the revolution 0° - (-90°)"; ros-industrial/abb_robot_driver_interfaces@f5d7d1176eaf4658bc74ca7675f359b19448d4d3
    abb_rapid_msgs/msg/RobTarget.msg: "The first positive quarter revolution 0 to 90 degrees is
    defined as 0"."""
    q = np.radians([45.0, 0.0, 0.0, 135.0, 30.0, -45.0])
    assert brand_text("abb", 0, 0, q).startswith("[0,1,-1,")
    q = np.radians([-135.0, 0.0, 0.0, 275.0, 30.0, -300.0])
    assert brand_text("abb", 0, 0, q).startswith("[-2,3,-4,")


def test_abb_cfx_as_robodk_wrote_it(rosi: dict[str, RobotModel]) -> None:
    """RoboDK v3.6.2 for an IRB 1200 (RoboDK/Industrial-Robots-VSCode@6b1e43c3ce604fa1774533eb6b6437621376da46
    examples/Program.mod, MIT): line 22 moves to J = (0, -3.687, -0.703, 0, -56.115, 0) deg and
    line 24 moves linearly from there with confdata [0,0,-1,1]: cfx 1 = wrist centre in front of
    axis 1 and of the lower arm, axis 5 negative (cf6 -1 there: J6 just below 0 after the move).
    The IRB 1200 is not in this repository; the ROS-Industrial IRB 2400 counts its joints the same
    way, and at this posture (lower arm upright, forearm ahead) the wrist centre is far from
    either boundary on both."""
    robot = rosi["irb2400"]
    q = np.radians([0.0, -3.686624, -0.702897, 0.0, -56.114712, 0.0])
    assert brand_text_of(robot, q, "abb") == "[0,0,0,1]"
