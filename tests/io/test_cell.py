"""Cell loading: the reference cell loads; every malformed-cell case gives one located message."""

from __future__ import annotations

import copy
import math
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, app
from robomax_py.errors import CellFileError, RobomaxError, RobotModelError
from robomax_py.io.cell import load_cell
from robomax_py.spec import Box, MeshShape

ANGLE_TOL_RAD = 1e-12
runner = CliRunner()


@pytest.fixture(scope="module")
def good_cell(reference_cell_path: Path) -> dict[str, Any]:
    data = yaml.safe_load(reference_cell_path.read_text())
    assert isinstance(data, dict)
    return data


def write_cell(tmp: Path, data: dict[str, Any], reference: Path) -> Path:
    """A copy of the reference cell's folder with the given cell content."""
    if not (tmp / "parts").exists():
        shutil.copytree(reference.parent / "parts", tmp / "parts")
    path = tmp / "cell.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_reference_cell_loads(reference_cell_path: Path) -> None:
    cell = load_cell(reference_cell_path)
    assert cell.name == "cabin_flange"
    assert cell.robot.name == "kr125" and cell.tool.name == "spot_gun_c"
    assert len(cell.seams) == 1 and len(cell.seams[0].spots) == 15
    seam = cell.seams[0]
    assert_allclose(seam.alpha_max, math.radians(10), atol=ANGLE_TOL_RAD)
    assert_allclose(seam.gamma_range, (-math.pi, math.pi), atol=ANGLE_TOL_RAD)
    assert_allclose(cell.home, np.radians([0, -90, 90, 0, 0, 0]), atol=ANGLE_TOL_RAD)
    panel = next(o for o in cell.objects if o.name == "cabin_panel")
    assert isinstance(panel.shape, MeshShape) and panel.workpiece
    jaw = next(o for o in cell.objects if o.name == "clamp1_jaw")
    assert isinstance(jaw.shape, Box) and jaw.shape.extents == (0.05, 0.11, 0.07)
    # rpy yaw 82.333 deg about z: the box's x axis turned accordingly.
    assert_allclose(jaw.T_world_object[:2, 0], [math.cos(math.radians(82.333)), math.sin(math.radians(82.333))],
                    atol=1e-12)
    for spot in seam.spots:
        assert_allclose(np.linalg.norm(spot.normal), 1.0, atol=1e-12)
        assert_allclose(np.dot(spot.normal, spot.direction), 0.0, atol=1e-12)


def test_check_command_on_reference_cell(reference_cell_path: Path) -> None:
    result = runner.invoke(app, ["check", str(reference_cell_path)])
    assert result.exit_code == 0, result.output
    assert "kr125" in result.output and "cabin_panel" in result.output


def _set(path: str, value: Any) -> Callable[[dict[str, Any]], None]:
    def mutate(data: dict[str, Any]) -> None:
        node: Any = data
        parts = path.split(".")
        for p in parts[:-1]:
            node = node[int(p)] if p.isdigit() else node[p]
        last = parts[-1]
        node[int(last) if last.isdigit() else last] = value
    return mutate


def _delete(path: str) -> Callable[[dict[str, Any]], None]:
    def mutate(data: dict[str, Any]) -> None:
        node: Any = data
        parts = path.split(".")
        for p in parts[:-1]:
            node = node[int(p)] if p.isdigit() else node[p]
        del node[parts[-1]]
    return mutate


def _append_object(obj: dict[str, Any], key: str = "objects") -> Callable[[dict[str, Any]], None]:
    def mutate(data: dict[str, Any]) -> None:
        data.setdefault(key, []).append(obj)
    return mutate


def _both(*mutations: Callable[[dict[str, Any]], None]) -> Callable[[dict[str, Any]], None]:
    def mutate(data: dict[str, Any]) -> None:
        for m in mutations:
            m(data)
    return mutate


def _second_seam(name: str) -> Callable[[dict[str, Any]], None]:
    def mutate(data: dict[str, Any]) -> None:
        seam = copy.deepcopy(data["seams"][0])
        seam["name"] = name
        seam["spots"] = seam["spots"][:2]
        data["seams"].append(seam)
    return mutate


