"""The programs robomax writes, judged by the controller models.

Two cells, each planned with ``robomax plan --format all``:

- the small cell (s7 and s8 of the frozen reference cell, grid 3, gamma 0) moved as a whole by one
  rigid transform -- the robot 1.5 m from the cell origin, turned 30 deg, on a 0.4 m riser -- with
  the controller's default frames (no user frame: targets in the robot base; the calibrated tool 1);
- the process cell (tests/conftest.py `write_process_cell`: the robot 1.6 m off the origin, turned
  30 deg, on a riser tilted 2 deg) with the integrator's numbers: tool 2 named gun2, user frame 3
  on the fixture plate, position registers 40 and 41 that the FANUC setup program fills before
  setting UTOOL[2] and UFRAME[3], the clamp and door on inputs 5 and 6.

Each written program is read by its controller model (with its frames setup file, run first on
the same controller), and every weld target (the motion right before the n-th ``spot_weld`` call)
is placed in the world as the controller places it: cell placement · controller base · the
model's TCP in the robot base (the user frame composed in by the model). It must be at the spot
(the cell file's xyz) and at the TCP of the trajectory file's joints at the spot's arrival
(pinocchio FK from the robot's URDF and the tool.yaml tcp). The user frame in force must be the
one the cell names, placed in the world the same way; joint targets must lie on the trajectory,
and the configuration data must name the planned joints' configuration as each vendor defines it
(computed here from the arm's geometry).

Kawasaki AS and Yaskawa INFORM programs are judged the same way; for INFORM, whose joint
positions count encoder pulses, the test arm's robot.yaml is copied with the pulses per degree a
controller would state (`_with_pulses`). AS joint values carry the configuration, its
transformation values none; INFORM's RCONF is not judged here.

These caught the robot's placement written as KRL `$BASE` and as the RAPID work object's uframe
(every weld 1.1 m and 30 deg off) and FANUC's flip letter inverted, all of which the writers'
own readers had passed.
"""

from __future__ import annotations

import itertools
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml

from controller_model.common import (
    Call,
    FanucConfig,
    FloatArray,
    KrlConfig,
    Motion,
    ProgramRun,
    RapidConfig,
)
from controller_model.fanuc import controller_joints_deg
from controller_model.world import (
    DIALECTS,
    REPO,
    ROBOTS,
    Plan,
    T_from,
    Weld,
    abb_config,
    angle_deg,
    config_mismatch,
    deviation,
    fanuc_letters,
    geometry,
    kuka_config,
    load_arm,
    read_plan,
    run_program,
    welds,
    xyz_rpy,
)

PLACEMENT_XYZ_M = (1.2, -0.9, 0.4)       # 1.5 m from the cell origin, on a 0.4 m riser
PLACEMENT_YAW_DEG = 30.0
POS_TOL_M = 1e-4                         # 0.1 mm
ANGLE_TOL_DEG = 0.01
JOINT_TOL_DEG = 0.01                     # a stop point the trajectory passes through
BLEND_APPROACH_DEG = 2.0                 # how close the trajectory comes to a blended via point


# ------------------------------------------------------------------------------------------ frames
def _place_cell(source: Path, G: FloatArray) -> None:
    """Moves the whole cell by G: the robot's base, every object pose, every spot's xyz, normal, direction."""
    data = yaml.safe_load(source.read_text())
    base = data["robot"].get("base", {})
    data["robot"]["base"] = xyz_rpy(G @ T_from(base.get("xyz", (0, 0, 0)), base.get("rpy", (0, 0, 0))))
    for obj in data["objects"]:
        pose = obj.get("pose", {})
        obj["pose"] = xyz_rpy(G @ T_from(pose.get("xyz", (0, 0, 0)), pose.get("rpy", (0, 0, 0))))
    for seam in data["seams"]:
        for spot in seam["spots"]:
            spot["xyz"] = [float(v) for v in G[:3, :3] @ np.asarray(spot["xyz"]) + G[:3, 3]]
            spot["normal"] = [float(v) for v in G[:3, :3] @ np.asarray(spot["normal"])]
            spot["direction"] = [float(v) for v in G[:3, :3] @ np.asarray(spot["direction"])]
    source.write_text(yaml.safe_dump(data, sort_keys=False))


# -------------------------------------------------------------------------------------- the plan
CELLS = ("small", "process")
PULSES_PER_DEGREE = [1194.7, 1194.7, 1194.7, 853.3, 853.3, 512.0]   # tests/conftest.py TEST_PULSES_PER_DEGREE


