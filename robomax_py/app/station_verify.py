"""`robomax verify STATION OUT_DIR` (or the programs listed): each robot's program found or named,
its cell view (the station's cell for that robot, narrowed to the spots its program welds, with the
interlock I/O numbers the plan gave it), the replay (`verify_station`) and its report."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from robomax_py.errors import CellFileError, ProgramError
from robomax_py.spec import ControllerInput, ControllerOutput
from robomax_py.spec_station import StationSpec, robot_view
from robomax_py.verify_station import StationMember, StationReport, verify_station


def station_programs(station: StationSpec, given: list[Path]) -> list[dict[str, Path]]:
    """The program sets to verify: the files named (one per robot, `<station>_<robot>.<ext>`), or
    in the one folder given, every dialect whose program every robot has there (one set each), and
    the robots' own controllers' programs (`plan --format native`: a KUKA and a FANUC robot in one
    station each run their own dialect) where they are not one dialect's set already."""
    from robomax_py.export import DIALECTS, Dialect, native_dialect
    from robomax_py.program import identifier

    def program_file(folder: Path, robot: str, d: Dialect) -> Path:
        # FANUC, KRL and RAPID name their files after the program (CROSSING_R1.ls): the dialect's
        # own name for the program's, which is the identifier of the robot's plan name.
        name = f"{station.name}_{robot}"
        return folder / f"{d.program_name(identifier(name)) if d.program_name else name}{d.extensions[0]}"

    robots = station.robot_names
    if len(given) == 1 and given[0].is_dir():
        folder = given[0]
        sets = []
        for d in DIALECTS.values():
            found = {r: program_file(folder, r, d) for r in robots}
            if all(p.is_file() for p in found.values()):
                sets.append(found)
        natives = {r: native_dialect(station.robot(r).cell.robot.controller.brand) for r in robots}
        if all(n is not None for n in natives.values()) and len({*natives.values()}) > 1:
            mixed = {r: program_file(folder, r, DIALECTS[str(n)]) for r, n in natives.items()}
            if all(p.is_file() for p in mixed.values()):
                sets.append(mixed)
        if not sets:
            raise ProgramError(folder, None, f"no program set of station {station.name} here: expected "
                                             f"{', '.join(f'{station.name}_{r}.<ext>' for r in robots)}")
        return sets
    named: dict[str, Path] = {}
    for path in given:
        if not path.exists():
            raise ProgramError(path, None, "no such file or folder")
        if path.suffix.lower() == ".json":
            # A robot's trajectory file holds its own motion; its interlocks are statements of its
            # program only, so the station is replayed from the programs (the read would otherwise
            # fail with "expected a trajectory file (.json) or a program", naming what was given).
            raise ProgramError(path, None, f"a trajectory file: station {station.name} is replayed from its robots' "
                                           "programs (their interlocks are statements there); give one program per "
                                           "robot or the output folder")
        robot = next((r for r in robots if path.stem.lower() == f"{station.name}_{r}".lower()), None)
        if robot is None:
            raise ProgramError(path, None, f"not a program of station {station.name}'s robots "
                                           f"({', '.join(f'{station.name}_{r}' for r in robots)})")
        if robot in named:
            raise ProgramError(path, None, f"a second program for robot {robot} (also {named[robot].name})")
        named[robot] = path
    missing = [r for r in robots if r not in named]
    if missing:
        raise ProgramError(given[0], None, f"no program for robot(s) {', '.join(missing)} of station {station.name}")
    return [named]


def interlock_io(station: StationSpec, folder: Path) -> dict[str, tuple[dict[str, int], dict[str, int]]]:
    """Per robot, the interlock inputs and outputs (signal -> number) the plan gave it, from
    `<station>.station.json` beside the programs: each of its `interlocks` is the `leader`'s
    output `leader_output` and the `waiter`'s input `waiter_input` of its `signal`. None when
    there is no such file (programs that name their signals, SRCL and RAPID, need none)."""
    path = folder / f"{station.name}.station.json"
    if not path.is_file():
        return {}
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ProgramError(path, None, f"cannot read the station file: {exc}") from None
    out: dict[str, tuple[dict[str, int], dict[str, int]]] = {r: ({}, {}) for r in station.robot_names}
    interlocks = data.get("interlocks", []) if isinstance(data, dict) else None
    if not isinstance(interlocks, list):
        raise ProgramError(path, "interlocks", "expected a list")
    for i, entry in enumerate(interlocks):
        try:
            signal, leader, waiter = str(entry["signal"]), str(entry["leader"]), str(entry["waiter"])
            output, input_ = entry["leader_output"], entry["waiter_input"]
        except (KeyError, TypeError):
            raise ProgramError(path, f"interlocks[{i}]", "expected signal, leader, waiter, leader_output and "
                                                         "waiter_input") from None
        for robot, number, key in ((leader, output, "leader"), (waiter, input_, "waiter")):
            if robot not in out:
                raise ProgramError(path, f"interlocks[{i}].{key}", f"{robot!r} is no robot of station {station.name}")
            if isinstance(number, int) and not isinstance(number, bool):
                out[robot][0 if key == "waiter" else 1][signal] = number
            elif number is not None:
                raise ProgramError(path, f"interlocks[{i}].{key}_{'input' if key == 'waiter' else 'output'}",
                                   f"expected an I/O number, got {number!r}")
    return out


def members_of(station: StationSpec, programs: dict[str, Path]) -> list[StationMember]:
    """Each robot's member: its cell narrowed to the spots its program welds, with its interlock I/O."""
    from robomax_py.io.cell import load_cell_robot
    from robomax_py.program import Spot, identifier
    from robomax_py.verify import read_program

    io = interlock_io(station, next(iter(programs.values())).parent)
    out = []
    for name, path in programs.items():
        cell = station.robot(name).cell
        robot = load_cell_robot(cell)
        welded = {(ins.seam, ins.name) for ins in read_program(robot, path)[2].program.instructions
                  if isinstance(ins, Spot)}
        spots = [s.key for s in station.spots if (identifier(s.seam), identifier(s.spot)) in welded]
        view = robot_view(station, name, spots)
        inputs, outputs = io.get(name, ({}, {}))
        # The plan's own setup (with_interlock_io) may hold them already: the file's numbers are added where not.
        have_in = {i.signal for i in view.controller.inputs}
        have_out = {o.signal for o in view.controller.outputs}
        controller = dataclasses.replace(
            view.controller,
            inputs=(*view.controller.inputs, *(ControllerInput(s, n) for s, n in inputs.items() if s not in have_in)),
            outputs=(*view.controller.outputs,
                     *(ControllerOutput(s, n) for s, n in outputs.items() if s not in have_out)))
        out.append(StationMember(name, dataclasses.replace(view, controller=controller), robot, path))
    return out


def verify_station_files(station_file: Path, given: list[Path]) -> list[tuple[dict[str, Path], list[StationMember],
                                                                         StationReport]]:
    """Every program set found or named: its files, members and replay (see the module docstring)."""
    from robomax_py.io.station import load_station

    station = load_station(station_file)
    if not given:
        raise CellFileError(station_file, None, "verify a station with its output folder or its robots' programs")
    out = []
    for programs in station_programs(station, given):
        members = members_of(station, programs)
        out.append((programs, members, verify_station(members, margin=station.clearance,
                                                       spots=[s.key for s in station.spots])))
    return out
