"""robomax_py's configuration data against a second implementation written from the vendors'
definitions (tests/robot/vendor_config.py), on the shipped arms and on ROS-Industrial arms imported
from tests/data/rosi; and against configuration data published with joint values.

A writer and its own reader can share a wrong convention and still agree with each other; the
second implementation shares nothing with robomax's configuration code but the definitions.
"""

from __future__ import annotations

import dataclasses
import itertools
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from robomax_py.app.import_urdf import import_urdf
from robomax_py.io.robot import load_robot_spec, shipped_robots_dir
from robomax_py.robot import RobotModel, load_robot
from robomax_py.robot.solve import brand_text_of
from tests.robot.vendor_config import (
    abb_text,
    arm_geometry,
    fanuc_text,
    joint_margin_deg,
    kuka_text,
    posture,
    wrist_point,
)

ROSI = Path(__file__).parent.parent / "data" / "rosi"
IMPORTED = {
    "irb2400": ROSI / "abb_irb2400_support/urdf/irb2400.xacro",
    "m20ia": ROSI / "fanuc_m20ia_support/urdf/m20ia.xacro",
    "kr120r2500pro": ROSI / "kuka_kr120_support/urdf/kr120r2500pro.xacro",
}
SPHERICAL = ["kr16", "kr125", *IMPORTED]
BRANDS = ("kuka", "abb", "fanuc")
# Samples this close to a value where the data changes are not decided by a program's decimals
# (SPEC §6: re-solving a target gives the planned joints within 0.01 deg).
BOUNDARY_DEG = 0.01
# Pinocchio's axes of a spherical wrist meet to round-off.
SPHERICAL_TOL_M = 1e-9


@pytest.fixture(scope="module")
def arms(tmp_path_factory: pytest.TempPathFactory) -> dict[str, RobotModel]:
    root = tmp_path_factory.mktemp("robots")
    out = {name: load_robot(load_robot_spec(shipped_robots_dir() / name / "robot.yaml")) for name in ("kr16", "kr125")}
    for name, source in IMPORTED.items():
        out[name] = load_robot(load_robot_spec(import_urdf(source, root / name, (ROSI,)).folder / "robot.yaml"))
    return out


def controller_deg(robot: RobotModel, q: np.ndarray) -> np.ndarray:
    """J1..J6 in degrees as the controller counts them: with `j23_coupling` FANUC measures J3 from
    the horizontal, J3 = J3 - J2 of the URDF (SPEC §6; ros-industrial/fanuc@8fee5e30e535378758ace26dfdffb8ab0403e23c
    fanuc_driver/src/fanuc_joint_streamer_node.cpp line 74 with fanuc_utils.h line 60, J23_factor = 1)."""
    j = np.array(np.degrees(q), dtype=float)
    if robot.controller.j23_coupling:
        j[2] = j[2] - j[1]
    return j


def vendor_texts(robot: RobotModel, q: np.ndarray, wrist: np.ndarray) -> dict[str, str]:
    p = posture(arm_geometry(robot.model, q), wrist)
    return {"kuka": kuka_text(p, q), "abb": abb_text(p, q), "fanuc": fanuc_text(p, controller_deg(robot, q))}


def joint_vectors(robot: RobotModel) -> st.SearchStrategy[np.ndarray]:
    """Joint vectors within the limits, rad, every joint more than BOUNDARY_DEG from a multiple of
    90 deg (where turn bits, quadrants, FANUC turns and F/N change): a quarter turn is drawn, then
    an angle inside it, so no draw is thrown away."""
    joints = []
    for lo, hi in zip(np.degrees(robot.limits.lower), np.degrees(robot.limits.upper), strict=True):
        spans = []
        for k in range(int(np.floor(lo / 90.0)), int(np.floor(hi / 90.0)) + 1):
            a, b = max(lo, 90.0 * k + 2 * BOUNDARY_DEG), min(hi, 90.0 * k + 90.0 - 2 * BOUNDARY_DEG)
            if b > a:
                spans.append((float(a), float(b)))
        joints.append(st.sampled_from(spans).flatmap(lambda ab: st.floats(*ab)))
    return st.tuples(*joints).map(lambda deg: np.radians(np.asarray(deg, dtype=float)))


@pytest.mark.parametrize("name", SPHERICAL)
def test_brand_text_equals_the_vendor_definitions(arms: dict[str, RobotModel], name: str) -> None:
    robot = arms[name]

    @settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(joint_vectors(robot))
    def agree(q: np.ndarray) -> None:
        geom = arm_geometry(robot.model, q)
        wrist, spread = wrist_point(geom)
        assert spread < SPHERICAL_TOL_M
        assert joint_margin_deg(q) > BOUNDARY_DEG
        assume(posture(geom, wrist).margin_deg > BOUNDARY_DEG)
        want = vendor_texts(robot, q, wrist)
        for brand in BRANDS:
            assert brand_text_of(robot, q, brand) == want[brand], (brand, np.degrees(q).round(3).tolist())

    agree()


def ur10_robot() -> RobotModel:
    if not any(str(f).endswith("ur10_robot.urdf") for f in metadata.files("example-robot-data") or []):
        pytest.skip("example-robot-data's ur10_robot.urdf not installed")
    return load_robot(load_robot_spec(shipped_robots_dir() / "ur10" / "robot.yaml"))


def test_brand_text_on_an_arm_without_a_spherical_wrist() -> None:
    """UR10: axes 4, 5 and 6 do not meet, so 'the wrist point' of the definitions is not one point.

    Axes 4 and 5 meet at one point, axes 5 and 6 at another (d5 = 0.116 m apart), and the point
    nearest all three lies between. Turn bits, quadrants, turn numbers, KUKA's A5 bit, ABB's axis-5
    sign and FANUC's F/N do not depend on it; the bits that do (KUKA bits 0 and 1, ABB cfx bits 2
    and 1, FANUC U/D and T/B) are decided only where every choice of wrist point gives the same
    answer. So robomax's data must be one of the readings the definitions allow for some choice of
    wrist point for each fact, and where the choices agree, the only one.
    """
    robot = ur10_robot()
    unique = 0

    @settings(max_examples=200, deadline=None)
    @given(joint_vectors(robot))
    def agree(q: np.ndarray) -> None:
        nonlocal unique
        geom = arm_geometry(robot.model, q)
        candidates = [wrist_point(geom, axes)[0] for axes in ((3, 4), (4, 5), (3, 4, 5))]
        postures = [posture(geom, w) for w in candidates]
        assert joint_margin_deg(q) > BOUNDARY_DEG
        assume(min(p.margin_deg for p in postures) > BOUNDARY_DEG)
        allowed: dict[str, set[str]] = {brand: set() for brand in BRANDS}
        for pa, pb in itertools.product(postures, repeat=2):
            # The fact about axis 1 from one wrist point, the facts about the arm from another.
            mixed = dataclasses.replace(pb, wrist_behind_axis1=pa.wrist_behind_axis1)
            for brand, fn in (("kuka", kuka_text), ("abb", abb_text)):
                allowed[brand].add(fn(mixed, q))
            allowed["fanuc"].add(fanuc_text(mixed, controller_deg(robot, q)))
        for brand in BRANDS:
            assert brand_text_of(robot, q, brand) in allowed[brand], (brand, np.degrees(q).round(3).tolist())
        unique += all(len(v) == 1 for v in allowed.values())

    agree()
    assert unique > 50          # most postures are decided whatever the wrist point
