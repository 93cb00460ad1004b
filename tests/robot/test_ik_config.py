"""Configuration indicators: KUKA S/T bits, their string form, ABB and Fanuc conversions."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from robomax_py.errors import ProgramError
from robomax_py.io.ik_params import params_from_mapping
from robomax_py.robot import JointLimits, RobotModel
from robomax_py.robot.ik.config import (
    ConfigIndicator,
    status_generic,
    status_opw,
    turn_bits,
)
from robomax_py.robot.ik.opw import (
    OpwParams,
    from_paper_angles,
    opw_fk,
    opw_pin_model,
    to_paper_angles,
)
from robomax_py.robot.solve import config_of, solve_all

REPO = Path(__file__).resolve().parents[2]
DEG = np.pi / 180.0
KR6_R700 = OpwParams(
    a1=0.025, a2=-0.035, b=0.0, c1=0.400, c2=0.315, c3=0.365, c4=0.080,
    offsets=(0.0, -np.pi / 2, 0.0, 0.0, 0.0, 0.0), sign_corrections=(-1, 1, 1, -1, 1, -1),
)
LATERAL = OpwParams(
    a1=0.150, a2=0.080, b=0.070, c1=0.500, c2=0.600, c3=0.700, c4=0.100,
    offsets=(0.0, 0.2, -0.3, 0.4, 0.0, 0.6), sign_corrections=(1, -1, -1, 1, 1, -1),
)


def robot_from(model: pin.Model, solver: str, params: object) -> RobotModel:
    n = model.nq
    limits = JointLimits(model.lowerPositionLimit.copy(), model.upperPositionLimit.copy(), np.ones(n), np.ones(n), np.ones(n))
    return RobotModel(
        "test", Path("test"), model, pin.GeometryModel(), pin.GeometryModel(), tuple(model.names[1:]),
        model.getFrameId("flange"), limits, solver, params, np.eye(4),
    )


def test_string_round_trip_all_values() -> None:
    for status in range(8):
        for turn in range(64):
            ind = ConfigIndicator(status, turn)
            text = str(ind)
            assert len(text) == len("S110 T010011")
            assert ConfigIndicator.parse(text) == ind
    assert str(ConfigIndicator(6, 0b010011)) == "S110 T010011"
    assert ConfigIndicator.parse("S110 T010") == ConfigIndicator(6, 2)    # short turn field
    assert ConfigIndicator(6, 19).to_kuka() == "S 'B110',T 'B010011'"


@pytest.mark.parametrize("text", ["S11 T010011", "S110T010011", "S120 T0", "s110 t010011", "S110 T0100110", "", "S110"])
def test_parse_rejects(text: str) -> None:
    with pytest.raises(ProgramError):
        ConfigIndicator.parse(text)


def test_value_range_checked() -> None:
    with pytest.raises(ValueError):
        ConfigIndicator(8, 0)
    with pytest.raises(ValueError):
        ConfigIndicator(0, 64)


def test_kuka_home_is_s010() -> None:
    """KUKA's home {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}: basic area, A3 >= phi, A5 = 0 -> S 'B010'."""
    q = np.array([0, -90, 90, 0, 0, 0]) * DEG
    assert int(status_opw(KR6_R700, q)) == 0b010
    robot = robot_from(opw_pin_model(KR6_R700), "opw", KR6_R700)
    assert str(config_of(robot, q)) == "S010 T000010"
    generic = robot_from(opw_pin_model(KR6_R700), "numeric", None)
    assert str(config_of(generic, q)) == "S010 T000010"


def test_wrist_bit_follows_kuka_manual() -> None:
    base = np.array([0, -90, 90, 0, 0, 0]) * DEG
    for a5_deg, bit in ((0, 0), (10, 0), (179, 0), (180, 1), (-180, 1), (-10, 1), (-190, 0), (200, 1)):
        q = base.copy()
        q[4] = a5_deg * DEG
        assert (int(status_opw(KR6_R700, q)) >> 2) == bit, a5_deg


def test_overhead_and_elbow_bits() -> None:
    home = np.array([0, -90, 90, 0, 30, 0]) * DEG
    overhead = home.copy()
    overhead[1] = -150 * DEG          # upper arm tilted back, forearm pointing up and back
    overhead[2] = 30 * DEG
    assert int(status_opw(KR6_R700, overhead)) & 1 == 1
    low_elbow = home.copy()
    low_elbow[2] = -60 * DEG          # A3 below the stretched angle phi ~ +5.5 deg
    assert int(status_opw(KR6_R700, low_elbow)) & 2 == 0
    phi = float((KR6_R700.offsets[2] - np.arctan2(KR6_R700.a2, KR6_R700.c3)) * KR6_R700.sign_corrections[2])
    for a3, bit in ((phi + 1e-6, 2), (phi - 1e-6, 0)):
        q = home.copy()
        q[2] = a3
        assert int(status_opw(KR6_R700, q)) & 2 == bit


def test_turn_bits() -> None:
    q = np.array([[91, -45, 37, 1, -1, 0], [-1, -1, -1, -1, -1, -1], [0, 0, 0, 0, 0, 0]]) * DEG
    assert turn_bits(q).tolist() == [0b010010, 0b111111, 0]
    assert turn_bits(np.full(6, np.nan)) == -1
    assert turn_bits(np.array([-1.0, 2.0])) == 0b01


