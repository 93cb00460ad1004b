"""Arms from ROS-Industrial support packages (tests/data/rosi, see SOURCES.md there), end to end:
`import-urdf` from their xacro files, IK parameters fitted from the URDF against the packages'
own OPW parameters, FK/IK agreement, disabled pairs from the SRDF, configuration data per brand,
and (slow) cells planned on each arm whose `.srcl` and `.json` programs `verify` accepts.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner
from urdf_case import serial_urdf, six_joint_urdf

from robomax_py.app.cli import app
from robomax_py.app.import_urdf import guess_brand, import_urdf
from robomax_py.errors import RobotModelError
from robomax_py.io.robot import ROBOTS_ENV, load_robot_spec
from robomax_py.robot import fk_flange, load_robot
from robomax_py.robot.ik.fit import FitError, fit_opw, fk_agreement
from robomax_py.robot.solve import config_text, solve_all

ROSI = Path(__file__).parent.parent / "data" / "rosi"
ARMS = {
    "irb2400": ROSI / "abb_irb2400_support/urdf/irb2400.xacro",
    "m20ia": ROSI / "fanuc_m20ia_support/urdf/m20ia.xacro",
    "kr120r2500pro": ROSI / "kuka_kr120_support/urdf/kr120r2500pro.xacro",
    # Axis 1 2.6 mm off base_link's origin, tool0 0.24 mm off axis 6: fixed offsets around the OPW chain.
    "kr210l150": ROSI / "kuka_kr210_support/urdf/kr210l150.xacro",
}
SRDF = {"irb2400": ROSI / "abb_irb2400_moveit_config/config/abb_irb2400.srdf"}
# Round trips of a correct closed-form solver are at float64 round-off; 1e-9 m leaves room.
ROUND_TRIP_M = 1e-9
runner = CliRunner()


@pytest.fixture(scope="module")
def arms(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("robots")
    out = {}
    for name, source in ARMS.items():
        out[name] = import_urdf(source, root / name, (ROSI,), srdf=SRDF.get(name)).folder
    return out


def _params(folder: Path) -> dict[str, object]:
    data = yaml.safe_load((folder / "robot.yaml").read_text())
    return dict(data["ik"]["params"])


def test_import_writes_a_self_contained_folder(arms: dict[str, Path]) -> None:
    for name, folder in arms.items():
        urdf = (folder / f"{name}.urdf").read_text()
        assert "package://" not in urdf
        assert all((folder / m).is_file() for m in ("robot.yaml", f"{name}.urdf"))
        assert list((folder / "meshes").rglob("*.stl"))
        spec = load_robot_spec(folder / "robot.yaml")
        assert spec.controller.brand == {"irb2400": "abb", "m20ia": "fanuc", "kr120r2500pro": "kuka", "kr210l150": "kuka"}[name]
        robot = load_robot(spec)
        # The test copies have no visual meshes: the collision meshes stand in, with a warning.
        assert robot.visual_model.ngeoms == robot.collision_model.ngeoms


def test_fitted_parameters_equal_the_packages_own(arms: dict[str, Path]) -> None:
    # fanuc_m20ia_support/config/opw_parameters_m20ia.yaml (copied in tests/data/rosi)
    m20 = yaml.safe_load((ROSI / "fanuc_m20ia_support/config/opw_parameters_m20ia.yaml").read_text()
                         .replace("deg(-90.0)", "-90").replace("deg(180.0)", "180"))
    got = _params(arms["m20ia"])
    for k, v in m20["opw_kinematics_geometric_parameters"].items():
        assert got[k] == pytest.approx(v, abs=1e-9)
    assert got["offsets"] == pytest.approx(m20["opw_kinematics_joint_offsets"], abs=1e-7)
    assert got["sign_corrections"] == m20["opw_kinematics_joint_sign_corrections"]
    # opw_kinematics' opw_parameters_examples.h, makeIrb2400_10: a1 0.100, a2 -0.135, b 0, c1 0.615,
    # c2 0.705, c3 0.755, c4 0.085, offsets (0, 0, -pi/2, 0, 0, 0), all signs +1.
    irb = _params(arms["irb2400"])
    assert [irb[k] for k in ("a1", "a2", "b", "c1", "c2", "c3", "c4")] == pytest.approx(
        [0.1, -0.135, 0.0, 0.615, 0.705, 0.755, 0.085], abs=1e-9)
    assert irb["offsets"] == pytest.approx([0, 0, -90, 0, 0, 0], abs=1e-7)


@pytest.mark.parametrize("name", list(ARMS))
def test_fk_agrees_and_ik_round_trips(arms: dict[str, Path], name: str) -> None:
    robot = load_robot(load_robot_spec(arms[name] / "robot.yaml"))
    assert fk_agreement(robot.model, robot.flange_frame_id, robot.ik_params).position_m < ROUND_TRIP_M

    @settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(st.lists(st.floats(0.02, 0.98), min_size=6, max_size=6))
    def round_trip(u: list[float]) -> None:
        q = robot.limits.lower + np.asarray(u) * (robot.limits.upper - robot.limits.lower)
        if abs(math.sin(q[4])) < 1e-3:
            return   # wrist singular: the branch is not unique
        T = fk_flange(robot, q)
        table = solve_all(robot, T)
        sols = table.q[table.valid]
        assert len(sols)
        err = np.abs(fk_flange(robot, sols)[:, :3, 3] - T[:3, 3]).max()
        assert err < ROUND_TRIP_M
        wrapped = np.abs(np.angle(np.exp(1j * (sols - q)))).max(axis=1)
        assert wrapped.min() < 1e-6

    round_trip()


def test_offsets_off_the_axes_are_fitted_exactly(arms: dict[str, Path]) -> None:
    """kuka_kr210_support/urdf/kr210l150_macro.xacro: joint_a1 at xyz -0.00262 0.00097586 0.33099 in
    base_link (axis z), link_6-flange at xyz 0.0375 0 -0.00023924 (axis 6 along x, tool0 = flange
    turned 90 deg about y, so 0.24 mm along tool0's x)."""
    robot = load_robot(load_robot_spec(arms["kr210l150"] / "robot.yaml"))
    assert robot.ik_solver == "opw"
    params = fit_opw(robot.model, robot.flange_frame_id)
    assert params.base_xy == pytest.approx((-0.00262, 0.00097586), abs=1e-12)
    assert params.flange_xy == pytest.approx((0.00023924, 0.0), abs=1e-12)
    assert fk_agreement(robot.model, robot.flange_frame_id, params).position_m < 1e-12
    # As written to robot.yaml (9 decimals) the parameters still agree within the round-trip bound.
    assert fk_agreement(robot.model, robot.flange_frame_id, robot.ik_params).position_m < ROUND_TRIP_M
    assert _params(arms["kr210l150"])["base_xy"] == [-0.00262, 0.00097586]
    # The arms on their axes write no offset keys.
    assert not {"base_xy", "flange_xy", "flange_rpy"} & set(_params(arms["kr120r2500pro"]))
    # Nor does any arm whose tool0 has z along axis 6 write a flange rotation.
    assert not any("flange_rpy" in _params(folder) for folder in arms.values())


def _irb4400_like_urdf(path: Path, tool0_xyz: str, tool0_rpy: str) -> Path:
    """The joints of abb_irb4400_support/urdf/irb4400l_30_243_macro.xacro (axis 6 along link_6's x),
    no meshes, with tool0 placed on link_6 as given; that package publishes xyz "0.14 0 0", rpy "0 0 0"."""
    joints = [("0 0 0", "0 0 1", -2.87979, 2.87979, 2), ("0.2 0 0.68", "0 1 0", -1.2217, 1.658, 2),
              ("0 0 0.89", "0 1 0", -1.0472, 1.1345, 2), ("1.38 0 0.15", "1 0 0", -3.49, 3.49, 2),
              ("0 0 0", "0 1 0", -2.0944, 2.0944, 2), ("0 0 0", "1 0 0", -6.9813, 6.9813, 2)]
    return serial_urdf(path, "irb4400_like", joints, f'<origin xyz="{tool0_xyz}" rpy="{tool0_rpy}"/>',
                       link="link_{}", joint="joint_{}", tool0_joint="joint_6-tool0")


@pytest.mark.parametrize(("xyz", "rpy"), [("0.14 0 0", "0 0 0"), ("0.14 0.003 -0.002", "0.4 -0.7 1.1")])
def test_flange_turned_against_axis_6_fits_opw_with_a_flange_rotation(tmp_path: Path, xyz: str, rpy: str) -> None:
    """A tool0 whose z is not along axis 6 (irb4400l_30_243 as published, and a tilted one off the
    axis): OPW with `flange_rpy`, exact against the URDF, written and read back, IK reproducing the
    URDF's flange poses; and the import says the frame is not the mounting-flange convention."""
    result = import_urdf(_irb4400_like_urdf(tmp_path / "irb4400_like.urdf", xyz, rpy), tmp_path / "irb4400_like")
    assert result.solver == "opw"
    [warning] = [w for w in result.warnings if w.startswith("the flange frame 'tool0' has its z axis")]
    assert "REP 199" in warning and "--flange" in warning and "fix the URDF" in warning
    assert len(_params(result.folder)["flange_rpy"]) == 3  # type: ignore[arg-type]

    robot = load_robot(load_robot_spec(result.folder / "robot.yaml"))
    assert robot.ik_solver == "opw"
    fitted = fit_opw(robot.model, robot.flange_frame_id)
    exact = fk_agreement(robot.model, robot.flange_frame_id, fitted)
    assert exact.position_m < 1e-12 and exact.rotation_rad < 1e-12
    read_back = fk_agreement(robot.model, robot.flange_frame_id, robot.ik_params)
    assert read_back.position_m < ROUND_TRIP_M and read_back.rotation_rad < ROUND_TRIP_M

    rng = np.random.default_rng(4)
    qs = robot.limits.lower + rng.uniform(0.02, 0.98, (40, 6)) * (robot.limits.upper - robot.limits.lower)
    for q in qs[np.abs(np.sin(qs[:, 4])) > 1e-3]:
        T = fk_flange(robot, q)                       # Pinocchio on the URDF
        table = solve_all(robot, T)
        sols = table.q[table.valid]
        assert len(sols)
        T_sols = fk_flange(robot, sols)
        assert np.abs(T_sols[:, :3, 3] - T[:3, 3]).max() < ROUND_TRIP_M
        assert np.abs(T_sols[:, :3, :3] - T[:3, :3]).max() < ROUND_TRIP_M
        assert np.abs(np.angle(np.exp(1j * (sols - q)))).max(axis=1).min() < 1e-6


def _non_opw_urdf(path: Path) -> Path:
    """Six revolute joints whose axes 2 and 3 are perpendicular (neither OPW nor UR), no meshes."""
    axes = ["0 0 1", "0 1 0", "1 0 0", "1 0 0", "0 1 0", "1 0 0"]
    origins = ["0 0 0.4", "0.1 0 0.3", "0 0 0.6", "0.5 0 0", "0.2 0 0", "0.1 0 0"]
    return six_joint_urdf(path, "odd6", axes, origins)


def test_fall_back_to_numeric_ik_says_why_and_what_it_costs(tmp_path: Path) -> None:
    result = import_urdf(_non_opw_urdf(tmp_path / "odd6.urdf"), tmp_path / "odd6")
    assert result.solver == "numeric"
    [warning] = [w for w in result.warnings if w.startswith("IK falls back to the numeric solver")]
    assert "opw: axes 2 and 3 must be parallel" in warning and "ur: axes 2 and 3 must be parallel" in warning
    assert "slower" in warning and "sampling" in warning
    # No name tells the maker: robot.yaml says kuka, and the import says it guessed.
    assert result.brand == "kuka"
    [brand_note] = [w for w in result.warnings if w.startswith("the controller brand is not told")]
    assert "odd6" in brand_note and "--brand" in brand_note
    # Asked for, numeric IK is no fall-back: no warning.
    asked = import_urdf(tmp_path / "odd6.urdf", tmp_path / "odd6n", solver="numeric", brand="abb")
    assert asked.solver == "numeric" and not [w for w in asked.warnings if w.startswith("IK falls back")]
    assert asked.brand == "abb" and not [w for w in asked.warnings if w.startswith("the controller brand")]


def test_continuous_joints_are_imported_within_a_full_turn_and_named(tmp_path: Path) -> None:
    """Many descriptions make the endless wrist axes `continuous` (no limits); a controller still
    bounds them in software, and the planner needs bounds. The import makes them revolute within
    ±360 deg and says so; a robot folder written by hand with one is refused, naming the joint and
    the two ways out."""
    axes = ["0 0 1", "0 1 0", "0 1 0", "1 0 0", "0 1 0", "1 0 0"]
    origins = ["0 0 0.4", "0.1 0 0", "0 0 0.5", "0.4 0 0.05", "0 0 0", "0.1 0 0"]
    text = six_joint_urdf(tmp_path / "src.urdf", "endless6", axes, origins).read_text()
    for j in ("j4", "j6"):
        text = text.replace(f'<joint name="{j}" type="revolute">', f'<joint name="{j}" type="continuous">')
    text = text.replace('<limit lower="-3" upper="3" effort="1" velocity="2"/></joint><joint name="j5"',
                        '<limit effort="1" velocity="2"/></joint><joint name="j5"')      # j4: no bounds at all
    assert text.count('type="continuous"') == 2 and text.count('lower="-3"') == 5
    (tmp_path / "endless6.urdf").write_text(text)
    result = import_urdf(tmp_path / "endless6.urdf", tmp_path / "endless6")
    [note] = [w for w in result.warnings if "imported as revolute" in w]
    assert "j4, j6 continuous: imported as revolute within ±360 deg" in note and "endless6.urdf" in note
    robot = load_robot(load_robot_spec(tmp_path / "endless6" / "robot.yaml"))
    assert result.solver == "opw"
    np.testing.assert_allclose(robot.limits.lower[[3, 5]], -2 * math.pi)
    np.testing.assert_allclose(robot.limits.upper[[3, 5]], 2 * math.pi)
    np.testing.assert_allclose(robot.limits.velocity[[3, 5]], 2.0)
    (tmp_path / "endless6" / "endless6.urdf").write_text(text)              # the folder's URDF edited by hand
    with pytest.raises(RobotModelError, match=r"joint j4: is continuous: give it the controller's software limits"):
        load_robot(load_robot_spec(tmp_path / "endless6" / "robot.yaml"))


def test_import_warns_where_the_controllers_joint_convention_is_not_known(tmp_path: Path) -> None:
    """KUKA URDFs that follow KUKA's axis directions and zero (kr120), FANUC (driver passes the
    values through but for the J2/J3 linkage, j23_coupling) and ABB arms whose support package
    leaves J2 and J3 uncoupled (abb_driver passes the values through: irb6640) are known; the
    IRB 2400's abb_driver couples J3 with J2 (its launch file's J23_coupled), which robot.yaml does
    not state for ABB: a warning. The KR 210 L150 (A1 about +z, A2 = 0 upright, kuka_experimental
    kuka_experimental issue 98) gets its keys derived, and says so."""
    irb6640 = ROSI / "abb_irb6640_support/urdf/irb6640_185_280.xacro"
    srdf6640 = ROSI / "abb_irb6640_moveit_config/config/abb_irb6640_185_280.srdf"

    def convention(name: str) -> list[str]:
        source, srdf = (irb6640, srdf6640) if name == "irb6640" else (ARMS[name], SRDF.get(name))
        result = import_urdf(source, tmp_path / name, (ROSI,), srdf=srdf)
        # Their tool0 has z along axis 6: no flange warning.
        assert not [w for w in result.warnings if w.startswith("the flange frame")]
        return [w for w in result.warnings if "controller.joint_signs" in w]

    assert convention("kr120r2500pro") == [] and convention("m20ia") == [] and convention("irb6640") == []
    [irb2400] = convention("irb2400")
    assert "J23_coupled" in irb2400 and "joint directions and zeros taken from the URDF" in irb2400
    [kr210] = convention("kr210l150")
    assert "differ from KUKA's" in kr210 and "derived from the axes" in kr210 and "issue 98" in kr210
    assert "joint_signs" not in (tmp_path / "kr120r2500pro" / "robot.yaml").read_text()


def test_a_kawasaki_urdf_counts_its_joints_as_the_controller(tmp_path: Path) -> None:
    """Kawasaki's own driver (khi_robot) exchanges joint angles with the controller unchanged: an
    arm its package names (khi_*) imports with the brand told and no keys or warning; the same arm
    named by nothing imports as kuka with the two warnings (the brand guessed, the counting not
    known)."""
    axes = ["0 0 -1", "0 1 0", "0 1 0", "-1 0 0", "0 1 0", "-1 0 0"]
    origins = ["0 0 0.4", "0.15 0 0.28", "0 0 0.87", "0.8 0 0.27", "0.0 0 0", "0.1 0 0"]
    khi = import_urdf(six_joint_urdf(tmp_path / "rs.urdf", "khi_rs080n", axes, origins), tmp_path / "rs")
    assert khi.brand == "kawasaki"
    assert not [w for w in khi.warnings if "controller.joint_signs" in w or w.startswith("the controller brand")]
    assert "joint_signs" not in (tmp_path / "rs" / "robot.yaml").read_text()
    # (Folders deep enough that the test's own folder name, which says kawasaki, is not read.)
    (tmp_path / "ws" / "arm_support" / "urdf").mkdir(parents=True)
    other = import_urdf(six_joint_urdf(tmp_path / "ws" / "arm_support" / "urdf" / "arm.urdf", "arm", axes, origins),
                        tmp_path / "arm")
    assert other.brand == "kuka"
    assert [w for w in other.warnings if w.startswith("the controller brand is not told")]


def _axis_origins(robot, q):  # type: ignore[no-untyped-def]
    import pinocchio as pin

    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, np.asarray(q, dtype=float))
    return [data.oMi[j].translation.copy() for j in range(1, 7)]


