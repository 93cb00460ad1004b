"""Station files (docs/stations.md) -> a checked StationSpec: several robots around one fixture.

A station file is a cell file with `robots:` (a list) instead of `robot:` and `tool:`, and seams and
spots that may name the robots allowed to weld them. Each robot is read as the single-robot cell it
would be on its own (the station's objects, seams, process and planner with that robot's model, tool,
placement, home and controller), by the cell reader itself, so every check of a cell applies and an
error names the station file and the station's key (`robots[1].home[2]`). Nothing here prints.
"""

from __future__ import annotations

import copy
import dataclasses
import re
from pathlib import Path
from typing import Annotated, Any

from pydantic import Field, ValidationError, model_validator

from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.io.cell import _cell_from_data
from robomax_py.io.cell_file import IncludeFile
from robomax_py.io.cell_file_values import (
    SUPPORTED_VERSIONS,
    CellName,
    PoseFile,
    Reference,
    _Strict,
    stem_name,
)
from robomax_py.io.cell_problems import _located
from robomax_py.io.includes import expand_includes
from robomax_py.io.yaml_files import read_yaml_mapping, validation_error
from robomax_py.program import identifier
from robomax_py.safe_files import LIMITS, read_text
from robomax_py.spec import Brand, dynamic_signal
from robomax_py.spec_station import IoRange, StationRobot, StationSpec, StationSpot

# Robot names become parts of program names and signal names (`<robot>_<zone>_clear`): identifiers.
RobotName = Annotated[str, Field(pattern=r"^[A-Za-z][A-Za-z0-9_]{0,15}$")]
MAX_STATION_ROBOTS = 16
IoNumber = Annotated[int, Field(ge=0, le=65535)]


class IoRangeFile(_Strict):
    inputs: Annotated[list[IoNumber], Field(min_length=2, max_length=2)]    # [first, last], ends included
    outputs: Annotated[list[IoNumber], Field(min_length=2, max_length=2)]

    @model_validator(mode="after")
    def _ordered(self) -> IoRangeFile:
        for key in ("inputs", "outputs"):
            first, last = getattr(self, key)
            if first > last:
                raise ValueError(f"{key}: expected [first, last] with first <= last, got [{first}, {last}]")
        return self


class StationControllerFile(_Strict):
    """A station robot's `controller`: a cell's `robot.controller` keys (checked by the cell reader)
    plus the brand it is expected to be and the I/O numbers interlocks may use."""

    model_config = _Strict.model_config | {"extra": "allow"}
    brand: Brand | None = None
    interlock_io: IoRangeFile | None = None


class StationRobotFile(_Strict):
    name: RobotName
    model: Reference
    tool: Reference
    base: PoseFile = PoseFile()
    frame: str | None = None
    home: list[Any]
    joint_limits: list[Any] | None = None     # checked as a cell's robot.joint_limits
    controller: StationControllerFile = StationControllerFile()


class StationKeysFile(_Strict):
    """The keys a station adds; the rest of the file is a cell's and is checked as one."""

    model_config = _Strict.model_config | {"extra": "allow"}
    robomax: int
    name: CellName | None = None
    robots: Annotated[list[StationRobotFile], Field(min_length=1, max_length=MAX_STATION_ROBOTS)]


def is_station_file(path: str | Path) -> bool:
    """Whether a cell file is a station (has a top-level `robots:` key); False for anything unreadable
    (the cell reader then names the problem)."""
    try:
        text = read_text(Path(path), LIMITS.cell, CellFileError, "cell file")
    except CellFileError:
        return False
    return re.search(r"^robots\s*:", text, re.MULTILINE) is not None


