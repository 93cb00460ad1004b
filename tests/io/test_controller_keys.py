"""The cell's `robot.controller` keys: the integrator's tool and user frame numbers, registers,
inputs and weld style load as given, and every mistake is one message naming the key."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml
from numpy.testing import assert_allclose
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, app
from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell

runner = CliRunner()
POSE_TOL_M = 1e-12


def _cell(folder: Path, write_small_cell: Callable[..., Path], controller: dict[str, Any],
          signal: bool = True) -> Path:
    path = write_small_cell(folder)
    data = yaml.safe_load(path.read_text())
    if signal:
        next(o for o in data["objects"] if o["name"] == "clamp1_jaw")["signal"] = "clamp1_closed"
    data["robot"]["controller"] = controller
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_the_keys_load_as_given(tmp_path: Path, write_small_cell: Callable[..., Path]) -> None:
    path = _cell(tmp_path, write_small_cell, {
        "tool": {"number": 2, "name": "gun2"},
        "frame": {"number": 3, "object": "fixture_plate"},
        "registers": {"position": [40, 41], "numeric": [7]},
        "inputs": {"clamp1_closed": {"number": 5, "name": "diClamp1"}},
        "weld": "package",
    })
    setup = load_cell(path).controller
    assert setup.tool is not None and (setup.tool.number, setup.tool.name, setup.tool.existing) == (2, "gun2", True)
    assert setup.frame is not None and setup.frame.frame.number == 3 and not setup.frame.frame.existing
    plate = next(o for o in load_cell(path).objects if o.name == "fixture_plate")
    assert_allclose(setup.frame.T_world_frame, plate.T_world_object, atol=POSE_TOL_M)
    assert setup.position_registers == (40, 41) and setup.numeric_registers == (7,)
    mapped = setup.input_of("clamp1_closed")
    assert mapped is not None and (mapped.number, mapped.name) == (5, "diClamp1")
    assert setup.weld == "package"


def test_defaults_select_tool_one_and_the_robot_base(tmp_path: Path, write_small_cell: Callable[..., Path]) -> None:
    setup = load_cell(write_small_cell(tmp_path)).controller
    assert setup.tool is None and setup.frame is None and not setup.inputs and setup.weld == "call"


def test_a_frame_given_by_pose_is_in_the_world(tmp_path: Path, write_small_cell: Callable[..., Path]) -> None:
    path = _cell(tmp_path, write_small_cell, {"frame": {"pose": {"xyz": [1.5, 0.2, 0.8], "rpy": [0, 0, 90]}}})
    frame = load_cell(path).controller.frame
    assert frame is not None and (frame.frame.number, frame.frame.name) == (1, "user_frame")
    assert_allclose(frame.T_world_frame[:3, 3], [1.5, 0.2, 0.8], atol=POSE_TOL_M)
    assert_allclose(frame.T_world_frame[:3, 0], [0.0, 1.0, 0.0], atol=POSE_TOL_M)


BAD: list[tuple[dict[str, Any], str, str]] = [
    ({"inputs": {"clamp9": 5}}, "robot.controller.inputs.clamp9", "no signal 'clamp9'"),
    ({"inputs": {"clamp1_closed": -1}}, "robot.controller.inputs", ""),
    ({"frame": {"number": 3}}, "robot.controller.frame", "exactly one of pose"),
    ({"frame": {"object": "fixture_plate", "pose": {"xyz": [0, 0, 0]}}}, "robot.controller.frame", "exactly one of pose"),
    ({"frame": {"object": "no_such_thing"}}, "robot.controller.frame.object", "no object 'no_such_thing'"),
    ({"tool": {"number": 0}}, "robot.controller.tool.number", ""),
    ({"tool": {"name": "9gun"}}, "robot.controller.tool.name", ""),
    ({"registers": {"position": [40, 40]}}, "robot.controller.registers.position", "listed twice"),
    ({"weld": "sometimes"}, "robot.controller.weld", ""),
    ({"tolls": {"number": 1}}, "robot.controller.tolls", "unknown key"),
]


@pytest.mark.parametrize(("controller", "key", "problem"), BAD, ids=[b[1] + ":" + b[2] for b in BAD])
def test_mistakes_name_the_key(tmp_path: Path, write_small_cell: Callable[..., Path], controller: dict[str, Any],
                               key: str, problem: str) -> None:
    path = _cell(tmp_path, write_small_cell, controller)
    with pytest.raises(CellFileError) as caught:
        load_cell(path)
    assert caught.value.key is not None and caught.value.key.startswith(key), caught.value
    assert problem in str(caught.value)


def test_two_signals_on_one_input_are_refused(tmp_path: Path, write_small_cell: Callable[..., Path]) -> None:
    path = write_small_cell(tmp_path)
    data = yaml.safe_load(path.read_text())
    for name, signal in (("clamp1_jaw", "clamp1_closed"), ("clamp2_jaw", "clamp2_closed")):
        next(o for o in data["objects"] if o["name"] == name)["signal"] = signal
    data["robot"]["controller"] = {"inputs": {"clamp1_closed": 5, "clamp2_closed": 5}}
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(CellFileError, match="input 5 is also clamp1_closed's") as caught:
        load_cell(path)
    assert caught.value.key == "robot.controller.inputs.clamp2_closed"


@pytest.mark.slow
def test_an_unmapped_signal_stops_plan_for_a_dialect_waiting_on_numbers(
        tmp_path: Path, write_small_cell: Callable[..., Path]) -> None:
    """SRCL and RAPID wait by name; KRL waits on an input number the cell must give: exit 2 with the
    key and nothing written."""
    path = _cell(tmp_path, write_small_cell, {})
    out = tmp_path / "programs"
    result = runner.invoke(app, ["plan", str(path), "-o", str(out), "--format", "srcl,krl"])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    assert "robot.controller.inputs.clamp1_closed" in result.output and "--format krl" in result.output
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.slow
def test_a_tool_number_beyond_the_controllers_slots_stops_plan(
        tmp_path: Path, write_small_cell: Callable[..., Path]) -> None:
    path = _cell(tmp_path, write_small_cell, {"tool": {"number": 12}}, signal=False)
    result = runner.invoke(app, ["plan", str(path), "-o", str(tmp_path / "out"), "--format", "fanuc"])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    assert "robot.controller.tool.number" in result.output and "1..10" in result.output


def test_outputs_load_as_given(tmp_path: Path, write_small_cell: Callable[..., Path]) -> None:
    """A station's interlock outputs: any signal name (another robot's input of that name is what
    it drives), a number or {number, name}, as inputs are given."""
    path = _cell(tmp_path, write_small_cell, {"outputs": {"r1_z1_clear": 3, "r1_z2_clear": {"number": 4, "name": "doZ2"}}},
                 signal=False)
    setup = load_cell(path).controller
    first, second = setup.output_of("r1_z1_clear"), setup.output_of("r1_z2_clear")
    assert first is not None and (first.number, first.name) == (3, None)
    assert second is not None and (second.number, second.name) == (4, "doZ2")
    assert setup.output_of("r1_z3_clear") is None


@pytest.mark.parametrize(("outputs", "key", "problem"), [
    ({"a_clear": 3, "b_clear": 3}, "robot.controller.outputs.b_clear", "output 3 is also a_clear's"),
    ({"a_clear": -1}, "robot.controller.outputs", ""),
    ({"a_clear": {"number": 2, "name": "9do"}}, "robot.controller.outputs", ""),
])
def test_output_mistakes_name_the_key(tmp_path: Path, write_small_cell: Callable[..., Path], outputs: dict[str, Any],
                                      key: str, problem: str) -> None:
    path = _cell(tmp_path, write_small_cell, {"outputs": outputs}, signal=False)
    with pytest.raises(CellFileError) as caught:
        load_cell(path)
    assert caught.value.key is not None and caught.value.key.startswith(key), caught.value
    assert problem in str(caught.value)