def test_kr210_keys_count_its_joints_as_kuka_does(arms: dict[str, Path]) -> None:
    """The derived keys make the KR 210 L150's controller values those of the kr120, whose URDF
    counts as KUKA does: at the same controller values both flanges point the same way, and the
    upper arm stands upright at KUKA's mastering position A2 = -90, A3 = 90 deg (both arms' axes
    lie on the base axes, so the flange orientations agree exactly; the KR 210 L150's link origins
    are a few mm off its axes, issue 98). What the flange cannot tell (A4 + 180, -A5, A6 + 180) the
    derivation takes from the URDF's zero as the mastering position."""
    kr210 = load_robot(load_robot_spec(arms["kr210l150"] / "robot.yaml"))
    kr120 = load_robot(load_robot_spec(arms["kr120r2500pro"] / "robot.yaml"))
    signs = np.asarray(kr210.controller.joint_signs)
    zeros = np.asarray(kr210.controller.joint_zeros)
    assert list(signs) == [-1, 1, 1, -1, 1, -1]
    assert np.degrees(zeros) == pytest.approx([0, -90, 90, 0, 0, 0])
    rng = np.random.default_rng(7)
    controller_deg = [[0, -90, 90, 0, 0, 0], [30, -60, 100, 45, 20, -70], [-120, -100, 40, -150, -60, 160]]
    controller_deg += [list(rng.uniform(-120, 120, 6)) for _ in range(3)]
    for c in np.radians(controller_deg):
        q210 = (c - zeros) * signs              # the keys' definition: controller = sign * URDF + zero
        R210, R120 = fk_flange(kr210, q210)[:3, :3], fk_flange(kr120, c)[:3, :3]
        assert R210 == pytest.approx(R120, abs=1e-9)
    p = _axis_origins(kr210, (np.radians([0, -90, 90, 0, 0, 0]) - zeros) * signs)
    upper = (p[2] - p[1]) / np.linalg.norm(p[2] - p[1])
    assert upper[2] > 0.99                      # A2 = -90 deg: upright, as KUKA documents its mastering position


