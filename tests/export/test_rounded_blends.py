"""A blend a dialect can state only at a coarse resolution (INFORM's `CR=` counts 0.1 mm): on a big
arm, where a corner turns the wrist more than it moves the TCP, the rounded distance puts the joints
a few hundredths of a degree off the plan's inside the blend (0.024 deg on a GP180 cell, against the
proof's 0.01), and the program was refused. It is proven in two steps (`publish`): the statements
with the planned distances rebuild the plan within the tolerances, and the program as written keeps
the TCP and the times within them and verifies clean. Tested on a KR 210 L150 imported from
tests/data/rosi, with pulse counts given for INFORM; a wrong target is still refused."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_BAD_INPUT, EXIT_OK, app
from robomax_py.export import DIALECTS
from robomax_py.export.dialect import Parsed
from robomax_py.program import Header, LinMove, Program, PtpMove, Spot
from robomax_py.publish import BLEND_ROUNDING_MM, _with_planned_blends

DATA = Path(__file__).resolve().parents[1] / "data"
runner = CliRunner()


@pytest.fixture(scope="module")
def rocker(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("rocker")
    robot = root / "robots" / "kr210"
    imported = runner.invoke(app, ["import-urdf", str(DATA / "rosi/kuka_kr210_support/urdf/kr210l150.xacro"),
                                   "-o", str(robot), "--packages", str(DATA / "rosi")])
    assert imported.exit_code == EXIT_OK, imported.output
    yaml_file = robot / "robot.yaml"
    # Any counts serve the proof; a real cell takes them from the controller's parameters.
    yaml_file.write_text(yaml_file.read_text().replace("controller:\n", "controller:\n  pulses_per_degree: "
                                                       "[1000, 1000, 1000, 1000, 1000, 1000]\n", 1))
    cell = root / "cells" / "kr210_rocker.yaml"
    (cell.parent / "parts").mkdir(parents=True)
    (cell.parent / "parts" / "rocker_mm.stl").write_bytes((DATA / "rocker_cell/parts/rocker_mm.stl").read_bytes())
    cell.write_text((DATA / "rocker_cell/kr210_rocker.yaml").read_text())
    return cell


def _plan(cell: Path, out: Path) -> Any:
    return runner.invoke(app, ["plan", str(cell), "-o", str(out), "--format", "inform", "--json"])


@pytest.mark.slow
def test_a_big_arms_inform_blends_are_proven_as_rounded(rocker: Path, tmp_path: Path) -> None:
    planned = _plan(rocker, tmp_path / "out")
    assert planned.exit_code == EXIT_OK, planned.output
    report = json.loads(planned.stdout)
    (program,) = [p for p in report["programs"] if p["format"] == "inform"]
    assert program["blends_rounded"] is True
    assert program["rebuilt_joint_deg"] > 0.01 and program["rebuilt_tcp_mm"] <= 0.1
    checked = runner.invoke(app, ["verify", str(rocker), str(tmp_path / "out" / "KR210_ROCKER.jbi")])
    assert checked.exit_code == EXIT_OK, checked.output


@pytest.mark.slow
def test_a_wrong_target_is_refused_though_the_blends_are_rounded(rocker: Path, tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    dialect = DIALECTS["inform"]

    def shifted(planned: Any, robot: Any) -> Program:
        """The job with its last joint target's axis 6 0.02 deg off (20 pulses), written and read
        back alike: the TCP moves under 0.1 mm, so only the rebuild with the planned blends tells."""
        program = dialect.adapt(planned, robot)
        ins = list(program.instructions)
        k = max(i for i, x in enumerate(ins) if isinstance(x, PtpMove))
        move = ins[k]
        assert isinstance(move, PtpMove)
        ins[k] = dataclasses.replace(move, target_deg=(*move.target_deg[:5], move.target_deg[5] + 0.02))
        return dataclasses.replace(program, instructions=tuple(ins))

    monkeypatch.setitem(DIALECTS, "inform", dataclasses.replace(dialect, adapt=shifted))
    planned = _plan(rocker, tmp_path / "out")
    assert planned.exit_code == EXIT_BAD_INPUT, planned.output
    assert "inform: the rebuilt motion differs from the planned one" in " ".join(planned.output.split())
    assert not (tmp_path / "out").exists()


def _parsed(*moves: PtpMove | LinMove) -> Parsed:
    header = Header("c", "r", "gun", 1.0, tuple(f"a{i}" for i in range(6)))
    return Parsed(Program("c", header, (), (*moves, Spot("s", "p", 0.4))), tuple(range(1, len(moves) + 2)), "")


def test_only_a_rounded_distance_is_taken_as_planned() -> None:
    q = (0.0, -90.0, 90.0, 0.0, 30.0, 0.0)
    written = _parsed(PtpMove(q, flyby_mm=33.2), PtpMove(q), LinMove((1, 2, 3), (0, 0, 0), flyby_mm=5.0))
    planned = _parsed(PtpMove(q, flyby_mm=33.2449), PtpMove(q), LinMove((1, 2, 3), (0, 0, 0), flyby_mm=4.97)).program
    got = _with_planned_blends(written, planned)
    assert got is not None
    assert [getattr(i, "flyby_mm", None) for i in got.program.instructions] == [33.2449, 0.0, 4.97, None]
    far = _parsed(PtpMove(q, flyby_mm=33.2 + 2 * BLEND_ROUNDING_MM), PtpMove(q), LinMove((1, 2, 3), (0, 0, 0),
                                                                                          flyby_mm=5.0))
    assert _with_planned_blends(far, planned) is None                     # not a rounding: refused
    assert _with_planned_blends(written, written.program) is None          # nothing rounded: nothing to excuse
    as_angles = _parsed(PtpMove(q, flyby=2.0), PtpMove(q), LinMove((1, 2, 3), (0, 0, 0), flyby=1.0))
    assert _with_planned_blends(as_angles, planned) is None               # blends not stated as distances
    assert _with_planned_blends(_parsed(PtpMove(q, flyby_mm=33.2)), planned) is None   # moves do not pair
