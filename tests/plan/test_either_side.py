"""A seam whose gun may stand on either side of the sheet (`tolerance.sides: either`): the grid is
searched on both sides, the plan takes the side the robot reaches, and `verify` holds the result to
the side rule the cell states, not to the planner's choice.

The spot is the reference cell's flange spot s8 with its normal reversed, as a spot list without
normals may give it: the given side puts the gun behind the flange, where the kr125 cannot turn it
(every candidate breaks a joint limit); the other side is the one a person would weld from.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import app
from robomax_py.io.cell import load_cell
from robomax_py.plan.poses import orientation_grid
from robomax_py.robot import fk_tcp
from robomax_py.spec import SeamSpec
from tests.plan.test_plan import PANEL_ON_TABLE, SPOTS, plan_file, write_cell

REVERSED_S8 = {**SPOTS["s8"], "normal": [1, 0, 0]}
AXIS_TOL = 1e-12        # rotation matrices built from exact angles: rounding only
runner = CliRunner()


def _either(path: Path, either: bool) -> Path:
    data = yaml.safe_load(path.read_text())
    if either:
        data["seams"][0]["tolerance"]["sides"] = "either"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def cells(tmp_path_factory: pytest.TempPathFactory) -> dict[bool, Path]:
    return {e: _either(write_cell(tmp_path_factory.mktemp(f"either_{e}"), [REVERSED_S8], PANEL_ON_TABLE), e)
            for e in (False, True)}


def test_the_other_side_doubles_the_grid_turned_about_the_seam_direction() -> None:
    spots = load_cell(Path(__file__).resolve().parents[1] / "data" / "flange_cell" / "cabin_flange.yaml").seams[0].spots
    one = SeamSpec(name="s", ordered=False, alpha_max=math.radians(10), beta_max=math.radians(10),
                   gamma_range=(0.0, math.radians(90)), grid=3, spots=spots)
    both = SeamSpec(**{**{f: getattr(one, f) for f in SeamSpec.__slots__}, "either_side": True})
    g1, g2 = orientation_grid(one), orientation_grid(both)
    assert len(g2) == 2 * len(g1)
    np.testing.assert_array_equal(g2.R_offset[:len(g1)], g1.R_offset)
    turn = np.diag([1.0, -1.0, -1.0])                           # Rx(180 deg)
    np.testing.assert_allclose(g2.R_offset[len(g1):], turn @ g1.R_offset, atol=AXIS_TOL)
    # Each angle triple still names its rotation, alpha within (-180, 180] deg.
    a = g2.angles[len(g1):, 0]
    assert np.all((a > -np.pi) & (a <= np.pi)) and np.all(np.abs(a) >= np.pi - one.alpha_max - AXIS_TOL)


def test_either_side_welds_the_spot_the_given_side_cannot(cells: dict[bool, Path]) -> None:
    _, _, only = plan_file(cells[False])
    assert only.status == "infeasible" and "s8" in only.message
    cell, robot, result = plan_file(cells[True])
    assert result.status == "planned", result.message
    (spot,) = result.spots
    assert abs(spot.angles[0]) > np.pi / 2                     # the other side's grid
    # At the controller's joints: the electrode axis (TCP z) runs along the given normal, not against
    # it, within the tilt the grid allows (alpha and beta up to 10 deg each).
    z = (np.asarray(cell.T_world_base) @ fk_tcp(robot, spot.q_spot))[:3, 2]
    assert float(z @ np.asarray(REVERSED_S8["normal"])) >= math.cos(math.radians(10)) ** 2


def test_verify_holds_the_plan_to_the_side_rule_of_the_cell(cells: dict[bool, Path], tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = runner.invoke(app, ["plan", str(cells[True]), "-o", str(out), "--format", "native"])
    assert done.exit_code == 0, done.output
    trajectory = out / "small.json"
    clean = runner.invoke(app, ["verify", str(cells[True]), str(trajectory)])
    assert clean.exit_code == 0 and "clean" in clean.output, clean.output
    # The same motion against the cell that allows only the given side: the orientation is outside.
    refused = runner.invoke(app, ["verify", str(cells[False]), str(trajectory)])
    assert refused.exit_code != 0 and "outside the tolerance" in refused.output, refused.output


def test_a_pinned_alpha_on_the_other_side_needs_either(tmp_path: Path) -> None:
    spot: dict[str, Any] = {**REVERSED_S8, "alpha": 175.0, "beta": 0.0, "gamma": 0.0}
    path = write_cell(tmp_path / "pinned", [spot], PANEL_ON_TABLE)
    refused = runner.invoke(app, ["check", str(path)])
    assert refused.exit_code == 2 and "seams[0].spots[0].alpha" in refused.output, refused.output
    assert runner.invoke(app, ["check", str(_either(path, True))]).exit_code == 0
