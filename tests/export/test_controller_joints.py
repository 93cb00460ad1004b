"""robot.yaml `controller.joint_signs` / `controller.joint_zeros_deg`: controller programs state each
joint as the controller counts it (sign * URDF value + zero, deg); SRCL and the trajectory keep the
URDF's values; what verify rebuilds from the controller's values is the plan."""

from __future__ import annotations

import dataclasses
import math
import re
import shutil
from pathlib import Path
from typing import Any

import pytest

from robomax_py.errors import RobotModelError
from robomax_py.export.plan_program import planned_program
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.io.robot import load_robot_spec
from robomax_py.plan import plan_cell
from robomax_py.program import LinMove
from robomax_py.publish import publish
from robomax_py.robot import load_robot
from robomax_py.verify import verify_program
from tests.conftest import with_pulses

# A5 and A6 turned the other way and A6's zero half a turn off: the turn bits, the wrist bit, ABB's
# quadrants and FANUC's flip and turn numbers of the controller's values differ from the URDF's.
SIGNS = (-1.0, 1.0, -1.0, -1.0, -1.0, -1.0)
# Whole numbers of the test's INFORM pulses (tests/conftest.py), as an encoder's zero is: the home
# then stays exactly the home in pulses.
ZEROS_DEG = (10.0, -90.0, 90.0, 0.0, 0.0, 180.0)
FORMATS = ("srcl", "krl", "rapid", "urscript", "fanuc", "inform", "as")


def _numbers(text: str) -> list[float]:
    return [float(v) for v in re.findall(r"-?\d+\.\d+|-?\d+", text)]


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory, write_small_cell) -> dict[str, Any]:  # type: ignore[no-untyped-def]
    folder = tmp_path_factory.mktemp("conventions")
    cell = load_cell(write_small_cell(folder))
    plain = with_pulses(load_cell_robot(cell))           # INFORM counts joint positions in pulses
    robot = dataclasses.replace(plain, controller=dataclasses.replace(
        plain.controller, joint_signs=SIGNS, joint_zeros=tuple(math.radians(z) for z in ZEROS_DEG)))
    result = plan_cell(cell, robot)
    assert result.status == "planned", result.message
    files, _ = publish(result, cell, robot, FORMATS)      # proven: read back and rebuilt to the plan
    plain_files, _ = publish(result, cell, plain, FORMATS)
    for name, text in files.items():
        (folder / name).write_text(text)
    planned = planned_program(result)
    lin_q = [[math.degrees(v) for v in q] for ins, q in zip(planned.program.instructions, planned.joints)
             if isinstance(ins, LinMove)]
    return {"cell": cell, "robot": robot, "files": files, "plain": plain_files, "folder": folder,
            "name": result.cell, "lin_q": lin_q}


def _srcl_targets(written: dict[str, Any]) -> list[list[float]]:
    text = written["files"][f"{written['name']}.srcl"]
    return [_numbers(m) for m in re.findall(r"MOVE PTP AXIS\(([^)]*)\)", text)]


def _expected(urdf_deg: list[float]) -> list[float]:
    # Computed here from the keys' definition, not by robomax: controller = sign * URDF + zero.
    return [s * v + z for v, s, z in zip(urdf_deg, SIGNS, ZEROS_DEG)]


def test_joint_targets_are_the_controllers_values(written: dict[str, Any]) -> None:
    name, files = written["name"], written["files"]
    urdf = _srcl_targets(written)
    assert len(urdf) >= 3
    krl = [_numbers(re.sub(r"[AE]\d ", " ", m))[:6]
           for m in re.findall(r"DECL E6AXIS XP\d+=\{([^}]*)\}", files[f"{name}.dat"])]
    rapid = [_numbers(m) for m in re.findall(r"CONST jointtarget jt\d+ := \[\[([^\]]*)\]", files[f"{name}.mod"])]
    ur = [[math.degrees(v) for v in _numbers(m)] for m in re.findall(r"movej\(\[([^\]]*)\]", files[f"{name}.script"])]
    fanuc_text = next(t for f, t in files.items() if f.endswith(".ls") and f.upper().startswith(name.upper()))
    fanuc = [[float(v) for v in re.findall(r"J\d=\s*(-?\d*\.\d+) deg", block)]
             for block in re.findall(r"P\[\d+[^\]]*\]\{(.*?)\};", fanuc_text, re.DOTALL) if "J1=" in block]
    for got in (krl, rapid, ur, fanuc):
        assert len(got) == len(urdf)
        for g, u in zip(got, urdf):
            assert g == pytest.approx(_expected(u), abs=1e-4)
    # The home (URDF 0, -90, 90, 0, 0, 0) as this controller counts it.
    assert krl[0] == pytest.approx([10, -180, 0, 0, 0, 180], abs=1e-4)