# (id, mutation, expected key path, expected words in the problem)
BROKEN_CELLS: list[tuple[str, Callable[[dict[str, Any]], None], str, str]] = [
    ("unknown key", _set("seams.0.tolerence", {"alpha": 5}), "seams[0].tolerence", "did you mean 'tolerance'"),
    ("unknown top key", _set("proces", {}), "proces", "did you mean 'process'"),
    # Capitals and '-' mark pydantic's union member tags in its locations: a key of the file so
    # spelt is still named and matched.
    ("capitalised key", _set("Robot", {}), "Robot", "did you mean 'robot'"),
    ("one capital", _set("A", 1), "A", "known keys: robomax"),
    ("dashed key", _set("seams.0.tol-erance", {}), "seams[0].tol-erance", "did you mean 'tolerance'"),
    ("wrong type", _set("seams.0.grid", "five"), "seams[0].grid", "valid integer"),
    ("wrong type list", _set("objects.0.box", "big"), "objects[0].box", "valid list"),
    ("missing key", _delete("seams.0.spots.3.normal"), "seams[0].spots[3].normal", "required key is missing"),
    ("missing robot", _delete("robot"), "robot", "required key is missing"),
    ("zero normal", _set("seams.0.spots.3.normal", [0, 0, 0]), "seams[0].spots[3].normal", "zero-length"),
    ("nan normal", _set("seams.0.spots.3.normal", [float("nan"), 0, 1]), "seams[0].spots[3].normal[0]", "finite"),
    ("parallel direction", _set("seams.0.spots.2.direction", [-0.964219, 0.265105, 0]),
     "seams[0].spots[2].direction", "parallel to the normal"),
    ("negative size", _set("objects.0.box", [0.8, -2, 0.62]), "objects[0].box[1]", "greater than 0"),
    ("zero radius", _append_object({"name": "p", "sphere": {"radius": 0}}), "objects[9].sphere.radius",
     "greater than 0"),
    ("two shapes", _append_object({"name": "p", "box": [1, 1, 1], "sphere": {"radius": 1}}), "objects[9]",
     "exactly one of"),
    ("missing mesh", _set("objects.2.mesh", "parts/nope.stl"), "objects[2].mesh", "not found"),
    ("unknown robot", _set("robot.model", "kr999"), "robot.model", "unknown robot 'kr999'"),
    ("unknown tool", _set("tool", "laser"), "tool", "unknown tool 'laser'"),
    ("home-folder path", _set("robot.model", "~/robots/kr16/robot.yaml"), "robot.model",
     "('~' is not the home folder in a cell file: give the path relative to the cell file, or in full): not found"),
    ("home outside limits", _set("robot.home", [0, -90, 90, 0, 170, 0]), "robot.home[4]", "outside its limits"),
    ("home wrong length", _set("robot.home", [0, -90, 90]), "robot.home", "expected 6 joint values"),
    # A line of no length: the plan ended "infeasible: timing failed", blaming the spots. (verify
    # takes 0: it then checks no approach line.)
    ("no approach line", _set("process.approach", 0), "process.approach",
     "0: plan reaches and leaves every spot on a straight line this long"),
    ("joint limits of another arm", _set("robot.joint_limits", [[-10, 10]]), "robot.joint_limits",
     "expected 6 ranges for kr125, one per joint"),
    ("joint limits wider than the URDF's", _set("robot.joint_limits", [None] * 5 + [[-400, 400]]),
     "robot.joint_limits[5]", "reaches beyond joint_a6's limits in the URDF"),
    ("joint limits reversed", _set("robot.joint_limits", [None] * 5 + [[10, -10]]), "robot.joint_limits[5]",
     "expected [min, max] with min below max"),
    ("home outside the joint limits", _set("robot.joint_limits", [None, [-80, 0], None, None, None, None]),
     "robot.home[1]", "joint_a2 = -90.000 deg is outside robot.joint_limits[1], [-80.000, 0.000] deg"),
    ("negative weld time", _set("process.weld_time", -0.5), "process.weld_time", "greater than or equal to 0"),
    ("grid zero", _set("seams.0.grid", 0), "seams[0].grid", "greater than or equal to 1"),
    ("windows out of order",
     _append_object({"name": "door", "box": [0.8, 0.05, 0.6], "present": [[20, 26], [0, 6]]}, "dynamic"),
     "dynamic[0].present", "before window 0 ends"),
    ("window reversed",
     _append_object({"name": "door", "box": [0.8, 0.05, 0.6], "present": [[6, 0]]}, "dynamic"),
     "dynamic[0].present", "start must be before end"),
    ("unsupported version", _set("robomax", 2), "robomax", "unsupported format version 2"),
    ("duplicate object", _set("objects.1.name", "table"), "objects[1].name", "duplicate name 'table'"),
    ("duplicate spot", _set("seams.0.spots.1.name", "s1"), "seams[0].spots[1].name", "duplicate spot name 's1'"),
    # Names a program states alike (programs name spots with letters, digits and '_' only): its
    # statements and verify reading them could not tell the spots apart.
    ("spots written alike", _both(_set("seams.0.spots.0.name", "点1"), _set("seams.0.spots.1.name", "线1")),
     "seams[0].spots[1].name", "'线1' and '点1' (spots[0]) are both written _1 in programs"),
    ("seams written alike", _both(_set("seams.0.name", "left-1"), _second_seam("left 1")),
     "seams[1].name", "'left 1' and 'left-1' (seams[0]) are both written left_1 in programs"),
    # Two signals a program waits for alike: one input would stand for both.
    ("signals written alike", _both(_set("objects.3.signal", "clamp-1"), _set("objects.6.signal", "clamp 1")),
     "objects[6].signal", "the signal 'clamp 1' and the signal 'clamp-1' (objects[3].signal) are both written clamp_1"),
    ("clear signal written as a clamp's",
     _both(_set("objects.3.signal", "press 1_clear"),
           _append_object({"name": "press-1", "box": [0.8, 0.05, 0.6], "present": [[0, 6]]}, "dynamic")),
     "dynamic[0].name", "the signal 'press-1_clear' and the signal 'press 1_clear' (objects[3].signal)"),
    ("outputs written alike", _set("robot.controller", {"outputs": {"r1-done": 1, "r1 done": 2}}),
     "robot.controller.outputs.r1 done", "the signal 'r1 done' and the signal 'r1-done'"),
    # The programs are named after the cell: a name no file system would take as it is given.
    ("hidden file name", _set("name", ".cell"), "name", "it must not start with '.'"),
    ("device file name", _set("name", "AUX"), "name", "'AUX' is a name Windows keeps for a device"),
    ("colon in the name", _set("name", "line:3"), "name", "no ':' (Windows refuses"),
    ("gamma reversed", _set("seams.0.tolerance.gamma", [90, -90]), "seams[0].tolerance.gamma", "min <= max"),
    ("gamma three numbers", _set("seams.0.tolerance.gamma", [0, 1, 2]), "seams[0].tolerance.gamma",
     "at most 2 items"),
]