def _with_pulses(cell: Path) -> None:
    """The cell's robot as a robot file beside the cell (the library's, its other files linked)
    that states the controller's encoder pulses per degree, so that `--format all` writes INFORM."""
    from controller_model.world import _reference

    data = yaml.safe_load(cell.read_text())
    source = _reference(cell, data["robot"]["model"], ROBOTS, "robot.yaml")
    folder = cell.parent / "robots_with_pulses" / source.parent.name      # a robot folder is named as the robot
    folder.mkdir(parents=True)
    for item in source.parent.iterdir():
        if item.name != "robot.yaml":
            (folder / item.name).symlink_to(item)
    robot = yaml.safe_load(source.read_text())
    robot["controller"] = {**(robot.get("controller") or {}), "pulses_per_degree": PULSES_PER_DEGREE}
    (folder / "robot.yaml").write_text(yaml.safe_dump(robot, sort_keys=False))
    data["robot"]["model"] = str(folder / "robot.yaml")
    cell.write_text(yaml.safe_dump(data, sort_keys=False))


def _plan_cell(cell: Path, name: str, formats: str = "all") -> Plan:
    out = cell.parent / "programs"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-m", "robomax_py", "plan", str(cell), "-o", str(out), "--format", formats],
                          capture_output=True, text=True, env=env, cwd=cell.parent, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    return read_plan(cell, out, name)


@pytest.fixture(scope="module", params=CELLS)
def plan(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory,
         write_small_cell: Callable[..., Path], write_process_cell: Callable[..., Path]) -> Plan:
    """The small cell moved off the origin with default frames, or the process cell with the
    integrator's tool, user frame, registers and inputs; planned, every dialect written."""
    folder = tmp_path_factory.mktemp(f"{request.param}_cell")
    if request.param == "small":
        cell = write_small_cell(folder, name="placed_cell")
        _place_cell(cell, T_from(PLACEMENT_XYZ_M, (0.0, 0.0, PLACEMENT_YAW_DEG)))
        _with_pulses(cell)
        return _plan_cell(cell, "placed_cell")
    cell = write_process_cell(folder, name="process_cell")
    _with_pulses(cell)
    return _plan_cell(cell, "process_cell")


def _run(plan: Plan, dialect: str) -> ProgramRun:
    return run_program(plan, dialect)


def _welds(plan: Plan, run: ProgramRun) -> list[Weld]:
    return welds(plan, run)


# ----------------------------------------------------------------------------------------- tests
def test_kuka_home_is_status_2_turn_2() -> None:
    """The configuration geometry on a posture whose KUKA data is known: HOME {A1 0, A2 -90, A3 90,
    A4 0, A5 0, A6 0} is S 'B010', T 'B000010'."""
    robot = ROBOTS / "kr125" / "robot.yaml"
    arm = load_arm(robot, ROBOTS / "tools" / "spot_gun_c" / "tool.yaml", [f"joint_a{i}" for i in range(1, 7)])
    assert kuka_config(arm, np.radians([0, -90, 90, 0, 0, 0])) == KrlConfig(2, 2)
    # the arm leaning back over the top puts the wrist point behind A1: bit 0
    assert kuka_config(arm, np.radians([0, -150, 20, 0, 30, 0])).status == 1 | 2


@pytest.mark.slow
@pytest.mark.parametrize("dialect", DIALECTS)
def test_program_runs_cleanly_with_a_weld_per_spot(plan: Plan, dialect: str) -> None:
    run = _run(plan, dialect)
    assert run.clean, run.issues
    for weld in _welds(plan, run):
        assert weld.motion.stops, f"{dialect}: the weld at {weld.spot} is not a stop point"
        assert weld.motion.T_base_tcp is not None, f"{dialect}: weld target at {weld.spot} is a joint target"


@pytest.mark.slow
@pytest.mark.parametrize("dialect", DIALECTS)
def test_weld_targets_are_at_the_spots_in_the_world(plan: Plan, dialect: str) -> None:
    errors = []
    for weld in _welds(plan, _run(plan, dialect)):
        assert weld.motion.T_base_tcp is not None
        T_world = plan.world(weld.motion.T_base_tcp)
        T_planned = plan.G @ plan.arm.tcp(plan.q_at(weld.t_arrive))
        off_spot = np.linalg.norm(T_world[:3, 3] - plan.spots[weld.spot])
        off_plan = np.linalg.norm(T_world[:3, 3] - T_planned[:3, 3])
        turned = angle_deg(T_world[:3, :3], T_planned[:3, :3])
        if off_spot > POS_TOL_M or off_plan > POS_TOL_M or turned > ANGLE_TOL_DEG:
            errors.append(f"{weld.spot}: {off_spot * 1e3:.3f} mm from the spot, {off_plan * 1e3:.3f} mm and "
                          f"{turned:.4f} deg from the planned TCP")
    assert not errors, f"{dialect}: " + "; ".join(errors)