def test_srcl_keeps_the_urdf_values_and_the_plain_robot_is_unchanged(written: dict[str, Any]) -> None:
    name = written["name"]
    assert written["files"][f"{name}.srcl"] == written["plain"][f"{name}.srcl"]
    assert written["files"][f"{name}.dat"] != written["plain"][f"{name}.dat"]
    # Cartesian targets' poses do not depend on how the controller counts its joints.
    poses = [re.findall(r"E6POS XP\d+=\{(X [^S]*)S", f[f"{name}.dat"]) for f in (written["files"], written["plain"])]
    assert poses[0] and poses[0] == poses[1]


# ----------------------------------------------------------------- configuration data
# Read from the written files, in the order of the LIN statements, and computed here from the
# vendors' definitions (SPEC §6) of the controller's joint values at each LIN's end, deg.


def _krl_configs(files: dict[str, str], name: str) -> list[tuple[int, int]]:
    data = {n: (int(st), int(t)) for n, st, t in
            re.findall(r"DECL E6POS (XP\d+)=\{[^}]*?S (\d+),T (\d+)", files[f"{name}.dat"])}
    return [data[p] for p in re.findall(r"(?m)^LIN (XP\d+)", files[f"{name}.src"])]


def _rapid_configs(files: dict[str, str], name: str) -> list[list[int]]:
    data = {n: [int(v) for v in cf.split(",")] for n, cf in
            re.findall(r"CONST robtarget (p\d+) := \[\[[^\]]*\], \[[^\]]*\], \[([^\]]*)\]", files[f"{name}.mod"])}
    return [data[p] for p in re.findall(r"MoveL (p\d+),", files[f"{name}.mod"])]


def _fanuc_configs(files: dict[str, str], name: str) -> list[str]:
    text = next(t for f, t in files.items() if f.upper() == f"{name.upper()}.LS")
    data = {int(n): c for n, c in re.findall(r"P\[(\d+)[^\]]*\]\{[^}]*?CONFIG : '([^']*)'", text)}
    return [data[int(n)] for n in re.findall(r"(?m)^\s*\d+:L P\[(\d+)", text)]


def _inform_configs(files: dict[str, str], name: str) -> list[list[int]]:
    text = next(t for f, t in files.items() if f.upper() == f"{name.upper()}.JBI")
    out, rconf = [], None
    for line in text.splitlines():
        if line.startswith("///RCONF"):
            rconf = [int(v) for v in line.split()[1].split(",")]
        elif line.startswith("///PULSE"):
            rconf = None
        elif re.match(r"C\d+=.*\.", line):
            out.append(rconf)
    return out


def _controller(q_urdf_deg: list[float]) -> list[float]:
    return _expected(q_urdf_deg)


def _turn(angle: float) -> int:
    # FANUC: the integer t with angle - 360 t in (-180, 180].
    return math.ceil((angle - 180.0) / 360.0)


def test_configuration_data_count_the_controllers_joints(written: dict[str, Any]) -> None:
    name, files, plain = written["name"], written["files"], written["plain"]
    qs = [_controller(q) for q in written["lin_q"]]
    assert len(qs) >= 2

    krl, krl_plain = _krl_configs(files, name), _krl_configs(plain, name)
    rapid, rapid_plain = _rapid_configs(files, name), _rapid_configs(plain, name)
    fanuc, fanuc_plain = _fanuc_configs(files, name), _fanuc_configs(plain, name)
    inform, inform_plain = _inform_configs(files, name), _inform_configs(plain, name)
    for got in (krl, rapid, fanuc, inform):
        assert len(got) == len(qs)
    changed = 0
    for i, q in enumerate(qs):
        # KUKA: Turn bit i = axis i+1 < 0; Status bit 2 = A5 < 0 (A5 modulo 360 in [180, 360));
        # bits 0 and 1 are where the wrist point lies, which no joint counting changes.
        turn = sum(1 << j for j in range(6) if q[j] < 0)
        wrist = (q[4] % 360.0) >= 180.0
        assert krl[i] == ((krl_plain[i][0] & 3) | 4 * wrist, turn)
        # ABB: cf1, cf4, cf6 = floor(angle / 90) of axes 1, 4, 6; cfx bit 0 = axis 5 negative.
        quadrants = [math.floor(q[j] / 90.0) for j in (0, 3, 5)]
        assert rapid[i] == [*quadrants, (rapid_plain[i][3] & 6) | (q[4] < 0)]
        # FANUC: F when J5 >= 0 within its turn; U/D and T/B geometric; turn numbers of J4, J5, J6.
        turns = [_turn(q[j]) for j in (3, 4, 5)]
        flip = "F" if q[4] - 360.0 * turns[1] >= 0 else "N"
        letters = fanuc_plain[i].split(",")[0].split()
        assert fanuc[i] == f"{flip} {letters[1]} {letters[2]}, {turns[0]}, {turns[1]}, {turns[2]}"
        # INFORM RCONF: Flip for R (axis 4) in (-90, 90] modulo 360; halves of R, T, S (axes 4, 6, 1).
        half = [0 if -180.0 < q[j] <= 180.0 else 1 for j in (3, 5, 0)]
        r_flip = 0 if 0.0 < (q[3] + 90.0) % 360.0 <= 180.0 else 1
        assert inform[i] == [r_flip, inform_plain[i][1], inform_plain[i][2], *half, 0, 0]
        changed += krl[i] != krl_plain[i] or rapid[i] != rapid_plain[i] or fanuc[i] != fanuc_plain[i]
    assert changed == len(qs)             # the keys above do change every target's data