@pytest.mark.parametrize(("mutate", "key", "words"), [c[1:] for c in BROKEN_CELLS], ids=[c[0] for c in BROKEN_CELLS])
def test_broken_cell_gives_one_located_message(
    tmp_path: Path, good_cell: dict[str, Any], reference_cell_path: Path,
    mutate: Callable[[dict[str, Any]], None], key: str, words: str,
) -> None:
    data = copy.deepcopy(good_cell)
    mutate(data)
    path = write_cell(tmp_path, data, reference_cell_path)
    result = runner.invoke(app, ["check", str(path)])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    message = result.stderr if hasattr(result, "stderr") else result.output
    assert "Traceback" not in result.output
    flat = " ".join(message.split())
    assert f"{path}: {key}: " in flat, flat
    assert words in flat, flat


def test_two_clamps_may_share_one_signal(tmp_path: Path, good_cell: dict[str, Any], reference_cell_path: Path) -> None:
    # One name twice is one input, the refusal above is only for two names written alike.
    data = copy.deepcopy(good_cell)
    _both(_set("objects.3.signal", "clamps-closed"), _set("objects.6.signal", "clamps-closed"))(data)
    assert load_cell(write_cell(tmp_path, data, reference_cell_path)).signals == ("clamps-closed",)


def test_unreadable_mesh(tmp_path: Path, good_cell: dict[str, Any], reference_cell_path: Path) -> None:
    path = write_cell(tmp_path, good_cell, reference_cell_path)
    (tmp_path / "parts" / "cabin_panel.stl").write_bytes(b"solid garbage\nthis is not an stl\n")
    with pytest.raises(CellFileError, match=r"objects\[2\]\.mesh: cannot read mesh"):
        load_cell(path)