def test_import_is_idempotent_and_never_overwrites(tmp_path: Path) -> None:
    out = tmp_path / "m20ia"
    first = import_urdf(ARMS["m20ia"], out, (ROSI,))
    assert not first.unchanged
    assert import_urdf(ARMS["m20ia"], out, (ROSI,)).unchanged
    (out / "robot.yaml").write_text((out / "robot.yaml").read_text() + "# edited\n")
    with pytest.raises(RobotModelError, match="--force"):
        import_urdf(ARMS["m20ia"], out, (ROSI,))
    assert (out / "robot.yaml").read_text().endswith("# edited\n")
    assert not import_urdf(ARMS["m20ia"], out, (ROSI,), force=True).unchanged
    assert not (out / "robot.yaml").read_text().endswith("# edited\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m20ia"]     # no staging folders left


def test_import_bad_input_leaves_nothing(tmp_path: Path) -> None:
    broken = tmp_path / "broken.xacro"
    broken.write_text('<robot xmlns:xacro="http://wiki.ros.org/xacro"><xacro:include filename="nope.xacro"/></robot>')
    result = runner.invoke(app, ["import-urdf", str(broken), "-o", str(tmp_path / "out")])
    assert result.exit_code == 2 and "xacro does not expand" in result.output and "broken.xacro" in result.output
    # A chain that is not OPW up to the named frame (the flange at link_4: four joints).
    result = runner.invoke(app, ["import-urdf", str(ARMS["m20ia"]), "-o", str(tmp_path / "out"), "--packages", str(ROSI),
                                 "--flange", "link_4", "--solver", "opw"])
    assert result.exit_code == 2 and "six revolute joints" in result.output
    result = runner.invoke(app, ["import-urdf", str(ARMS["m20ia"]), "-o", str(tmp_path / "out"), "--packages", str(ROSI),
                                 "--flange", "nope"])
    assert result.exit_code == 2 and "no frame 'nope'" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.xacro"]