def load_station(path: str | Path) -> StationSpec:
    """Read and check a station file and every robot, tool and mesh it names."""
    path = Path(path)
    text = read_text(path, LIMITS.cell, CellFileError, "station file")
    data = read_yaml_mapping(path, CellFileError, "station file", LIMITS.cell)
    for key in ("robot", "tool"):
        if key in data:
            raise CellFileError(path, key, "a station gives its robots under `robots:` (each with its own model and "
                                "tool); remove the single-robot `robot:`/`tool:` or the `robots:` list")
    version = data.get("robomax")
    if version not in SUPPORTED_VERSIONS:
        supported = ", ".join(str(v) for v in SUPPORTED_VERSIONS)
        raise CellFileError(path, "robomax", f"unsupported format version {version!r}; this robomax reads {supported}")
    try:
        keys = StationKeysFile.model_validate({k: data[k] for k in ("robomax", "name", "robots") if k in data})
    except ValidationError as exc:
        raise validation_error(exc, StationKeysFile, path, CellFileError) from None
    names = _robot_names(keys, path)
    shared = {k: v for k, v in data.items() if k != "robots"}
    seams_given = shared.get("seams")
    allowed = _allowed_robots(seams_given, names, path)
    if "seams" in shared:                   # absent: the spots come from `spot_lists` (a CAD export)
        shared["seams"] = _without_robot_keys(seams_given)
    expansion = expand_includes(shared, path, IncludeFile)
    digest = expansion.digest(text.encode("utf-8"))
    name = keys.name or stem_name(path)
    shared_data, listed = _without_list_robots(expansion.data, names, path)
    robots = tuple(_robot(shared_data=shared_data, robot=r, index=i, station=name, path=path, digest=digest,
                          expansion=expansion, count=len(names))
                   for i, r in enumerate(keys.robots))
    _no_interlock_names(shared_data, names, path)
    for i, list_robots in listed.items():
        # The spots list i gives, as the cell reader forms them: that list read alone, in the first
        # robot's cell (a list's seams do not depend on the others'; the whole cell was read above).
        alone = {**shared_data, "seams": [], "spot_lists": [shared_data["spot_lists"][i]]}
        view = _robot(shared_data=alone, robot=keys.robots[0], index=0, station=name, path=path, digest=digest,
                      expansion=expansion, count=len(names))
        allowed.update({(seam.name, spot.name): list_robots for seam in view.cell.seams for spot in seam.spots})
    spots = tuple(StationSpot(seam.name, spot.name, allowed.get((seam.name, spot.name), names))
                  for seam in robots[0].cell.seams for spot in seam.spots)
    notices = tuple(dict.fromkeys(n for r in robots for n in r.cell.notices))
    return StationSpec(name=name, source=path.resolve(), digest=digest, robots=robots, spots=spots, notices=notices)


def _no_interlock_names(data: dict[str, Any], robots: tuple[str, ...], path: Path) -> None:
    """Refuse a cell signal (a clamp's, a dynamic object's `<name>_clear`) that a program would
    write as an interlock's, `<robot>_z<k>_clear` (`station.interlocks`): the robot waiting for the
    one would wait on the other's input, or both."""
    pattern = re.compile(rf"({'|'.join(map(re.escape, robots))})_z[0-9]+_clear", re.IGNORECASE)
    given: list[tuple[str, str]] = []
    for group, key in (("objects", "signal"), ("dynamic", "name")):
        items = data.get(group)
        for i, item in enumerate(items if isinstance(items, list) else []):
            if isinstance(item, dict) and isinstance(item.get(key), str):
                signal = item[key] if group == "objects" else dynamic_signal(item[key], False)
                given.append((f"{group}[{i}].{key}", signal))
    for key, signal in given:
        if pattern.fullmatch(identifier(signal)):
            raise CellFileError(path, key, f"the signal '{signal}' is written as a station interlock's "
                                "(<robot>_z<k>_clear, set by one robot for another): give it another name")


def _robot_names(keys: StationKeysFile, path: Path) -> tuple[str, ...]:
    seen: dict[str, int] = {}
    for i, r in enumerate(keys.robots):
        if r.name in seen:
            raise CellFileError(path, f"robots[{i}].name", f"duplicate robot name '{r.name}' (also robots[{seen[r.name]}])")
        seen[r.name] = i
    return tuple(seen)


def _allowed_robots(seams: Any, names: tuple[str, ...], path: Path) -> dict[tuple[str, str], tuple[str, ...]]:
    """Per spot, the robots a seam's and a spot's `robots` keys allow (a spot's narrows its seam's)."""
    out: dict[tuple[str, str], tuple[str, ...]] = {}
    if not isinstance(seams, list):
        return out                          # the cell reader names the problem
    for i, seam in enumerate(seams):
        if not isinstance(seam, dict):
            continue
        seam_robots = _robot_list(seam.get("robots"), names, names, path, f"seams[{i}].robots")
        spots = seam.get("spots")
        for j, spot in enumerate(spots if isinstance(spots, list) else []):
            if not isinstance(spot, dict):
                continue
            spot_robots = _robot_list(spot.get("robots"), seam_robots, names, path, f"seams[{i}].spots[{j}].robots")
            if isinstance(seam.get("name"), str) and isinstance(spot.get("name"), str):
                out[(seam["name"], spot["name"])] = spot_robots
    return out


def _robot_list(given: Any, within: tuple[str, ...], names: tuple[str, ...], path: Path, key: str) -> tuple[str, ...]:
    if given is None:
        return within
    if not isinstance(given, list) or not given or not all(isinstance(g, str) for g in given):
        raise CellFileError(path, key, f"expected a non-empty list of robot names (of {', '.join(names)}), got {given!r}")
    for g in given:
        if g not in names:
            raise CellFileError(path, key, f"unknown robot '{g}' (the station's robots: {', '.join(names)})")
        if g not in within:
            raise CellFileError(path, key, f"robot '{g}' may not weld this seam (its `robots`: {', '.join(within)}): "
                                "a spot's list narrows its seam's")
    if len(set(given)) != len(given):
        raise CellFileError(path, key, "names a robot twice")
    return tuple(n for n in names if n in given)


