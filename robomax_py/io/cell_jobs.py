"""A cell's job as seams of spots: welding seams (each spot checked, skipped spots left out), a
tending job's station visits and a pick-and-place job's transfers (each one ordered seam), with
the machines, their doors and the parts those jobs name."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robomax_py.errors import CellFileError
from robomax_py.io.cell_file import CellFile, SeamFile, SpotFile, ToleranceFile
from robomax_py.io.cell_file_jobs import (
    PICK_PLACE_SEAM,
    TENDING_SEAM,
    PickPlaceFile,
    TcpLimitsFile,
)
from robomax_py.io.cell_file_values import MAX_WINDOW_S, MIN_DIRECTION_SINE
from robomax_py.io.cell_objects import _object, _pose
from robomax_py.io.cell_problems import _Problems
from robomax_py.program import identifier
from robomax_py.spec import (
    MachineSpec,
    ObjectSpec,
    PartSpec,
    RobotSpec,
    SeamSpec,
    SpotSpec,
    TcpLimits,
    ToolSpec,
    frozen_array,
)
from robomax_py.transforms import invert, pose_matrix
from robomax_py.units import deg_to_rad


def _job_seams(parsed: CellFile, path: Path, problems: _Problems) -> tuple[SeamSpec, ...]:
    if parsed.tending is not None:
        return _tending_seams(parsed, path)
    if parsed.pick_place is not None:
        return _pick_place_seams(parsed.pick_place, {o.name for o in parsed.objects}, path)
    return _seams(parsed, path, problems)


def _tcp_limits(limits: TcpLimitsFile | None) -> TcpLimits | None:
    return None if limits is None else TcpLimits(limits.v, limits.a_T, limits.a_R, limits.j_T, limits.j_R)


def _parts(parsed: CellFile, path: Path, robot: RobotSpec, triangles: list[int]) -> tuple[PartSpec, ...]:
    """The parts with their held pose in the TCP frame and the supports of the locations they visit."""
    job = parsed.pick_place
    if job is None:
        return ()
    out = []
    for i, part in enumerate(job.parts):
        key = f"pick_place.parts[{i}]"
        if robot.payload_kg is not None and part.mass > robot.payload_kg:
            raise CellFileError(path, f"{key}.mass", f"{part.mass:g} kg is above the robot's rated payload "
                                f"{robot.payload_kg:g} kg ({robot.source})")
        shape = _object(part, path, key, triangles).shape
        at = {t.from_ for t in job.transfers if t.part == part.name} | {t.to for t in job.transfers if t.part == part.name}
        lying = [loc for loc in job.locations if loc.name in at]
        supports = sorted({name for loc in lying for name in loc.support})
        # The world's up in the part's frame where it lies (each location pose's third row), their
        # mean; the world's z where there is none (a part no transfer moves) or the mean vanishes
        # (laid down upside down as often as not).
        up = np.mean([_pose(loc.pose)[2, :3] for loc in lying], axis=0) if lying else np.zeros(3)
        up = up / norm if (norm := float(np.linalg.norm(up))) > 1e-9 else np.array([0.0, 0.0, 1.0])
        out.append(PartSpec(name=part.name, shape=shape, mass=part.mass,
                            T_tcp_part=frozen_array(invert(_pose(part.grasp))),
                            limits=_tcp_limits(part.limits), supports=tuple(supports), up=frozen_array(up)))
    return tuple(out)


def check_tool_load(robot: RobotSpec, tool: ToolSpec, parts: tuple[PartSpec, ...], path: Path) -> None:
    """The tool's stated mass, with the heaviest part the job carries, within the robot's rated
    payload (both stated: a tool or robot file without them is not checked). The rating holds for
    everything on the flange, tool and part together."""
    if robot.payload_kg is None or tool.load is None:
        return
    heaviest = max(parts, key=lambda p: p.mass, default=None)
    total = tool.load.mass + (0.0 if heaviest is None else heaviest.mass)
    if total <= robot.payload_kg:
        return
    weight = f"the tool '{tool.name}' weighs {tool.load.mass:g} kg ({tool.source})"
    if heaviest is not None:
        weight += f" and carries the part '{heaviest.name}' of {heaviest.mass:g} kg: {total:g} kg"
    raise CellFileError(path, "tool", f"{weight}, "
                        f"above the robot's rated payload {robot.payload_kg:g} kg ({robot.source})")


def same_identifier(names: list[str], key: str, path: Path) -> None:
    """Refuse two names of the list at `key` that a program states alike (`program.identifier`:
    other characters than letters, digits and `_` become `_`): its statements, and `verify`
    reading them, could not tell the two apart."""
    found = _written_alike(names)
    if found is not None:
        i, k, ident = found
        raise CellFileError(path, f"{key}[{i}].name", f"'{names[i]}' and '{names[k]}' ({key.split('.')[-1]}[{k}]) are "
                            f"both written {ident} in programs, which name things with letters, digits and '_' "
                            "only: give names that differ there")


def signals_apart(signals: list[tuple[str, str]], path: Path) -> None:
    """Refuse two different signals, given as (key, name) pairs, that a program states alike: the
    same name twice is one input (two clamps may share one), but `clamp-1` and `clamp 1` would both
    be waited for as `clamp_1`, one input standing for two, without a word."""
    found = _written_alike([name for _, name in signals])
    if found is not None:
        i, k, ident = found
        raise CellFileError(path, signals[i][0], f"the signal '{signals[i][1]}' and the signal '{signals[k][1]}' "
                            f"({signals[k][0]}) are both written {ident} in programs, which name signals with letters, "
                            "digits and '_' only: give names that differ there")


def _written_alike(names: list[str]) -> tuple[int, int, str] | None:
    """(i, k, identifier): the first name i that a program writes as an earlier, different name k
    (the same name twice is one thing); None when every two are told apart."""
    seen: dict[str, int] = {}
    for i, name in enumerate(names):
        ident = identifier(name)
        k = seen.setdefault(ident, i)
        if names[k] != name:
            return i, k, ident
    return None


def _index_by_name(names: list[str], what: str, key: str, path: Path) -> dict[str, int]:
    """name -> index in the list at `key`; a repeated name is refused with both places."""
    out: dict[str, int] = {}
    for i, name in enumerate(names):
        if name in out:
            raise CellFileError(path, f"{key}[{i}].name", f"duplicate {what} name '{name}' (also {key.split('.')[-1]}[{out[name]}])")
        out[name] = i
    same_identifier(names, key, path)
    return out


def _pick_place_seams(job: PickPlaceFile, objects: set[str], path: Path) -> tuple[SeamSpec, ...]:
    """The transfers as one ordered seam: per transfer a grip where the part lies and a release
    where it goes, each at the TCP pose the part's grasp gives there."""
    parts = _index_by_name([p.name for p in job.parts], "part", "pick_place.parts", path)
    locations = _index_by_name([loc.name for loc in job.locations], "location", "pick_place.locations", path)
    for i, loc in enumerate(job.locations):
        for j, name in enumerate(loc.support):
            if name not in objects:
                raise CellFileError(path, f"pick_place.locations[{i}].support[{j}]",
                                    f"unknown object '{name}' (a support is one of the cell's objects)")
    spots = []
    for k, tr in enumerate(job.transfers):
        key = f"pick_place.transfers[{k}]"
        if tr.part not in parts:
            raise CellFileError(path, f"{key}.part", f"unknown part '{tr.part}' (parts: {', '.join(parts)})")
        for field, name in (("from", tr.from_), ("to", tr.to)):
            if name not in locations:
                raise CellFileError(path, f"{key}.{field}", f"unknown location '{name}' (locations: {', '.join(locations)})")
        if tr.from_ == tr.to:
            raise CellFileError(path, f"{key}.to", f"the part goes back where it lies ('{tr.to}'): a transfer moves it")
        T_tcp_in_part = _pose(job.parts[parts[tr.part]].grasp)
        for action, name, visit in (("grip", tr.from_, "pick"), ("release", tr.to, "place")):
            T = _pose(job.locations[locations[name]].pose) @ T_tcp_in_part
            R = T[:3, :3]
            spots.append(SpotSpec(
                name=f"t{k + 1}_{visit}_{name}", xyz=frozen_array(T[:3, 3]), normal=frozen_array(-R[:, 2]),
                direction=frozen_array(R[:, 0]),
                weld_time=job.gripper.grip if action == "grip" else job.gripper.release,
                angles=(0.0, 0.0, 0.0), action=action, key=key, part=tr.part,  # type: ignore[arg-type]
            ))
    return (SeamSpec(name=PICK_PLACE_SEAM, ordered=True, alpha_max=0.0, beta_max=0.0, gamma_range=(0.0, 0.0),
                     grid=1, spots=tuple(spots)),)


