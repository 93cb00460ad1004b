"""End to end on every shipped example cell (cells/*.yaml): `robomax plan --format all` writes the
trajectory file and every dialect's program the arm's robot.yaml has the data for (no INFORM: no
shipped arm states its encoder pulses), and `robomax verify` passes on each (its motion
rebuilt from the program's own statements); the frame's seams are all welded and its ordered
pillar seam keeps its order; the programs are byte for byte the committed ones
(tests/golden/shipped: the .srcl text, and the SHA-256 of every other program file), so a
restructuring that changes no behaviour is shown to change no program. The trajectory file, whose
10 ms samples carry six decimals, is compared with a thinned golden copy within stated tolerances
instead: a new release of numpy or scipy moves the last decimal of a sample now and then, which is no
change of behaviour. The tending cell's program waits in front
of the doors for their signals and grips and releases at the stations, and its motion keeps the
clearance from every door while it is closed. Slow: each cell plans in 10-60 s."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, app
from robomax_py.export import dialect_for_file
from robomax_py.export.srcl import parse_program
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.program import Gripper, Spot, WaitFor, identifier

REPO = Path(__file__).resolve().parents[1]
CELLS = sorted((REPO / "cells").glob("*.yaml"))
GOLDEN = REPO / "tests" / "golden" / "shipped"
runner = CliRunner()
MAIN_FILES = (".json", ".srcl", ".src", ".mod", ".ls", ".script")
HASHED = (".src", ".dat", ".mod", ".ls", ".script")
# The trajectory's golden copy: every THIN-th sample, and the spots' times and configurations.
THIN = 25
T_TOL_S = 1e-4          # a sample's or a spot's time, and the cycle (100x the file's last decimal)
Q_TOL_RAD = 1e-4        # a joint angle (0.006 deg: far below any program's own resolution)


def test_at_least_three_shipped_cells() -> None:
    assert {p.stem for p in CELLS} >= {"cabin_flange", "frame", "ur10_tray"}


def _file(name: str, ext: str) -> str:
    """A cell's program file: named after the cell, or, for FANUC, after its TP program."""
    dialect = dialect_for_file(ext)
    return f"{dialect.program_name(identifier(name)) if dialect and dialect.program_name else name}{ext}"


def _verified(cell: Path) -> tuple[str, ...]:
    """The files `robomax verify` reads back for a cell: the trajectory file and one program, a
    different dialect for each shipped cell in turn (SRCL, KRL, RAPID, FANUC TP, URScript: the
    seven cells cover each), so that every dialect is verified from disk through the command line.
    (`plan` has already proven every program it wrote: read back, rebuilt and verified in-process,
    before writing; and every file is compared with its golden copy below.)"""
    dialects = (".srcl", ".src", ".mod", ".ls", ".script")
    return ".json", dialects[CELLS.index(cell) % len(dialects)]


def _plan(cell: Path, out: Path) -> dict[str, object]:
    result = runner.invoke(app, ["plan", str(cell), "-o", str(out), "--format", "all"])
    assert result.exit_code == EXIT_OK, result.output
    name = yaml.safe_load(cell.read_text()).get("name", cell.stem)
    # No shipped arm states encoder pulses per degree: `all` passes INFORM over and says so.
    text = " ".join(result.output.split())
    assert "robot.yaml: controller.pulses_per_degree is not given: no inform program written" in text, text
    assert not list(out.glob("*.jbi")) and not list(out.glob("*.JBI"))
    assert (out / f"{name}.as").is_file()
    for ext in MAIN_FILES:
        program = out / _file(name, ext)
        assert program.is_file(), f"{program} not written"
        if ext in _verified(cell):
            check = runner.invoke(app, ["verify", str(cell), str(program)])
            assert check.exit_code == EXIT_OK, check.output
    data: dict[str, object] = json.loads((out / f"{name}.json").read_text())
    return data


@pytest.mark.slow
@pytest.mark.parametrize("cell", CELLS, ids=[p.stem for p in CELLS])
def test_shipped_cell_plans_and_verifies(cell: Path, tmp_path: Path, update_golden: bool) -> None:
    data = _plan(cell, tmp_path)
    name = yaml.safe_load(cell.read_text()).get("name", cell.stem)
    srcl = (tmp_path / f"{name}.srcl").read_bytes()
    digests = {_file(name, ext): hashlib.sha256((tmp_path / _file(name, ext)).read_bytes()).hexdigest() for ext in HASHED}
    sums_file = GOLDEN / "SHA256SUMS"
    sums = dict(reversed(line.split("  ")) for line in sums_file.read_text().splitlines() if line)
    if update_golden:
        (GOLDEN / f"{name}.srcl").write_bytes(srcl)
        sums.update(digests)
        sums_file.write_text("".join(f"{v}  {k}\n" for k, v in sorted(sums.items())))
    assert srcl == (GOLDEN / f"{name}.srcl").read_bytes(), f"{name}.srcl differs from tests/golden/shipped"
    for file, digest in digests.items():
        assert digest == sums.get(file), f"{file} differs from tests/golden/shipped/SHA256SUMS"
    _same_trajectory(data, GOLDEN / f"{name}.trajectory.json", update_golden)
    spec = yaml.safe_load(cell.read_text())
    if "tending" in spec:                   # the job as one ordered seam of station visits per cycle
        job = spec["tending"]
        visits = job.get("sequence") or [st["name"] for st in job["stations"]]
        spec["seams"] = [{"name": "tending", "ordered": True, "spots": [
            {"name": f"c{c}_{v}"} for c in range(1, job.get("cycles", 1) + 1) for v in visits]}]
    if "pick_place" in spec:                # each transfer a pick where the part lies and a place
        spec["seams"] = [{"name": "transfers", "ordered": True, "spots": [
            {"name": f"t{k}_{visit}_{loc}"} for k, tr in enumerate(spec["pick_place"]["transfers"], start=1)
            for visit, loc in (("pick", tr["from"]), ("place", tr["to"]))]}]
    if "spot_lists" in spec:                # seams read from CSV lists (and the cell's own): as loaded
        spec["seams"] = [{"name": s.name, "ordered": s.ordered, "spots": [{"name": p.name} for p in s.spots]}
                         for s in load_cell(cell).seams]
    wanted = {(s["name"], p["name"]) for s in spec["seams"] for p in s["spots"]}
    welded = [(s["seam"], s["name"]) for s in data["spots"]]  # type: ignore[union-attr]
    assert sorted(welded) == sorted(wanted)                      # every spot of every seam, once
    for seam in spec["seams"]:
        if seam.get("ordered"):
            got = [name for s, name in welded if s == seam["name"]]
            assert got == [p["name"] for p in seam["spots"]], f"{seam['name']} welded out of order"


    if "tending" in spec and spec["tending"].get("machines"):
        _tending_program_and_doors(cell, tmp_path / f"{name}.srcl", data)
    elif spec.get("dynamic"):
        _clear_of_dynamic_objects(cell, data)