def _without_list_robots(data: dict[str, Any], names: tuple[str, ...], path: Path
                         ) -> tuple[dict[str, Any], dict[int, tuple[str, ...]]]:
    """The station's data with each spot list's `robots` key taken out (a cell's list has none), and
    the robots each list that had one allows, by the list's index."""
    lists = data.get("spot_lists")
    if not isinstance(lists, list):
        return data, {}
    listed: dict[int, tuple[str, ...]] = {}
    kept = []
    for i, entry in enumerate(lists):
        if isinstance(entry, dict) and "robots" in entry:
            listed[i] = _robot_list(entry["robots"], names, names, path, f"spot_lists[{i}].robots")
            entry = {k: v for k, v in entry.items() if k != "robots"}
        kept.append(entry)
    return {**data, "spot_lists": kept}, listed


def _without_robot_keys(seams: Any) -> Any:
    """The seams as a cell file holds them: the station's `robots` keys taken out."""
    if not isinstance(seams, list):
        return seams
    out = []
    for seam in seams:
        if isinstance(seam, dict):
            seam = {k: v for k, v in seam.items() if k != "robots"}
            if isinstance(seam.get("spots"), list):
                seam["spots"] = [{k: v for k, v in s.items() if k != "robots"} if isinstance(s, dict) else s
                                 for s in seam["spots"]]
        out.append(seam)
    return out


def _robot(*, shared_data: dict[str, Any], robot: StationRobotFile, index: int, station: str, path: Path, digest: str,
           expansion: Any, count: int) -> StationRobot:
    """One robot read as the cell it would be alone; errors name the station's keys."""
    prefix = f"robots[{index}]"
    controller = robot.controller.model_dump(exclude={"brand", "interlock_io"}, exclude_none=False)
    controller = {k: v for k, v in controller.items() if k in (robot.controller.model_extra or {})}
    robot_data: dict[str, Any] = {"model": robot.model, "base": robot.base.model_dump(), "home": robot.home,
                                  "controller": copy.deepcopy(controller)}
    if robot.frame is not None:
        robot_data["frame"] = robot.frame
    if robot.joint_limits is not None:
        robot_data["joint_limits"] = copy.deepcopy(robot.joint_limits)
    data = {**copy.deepcopy(shared_data), "name": f"{station}_{robot.name}", "robot": robot_data, "tool": robot.tool}
    try:
        cell = _located(expansion, _cell_from_data, data, path, digest, expansion)
    except (CellFileError, RobotModelError) as exc:
        if exc.file != str(path):
            raise
        raise type(exc)(exc.file, _station_key(exc.key, prefix), exc.problem) from None
    brand = robot.controller.brand
    if brand is not None and brand != cell.robot.controller.brand:
        raise CellFileError(path, f"{prefix}.controller.brand", f"'{brand}', but {robot.model}'s robot.yaml names "
                            f"'{cell.robot.controller.brand}': the robot.yaml's controller is the one its programs are "
                            "written for")
    io = robot.controller.interlock_io
    if io is None:
        if count > 1:
            raise CellFileError(path, f"{prefix}.controller.interlock_io", "required in a station of several robots: "
                                "{inputs: [first, last], outputs: [first, last]}, the I/O numbers interlocks may use")
        io = IoRangeFile(inputs=[0, 0], outputs=[0, 0])
    inputs, outputs = IoRange(*io.inputs), IoRange(*io.outputs)
    for kind, rng, taken in (("inputs", inputs, cell.controller.inputs), ("outputs", outputs, cell.controller.outputs)):
        clash = next((t for t in taken if rng.first <= t.number <= rng.last), None)
        if clash is not None:
            raise CellFileError(path, f"{prefix}.controller.interlock_io.{kind}",
                                f"[{rng.first}, {rng.last}] holds {kind[:-1]} {clash.number}, already {clash.signal}'s")
    return StationRobot(name=robot.name, cell=dataclasses.replace(cell, notices=()), interlock_inputs=inputs,
                        interlock_outputs=outputs)


def _station_key(key: str | None, prefix: str) -> str | None:
    """A key of the robot's stand-in cell as the station file spells it."""
    if key is None:
        return None
    if key == "robot" or key.startswith(("robot.", "robot[")):
        return prefix + key[len("robot"):]
    if key == "tool" or key.startswith("tool."):
        return f"{prefix}.{key}"
    if key == "name":
        return f"{prefix}.name"
    return key