def test_wrong_or_misnamed_robot_data_is_refused(arms: dict[str, Path], tmp_path: Path) -> None:
    folder = tmp_path / "kr120r2500pro"
    import shutil

    shutil.copytree(arms["kr120r2500pro"], folder)
    text = (folder / "robot.yaml").read_text()
    a2 = _params(folder)["a2"]
    (folder / "robot.yaml").write_text(text.replace(f"a2: {a2}", f"a2: {-float(a2)}"))   # type: ignore[arg-type]
    with pytest.raises(RobotModelError, match=r"ik\.params: the opw solver's forward kinematics disagrees"):
        load_robot(load_robot_spec(folder / "robot.yaml"))
    (folder / "robot.yaml").write_text(text + "collision:\n  disable: [[link_4, link_9]]\n")
    with pytest.raises(RobotModelError, match=r"collision\.disable\[0\]: link 'link_9' is not in the URDF"):
        load_robot(load_robot_spec(folder / "robot.yaml"))


def test_fit_refuses_a_chain_of_another_class(arms: dict[str, Path]) -> None:
    robot = load_robot(load_robot_spec(arms["m20ia"] / "robot.yaml"))
    model = robot.model.copy()
    model.jointPlacements[5].translation = model.jointPlacements[5].translation + np.array([0.0, 0.05, 0.0])
    with pytest.raises(FitError, match="wrist axes must meet"):
        fit_opw(model, robot.flange_frame_id)


