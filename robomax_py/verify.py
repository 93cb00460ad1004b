"""Re-simulate a written program against its cell and report every violation (no printing).

A trajectory file (docs/cell-files.md, "The trajectory file") is checked on its own samples, the motion between samples taken as
linear in joint space: joint position, velocity and acceleration limits; collisions with static
objects, dynamic objects inside their windows and the robot itself, swept between samples with the
collision world's 2 mm bound; start and end at home; every spot of the cell welded once, at rest
for at least the weld time with the TCP within 0.1 mm of the spot and its orientation within the
seam's tolerance; the configuration indicator as written; ordered seams in their order.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import ProgramError
from robomax_py.export.trajectory_json import load_trajectory_file
from robomax_py.io.files import check_set
from robomax_py.plan.loads import Loads, check_carried_motion
from robomax_py.plan.poses import nominal_rotation
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.robot.ik import same_config
from robomax_py.robot.solve import brand_text_of, config_texts_near
from robomax_py.safe_files import LIMITS, read_text
from robomax_py.spec import CellSpec
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.transforms import rot_x, rot_y, rot_z
from robomax_py.world.collision import CollisionWorld
from robomax_py.world.motion import Clearance, Violation, check_motion, min_clearance
from robomax_py.world.scene import build_scene

if TYPE_CHECKING:
    from robomax_py.export.rebuild import Rebuilt

HOME_TOL_RAD = TOL.home_tol_rad
REST_TOL_RAD = TOL.rest_tol_rad
ANGLE_TOL_RAD = TOL.angle_tol_rad
TIME_TOL_S = TOL.time_tol_s
# A pinned orientation is kept when the rotation matrices agree to this (file precision: 1e-4 deg).
PIN_TOL = 1e-5




@dataclass(frozen=True, slots=True)
class VerifyReport:
    program: str
    samples: int
    cycle_time: float
    collision_checks: int
    violations: tuple[Violation, ...]
    ignored: tuple[tuple[int, str], ...] = ()     # (line, statement) read but without effect on motion
    clearance: Clearance | None = None            # the smallest distance reached (None: not measured)
    clearance_line: int | None = None             # the program line moving the robot then
    notes: tuple[str, ...] = ()                   # about the file, not the motion (its plan's set)

    @property
    def clean(self) -> bool:
        return not self.violations


def verify_program(cell: CellSpec, robot: RobotModel, path: Path) -> VerifyReport:
    """Verify a trajectory file (.json) or a program of any dialect robomax writes (its motion
    rebuilt from its statements alone)."""
    from robomax_py.io.plan_set import MANIFEST_SUFFIX

    if path.name.lower().endswith(MANIFEST_SUFFIX):
        # Ends in .json like a trajectory file: say what it is rather than that its format is wrong.
        stem = path.name[:-len(MANIFEST_SUFFIX)]
        raise ProgramError(path, None, f"is the manifest of the set of programs planned together: verify one of the "
                           f"programs it lists ({stem}.json, {stem}.src, ...)")
    if path.suffix.lower() == ".json":
        return _with_set(cell, path, (path,), verify_trajectory_file(cell, robot, path))
    return verify_read(cell, robot, path, read_program_files(robot, path))[0]


def verify_read(cell: CellSpec, robot: RobotModel, path: Path, read: tuple[Any, Path, Any, tuple[Path, ...]],
                station: frozenset[str] | None = None) -> tuple[VerifyReport, Any]:
    """Verify a program read by `read_program_files`, and its rebuilt motion (`export.rebuild.Rebuilt`;
    None when no motion runs). `station`: the signals the robots of a station set (`rebuild`)."""
    from robomax_py.program import LinMove, PtpMove

    _, _, parsed, files = read
    unsimulated = tuple(Violation(None, "unsupported", f"{text} is not simulated: the program cannot be verified", line)
                        for line, text in _not_simulated(parsed))
    stated = tuple(Violation(None, kind, detail, line) for line, kind, detail in parsed.problems)
    ignored = tuple(i for i in parsed.ignored if not _is_motion(parsed, i[0]))
    if not any(isinstance(i, (PtpMove, LinMove)) for i in parsed.program.instructions):
        # No motion runs (the program ends, or jumps past them, before its first motion): it
        # welds nothing.
        nowhere = () if stated or unsimulated else (
            Violation(None, "flow", "no motion of the program runs: it moves the robot nowhere"),)
        never = tuple(Violation(None, "spot", f"{seam.name}/{spot.name} is never welded")
                      for seam in cell.seams for spot in seam.spots)
        return _with_set(cell, path, files, VerifyReport(str(path), 0, float("nan"), 0,
                                                         unsimulated + stated + nowhere + never, ignored)), None
    rebuilt = rebuild_read(cell, robot, read, station)
    report = verify_rebuilt(cell, robot, str(path), rebuilt)
    report = dataclasses.replace(report, violations=unsimulated + stated + report.violations, ignored=ignored)
    return _with_set(cell, path, files, report), rebuilt


def rebuild_read(cell: CellSpec, robot: RobotModel, read: tuple[Any, Path, Any, tuple[Path, ...]],
                 station: frozenset[str] | None = None) -> Rebuilt:
    """The motion of a program read by `read_program_files`, as its controller runs it
    (`export.rebuild.Rebuilt`): its joint targets counted the controller's way, its frames those
    the controller composes (`export.controller_rebuild`)."""
    from robomax_py.export import controller_rebuild

    dialect, main, parsed, _ = read
    return controller_rebuild(dialect, cell, robot, main, parsed, station)


# No value of a robot program is larger than this (mm, deg, mm/s, s: a position 1,000 km away): a
# number beyond it, or one that is no number (KRL reads `nan`), is a broken file, not a motion to
# rebuild (a target of 1E300 mm overflowed the rebuild into an internal fault).
PLAUSIBLE_MAGNITUDE = 1e9


def _numbers_checked(parsed: Any, main: Path) -> None:
    """ProgramError naming the line of the first instruction, or the frame, one of whose numbers is
    not finite or beyond `PLAUSIBLE_MAGNITUDE`."""
    program = parsed.program
    lines = [*parsed.lines, *[None] * (len(program.instructions) - len(parsed.lines))]    # a reader's slip: no fault
    items = [*((ins, "the program" if line is None else f"line {line}") for ins, line in zip(program.instructions, lines)),
             *((frame, f"frame {frame.name}") for frame in program.frames)]
    for item, where in items:
        for f in dataclasses.fields(item):
            value = getattr(item, f.name)
            for v in (value if isinstance(value, tuple) else (value,)):
                if isinstance(v, float) and not (math.isfinite(v) and abs(v) <= PLAUSIBLE_MAGNITUDE):
                    why = "is not a number" if math.isnan(v) else f"is beyond any robot's ({PLAUSIBLE_MAGNITUDE:g})"
                    raise ProgramError(main, where, f"{type(item).__name__} {f.name}: {v!r} {why}")


def read_program(robot: RobotModel, path: Path) -> tuple[Any, Path, Any]:
    """A program's files read as verify reads them: (its `Dialect`, its main file, the `Parsed`
    program), with the files beside it the dialect reads too (a KRL .dat, the companions, the
    dialect's shared routines)."""
    dialect, main, parsed, _ = read_program_files(robot, path)
    return dialect, main, parsed


def read_program_files(robot: RobotModel, path: Path) -> tuple[Any, Path, Any, tuple[Path, ...]]:
    """`read_program` and the files of the program's own set it read (its shared routines, which
    every plan of a folder writes alike, are not among them)."""
    from robomax_py.export import DIALECTS, dialect_for_file

    suffix = path.suffix.lower()
    dialect = dialect_for_file(suffix)
    if dialect is None:
        known = ", ".join(sorted({e for d in DIALECTS.values() for e in d.extensions}))
        raise ProgramError(path, None, f"expected a trajectory file (.json) or a program ({known})")
    _not_a_setup_file(dialect, path)
    unfit = dialect.unfit(robot)
    if unfit:
        # Read as this robot's, its values would be misread: a track's deg taken for mm, or a
        # seventh joint left unstated.
        raise ProgramError(path, None, f"cannot be this robot's program: {unfit}")
    texts = {}
    read = []
    if dialect.any_extension:
        texts[dialect.extensions[0]] = read_text(path, LIMITS.program, ProgramError, "program file",
                                                 fallback=dialect.fallback_encoding)
        parsed = dialect.parse(texts, str(path), robot)
        _numbers_checked(parsed, path)
        return dialect, path, parsed, (path,)
    for ext in dialect.extensions:
        sibling = path.with_suffix(ext) if suffix != ext else path
        if sibling == path or sibling.exists():
            texts[ext] = read_text(sibling, LIMITS.program, ProgramError, "program file",
                                   fallback=dialect.fallback_encoding, max_lines=LIMITS.program_lines)
            read.append(sibling)
    main = path.with_suffix(dialect.extensions[0])
    if dialect.extensions[0] not in texts:
        raise ProgramError(main, None, f"{path.name} needs its main file {main.name} beside it")
    for key in dialect.companions:
        # A setup file beside the program (its frames) is what the controller was loaded with;
        # without one, the controller holds the cell's calibrated frames (`controller_frames`).
        companion = _beside(main, main.stem + key)
        if companion is not None:
            texts[key] = read_text(companion, LIMITS.program, ProgramError, "program file",
                                   fallback=dialect.fallback_encoding, max_lines=LIMITS.program_lines)
            read.append(companion)
    for name in dialect.shared:
        # The dialect's routines every program calls alike (FANUC's SPOT_WELD.ls): the reader
        # checks that the one beside the program does what a weld call is taken to do.
        routine = _beside(main, name)
        if routine is not None:
            texts[name] = read_text(routine, LIMITS.program, ProgramError, "program file",
                                    fallback=dialect.fallback_encoding, max_lines=LIMITS.program_lines)
    parsed = dialect.parse(texts, str(main), robot)
    _numbers_checked(parsed, main)
    return dialect, main, parsed, tuple(read)


def _not_a_setup_file(dialect: Any, path: Path) -> None:
    """A ProgramError naming the program to verify where `path` is one a program reads, not one the
    controller runs as the job: a frames setup program beside its program (`<name>_frames.src`),
    or a routine every program calls (FANUC's SPOT_WELD.ls). Verified alone, it welds no spot."""
    name = path.name.lower()
    for key in dialect.companions:
        if name.endswith(key.lower()):
            main = path.with_name(path.name[:-len(key)] + dialect.extensions[0])
            if main.is_file():
                raise ProgramError(path, None, f"is the frames setup program of {main.name}: verify {main.name}, "
                                   "which reads its frames from it")
    if name in {r.lower() for r in dialect.shared}:
        raise ProgramError(path, None, "is the routine the programs call at each weld: verify the program "
                           "that calls it (it is read with it)")


def _with_set(cell: CellSpec, path: Path, read: tuple[Path, ...], report: VerifyReport) -> VerifyReport:
    """The report with what the manifest of the program's set says: files read (those beside the
    program, as a controller would be loaded with them) that are not the ones the plan wrote
    together (a folder mixing plans, or an edited file) are a `set` violation; a
    program without a manifest is verified as a lone program, and one planned from another
    version of the cell file is noted (the motion is what verify judges)."""
    check = check_set(path, read)
    if check.manifest is None:
        lone = "no plan's manifest beside it names it: verified as a lone program, not as one plan's set"
        return dataclasses.replace(report, notes=(*report.notes, lone))
    found = tuple(Violation(None, "set", m) for m in check.mismatched)
    notes = report.notes
    if check.cell_sha256 and check.cell_sha256 != cell.digest:
        other = (f"planned from another version of the cell file (sha256 {check.cell_sha256[:12]}..., "
                 f"this one {cell.digest[:12]}...)")
        if check.cell_file:
            # A continuation starts where the robot stopped and welds what was left, in the cell as
            # it changed: against any other cell, that shows as violations; name the one it runs in.
            other = (f"this program runs in the cell {path.parent / check.cell_file} beside it (a continuation "
                     f"written by robomax replan), not in this one: verify it against that file")
        notes = (*notes, other)
    return dataclasses.replace(report, violations=found + report.violations, notes=notes)


def _beside(path: Path, name: str) -> Path | None:
    """The file `name` in `path`'s folder; on a case-sensitive file system also one whose name
    differs in case only (a controller's backup writes `home.ls` for the program HOME)."""
    exact = path.with_name(name)
    if exact.exists():
        return exact
    try:
        return next((p for p in path.parent.iterdir() if p.name.lower() == name.lower() and p.is_file()), None)
    except OSError:
        return None


def _not_simulated(parsed: Any) -> list[tuple[int, str]]:
    """(line, statement and why) of every statement the reader marks as not simulated."""
    from robomax_py.program import Comment

    mark = "not simulated: "
    return [(at, ins.text[len(mark):]) for ins, at in zip(parsed.program.instructions, parsed.lines)
            if isinstance(ins, Comment) and ins.text.startswith(mark)]


def _is_motion(parsed: Any, line: int) -> bool:
    from robomax_py.program import Comment

    return any(isinstance(ins, Comment) and ins.text.startswith("not simulated:") and at == line
               for ins, at in zip(parsed.program.instructions, parsed.lines))


def verify_rebuilt(cell: CellSpec, robot: RobotModel, name: str, rebuilt: Any, clearance: bool = True) -> VerifyReport:
    """Check a rebuilt motion (`export.rebuild.Rebuilt`) like a trajectory, with the program line
    of each violation (and of the smallest clearance, unless `clearance` is False)."""
    out = [Violation(p.t, p.kind, p.detail, p.line) for p in rebuilt.problems]
    if rebuilt.trajectory is None:
        return VerifyReport(name, 0, float("nan"), 0, tuple(out))
    traj = rebuilt.trajectory
    data = {"t": np.asarray(traj.t), "q": np.asarray(traj.q), "spots": rebuilt.spots, "joint_step": rebuilt.joint_step}
    report = _verify_motion(cell, robot, name, data, out, clearance)
    lined = tuple(v if v.line is not None else dataclasses.replace(v, line=rebuilt.line_at(v.t))
                  for v in report.violations)
    line = rebuilt.line_at(report.clearance.t) if report.clearance is not None else None
    return dataclasses.replace(report, violations=lined, clearance_line=line)


def verify_trajectory_file(cell: CellSpec, robot: RobotModel, path: Path) -> VerifyReport:
    data = load_trajectory_file(path, robot)
    t = data["t"]
    out: list[Violation] = []
    if abs(float(data.get("cycle_time", t[-1] - t[0])) - (t[-1] - t[0])) > TIME_TOL_S:
        out.append(Violation(None, "format", f"cycle_time {data['cycle_time']} is not last t - first t"))
    if np.diff(t).max() > 0.010 + TIME_TOL_S:
        i = int(np.argmax(np.diff(t)))
        out.append(Violation(float(t[i]), "format", f"samples {np.diff(t)[i] * 1000:.1f} ms apart (at most 10 ms)"))
    return _verify_motion(cell, robot, str(path), data, out)


def verify_srcl_file(cell: CellSpec, robot: RobotModel, path: Path) -> VerifyReport:
    """Parse an SRCL program, rebuild its motion and check it like a trajectory."""
    return verify_program(cell, robot, path)


def _verify_motion(cell: CellSpec, robot: RobotModel, name: str, data: dict[str, Any], out: list[Violation],
                   clearance: bool = True) -> VerifyReport:
    """Home at both ends, limits and swept collisions, spots: appended to `out`; and the smallest
    clearance reached (when asked)."""
    t, q = data["t"], data["q"]
    # A program that states joints coarser than the check (INFORM's pulses) starts and ends within
    # half its step of home: the controller's nearest position.
    step = np.asarray(data.get("joint_step") or (0.0,) * q.shape[1], dtype=float)
    for end, idx, want, where in (("start", 0, cell.q_start, "robot.home" if cell.start is None else
                                   "the stop configuration it continues from"), ("end", -1, cell.home, "robot.home")):
        if np.any(np.abs(q[idx] - want) > HOME_TOL_RAD + step / 2):
            out.append(Violation(float(t[idx]), "home", f"program does not {end} at {where}"))
    world = CollisionWorld(robot, build_scene(cell, robot), cell.process.clearance)
    loads = Loads.of(cell, robot)
    if loads is None:
        motion = check_motion(world, robot, t, q)
    else:
        # While a part is held: checked with it in the gripper, under its limits (`plan.loads`).
        motion = check_carried_motion(cell, robot, world, loads.worlds, t, q, data["spots"])
    out.extend(motion.violations)
    out.extend(_check_spots(cell, robot, data))
    closest = min_clearance(world, t, q) if clearance else None
    return VerifyReport(name, len(t), float(t[-1] - t[0]), motion.checks, tuple(out), clearance=closest)




def _check_spots(cell: CellSpec, robot: RobotModel, data: dict[str, Any]) -> list[Violation]:
    t, q = data["t"], data["q"]
    out: list[Violation] = []
    from robomax_py.program import identifier

    wanted = {(seam.name, spot.name): (seam, spot) for seam in cell.seams for spot in seam.spots}
    # A controller program names a spot by its identifiers (a seam called `seam`, a keyword, is
    # written `seam_`; `door-L 2` is `door_L_2`): read back as the cell's own names.
    written_as = {(identifier(seam.name), identifier(spot.name)): key for key, (seam, spot) in wanted.items()}
    seen: dict[tuple[str, str], float] = {}
    for entry in data["spots"]:
        key = (str(entry["seam"]), str(entry["name"]))
        if key not in wanted:
            key = written_as.get(key, key)
        label = f"{key[0]}/{key[1]}"
        if key not in wanted:
            out.append(Violation(None, "spot", f"{label} is not a spot of the cell"))
            continue
        if key in seen:
            out.append(Violation(None, "spot", f"{label} welded twice"))
            continue
        seam, spot = wanted[key]
        t0, t1 = float(entry["t_arrive"]), float(entry["t_leave"])
        seen[key] = t0
        weld_time = cell.process.weld_time_of(spot)
        if t1 - t0 < weld_time - TIME_TOL_S:
            out.append(Violation(t0, "dwell", f"{label}: dwell {t1 - t0:.3f} s < weld time {weld_time:.3f} s"))
        inside = (t >= t0 - TIME_TOL_S) & (t <= t1 + TIME_TOL_S)
        if inside.sum() < 2:
            out.append(Violation(t0, "dwell", f"{label}: no samples between arrive and leave"))
            continue
        qs = q[inside]
        if np.ptp(qs, axis=0).max() > REST_TOL_RAD:
            out.append(Violation(t0, "dwell", f"{label}: the robot moves while welding"))
        out.extend(_approach_straight(cell, robot, t, q, spot, label, t0, t1))
        T_world = np.asarray(cell.T_world_base) @ fk_tcp(robot, qs)
        err = np.linalg.norm(T_world[:, :3, 3] - spot.xyz, axis=1).max()
        if err > TOL.spot_pos_m:
            out.append(Violation(t0, "spot", f"{label}: TCP {err * 1000:.3f} mm from the spot (at most 0.1 mm)"))
        alpha, beta, gamma = _tolerance_angles(nominal_rotation(spot), T_world[0, :3, :3])
        g0, g1 = seam.gamma_range
        gamma_ok = g1 - g0 >= 2 * math.pi - ANGLE_TOL_RAD or any(
            g0 - ANGLE_TOL_RAD <= gamma + k * 2 * math.pi <= g1 + ANGLE_TOL_RAD for k in (-1, 0, 1))
        if spot.angles is not None:
            R_pin = rot_x(spot.angles[0]) @ rot_y(spot.angles[1]) @ rot_z(spot.angles[2])
            R_got = rot_x(alpha) @ rot_y(beta) @ rot_z(gamma)
            if np.abs(R_pin - R_got).max() > PIN_TOL:
                out.append(Violation(t0, "spot", f"{label}: orientation alpha {math.degrees(alpha):.2f} beta "
                                                 f"{math.degrees(beta):.2f} gamma {math.degrees(gamma):.2f} deg is not the "
                                                 "pinned one"))
        # On the sheet's other side (a seam whose gun may stand on either) the tilt is alpha -+ 180 deg.
        tilt = alpha - math.copysign(math.pi, alpha) if seam.either_side and abs(alpha) > math.pi / 2 else alpha
        if abs(tilt) > seam.alpha_max + ANGLE_TOL_RAD or abs(beta) > seam.beta_max + ANGLE_TOL_RAD or not gamma_ok:
            out.append(Violation(t0, "spot", f"{label}: orientation alpha {math.degrees(alpha):.2f} beta "
                                             f"{math.degrees(beta):.2f} gamma {math.degrees(gamma):.2f} deg outside the tolerance"))
        written = entry.get("config")
        if written is not None:
            brand = str(entry.get("brand", robot.controller.brand))
            counted = bool(entry.get("controller", False))
            tol = math.radians(TOL.config_tol_deg)
            nearby = config_texts_near(robot, qs[0], brand, tol, counted)
            actual = brand_text_of(robot, qs[0], brand, counted)
            # A pinned configuration is the planner's (URDF joint values, `solve.config_text`); a
            # controller program states its own from the controller's values of the same joints.
            recounted = counted and bool(robot.controller.joint_signs or robot.controller.joint_zeros)
            pinned_ok = spot.config is None or brand != robot.controller.brand or (
                any(same_config(spot.config, t) for t in config_texts_near(robot, qs[0], brand, tol)) if recounted
                else same_config(spot.config, str(written)))
            if not pinned_ok:
                out.append(Violation(t0, "spot", f"{label}: configuration {written}, pinned {spot.config}"))
            if not any(same_config(str(written), text) for text in nearby):
                out.append(Violation(t0, "spot", f"{label}: configuration written as {written}, robot is in {actual}"))
    for key in wanted:
        if key not in seen:
            out.append(Violation(None, "spot", f"{key[0]}/{key[1]} is never welded"))
    for seam in cell.seams:
        if seam.ordered:
            times = [seen[(seam.name, s.name)] for s in seam.spots if (seam.name, s.name) in seen]
            if any(b < a for a, b in pairwise(times)):
                out.append(Violation(None, "order", f"seam {seam.name} is ordered but welded out of order"))
    return out


def _approach_straight(cell: CellSpec, robot: RobotModel, t: FloatArray, q: FloatArray, spot: Any, label: str,
                       t0: float, t1: float) -> list[Violation]:
    """Over the approach distance, before and after the weld, the TCP moves only along the
    electrode axis (the TCP z axis at the spot) on the approach side: from the weld outwards until
    it is `process.approach` up the axis (or that far from the spot)."""
    approach = cell.process.approach
    if approach <= 0:
        return []
    i0, i1 = int(np.searchsorted(t, t0 - TIME_TOL_S)), int(np.searchsorted(t, t1 + TIME_TOL_S, side="right")) - 1
    T_spot = np.asarray(cell.T_world_base) @ fk_tcp(robot, q[i0])
    origin, axis = T_spot[:3, 3], T_spot[:3, 2]
    out: list[Violation] = []
    for step, start in ((-1, i0 - 1), (1, i1 + 1)):
        worst, at, i = 0.0, None, start
        while 0 <= i < len(t):
            rel = (np.asarray(cell.T_world_base) @ fk_tcp(robot, q[i]))[:3, 3] - origin
            along = float(rel @ axis)
            # The approach distance is covered once the TCP is that far up the axis, or that far away.
            if along >= approach - TOL.straight_tol_m or np.linalg.norm(rel) > approach:
                break
            off = max(float(np.linalg.norm(rel - along * axis)), -along)
            if off > worst:
                worst, at = off, float(t[i])
            i += step
        if worst > TOL.straight_tol_m:
            side = "approach" if step < 0 else "retract"
            out.append(Violation(at, "approach", f"{label}: the {side} leaves the electrode axis by {worst * 1000:.2f} mm "
                                                 f"within {approach * 1000:.0f} mm of the spot"))
    return out


def _tolerance_angles(R_nominal: FloatArray, R: FloatArray) -> tuple[float, float, float]:
    """(alpha, beta, gamma) with R = R_nominal Rx(alpha) Ry(beta) Rz(gamma), rad."""
    M = R_nominal.T @ R
    beta = math.atan2(M[0, 2], math.hypot(M[1, 2], M[2, 2]))
    alpha = math.atan2(-M[1, 2], M[2, 2])
    gamma = math.atan2(-M[0, 1], M[0, 0])
    return alpha, beta, gamma