def test_turn_bit_of_negative_zero_survives_fixed_decimals() -> None:
    """Regression (cabin_flange cell): A4 = -1e-12 rad at a spot was stated T..1..., written to the
    trajectory file as -0.000000000, read back as -0.0 and judged T..0... by `robomax verify`."""
    planned = np.array([0.5, -1.5, 2.1, -1e-12, 1.0, -2.4])
    read_back = np.array([float(f"{v:.9f}") for v in planned])
    assert read_back[3] == 0.0                      # -0.0
    assert turn_bits(read_back) == turn_bits(planned) == 0b101010
    assert turn_bits(np.array([0.0, 0, 0, 0, 0, 0])) == 0


def test_abb_confdata() -> None:
    ind = ConfigIndicator(status=0b010, turn=0)
    q = np.array([100, -30, 40, -45, 20, 190]) * DEG
    assert ind.to_abb(q) == (1, -1, 2, 0)                 # front, in front of lower arm, A5 positive
    assert ConfigIndicator(0b101, 0).to_abb(np.zeros(6)) == (0, 0, 0, 4 + 2 + 1)
    assert ConfigIndicator(0b110, 0).to_abb(np.array([-1e-9, 0, 0, -90 * DEG, 0, -181 * DEG])) == (-1, -1, -3, 1)


def test_fanuc_config() -> None:
    """F when J5 >= 0 (FANUC's flip, not KUKA's A5 < 0 bit) and the turn numbers of J4, J5, J6, as
    SPEC §6 states; this test once held F for J5 < 0 and the turns of J1, J4, J6, a convention the
    writer and this test shared but no FANUC controller does."""
    q = np.array([0, 0, 0, 0, 30, -200]) * DEG
    assert ConfigIndicator(0b010, 0).to_fanuc(q) == "F U T, 0, 0, -1"
    assert ConfigIndicator(0b110, 0).to_fanuc(np.array([0, 0, 0, 0, -30, 0]) * DEG) == "N U T, 0, 0, 0"
    assert ConfigIndicator(0b101, 0).to_fanuc(np.array([181, 0, 0, 540, 0, 180]) * DEG) == "F D B, 1, 0, 0"
    assert ConfigIndicator(0b100, 0).to_fanuc(np.array([0, 0, 0, 0, 200, 0]) * DEG) == "N D T, 0, 1, 0"
    assert ConfigIndicator(0, 0).to_fanuc(np.array([0, 0, 0, -180, 0, 0]) * DEG).endswith("-1, 0, 0")


@pytest.mark.parametrize("params", [KR6_R700, LATERAL], ids=["kr6", "lateral"])
def test_opw_and_generic_status_agree(params: OpwParams, rng: np.random.Generator) -> None:
    """The fast paper-angle bits equal the geometric bits from Pinocchio joint placements."""
    model = opw_pin_model(params)
    q = rng.uniform(-np.pi, np.pi, size=(3000, 6))
    th = to_paper_angles(params, q)
    beta = th[:, 2] + np.arctan2(params.a2, params.c3)
    x_wrist = params.c2 * np.sin(th[:, 1]) + np.hypot(params.a2, params.c3) * np.sin(th[:, 1] + beta) + params.a1
    clear = (np.abs(np.sin(beta)) > 1e-9) & (np.abs(x_wrist) > 1e-9)
    fast = status_opw(params, q)
    generic = status_generic(model, model.getFrameId("flange"), q)
    assert np.array_equal(fast[clear], generic[clear])
    assert set(np.unique(fast)) == set(range(8))
    q[5, 2] = np.nan
    assert status_opw(params, q)[5] == -1 and status_generic(model, model.getFrameId("flange"), q)[5] == -1


def test_status_distinct_over_branches_in_solve_all(rng: np.random.Generator) -> None:
    robot = robot_from(opw_pin_model(LATERAL), "opw", LATERAL)
    th = rng.uniform(-2.5, 2.5, size=(200, 6))
    T = opw_fk(LATERAL, from_paper_angles(LATERAL, th))
    table = solve_all(robot, T, expand_turns=False)
    full = table.valid.all(axis=-1)
    assert full.sum() > 20
    assert np.all(np.sort(table.status[full], axis=-1) == np.arange(8))
    for k in np.flatnonzero(full)[:20]:
        for b in range(8):
            assert config_of(robot, table.q[k, b]) == ConfigIndicator(int(table.status[k, b]), int(table.turn[k, b]))


def test_against_robot_urdf_if_present(rng: np.random.Generator) -> None:
    yaml = pytest.importorskip("yaml")
    folder = REPO / "robomax_py" / "robots" / "kr16"
    assert (folder / "kr16.urdf").is_file() and (folder / "robot.yaml").is_file(), "robots/kr16 is shipped with the repository"
    spec = yaml.safe_load((folder / "robot.yaml").read_text())
    params = params_from_mapping("opw", spec["ik"]["params"])
    assert isinstance(params, OpwParams)
    model = pin.buildModelFromUrdf(str(folder / "kr16.urdf"))
    q = rng.uniform(model.lowerPositionLimit, model.upperPositionLimit, size=(2000, 6))
    fast = status_opw(params, q)
    generic = status_generic(model, model.getFrameId(spec["flange"]), q)
    assert np.mean(fast == generic) > 0.999