def test_srdf_pairs_are_not_checked(arms: dict[str, Path]) -> None:
    robot = load_robot(load_robot_spec(arms["irb2400"] / "robot.yaml"))
    assert frozenset(("link_4", "link_6")) in robot.disabled_links


def test_configuration_data_is_geometric_on_a_fanuc_arm(arms: dict[str, Path]) -> None:
    # ROS-I FANUC arms turn J3 about -y. J2 = J3 = 0: upper arm vertical, forearm forward: the
    # elbow is above the shoulder-wrist line (U), the wrist in front of J1 (T); J5 = -30 deg: no
    # flip (FANUC's F is J5 >= 0, SPEC §6).
    robot = load_robot(load_robot_spec(arms["m20ia"] / "robot.yaml"))
    q = np.radians([0.0, 0.0, 0.0, 0.0, -30.0, 0.0])
    assert config_text(robot, q) == "N U T, 0, 0, 0"
    # Independently of the solver: the elbow letter from the joint origins (A2, A3 and the wrist
    # centre = the joint-5 origin of these URDFs) for J1 = 0, over the J3 range.
    import pinocchio as pin

    data = robot.model.createData()
    letters = set()
    for q3 in np.radians(np.linspace(-180, 260, 23)):
        q = np.array([0.0, 0.3, q3, 0.2, 0.5, 4.0])
        pin.forwardKinematics(robot.model, data, q)
        a2, a3, w = (data.oMi[robot.model.getJointId(f"joint_{k}")].translation for k in (2, 3, 5))
        up = np.cross(a3 - a2, w - a3)[1] > 0
        front = w[0] > 0
        want = f"F {'U' if up else 'D'} {'T' if front else 'B'}, 0, 0, 1"      # J5 = 0.5 rad: flip
        assert config_text(robot, q) == want
        letters.add(want[2])
    assert letters == {"U", "D"}
    # The KUKA arm's A3 turns about +y: the same posture reads elbow up as well.
    kr = load_robot(load_robot_spec(arms["kr120r2500pro"] / "robot.yaml"))
    assert config_text(kr, np.radians([0.0, -90.0, 90.0, 0.0, 30.0, 0.0])).startswith("S010")
    abb = load_robot(load_robot_spec(arms["irb2400"] / "robot.yaml"))
    assert config_text(abb, np.radians([100.0, 0.0, 0.0, -10.0, -30.0, 200.0])) == "[1,-1,2,1]"


# ---------------------------------------------------------------------- the ROS-Industrial `base` link

# Each arm's xacro macro, where its `base` link is attached (the fixed joint `${prefix}base_link-base`).
MACROS = {
    "irb2400": ROSI / "abb_irb2400_support/urdf/irb2400_macro.xacro",
    "m20ia": ROSI / "fanuc_m20ia_support/urdf/m20ia_macro.xacro",
    "kr120r2500pro": ROSI / "kuka_kr120_support/urdf/kr120r2500pro_macro.xacro",
    "kr210l150": ROSI / "kuka_kr210_support/urdf/kr210l150_macro.xacro",
}
BASE_TOL_M = 1e-9       # robot.yaml states the base in m and deg with 9 decimals


def _rpy_pose(xyz: list[float], rpy: list[float]) -> np.ndarray:
    """URDF <origin>: x' = Rz(yaw) Ry(pitch) Rx(roll) x + xyz (rad), written out here."""
    (cr, sr), (cp, sp), (cy, sy) = ((math.cos(a), math.sin(a)) for a in rpy)
    T = np.eye(4)
    T[:3, :3] = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) \
        @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    T[:3, 3] = xyz
    return T


def _base_joint_in_xacro(name: str) -> np.ndarray:
    """The `base` link's pose in `base_link`, read from the xacro text, and `base_link` checked to be
    the macro's root link (no joint has it as child)."""
    import xml.etree.ElementTree as ET

    def end(joint: ET.Element, tag: str) -> str | None:
        el = joint.find(tag)
        return None if el is None else el.get("link")

    macro = ET.parse(MACROS[name]).getroot()
    joints = list(macro.iter("joint"))
    (joint,) = [j for j in joints if j.get("name") == "${prefix}base_link-base"]
    assert joint.get("type") == "fixed"
    assert (end(joint, "parent"), end(joint, "child")) == ("${prefix}base_link", "${prefix}base")
    assert all(end(j, "child") != "${prefix}base_link" for j in joints)
    origin = joint.find("origin")
    assert origin is not None
    xyz, rpy = ([float(v) for v in origin.get(k, "0 0 0").split()] for k in ("xyz", "rpy"))
    return _rpy_pose(xyz, rpy)