def _check_pinned(spot: SpotFile, tol: ToleranceFile, path: Path, key: str) -> None:
    """A pinned orientation must lie inside its seam's tolerance window (on the other side of the
    sheet, alpha 180 deg from it, where the seam's gun may stand on either side)."""
    for name, value, lo, hi in (("alpha", spot.alpha, -tol.alpha, tol.alpha), ("beta", spot.beta, -tol.beta, tol.beta)):
        if value is None or lo - 1e-9 <= value <= hi + 1e-9:
            continue
        if name == "alpha" and tol.sides == "either" and 180.0 - abs(value) <= tol.alpha + 1e-9:
            continue
        sides = " or 180 deg from it (sides: either)" if name == "alpha" and tol.sides == "either" else ""
        raise CellFileError(path, f"{key}.{name}", f"pinned {name} {value:g} deg is outside the seam's tolerance "
                                                  f"[{lo:g}, {hi:g}]{sides}")
    g0, g1 = tol.gamma
    g = spot.gamma
    if g is not None and g1 - g0 < 360 and not any(g0 - 1e-9 <= g + k * 360 <= g1 + 1e-9 for k in (-1, 0, 1)):
        raise CellFileError(path, f"{key}.gamma", f"pinned gamma {g:g} deg is outside the seam's tolerance [{g0:g}, {g1:g}]")


