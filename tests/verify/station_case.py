"""A two-robot station for the station replay's tests: two KR 125 with spot guns facing each other
across a shared zone, neither at the cell origin (r1 on a 0.3 m riser yawed 10 deg, r2 4.3 m away
yawed 190 deg); each welds one spot in the zone, where the two arms touch when both are in it and
neither touches the other at home. Programs are written from values, in any dialect."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from robomax_py.export import DIALECTS
from robomax_py.export.dialect import PlannedProgram, in_controller_terms
from robomax_py.io.cell import load_cell, load_cell_robot
from robomax_py.program import (
    Header,
    Instruction,
    Program,
    PtpMove,
    SetSignal,
    Spot,
    WaitFor,
)
from robomax_py.robot import fk_tcp
from robomax_py.spec import CellSpec, ControllerInput, ControllerOutput
from robomax_py.verify_station import StationMember

PLACES = {"r1": ((0.0, 0.0, 0.3), 10.0), "r2": ((4.3, 0.5, 0.0), 190.0)}
ZONE_DEG = (0.0, -20.0, 0.0, 0.0, 40.0, 0.0)     # each arm's joints in the shared zone
HOME_DEG = (0.0, -90.0, 90.0, 0.0, 0.0, 0.0)


def _cell_data(name: str, xyz: tuple[float, ...], yaw: float, spot: dict[str, Any]) -> dict[str, Any]:
    return {"robomax": 1, "name": name,
            "robot": {"model": "kr125", "base": {"xyz": list(xyz), "rpy": [0, 0, yaw]}, "home": list(HOME_DEG)},
            "tool": "spot_gun_c", "objects": [],
            "seams": [{"name": "zone", "tolerance": {"alpha": 5, "beta": 5, "gamma": [-180, 180]}, "grid": 3,
                       "spots": [spot]}],
            "process": {"weld_time": 0.5, "approach": 0.0}}


def station_cells(folder: Path) -> dict[str, tuple[CellSpec, Any]]:
    """Each robot's cell view and robot model; its one spot where its TCP is at ZONE_DEG, the
    station's signals mapped to inputs 1, 2 and outputs 3, 4."""
    out = {}
    for name, (xyz, yaw) in PLACES.items():
        path = folder / f"{name}.yaml"
        path.write_text(yaml.safe_dump(_cell_data(name, xyz, yaw, {"name": "s1", "xyz": [0, 0, 0], "normal": [0, 0, 1],
                                                                   "direction": [1, 0, 0]})))
        cell = load_cell(path)
        robot = load_cell_robot(cell)
        T = cell.T_world_base @ fk_tcp(robot, np.radians(ZONE_DEG))
        spot = {"name": "s1", "xyz": [float(v) for v in T[:3, 3]], "normal": [float(-v) for v in T[:3, 2]],
                "direction": [float(v) for v in T[:3, 0]]}
        path.write_text(yaml.safe_dump(_cell_data(name, xyz, yaw, spot)))
        cell = load_cell(path)
        other = "r2" if name == "r1" else "r1"
        # The interlock signals are the station's, not the single cell's: set on the view as a station gives them.
        controller = dataclasses.replace(
            cell.controller, inputs=(ControllerInput(f"{other}_z1_clear", 1), ControllerInput("r3_z9_clear", 2)),
            outputs=(ControllerOutput(f"{name}_z1_clear", 3),))
        out[name] = (dataclasses.replace(cell, controller=controller), robot)
    return out


def program(cell: CellSpec, robot: Any, name: str, waits: tuple[str, ...] = (), sets: tuple[str, ...] = (),
            spot: str = "s1") -> Program:
    """Home; wait for each of `waits`; into the zone, weld `spot`; home; set each of `sets`."""
    number = {i.signal: i.number for i in cell.controller.inputs}
    out_number = {o.signal: o.number for o in cell.controller.outputs}
    ins: list[Instruction] = [PtpMove(HOME_DEG)]
    ins += [WaitFor(s, number.get(s)) for s in waits]
    ins += [PtpMove(ZONE_DEG), Spot(spot, "zone", 0.5), PtpMove(HOME_DEG)]
    ins += [SetSignal(s, out_number.get(s), True) for s in sets]
    header = Header(cell.name, robot.name, cell.tool.name, 0.0, tuple(robot.joint_names))
    return Program(name, header, instructions=tuple(ins))


def write(folder: Path, cell: CellSpec, robot: Any, prog: Program, dialect: str) -> Path:
    """The program in `dialect`, as publishing writes it; its main file."""
    d = DIALECTS[dialect]
    joints = tuple(np.radians(i.target_deg) if isinstance(i, PtpMove) else np.radians(HOME_DEG)
                   for i in prog.instructions)
    planned = PlannedProgram(prog, joints, cell.controller)
    if d.brand:
        planned = in_controller_terms(planned, robot)
    texts = d.write(d.adapt(planned, robot), robot)
    for ext, text in texts.items():
        target = folder / (prog.name + ext)
        target.write_bytes(text.encode(d.fallback_encoding or "utf-8"))
    return folder / (prog.name + d.extensions[0])


def members(folder: Path, cells: dict[str, tuple[CellSpec, Any]], plans: dict[str, tuple[tuple[str, ...],
            tuple[str, ...], str]]) -> list[StationMember]:
    """Each robot's program (waits, sets, dialect) written into `folder` and named as a member."""
    out = []
    for name, (waits, sets, dialect) in plans.items():
        cell, robot = cells[name]
        path = write(folder, cell, robot, program(cell, robot, f"st_{name}", waits, sets), dialect)
        out.append(StationMember(name, cell, robot, path))
    return out


def station_file(folder: Path, cells: dict[str, tuple[CellSpec, Any]]) -> Path:
    """The same two robots as one station file `duo.yaml`: r1 welds zone/a1, r2 zone/b1 (each the
    spot of its own cell view), interlock I/O 1..4 on both."""
    spots = []
    for name, spot in (("r1", "a1"), ("r2", "b1")):
        seam = cells[name][0].seams[0].spots[0]
        spots.append({"name": spot, "xyz": [float(v) for v in seam.xyz], "normal": [float(v) for v in seam.normal],
                      "direction": [float(v) for v in seam.direction], "robots": [name]})
    data = {"robomax": 1, "name": "duo",
            "robots": [{"name": n, "model": "kr125", "tool": "spot_gun_c",
                        "base": {"xyz": list(xyz), "rpy": [0, 0, yaw]}, "home": list(HOME_DEG),
                        "controller": {"interlock_io": {"inputs": [1, 4], "outputs": [1, 4]}}}
                       for n, (xyz, yaw) in PLACES.items()],
            "objects": [],
            "seams": [{"name": "zone", "tolerance": {"alpha": 5, "beta": 5, "gamma": [-180, 180]}, "grid": 3,
                       "spots": spots}],
            "process": {"weld_time": 0.5, "approach": 0.0}}
    path = folder / "duo.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path