def _stated_base(folder: Path) -> np.ndarray:
    base = yaml.safe_load((folder / "robot.yaml").read_text())["controller"]["base"]
    return _rpy_pose(base.get("xyz", [0, 0, 0]), [math.radians(a) for a in base.get("rpy", [0, 0, 0])])


@pytest.mark.parametrize("name", list(ARMS))
def test_import_states_the_base_link_as_controller_base(arms: dict[str, Path], name: str, tmp_path: Path) -> None:
    want = _base_joint_in_xacro(name)
    text = (arms[name] / "robot.yaml").read_text()
    assert "  base: {xyz: [" in text and "# ROS-Industrial's `base` link: the vendor's base frame" in text
    np.testing.assert_allclose(_stated_base(arms[name]), want, atol=BASE_TOL_M)
    np.testing.assert_allclose(load_robot_spec(arms[name] / "robot.yaml").controller.T_root_base, want, atol=BASE_TOL_M)
    # Without the key, loading finds the same frame in the URDF.
    import shutil

    folder = tmp_path / name
    shutil.copytree(arms[name], folder)
    (folder / "robot.yaml").write_text("".join(line for line in text.splitlines(keepends=True)
                                               if not line.startswith("  base: ")))
    np.testing.assert_allclose(load_robot_spec(folder / "robot.yaml").controller.T_root_base, want, atol=BASE_TOL_M)


def test_fanuc_base_is_at_j2_height(arms: dict[str, Path]) -> None:
    # fanuc_m20ia_support/urdf/m20ia_macro.xacro:160, the joint base_link-base: <origin xyz="0 0 0.525"/>;
    # J2's axis: joint_1 at xyz 0 0 0.525 (line 115), joint_2 at xyz 0.150 0 0 from it (line 122).
    import pinocchio as pin

    base = _base_joint_in_xacro("m20ia")
    np.testing.assert_allclose(base[:3, 3], [0.0, 0.0, 0.525], atol=BASE_TOL_M)
    robot = load_robot(load_robot_spec(arms["m20ia"] / "robot.yaml"))
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, np.zeros(robot.dof))
    j2 = data.oMi[robot.model.getJointId("joint_2")].translation
    assert robot.controller.T_root_base[2, 3] == pytest.approx(j2[2], abs=BASE_TOL_M)
    # The ABB and KUKA arms' `base` is their base_link (ABB base frame, KUKA $ROBROOT at the foot).
    for name in ("irb2400", "kr120r2500pro"):
        assert np.array_equal(load_robot_spec(arms[name] / "robot.yaml").controller.T_root_base, np.eye(4))


@pytest.mark.parametrize("name", list(ARMS))
def test_flange_in_the_controller_base_is_where_the_vendor_frame_has_it(arms: dict[str, Path], name: str) -> None:
    """FK in the URDF root frame, expressed in the controller's base: the flange relative to the
    URDF's `base` link (Pinocchio's frames), and on the FANUC arm the height its world frame gives."""
    import pinocchio as pin

    from robomax_py.program import to_frame

    robot = load_robot(load_robot_spec(arms[name] / "robot.yaml"))
    home = np.zeros(robot.dof)
    got = to_frame(robot.controller.T_root_base, fk_flange(robot, home))
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, home)
    base, flange = (data.oMf[robot.model.getFrameId(f)] for f in ("base", "tool0"))
    np.testing.assert_allclose(got, (base.inverse() * flange).homogeneous, atol=BASE_TOL_M)
    if name == "m20ia":
        # FANUC's world frame is at J2 height: at home the upper arm stands c2 above J2 and the
        # wrist centre |a2| above J3 (fanuc_m20ia_support/config/opw_parameters_m20ia.yaml: c2 0.79,
        # a2 -0.25), so the flange is 1.040 m above the world origin and 1.565 m above base_link.
        opw = yaml.safe_load((ROSI / "fanuc_m20ia_support/config/opw_parameters_m20ia.yaml").read_text()
                             .replace("deg(-90.0)", "-90").replace("deg(180.0)", "180"))["opw_kinematics_geometric_parameters"]
        assert got[2, 3] == pytest.approx(opw["c2"] - opw["a2"], abs=BASE_TOL_M)
        assert got[2, 3] == pytest.approx(1.040, abs=BASE_TOL_M)
        assert fk_flange(robot, home)[2, 3] == pytest.approx(1.565, abs=BASE_TOL_M)


def test_ur_base_link_is_the_shipped_ur10_base(tmp_path: Path) -> None:
    """The UR10 URDF of example-robot-data has a `base` link turned -180 deg about z from base_link
    (joint base_link-base_fixed_joint): imported, it is the half turn the shipped ur10 states."""
    from robomax_py.io.robot import package_share_dirs, shipped_robots_dir

    shipped = load_robot_spec(shipped_robots_dir() / "ur10" / "robot.yaml")
    folder = import_urdf(shipped.urdf, tmp_path / "ur10x", package_share_dirs()).folder
    text = (folder / "robot.yaml").read_text()
    assert "  base: {xyz: [0, 0, 0], rpy: [0, 0, 180]}  # ROS-Industrial's `base` link" in text
    np.testing.assert_allclose(load_robot_spec(folder / "robot.yaml").controller.T_root_base,
                               shipped.controller.T_root_base, atol=BASE_TOL_M)
    # Without the key the URDF's link gives the same frame (to the URDF's 11 decimals of pi).
    (folder / "robot.yaml").write_text(text.replace(text[text.index("  base: "):text.index("\n", text.index("  base: ")) + 1], ""))
    np.testing.assert_allclose(load_robot_spec(folder / "robot.yaml").controller.T_root_base,
                               shipped.controller.T_root_base, atol=BASE_TOL_M)


