"""A tool's stated load in the programs: RAPID tooldata's tload and URScript's set_payload, each read
here as the vendor defines it (not by robomax's readers), the programs still proven by robomax's
own readers; every other file the same as the program of the same plan without a load.

RAPID ([R3] ABB RAPID Reference Manual BaseWare OS 3.x p. 225-226, tooldata; p. 183, loaddata):
tooldata = [robhold, tframe [trans [x, y, z] mm, rot [q1..q4]], tload [mass kg, cog [x, y, z] mm
in the wrist frame, aom [q1..q4], ix, iy, iz kgm2]]. URScript (Universal Robots, "How to change
payload and center of gravity settings using URScript"): set_payload(mass kg, [Cx, Cy, Cz] m from
the tool flange)."""

from __future__ import annotations

import ast
import dataclasses
import json
import re
from typing import Any

import pytest

from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.plan import plan_cell
from robomax_py.publish import publish

MASS_KG = 110.0
COG_M = (0.12, -0.015, 0.18)
# The files write mass and centre of gravity in mm to 3 decimals, m to 6: read back within these.
MASS_TOL_KG = 5e-4
COG_TOL_MM = 5e-4
DIALECTS = ("rapid", "urscript")


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory, write_tool: Any, write_small_cell_with_tool: Any) -> dict[str, Any]:
    """The small cell planned with spot_gun_c stating a 110 kg load; its RAPID and URScript files,
    and those of the same plan without the load."""
    root = tmp_path_factory.mktemp("loaded")
    gun = write_tool(root / "gun", "spot_gun_c", {"mass": MASS_KG, "cog": list(COG_M)})
    path = write_small_cell_with_tool(root, gun)
    cell = load_cell(path)
    robot = load_cell_robot(cell)
    result = plan_cell(cell, robot)
    assert result.status == "planned", result.message
    files, checked = publish(result, cell, robot, DIALECTS)
    bare, _ = publish(dataclasses.replace(result, tool_load=None), cell, robot, DIALECTS)
    return {"files": files, "checked": checked, "bare": bare}


def _aggregate(text: str) -> Any:
    """A RAPID aggregate of numbers and booleans, as nested lists (its brackets are JSON's)."""
    return json.loads(re.sub(r"\bTRUE\b", "true", re.sub(r"\bFALSE\b", "false", text)))


def _tooldata(module: str) -> dict[str, Any]:
    """Every `PERS tooldata name := [...];` of a module, the statement's comment left out."""
    found = re.findall(r"^\s*PERS\s+tooldata\s+(\w+)\s*:=\s*(\[.*\])\s*;", module, flags=re.MULTILINE)
    return {name: _aggregate(value) for name, value in found}


def test_rapid_tooldata_carries_the_tool_load(written: dict[str, Any]) -> None:
    (tool,) = _tooldata(written["files"]["small_cell_frames.mod"]).values()
    robhold, (trans, rot), tload = tool
    assert robhold is True and len(trans) == 3 and len(rot) == 4
    mass, cog, aom, ix, iy, iz = tload
    assert mass == pytest.approx(MASS_KG, abs=MASS_TOL_KG)
    assert cog == pytest.approx([1000.0 * v for v in COG_M], abs=COG_TOL_MM)
    assert aom == [1, 0, 0, 0] and (ix, iy, iz) == (0, 0, 0)       # a point mass ([R3] p. 226)


def test_rapid_without_a_load_keeps_the_placeholder(written: dict[str, Any]) -> None:
    module = written["bare"]["small_cell_frames.mod"]
    (tool,) = _tooldata(module).values()
    _, (trans, _), (mass, cog, *_) = tool
    assert mass == 1 and cog == trans                                  # 1 kg at the TCP
    assert "a placeholder: replace with the gun's (LoadIdentify)" in module


def test_urscript_sets_the_payload_before_the_first_motion(written: dict[str, Any]) -> None:
    lines = written["files"]["small_cell.script"].splitlines()
    assert lines[0].startswith("def ") and lines[0].endswith("():")
    calls = [(k, line) for k, line in enumerate(lines) if re.match(r"^\s+set_payload\(", line)]
    assert len(calls) == 1
    k, line = calls[0]
    first_motion = next(i for i, text in enumerate(lines) if re.match(r"^\s+move[jl]\(", text))
    assert 0 < k < first_motion
    mass, cog = ast.literal_eval(line.split("#")[0].strip()[len("set_payload"):])
    assert mass == pytest.approx(MASS_KG, abs=MASS_TOL_KG)
    assert [1000.0 * v for v in cog] == pytest.approx([1000.0 * v for v in COG_M], abs=COG_TOL_MM)
    assert "set_payload" not in written["bare"]["small_cell.script"]


def test_programs_with_a_load_are_proven_and_otherwise_unchanged(written: dict[str, Any]) -> None:
    """robomax's readers accept the programs (the plan's motion, a clean report), and the only lines
    that differ from the program without a load are the load's own."""
    for c in written["checked"]:
        assert c.difference.within()
        assert c.report is None or c.report.clean
    assert set(written["files"]) == set(written["bare"])
    for name, text in written["files"].items():
        old, new = written["bare"][name].splitlines(), text.splitlines()
        changed = [line for line in new if line not in old]
        gone = [line for line in old if line not in new]
        if name == "small_cell_frames.mod":
            assert len(changed) == len(gone) == 1 and "tooldata" in changed[0]
        elif name == "small_cell.script":
            assert not gone and len(changed) == 1 and "set_payload" in changed[0]
        else:
            assert text == written["bare"][name], name