@pytest.mark.parametrize("ext", [".src", ".mod", ".script", ".ls", ".jbi", ".as"])
def test_verify_rebuilds_the_plan_from_the_controllers_values(written: dict[str, Any], ext: str) -> None:
    # FANUC and INFORM name the file after the program (capitals).
    [main] = [f for f in written["files"] if f.lower() == f"{written['name']}{ext}"]
    report = verify_program(written["cell"], written["robot"], written["folder"] / main)
    assert report.clean, report.violations[:3]


def _robot_yaml(tmp_path: Path, name: str, controller: str) -> Path:
    """A copy of the shipped kr16 with `controller` lines in place of its controller section."""
    shutil.copytree(Path(__file__).resolve().parents[2] / "robomax_py" / "robots" / "kr16", tmp_path / name)
    path = tmp_path / name / "robot.yaml"
    body = re.sub(r"(?ms)^controller:.*?(?=^\S|\Z)", "", path.read_text()).replace("name: kr16", f"name: {name}")
    path.write_text(body + f"controller:\n  brand: kuka\n{controller}")
    return path


def test_keys_are_read_in_degrees_and_checked(tmp_path: Path) -> None:
    spec = load_robot_spec(_robot_yaml(tmp_path, "a", "  joint_signs: [-1, 1, 1, -1, 1, -1]\n"
                                                       "  joint_zeros_deg: [0, -90, 90, 0, 0, 180]\n"))
    assert spec.controller.joint_signs == (-1, 1, 1, -1, 1, -1)
    assert spec.controller.joint_zeros == pytest.approx((0, -math.pi / 2, math.pi / 2, 0, 0, math.pi))
    for name, bad, key in (("b", "  joint_signs: [1, 2, 1, 1, 1, 1]\n", "joint_signs"),
                           ("c", "  joint_zeros_deg: [0, .nan, 0, 0, 0, 0]\n", "joint_zeros_deg")):
        with pytest.raises(RobotModelError, match=key):
            load_robot_spec(_robot_yaml(tmp_path, name, bad))
    with pytest.raises(RobotModelError, match=r"controller.joint_signs.*expected 6 values"):
        load_robot(load_robot_spec(_robot_yaml(tmp_path, "d", "  joint_signs: [1, 1, 1]\n")))


def test_verify_reports_configuration_data_in_the_urdfs_count(written: dict[str, Any], tmp_path: Path) -> None:
    # The keyed program with each target's Status and Turn as the URDF's values would give them:
    # the controller would take another turn or wrist branch, which verify must catch.
    name, files, plain = written["name"], written["files"], written["plain"]
    urdf_st = dict(re.findall(r"DECL E6POS (XP\d+)=\{[^}]*?(S \d+,T \d+)", plain[f"{name}.dat"]))
    dat = re.sub(r"(DECL E6POS (XP\d+)=\{[^}]*?)S \d+,T \d+", lambda m: m[1] + urdf_st[m[2]], files[f"{name}.dat"])
    assert dat != files[f"{name}.dat"]
    for file_name in (f"{name}.src", f"{name}_frames.src"):
        (tmp_path / file_name).write_text(files[file_name])
    (tmp_path / f"{name}.dat").write_text(dat)
    report = verify_program(written["cell"], written["robot"], tmp_path / f"{name}.src")
    assert any(v.kind == "config" for v in report.violations), report.violations[:3]