@pytest.mark.slow
def test_fanuc_targets_are_measured_from_the_world_frame_at_j2_height(arms: dict[str, Path], tmp_path: Path) -> None:
    """SPEC §6 on the FANUC arm: `UF : 0` targets are in FANUC's world frame, 525 mm above base_link,
    so a spot 0.95 m above base_link is written at Z = 425 mm; verify reads the program back."""
    import re

    cell = tmp_path / "m20ia_flange.yaml"
    cell.write_text(_flange_cell(arms["m20ia"] / "robot.yaml", "spot_gun_light", 1.05, 0.95))
    out = tmp_path / "programs"
    result = runner.invoke(app, ["plan", str(cell), "-o", str(out), "--format", "fanuc"])
    assert result.exit_code == 0, result.output
    program = out / "M20IA_FLANGE.ls"
    verified = runner.invoke(app, ["verify", str(cell), str(program)])
    assert verified.exit_code == 0, verified.output
    text = program.read_text()
    # The LIN target right before each weld call is the spot's TCP pose.
    welds = re.findall(r"L P\[(\d+)(?::\w+)?\][^\n]*FINE +;\n\s*\d+:\s*CALL SPOT_WELD", text)
    assert len(welds) == 4
    for k in welds:
        block = re.search(rf"P\[{k}(?::\"\w+\")?\]\{{.*?X = +(\S+)  mm,\tY = +(\S+)  mm,\tZ = +(\S+)  mm", text, re.DOTALL)
        assert block is not None
        x, y, z = (float(v) for v in block.groups())
        assert x == pytest.approx(1050.0, abs=1e-3) and z == pytest.approx(425.0, abs=1e-3)
        assert min(abs(y - yy) for yy in (-300.0, -100.0, 100.0, 300.0)) < 1e-3


def test_brand_guess() -> None:
    assert guess_brand("kr120r2500pro") == "kuka"
    assert guess_brand("abb_irb4600") == "abb"
    assert guess_brand("fanuc_m20ia") == "fanuc"
    assert guess_brand("m20ia") == "fanuc"
    assert guess_brand("ur10e") == "ur"
    # Kawasaki's own packages (khi_robot) name the arm khi_rs080n in khi_rs_description.
    assert guess_brand("rs080n", "khi_rs_description", "urdf", "rs080n.urdf.xacro", "khi_rs080n") == "kawasaki"
    assert guess_brand("rs007l") == "kawasaki" and guess_brand("duaro") == "kawasaki"
    assert guess_brand("comau_nj220") == "comau" and guess_brand("nachi_mz07") == "nachi"
    # No name tells: no guess (the import then says so; words that merely contain the letters don't count).
    assert guess_brand("odd6", "tmp", "odd6.urdf") is None
    assert guess_brand("sensors100n", "thinking") is None


def test_library_path_and_robots_flag(arms: dict[str, Path], tmp_path: Path) -> None:
    lib = arms["m20ia"].parent
    env = {**os.environ, ROBOTS_ENV: str(lib)}
    done = subprocess.run([sys.executable, "-m", "robomax_py", "robots"], capture_output=True, text=True, env=env,
                          check=False)
    assert done.returncode == 0, done.stderr
    for name in ("m20ia", "kr125", "spot_gun_c"):            # the shipped library stays searched
        assert name in done.stdout
    env.pop(ROBOTS_ENV)
    done = subprocess.run([sys.executable, "-m", "robomax_py", "robots", "--robots", str(lib)],
                          capture_output=True, text=True, env=env, check=False)
    assert done.returncode == 0 and "irb2400" in done.stdout


def _flange_cell(robot_yaml: Path, tool: str, x: float, z: float, home: str = "[0, 0, 0, 0, 30, 0]") -> str:
    spots = "\n".join(
        f"      - {{name: s{k + 1}, xyz: [{x}, {y}, {z}], normal: [-1, 0, 0], direction: [0, 1, 0]}}"
        for k, y in enumerate((-0.3, -0.1, 0.1, 0.3)))
    return f"""robomax: 1
robot: {{model: {robot_yaml}, home: {home}}}
tool: {tool}
objects:
  - {{name: flange, box: [0.002, 0.8, 0.06], pose: {{xyz: [{x}, 0, {z - 0.02}]}}, workpiece: true}}
  - {{name: post, box: [0.1, 0.1, {z - 0.1:.3f}], pose: {{xyz: [{x + 0.15}, 0, {(z - 0.1) / 2:.3f}]}}}}
seams:
  - name: flange
    ordered: false
    tolerance: {{alpha: 10, beta: 10, gamma: [-180, 180]}}
    grid: 3
    spots:
{spots}
process: {{weld_time: 0.3, approach: 0.03, clearance: 0}}
"""


def _plan_and_verify(cell: Path, out: Path) -> None:
    result = runner.invoke(app, ["plan", str(cell), "-o", str(out)])
    assert result.exit_code == 0, result.output
    for ext in ("srcl", "json"):
        program = out / f"{cell.stem}.{ext}"
        verified = runner.invoke(app, ["verify", str(cell), str(program)])
        assert verified.exit_code == 0, verified.output