def test_yaml_syntax_error_names_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("robomax: 1\nrobot: {model: kr125\n")
    with pytest.raises(CellFileError, match=r"bad\.yaml: line \d+, column \d+: not valid YAML"):
        load_cell(path)


def test_duplicate_yaml_key_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "dup.yaml"
    path.write_text("robomax: 1\nrobomax: 1\n")
    with pytest.raises(CellFileError, match="duplicate key 'robomax'"):
        load_cell(path)


def test_missing_cell_file(tmp_path: Path) -> None:
    result = runner.invoke(app, ["check", str(tmp_path / "nope.yaml")])
    assert result.exit_code == EXIT_BAD_INPUT
    assert "cell file not found" in " ".join(result.output.split())


def test_robot_by_path_and_missing_flange(tmp_path: Path, good_cell: dict[str, Any], reference_cell_path: Path) -> None:
    """A robot named by path loads; a robot.yaml whose flange frame is not in the URDF is named."""
    from robomax_py.io.robot import shipped_robots_dir

    robot_dir = tmp_path / "myarm"
    shutil.copytree(shipped_robots_dir() / "kr16", robot_dir)
    text = (robot_dir / "robot.yaml").read_text().replace("name: kr16", "name: myarm")
    (robot_dir / "robot.yaml").write_text(text)
    data = copy.deepcopy(good_cell)
    data["robot"]["model"] = "myarm/robot.yaml"
    path = write_cell(tmp_path, data, reference_cell_path)
    assert load_cell(path).robot.name == "myarm"

    (robot_dir / "robot.yaml").write_text(text.replace("flange: tool0", "flange: tool_flange"))
    with pytest.raises(RobotModelError, match=r"robot\.yaml: flange: URDF kr16\.urdf has no frame 'tool_flange'"):
        load_cell(path)


# Values a careless edit might leave behind.
JUNK = st.one_of(
    st.none(), st.booleans(), st.integers(-5, 5), st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=5), st.lists(st.floats(-3, 3), max_size=4), st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
)


def _paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = [prefix] if prefix else []
    if isinstance(node, dict):
        for k, v in node.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _paths(v, (*prefix, i))
    return out


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_random_mutations_never_traceback(
    tmp_path: Path, good_cell: dict[str, Any], reference_cell_path: Path, data: st.DataObject
) -> None:
    cell = copy.deepcopy(good_cell)
    for _ in range(data.draw(st.integers(1, 3))):
        paths = _paths(cell)
        target = data.draw(st.sampled_from(paths))
        parent: Any = cell
        for p in target[:-1]:
            parent = parent[p]
        action = data.draw(st.sampled_from(["replace", "delete", "add"]))
        if action == "replace":
            parent[target[-1]] = data.draw(JUNK)
        elif action == "delete":
            del parent[target[-1]]
        elif isinstance(parent, dict):
            parent[data.draw(st.text(min_size=1, max_size=6))] = data.draw(JUNK)
        else:
            parent.append(data.draw(JUNK))
    path = write_cell(tmp_path, cell, reference_cell_path)
    # Only the cell changes, so load_cell (which also checks home against the URDF) covers every
    # path a mutation can reach; the link meshes it does not read are the robot's, not the cell's.
    try:
        load_cell(path)
    except RobomaxError:
        pass