def _thinned(data: dict[str, Any]) -> dict[str, Any]:
    return {"cycle_time": data["cycle_time"], "t": data["t"][::THIN], "q": data["q"][::THIN],
            "spots": [{k: s[k] for k in ("seam", "name", "t_arrive", "t_leave", "config")} for s in data["spots"]]}


def _same_trajectory(data: dict[str, Any], golden: Path, update: bool) -> None:
    """The trajectory file against its thinned golden copy: the same spots in the same order with
    the same configurations, and times and joint angles within T_TOL_S and Q_TOL_RAD."""
    mine = _thinned(data)
    if update:
        golden.write_text(json.dumps(mine, separators=(",", ":")) + "\n")
    want = json.loads(golden.read_text())
    assert [(s["seam"], s["name"], s["config"]) for s in mine["spots"]] == \
        [(s["seam"], s["name"], s["config"]) for s in want["spots"]], f"{golden.name}: other spots or configurations"
    for key in ("t_arrive", "t_leave"):
        got, ref = (np.array([s[key] for s in d["spots"]]) for d in (mine, want))
        np.testing.assert_allclose(got, ref, rtol=0, atol=T_TOL_S, err_msg=f"{golden.name}: spot {key}")
    assert abs(mine["cycle_time"] - want["cycle_time"]) <= T_TOL_S, (mine["cycle_time"], want["cycle_time"])
    assert len(mine["t"]) == len(want["t"]), f"{golden.name}: {len(mine['t'])} thinned samples, golden {len(want['t'])}"
    np.testing.assert_allclose(mine["t"], want["t"], rtol=0, atol=T_TOL_S, err_msg=f"{golden.name}: t")
    np.testing.assert_allclose(mine["q"], want["q"], rtol=0, atol=Q_TOL_RAD, err_msg=f"{golden.name}: q")


def _tending_program_and_doors(cell_path: Path, srcl: Path, data: dict[str, object]) -> None:
    """The tending cell's written program and motion: waits only for the door signals, and some;
    grip then release at each machine, three cycles; no weld; never within the process clearance of
    a door while it is closed (every sample's exact minimum, refined between samples)."""
    from dataclasses import replace

    from robomax_py.world.collision import CollisionWorld
    from robomax_py.world.motion import min_clearance
    from robomax_py.world.scene import build_scene

    program = parse_program(srcl.read_text(), srcl)
    waits = [i.signal for i in program.instructions if isinstance(i, WaitFor)]
    assert waits and set(waits) <= {"cnc1_door_open", "cnc2_door_open"}, waits
    actions = [i.action for i in program.instructions if isinstance(i, Gripper)]
    assert actions == ["grip", "release", "grip", "release"] * 3, actions
    assert not any(isinstance(i, Spot) for i in program.instructions)
    cell = load_cell(cell_path)
    robot = load_cell_robot(cell)
    doors = CollisionWorld(robot, build_scene(replace(cell, objects=()), robot), 0.0).restricted(self_pairs=False)
    least = min_clearance(doors, np.asarray(data["t"], dtype=float), np.asarray(data["q"], dtype=float))
    assert least is not None and least.distance_m >= cell.process.clearance, least


def _clear_of_dynamic_objects(cell_path: Path, data: dict[str, object]) -> None:
    """A cell with moving objects (conveyor_crossing): the motion never comes within the process
    clearance of one while it is there (every sample's exact minimum against the spans that stand
    for it at that time, refined between samples)."""
    from dataclasses import replace

    from robomax_py.world.collision import CollisionWorld
    from robomax_py.world.motion import min_clearance
    from robomax_py.world.scene import build_scene

    cell = load_cell(cell_path)
    robot = load_cell_robot(cell)
    world = CollisionWorld(robot, build_scene(replace(cell, objects=()), robot), 0.0).restricted(self_pairs=False)
    least = min_clearance(world, np.asarray(data["t"], dtype=float), np.asarray(data["q"], dtype=float))
    assert least is not None and least.distance_m >= cell.process.clearance, least


def test_frame_has_an_ordered_seam_and_several_seams() -> None:
    spec = yaml.safe_load((REPO / "cells" / "frame.yaml").read_text())
    assert 3 <= len(spec["seams"]) <= 4
    assert [s["name"] for s in spec["seams"] if s.get("ordered")] == ["pillar"]