@pytest.mark.slow
@pytest.mark.parametrize("name, tool, x, z, home", [
    ("irb2400", "spot_gun_light", 1.05, 0.95, "[0, 0, 0, 0, 30, 0]"),
    ("m20ia", "spot_gun_light", 1.05, 0.95, "[0, 0, 0, 0, 30, 0]"),
    ("kr120r2500pro", "spot_gun_c", 1.6, 1.2, "[0, -90, 90, 0, 30, 0]"),   # KUKA: A2 = -90 is upright
    ("kr210l150", "spot_gun_c", 1.6, 1.2, "[0, 0, 0, 0, 30, 0]"),          # this URDF's zero is upright
])
def test_each_arm_plans_and_verifies(arms: dict[str, Path], tmp_path: Path, name: str, tool: str, x: float, z: float,
                                     home: str) -> None:
    cell = tmp_path / f"{name}_flange.yaml"
    cell.write_text(_flange_cell(arms[name] / "robot.yaml", tool, x, z, home))
    assert runner.invoke(app, ["check", str(cell)]).exit_code == 0
    _plan_and_verify(cell, tmp_path / "programs")


@pytest.mark.slow
def test_lin_whose_j2_changes_sign_states_each_targets_configuration(arms: dict[str, Path], tmp_path: Path) -> None:
    """Regression: the retract LIN was written with the spot's CONFIG; on this ABB arm
    J2 is near 0 at the spot and changes sign over the 30 mm line, so KUKA turn bits differ."""
    import shutil

    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.plan import PlanOptions, plan_cell

    folder = tmp_path / "irb2400k"
    shutil.copytree(arms["irb2400"], folder)
    text = (folder / "robot.yaml").read_text().replace("name: irb2400", "name: irb2400k").replace("brand: abb", "brand: kuka")
    (folder / "robot.yaml").write_text(text)
    cell = tmp_path / "j2_cross.yaml"
    cell.write_text(_flange_cell(folder / "robot.yaml", "spot_gun_light", 0.85, 0.95))
    spec = load_cell(cell)
    result = plan_cell(spec, load_cell_robot(spec), PlanOptions())
    crossing = [s for s in result.spots if s.config != s.config_app]
    assert crossing, "the cell no longer has a LIN whose J2 changes sign"
    assert all(np.sign(s.q_spot[1]) != np.sign(s.q_app[1]) or s.config != s.config_app for s in crossing)
    _plan_and_verify(cell, tmp_path / "programs")


def test_out_of_reach_spot_fails_check_with_the_distance(tmp_path: Path) -> None:
    cell = tmp_path / "far.yaml"
    text = _flange_cell(Path("kr125"), "spot_gun_c", 1.6, 1.2, "[0, -90, 90, 0, 30, 0]")
    cell.write_text(text.replace("[1.6, 0.3, 1.2]", "[4.6, 0.3, 1.2]"))
    result = runner.invoke(app, ["check", str(cell)])
    assert result.exit_code == 2
    assert "seams[0].spots[3]" in result.output and "out of kr125's reach by" in result.output


@pytest.mark.slow
def test_cartesian_targets_are_stated_in_the_controller_base(arms: dict[str, Path], tmp_path: Path) -> None:
    """SPEC §6: controller.base moves the frame LIN targets are written in; the rebuilt motion and
    the verifier see the same robot motion as with the identity base."""
    import re
    import shutil

    from robomax_py.transforms import invert, pose_matrix

    folder = tmp_path / "kr120r2500pro"
    shutil.copytree(arms["kr120r2500pro"], folder)
    text = (folder / "robot.yaml").read_text()
    stated = re.search(r"^  base: .*$", text, re.MULTILINE)      # the imported `base` link (identity here)
    assert stated is not None
    text = text.replace(stated.group(0), "  base: {xyz: [0.1, -0.2, 0.3], rpy: [0, 0, 90]}")
    (folder / "robot.yaml").write_text(text)
    cell = tmp_path / "based.yaml"
    cell.write_text(_flange_cell(folder / "robot.yaml", "spot_gun_c", 1.6, 1.2, "[0, -90, 90, 0, 30, 0]"))
    _plan_and_verify(cell, tmp_path / "programs")
    srcl = (tmp_path / "programs" / "based.srcl").read_text()
    first = re.search(r"MOVE LIN POS\(([^)]*)\)", srcl)
    assert first is not None
    x, y, z = (float(v) / 1000 for v in first.group(1).split(","))
    C = pose_matrix([0.1, -0.2, 0.3], [0.0, 0.0, math.pi / 2])
    root = C @ np.array([x, y, z, 1.0])
    # The first spot welded is one of the four, in the root frame (within the program's 1e-3 mm).
    spots = [np.array([1.6, yy, 1.2]) for yy in (-0.3, -0.1, 0.1, 0.3)]
    assert min(np.linalg.norm(root[:3] - s) for s in spots) < 2e-6
    assert np.linalg.norm(invert(C)[:3, 3]) > 0.1          # the frame really moved the numbers
    assert "BASE FRAME" not in srcl                          # stated in the controller base itself


def test_import_says_whether_an_srdf_was_read(tmp_path: Path) -> None:
    """The summary line counts the SRDF's disabled pairs only when one was given; without it, it
    says none was (a count of 0 'from the SRDF' read as if one had been read)."""
    args = ["import-urdf", str(ARMS["irb2400"]), "--packages", str(ROSI)]
    without = runner.invoke(app, [*args, "-o", str(tmp_path / "a")])
    assert without.exit_code == 0, without.output
    said = " ".join(without.output.split())
    assert "no SRDF given" in said and "from the SRDF" not in said
    given = runner.invoke(app, [*args, "-o", str(tmp_path / "b"), "--srdf", str(SRDF["irb2400"])])
    assert given.exit_code == 0, given.output
    assert re.search(r"[1-9][0-9]* disabled pairs from the SRDF", " ".join(given.output.split()))