@pytest.mark.slow
@pytest.mark.parametrize("dialect", DIALECTS)
def test_weld_tool_frame_is_the_tools_tcp(plan: Plan, dialect: str) -> None:
    for weld in _welds(plan, _run(plan, dialect)):
        tool = weld.motion.T_flange_tcp
        assert tool is not None, f"{dialect}: no tool frame in force at {weld.spot}"
        assert np.linalg.norm(tool[:3, 3] - plan.arm.T_flange_tcp[:3, 3]) <= POS_TOL_M
        assert angle_deg(tool[:3, :3], plan.arm.T_flange_tcp[:3, :3]) <= ANGLE_TOL_DEG


@pytest.mark.slow
@pytest.mark.parametrize("dialect", DIALECTS)
def test_weld_user_frame_is_the_cells(plan: Plan, dialect: str) -> None:
    """The user frame in force at every weld, placed in the world as the controller places it, is
    the one the cell names (the fixture plate), or the robot base frame when it names none; URScript
    commands its targets in the base, so the model reports the identity there and the user frame is
    judged by the weld positions alone."""
    want = plan.user_frame_world()
    for weld in _welds(plan, _run(plan, dialect)):
        user = weld.motion.T_base_user
        assert user is not None, f"{dialect}: no user frame in force at {weld.spot}"
        if dialect == "urscript":
            continue
        got = plan.world(user)
        expected = plan.world(np.eye(4)) if want is None else want
        off = np.linalg.norm(got[:3, 3] - expected[:3, 3])
        turned = angle_deg(got[:3, :3], expected[:3, :3])
        assert off <= POS_TOL_M and turned <= ANGLE_TOL_DEG, \
            f"{dialect}: user frame at {weld.spot} is {off * 1e3:.3f} mm and {turned:.4f} deg off the cell's"


@pytest.mark.slow
@pytest.mark.parametrize("dialect", DIALECTS)
def test_waits_are_for_the_cells_inputs(plan: Plan, dialect: str) -> None:
    """Every input wait names an input the cell maps: by number (KRL $IN through its SIGNAL, FANUC
    DI, UR standard digital input) or, in RAPID, by the signal name the cell gives (else the cell's
    signal name)."""
    inputs = plan.controller.get("inputs", {})
    numbers = {v if isinstance(v, int) else v["number"] for v in inputs.values()}
    names = {(v.get("name") if isinstance(v, dict) else None) or k for k, v in inputs.items()}
    waits = [w for w in _run(plan, dialect).waits if w.seconds is None]
    assert bool(waits) == bool(inputs), f"{dialect}: waits {waits} for the cell's inputs {inputs}"
    for wait in waits:
        if dialect == "rapid":
            assert wait.signal in names, f"{dialect}: {wait.signal} at {wait.where} is none of {sorted(names)}"
        else:
            assert wait.input_number in numbers, f"{dialect}: input {wait.input_number} at {wait.where} is none " \
                                                 f"of {sorted(numbers)}"
        assert wait.state is not False, f"{dialect}: waits for the input to go off at {wait.where}"


@pytest.mark.slow
@pytest.mark.parametrize("dialect", DIALECTS)
def test_joint_targets_lie_on_the_trajectory(plan: Plan, dialect: str) -> None:
    """Stop points in program order are passed through at increasing times; a blended via point is
    approached between the stop points around it."""
    run = _run(plan, dialect)
    welds = {id(w.motion): w.t_arrive for w in _welds(plan, run)}
    q_ctrl = np.asarray([controller_joints_deg(tuple(np.degrees(q)), plan.arm.j23_coupling) if dialect == "fanuc"
                         else np.degrees(q) for q in plan.q])
    anchors: list[tuple[int, float]] = []      # (motion index, time) of each stop point and weld
    t_cursor = plan.t[0] - 1.0
    motions = run.motions
    for k, m in enumerate(motions):
        if id(m) in welds:
            t_cursor = welds[id(m)]
            anchors.append((k, t_cursor))
        elif m.joints_deg is not None and m.stops:
            gap = np.abs(q_ctrl - np.asarray(m.joints_deg)).max(axis=1)
            hits = np.flatnonzero((gap <= JOINT_TOL_DEG) & (plan.t >= t_cursor))
            assert hits.size, f"{dialect}: stop point at {m.where} is not on the trajectory after t = {t_cursor:.3f} s"
            t_cursor = float(plan.t[hits[0]])
            anchors.append((k, t_cursor))
    assert anchors and anchors[0] == (0, plan.t[0]) and anchors[-1] == (len(motions) - 1, plan.t[-1])
    for (k0, t0), (k1, t1) in itertools.pairwise(anchors):
        window = (plan.t >= t0) & (plan.t <= t1)
        for m in motions[k0 + 1:k1]:
            if m.joints_deg is not None:
                gap = np.abs(q_ctrl[window] - np.asarray(m.joints_deg)).max(axis=1).min()
                assert gap <= BLEND_APPROACH_DEG, f"{dialect}: via point at {m.where} is {gap:.3f} deg off the path"