def _machines(parsed: CellFile, path: Path, triangles: list[int]) -> tuple[tuple[MachineSpec, ...], tuple[ObjectSpec, ...]]:
    """Each machine and its door, a dynamic object closed in the schedule's windows."""
    if parsed.tending is None:
        return (), ()
    machines, doors = [], []
    for i, m in enumerate(parsed.tending.machines):
        sched = m.schedule
        if sched is None:                   # the windows as they are (checked in order by the schema)
            assert m.windows is not None
            windows = tuple((float(a), float(b)) for a, b in m.windows)
        else:
            count = sched.count or parsed.tending.cycles
            windows = tuple((sched.start + k * sched.period, sched.start + k * sched.period + sched.machining)
                            for k in range(count))
        if windows and windows[-1][1] > MAX_WINDOW_S:
            raise CellFileError(path, f"tending.machines[{i}].schedule", f"the last machining ends at "
                                f"{windows[-1][1]:g} s, beyond a day ({MAX_WINDOW_S:g} s) of program time")
        door = _object(m.door, path, f"tending.machines[{i}].door", triangles)
        doors.append(ObjectSpec(name=door.name, shape=door.shape, T_world_object=door.T_world_object,
                                present=windows, door=True))
        machines.append(MachineSpec(m.name, door.name, windows))
    return tuple(machines), tuple(doors)