@pytest.mark.slow
@pytest.mark.parametrize("dialect", ("krl", "rapid", "fanuc"))
def test_configuration_names_the_planned_joints(plan: Plan, dialect: str) -> None:
    """URScript targets carry no configuration data."""
    for weld in _welds(plan, _run(plan, dialect)):
        q = plan.q_at(weld.t_arrive)
        config = weld.motion.config
        if dialect == "krl":
            assert isinstance(config, KrlConfig) and config.status is not None
            want = kuka_config(plan.arm, q)
            assert (config.status & 7, config.turn) == (want.status, want.turn), weld.spot   # bit 4: KSS 8 teaching
        elif dialect == "rapid":
            assert config == abb_config(plan.arm, q), weld.spot
        else:
            assert isinstance(config, FanucConfig)
            assert (config.flip, config.elbow, config.front) == fanuc_letters(plan.arm, q), weld.spot
            deg = controller_joints_deg(tuple(np.degrees(q)), plan.arm.j23_coupling)
            if all(-180.0 < deg[i] < 180.0 for i in (0, 3, 4, 5)):   # 0 whichever three axes they count
                assert config.turns == (0, 0, 0), weld.spot


@pytest.mark.slow
@pytest.mark.parametrize("dialect", DIALECTS)
def test_the_gun_lands_where_the_plan_puts_it(plan: Plan, dialect: str) -> None:
    """The figures the arm bench reports (world.deviation), on these cells: the gun's real TCP at
    every weld (the flange at target · tool⁻¹ in force) within 0.1 mm and 0.01 deg of the planned
    TCP and of the spot, joint stop points on the trajectory, configurations as planned."""
    dev = deviation(plan, dialect)
    assert not dev.issues, dev.issues
    assert dev.tcp_mm <= POS_TOL_M * 1e3 and dev.spot_mm <= POS_TOL_M * 1e3, dev
    assert dev.tcp_deg <= ANGLE_TOL_DEG and dev.joint_deg <= JOINT_TOL_DEG, dev
    assert dev.via_deg <= BLEND_APPROACH_DEG and not dev.configs, dev


def test_a_joint_on_a_boundary_names_both_sides_and_only_there() -> None:
    """A4 planned at -1e-12 rad (written -0.0 in the trajectory file): the KUKA Turn bit and the ABB
    quadrant of either side name it; half a degree off the boundary, only its own side does."""
    robot = ROBOTS / "kr125" / "robot.yaml"
    arm = load_arm(robot, ROBOTS / "tools" / "spot_gun_c" / "tool.yaml", [f"joint_a{i}" for i in range(1, 7)])
    on = np.radians([10.0, -80.0, 100.0, 0.0, 40.0, 20.0])
    on[3] = -1e-12
    status, turn = kuka_config(arm, on).status, (kuka_config(arm, on).turn or 0) & ~8    # bit 3: A4 < 0
    for t in (turn, turn | 8):
        assert config_mismatch(arm, "krl", KrlConfig(status, t), on) is None
    for cf4 in (-1, 0):
        assert config_mismatch(arm, "rapid", RapidConfig(0, cf4, 0, abb_config(arm, on).cfx), on) is None
    off = on.copy()
    off[3] = np.radians(-0.5)
    assert config_mismatch(arm, "krl", KrlConfig(status, turn), off) is not None
    assert config_mismatch(arm, "rapid", RapidConfig(0, 0, 0, abb_config(arm, off).cfx), off) is not None