def _tending_seams(parsed: CellFile, path: Path) -> tuple[SeamSpec, ...]:
    """The tending job as one ordered seam: every cycle's station visits in order, each a stop at
    the station's TCP pose (pinned, orientation as given) with the gripper's action as its dwell."""
    tending = parsed.tending
    assert tending is not None
    stations = _index_by_name([st.name for st in tending.stations], "station", "tending.stations", path)
    machines = {m.name for m in tending.machines}
    for i, st in enumerate(tending.stations):
        if st.machine is not None and st.machine not in machines:
            known = ", ".join(sorted(machines)) or "none"
            raise CellFileError(path, f"tending.stations[{i}].machine", f"unknown machine '{st.machine}' (machines: {known})")
    sequence = tending.sequence or [st.name for st in tending.stations]
    for j, name in enumerate(sequence):
        if name not in stations:
            raise CellFileError(path, f"tending.sequence[{j}]", f"unknown station '{name}' (stations: "
                                f"{', '.join(stations)})")
    spots = []
    for cycle in range(1, tending.cycles + 1):
        seen: dict[str, int] = {}
        for name in sequence:
            seen[name] = seen.get(name, 0) + 1
            st = tending.stations[stations[name]]
            R = pose_matrix([0.0, 0.0, 0.0], [deg_to_rad(a) for a in st.rpy])[:3, :3]
            visit = f"c{cycle}_{name}" + (f"_{seen[name]}" if seen[name] > 1 else "")
            spots.append(SpotSpec(
                name=visit, xyz=frozen_array(st.xyz), normal=frozen_array(-R[:, 2]), direction=frozen_array(R[:, 0]),
                weld_time=tending.gripper.grip if st.action == "grip" else tending.gripper.release,
                angles=(0.0, 0.0, 0.0), config=st.config, action=st.action, machine=st.machine,
                key=f"tending.stations[{stations[name]}]",
            ))
    return (SeamSpec(name=TENDING_SEAM, ordered=True, alpha_max=0.0, beta_max=0.0, gamma_range=(0.0, 0.0), grid=1,
                     spots=tuple(spots)),)


def _seams(parsed: CellFile, path: Path, problems: _Problems) -> tuple[SeamSpec, ...]:
    """The seams with their spots to weld: spots marked `skip` are left out, and so is a seam
    left without spots; a cell left without any is an error. Every seam is checked (`problems`
    keeps each refusal)."""
    before = len(problems.found)
    checked = [_seam(s, path, f"seams[{i}]", problems) for i, s in enumerate(parsed.seams)]
    seams = tuple(s for s in checked if s.spots)
    if not seams and len(problems.found) == before:     # not when spots were refused: those are the problem
        raise CellFileError(path, "seams", "every spot is marked skip: nothing to weld")
    return seams


def _seam(seam: SeamFile, path: Path, key: str, problems: _Problems) -> SeamSpec:
    spots = []
    for j, spot in enumerate(seam.spots):
        checked = None if spot.skip else problems.attempt(_spot, spot, seam.tolerance, path, f"{key}.spots[{j}]")
        if checked is not None:
            spots.append(checked)
    tol = seam.tolerance
    return SeamSpec(
        name=seam.name,
        ordered=seam.ordered,
        alpha_max=deg_to_rad(tol.alpha),
        beta_max=deg_to_rad(tol.beta),
        gamma_range=(deg_to_rad(tol.gamma[0]), deg_to_rad(tol.gamma[1])),
        grid=seam.grid,
        spots=tuple(spots),
        either_side=tol.sides == "either",
    )


def _spot(spot: SpotFile, tol: ToleranceFile, path: Path, spot_key: str) -> SpotSpec:
    normal = _unit(spot.normal, path, f"{spot_key}.normal")
    direction = _unit(spot.direction, path, f"{spot_key}.direction")
    along = direction - np.dot(direction, normal) * normal
    if np.linalg.norm(along) < MIN_DIRECTION_SINE:
        raise CellFileError(path, f"{spot_key}.direction", f"parallel to the normal {spot.normal}: no seam direction")
    angles = None
    if spot.alpha is not None and spot.beta is not None and spot.gamma is not None:
        angles = (deg_to_rad(spot.alpha), deg_to_rad(spot.beta), deg_to_rad(spot.gamma))
        _check_pinned(spot, tol, path, spot_key)
    return SpotSpec(
        name=spot.name,
        xyz=frozen_array(spot.xyz),
        normal=frozen_array(normal),
        direction=frozen_array(along / np.linalg.norm(along)),
        weld_time=spot.weld_time, schedule=spot.schedule, angles=angles, config=spot.config,
    )


def _unit(v: list[float], path: Path, key: str) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    scale = float(np.max(np.abs(arr)))           # scaled first: the norm of [1e308, 1e308, 0] overflows
    if not 1e-9 <= scale <= 1e9:
        raise CellFileError(path, key, f"expected a direction (not zero-length, components at most 1e9), got {v}")
    arr = arr / scale
    return arr / float(np.linalg.norm(arr))