def _serial_arm(folder: Path, joints: list[tuple[tuple[float, float, float], tuple[int, int, int]]]) -> Path:
    """robot.yaml of a bare six-axis URDF: each joint's origin in its parent (m) and axis."""
    links = "".join(f'<link name="l{i}"/>' for i in range(7)) + '<link name="tool0"/>'
    chain = "".join(
        f'<joint name="j{i + 1}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="{x} {y} {z}"/><axis xyz="{ax} {ay} {az}"/>'
        f'<limit lower="-6" upper="6" effort="1" velocity="1"/></joint>'
        for i, ((x, y, z), (ax, ay, az)) in enumerate(joints))
    chain += '<joint name="flange" type="fixed"><parent link="l6"/><child link="tool0"/></joint>'
    (folder / "arm.urdf").write_text(f'<robot name="arm">{links}{chain}</robot>')
    (folder / "robot.yaml").write_text("name: arm\nurdf: arm.urdf\nflange: tool0\n")
    return folder / "robot.yaml"


def test_configuration_geometry_takes_front_and_up_from_the_a1_frame(tmp_path: Path) -> None:
    """The A1 frame is the robot base turned with A1, not the arm's shape: a ROS-Industrial KUKA URDF
    (A1 joint at shoulder height turning about -z) at KUKA's HOME is S 'B010'; an arm without a
    shoulder offset (a Staubli TX60's shape) whose upper arm leans 5 deg back while the forearm
    reaches forward has its wrist point in front of A1."""
    tool = ROBOTS / "tools" / "spot_gun_c" / "tool.yaml"
    (tmp_path / "kuka").mkdir()
    kuka = _serial_arm(tmp_path / "kuka", [((0, 0, 0.675), (0, 0, -1)), ((0.26, 0, 0), (0, 1, 0)),
                                           ((0.68, 0, 0), (0, 1, 0)), ((0.67, 0, -0.035), (-1, 0, 0)),
                                           ((0, 0, 0), (0, 1, 0)), ((0.158, 0, 0), (-1, 0, 0))])
    arm = load_arm(kuka, tool, [f"j{i}" for i in range(1, 7)])
    assert kuka_config(arm, np.radians([0, -90, 90, 0, 30, 0])).status == 2
    assert kuka_config(arm, np.radians([120, -90, 90, 0, 30, 0])).status == 2     # turned with A1
    (tmp_path / "tx60").mkdir()
    staubli = _serial_arm(tmp_path / "tx60", [((0, 0, 0.375), (0, 0, 1)), ((0, 0, 0), (0, 1, 0)),
                                              ((0, 0.02, 0.29), (0, 1, 0)), ((0, 0, 0.31), (0, 0, 1)),
                                              ((0, 0, 0), (0, 1, 0)), ((0, 0, 0.07), (0, 0, 1))])
    arm = load_arm(staubli, tool, [f"j{i}" for i in range(1, 7)])
    assert geometry(arm, np.radians([0, -5, 90, 0, 30, 0])).wrist_behind_axis1 is False
    assert geometry(arm, np.radians([0, 5, -90, 0, 30, 0])).wrist_behind_axis1 is True


@pytest.mark.slow
def test_krl_package_welds_call_the_spot_package_at_the_spots(tmp_path: Path,
                                                               write_small_cell: Callable[..., Path]) -> None:
    """With `weld: package` each weld is ``USERSPOT(#SPOT,SDATn)``, the KUKA spot package's user
    routine (ZINK KRC/R1/TP/GripperSpotTech/Spot_User.src), called at rest at its spot."""
    cell = write_small_cell(tmp_path, name="placed_cell")
    _place_cell(cell, T_from(PLACEMENT_XYZ_M, (0.0, 0.0, PLACEMENT_YAW_DEG)))
    data = yaml.safe_load(cell.read_text())
    data["robot"]["controller"] = {"weld": "package"}
    cell.write_text(yaml.safe_dump(data, sort_keys=False))
    plan = _plan_cell(cell, "placed_cell", "krl")
    run = _run(plan, "krl")
    assert run.clean, run.issues
    calls = [(k, e) for k, e in enumerate(run.events) if isinstance(e, Call) and e.name.upper() == "USERSPOT"]
    assert calls[0][1].args == ("#INIT",)               # the SPOTTECH INI fold
    welds = [(k, e) for k, e in calls if e.args and e.args[0] == "#SPOT"]
    assert [e.args[1] for _, e in welds] == [f"SDAT{n}" for n in range(1, len(plan.spot_times) + 1)]
    for (k, _), (name, _) in zip(welds, plan.spot_times, strict=True):
        motion = run.events[k - 1]
        assert isinstance(motion, Motion) and motion.stops and motion.T_base_tcp is not None
        assert np.linalg.norm(plan.world(motion.T_base_tcp)[:3, 3] - plan.spots[name]) <= POS_TOL_M, name
