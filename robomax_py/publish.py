"""A planned result -> the program files `plan` writes, each proven before anything is written.

For every requested dialect: the plan becomes the dialect-free program (`export.plan_program`),
the dialect adapts and writes it, and then, in memory, the written text is read back with the
dialect's own parser, the reading must give the adapted program statement for statement, its
motion is rebuilt from those statements alone (`export.rebuild`) and compared with the planned
motion (largest joint and TCP difference, time shift of every weld), and, when it is not the
planned motion sample for sample, verified against the cell as `robomax verify` would. Any
failure is an ExportError naming the dialect and the statement (file line): then nothing is
written.

A dialect that states a blend as a TCP distance at a coarse resolution (INFORM's `CR=` counts
0.1 mm) cannot state the planned blend exactly, and where a corner turns the wrist more than it
moves the TCP, the joints then follow a blend up to a few hundredths of a degree off the plan's.
Such a program is proven in two steps: the same statements with each blend at its planned
distance must rebuild the planned motion within the tolerances above (every target, frame, speed
and configuration as planned), and the program as written must keep the TCP and the welds' times
within them and be clean by `verify` (the joints' difference is reported, `blends_rounded`).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.errors import (
    CellFileError,
    ControllerSetupError,
    ExportError,
    ProgramError,
)
from robomax_py.export import (
    DIALECTS,
    controller_rebuild,
    render_trajectory,
    require_calibration,
)
from robomax_py.export.dialect import (
    Dialect,
    Parsed,
    PlannedProgram,
    in_controller_terms,
    with_tcp_blends,
)
from robomax_py.export.plan_program import planned_program
from robomax_py.export.spline_lines import as_lines as lines_for_splines
from robomax_py.export.spline_lines import has_splines
from robomax_py.plan import PlanResult, method_suffix
from robomax_py.program import LinMove, Program, PtpMove, lin_pose
from robomax_py.robot import RobotModel, fk_tcp
from robomax_py.spec import CellSpec
from robomax_py.timing import Trajectory
from robomax_py.timing.trajectory import evaluate
from robomax_py.tolerances import DEFAULT as TOL
from robomax_py.verify import VerifyReport, verify_rebuilt

__all__ = ["CheckedProgram", "MotionDifference", "file_names", "motion_difference", "publish"]

# The most a dialect rounds a blend's TCP distance (mm): half INFORM's 0.1 mm step of `CR=`.
BLEND_ROUNDING_MM = 0.05 + 1e-9
# Samples per interval between weld boundaries when comparing rebuilt and planned motion.
COMPARE_SAMPLES = 40
COMPARE_DT_S = 0.001


@dataclass(frozen=True, slots=True)
class MotionDifference:
    """Largest difference between a rebuilt and the planned motion: joint (deg) and TCP (mm) at
    the same fraction of every interval between weld boundaries, and the largest shift of those
    boundaries and of the end (s)."""

    joint_deg: float
    tcp_mm: float
    time_s: float
    t_worst: float | None = None

    @property
    def identical(self) -> bool:
        return self.joint_deg == 0.0 and self.time_s == 0.0

    def within(self, cycle_s: float | None = None) -> bool:
        """Within the rebuilt-motion tolerances; with `cycle_s` (the planned cycle, s), within
        those of spline blocks written as lines (`export.spline_lines`)."""
        if cycle_s is not None:
            return (self.joint_deg <= TOL.spline_lines_joint_deg and self.tcp_mm <= TOL.spline_lines_mm
                    and self.time_s <= TOL.spline_lines_time * cycle_s)
        return (self.joint_deg <= TOL.rebuilt_joint_deg and self.tcp_mm <= TOL.rebuilt_tcp_mm
                and self.time_s <= TOL.rebuilt_time_s)


@dataclass(frozen=True, slots=True)
class CheckedProgram:
    """One dialect's files, proven: file name -> text, and what the proof measured."""

    format: str
    files: dict[str, str]
    difference: MotionDifference
    write_seconds: float
    check_seconds: float
    report: VerifyReport | None       # the rebuilt motion's verification (None: identical to the plan)
    # Proven with its blends at the dialect's resolution (the module docstring): the joints may be
    # further off the plan inside a blend than the tolerance, the TCP and the times are not.
    blends_rounded: bool = False


def file_names(name: str, files: dict[str, str]) -> dict[str, str]:
    """Dialect keys (".src" or "_frames.src", after the program's name, or a whole file name such as
    "SPOT_WELD.ls") -> file names."""
    return {(f"{name}{key}" if key.startswith((".", "_")) else key): text for key, text in files.items()}


def publish(result: PlanResult, cell: CellSpec, robot: RobotModel, formats: tuple[str, ...], *,
            stamp: str = "", method: str = "optimised",
            edit: Callable[[PlannedProgram], PlannedProgram] | None = None,
            station: frozenset[str] | None = None) -> tuple[dict[str, str], list[CheckedProgram]]:
    """Every file of a planned result (the trajectory file first, then each format's files), all
    proven; ExportError when any is not.

    method : the plan's method; a baseline's files are named `<cell>_published.*` or
        `<cell>_teach_in.*` (`method_suffix`), so that a baseline run never replaces the optimised
        program.
    edit : a change to the dialect-free program before any dialect writes it (a station's
        interlocks: statements that take no time in the program's own motion).
    station : the signals the robots of a station set for each other; the proof then reads a wait
        for one of them as taking no time (the station replay times it), as `rebuild` does.
    """
    for fmt in formats:                          # before any dialect is proven: one clear message
        require_calibration(fmt, robot)
    name = result.cell + method_suffix(method)
    files = {f"{name}.json": render_trajectory(result)}
    planned = planned_program(result, cell.digest, stamp)
    if edit is not None:
        planned = edit(planned)
    checked = []
    reference: list[PlannedPath] = []            # made once, by the first dialect that needs it
    for fmt in formats:
        try:
            one = _checked(fmt, planned, result, cell, robot, name, reference, station)
        except ExportError as exc:
            others = [f for f in formats if f != fmt]
            if not others:
                raise
            # Nothing is written when one format fails its proof: say how to have the others.
            raise ExportError(f"{exc}; nothing was written (--format {','.join(others)} asks for the other "
                              "formats alone)") from None
        for file_name in one.files:
            if file_name in files and files[file_name] != one.files[file_name]:
                raise ExportError(f"two formats write {file_name} with different contents")
        files.update(one.files)
        checked.append(one)
    return files, checked


def _checked(fmt: str, planned: PlannedProgram, result: PlanResult, cell: CellSpec, robot: RobotModel,
             name: str, reference: list[PlannedPath], station: frozenset[str] | None = None) -> CheckedProgram:
    dialect = DIALECTS[fmt]
    t0 = time.process_time()
    if name != result.cell:
        # A baseline program is named apart before the dialect names it its way.
        planned = dataclasses.replace(planned, program=dataclasses.replace(
            planned.program, name=planned.program.name + name[len(result.cell):]))
    as_lines = has_splines(planned) and not dialect.splines
    if as_lines:
        planned = lines_for_splines(planned, robot)
    try:
        if dialect.brand:
            planned = in_controller_terms(planned, robot)
        adapted = dialect.adapt(planned, robot)
    except ControllerSetupError as exc:
        raise CellFileError(cell.source, exc.key, f"{exc.problem} (--format {fmt})") from None
    texts = dialect.write(adapted, robot)
    t1 = time.process_time()
    stem = adapted.name if dialect.program_name else name
    main = f"{stem}{dialect.extensions[0]}"
    try:
        parsed = dialect.parse(texts, main, robot)
    except ProgramError as exc:
        raise ExportError(f"{fmt}: the written program does not read back: {exc}") from None
    if parsed.problems:
        at, kind, detail = parsed.problems[0]
        raise ExportError(f"{fmt}: the written program is not clean: {kind}: {detail} (line {at} of {main})")
    _same_program(fmt, main, adapted, parsed)
    rebuilt = controller_rebuild(dialect, cell, robot, main, parsed, station)
    if rebuilt.problems or rebuilt.trajectory is None:
        p = rebuilt.problems[0] if rebuilt.problems else None
        where = f"line {p.line}: " if p and p.line else ""
        raise ExportError(f"{fmt}: the written program's motion cannot be rebuilt: {where}{p.detail if p else ''}")
    assert result.trajectory is not None
    traj = result.trajectory
    if not _same_samples(traj, rebuilt.trajectory) and not reference:
        reference.append(PlannedPath.of(traj, robot))
    diff = motion_difference(traj, rebuilt.trajectory, robot, reference[0] if reference else None)
    rounded = (not as_lines and not diff.within() and diff.tcp_mm <= TOL.rebuilt_tcp_mm
               and diff.time_s <= TOL.rebuilt_time_s
               and _proven_but_blends(dialect, cell, robot, main, parsed, planned, traj, reference, station))
    if not rounded and not diff.within(traj.duration if as_lines else None):
        line = rebuilt.line_at(diff.t_worst)
        most = (f"{TOL.spline_lines_joint_deg} deg, {TOL.spline_lines_mm} mm, {TOL.spline_lines_time:.0%} of the cycle "
                "with spline blocks as lines") if as_lines else \
            f"{TOL.rebuilt_joint_deg} deg, {TOL.rebuilt_tcp_mm} mm, {TOL.rebuilt_time_s * 1000:.0f} ms"
        raise ExportError(
            f"{fmt}: the rebuilt motion differs from the planned one by {diff.joint_deg:.4f} deg, {diff.tcp_mm:.3f} mm, "
            f"{diff.time_s * 1000:.1f} ms (at most {most}){f', at line {line} of {main}' if line else ''}")
    report = None
    if not diff.identical:
        report = verify_rebuilt(cell, robot, main, rebuilt, clearance=False)
        if not report.clean:
            v = report.violations[0]
            raise ExportError(f"{fmt}: the written program's motion is not clean: {v.kind}: {v.detail}"
                              f"{f' (line {v.line} of {main})' if v.line else ''}")
    return CheckedProgram(fmt, file_names(stem, texts), diff, t1 - t0, time.process_time() - t1, report, rounded)


def _proven_but_blends(dialect: Dialect, cell: CellSpec, robot: RobotModel, main: str, parsed: Parsed,
                       planned: PlannedProgram, traj: Trajectory, reference: list[PlannedPath],
                       station: frozenset[str] | None) -> bool:
    """Whether the program read back, with each blend at its planned TCP distance instead of the
    one the dialect could state, rebuilds the planned motion within the tolerances: then the
    blends' rounding is all that differs."""
    exact = _with_planned_blends(parsed, with_tcp_blends(planned, robot))
    if exact is None:
        return False
    again = controller_rebuild(dialect, cell, robot, main, exact, station)
    if again.problems or again.trajectory is None:
        return False
    return motion_difference(traj, again.trajectory, robot, reference[0] if reference else None).within()


def _with_planned_blends(parsed: Parsed, stated: Program) -> Parsed | None:
    """`parsed` with every blended move's TCP distance as `stated` has it (moves paired in order),
    when each written distance is that one rounded to at most BLEND_ROUNDING_MM; None otherwise (a
    dialect that states blends otherwise, or a distance not merely rounded)."""
    moves = [i for i, ins in enumerate(parsed.program.instructions) if isinstance(ins, (PtpMove, LinMove))]
    planned = [ins for ins in stated.instructions if isinstance(ins, (PtpMove, LinMove))]
    if len(moves) != len(planned):
        return None
    out = list(parsed.program.instructions)
    changed = False
    for i, want in zip(moves, planned):
        got = out[i]
        assert isinstance(got, (PtpMove, LinMove))
        if got.flyby_mm == want.flyby_mm:
            continue
        if got.flyby_mm <= 0 or want.flyby_mm <= 0 or abs(got.flyby_mm - want.flyby_mm) > BLEND_ROUNDING_MM:
            return None
        out[i] = dataclasses.replace(got, flyby_mm=want.flyby_mm)
        changed = True
    if not changed:
        return None
    return dataclasses.replace(parsed, program=dataclasses.replace(parsed.program, instructions=tuple(out)))


def _same_program(fmt: str, main: str, adapted: Program, parsed: Parsed) -> None:
    """The program read back must be the one written: the same header, frames and statements."""
    got = parsed.program
    if got.name != adapted.name or got.header != adapted.header:
        raise ExportError(f"{fmt}: {main} reads back with another name or header ({got.name}, {got.header})")
    if len(got.frames) != len(adapted.frames) or any(not _same(a, b) for a, b in zip(adapted.frames, got.frames)):
        raise ExportError(f"{fmt}: {main} reads back with other frames: {got.frames} instead of {adapted.frames}")
    if len(got.instructions) != len(adapted.instructions):
        raise ExportError(f"{fmt}: {main} reads back {len(got.instructions)} statements, "
                          f"{len(adapted.instructions)} were written")
    for k, (a, b) in enumerate(zip(adapted.instructions, got.instructions)):
        if not _same(a, b):
            raise ExportError(f"{fmt}: line {parsed.lines[k]} of {main} reads back as {b}, {a} was written")


def _same(a: object, b: object) -> bool:
    """Equal, or Cartesian values equal up to the ZYX angles' own ambiguity (B = ±90 deg)."""
    if a == b:
        return True
    if type(a) is not type(b) or not dataclasses.is_dataclass(a):
        return False
    fields = {f.name for f in dataclasses.fields(a)}
    if "zyx_deg" not in fields:
        return False
    rest = [f for f in fields if f != "zyx_deg"]
    if any(getattr(a, f) != getattr(b, f) for f in rest):
        return False
    Ra = lin_pose(LinMove((0.0, 0.0, 0.0), cast(Any, a).zyx_deg))[:3, :3]     # a dataclass with zyx_deg (above)
    Rb = lin_pose(LinMove((0.0, 0.0, 0.0), cast(Any, b).zyx_deg))[:3, :3]
    angle = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(Ra.T @ Rb) - 1.0) / 2.0))))
    return angle <= TOL.readback_angle_deg


def _anchors(traj: Trajectory) -> FloatArray:
    times = [float(traj.t[0])]
    for phase in traj.phases_of("weld"):
        times += [float(phase.t_start), float(phase.t_end)]
    times.append(float(traj.t[-1]))
    return np.array(times)


@dataclass(frozen=True, slots=True, eq=False)
class PlannedPath:
    """The planned motion as the comparison needs it, made once for all dialects: its weld
    boundaries, and between each two the path sampled at COMPARE_DT_S (chords between its 10 ms
    samples would sag off a blend), in joint space and as TCP positions."""

    anchors: FloatArray
    joints: tuple[FloatArray, ...]
    tcp: tuple[FloatArray, ...]

    @staticmethod
    def of(planned: Trajectory, robot: RobotModel) -> PlannedPath:
        a = _anchors(planned)
        joints = []
        for i in range(len(a) - 1):
            dense = np.linspace(a[i], a[i + 1], max(2, int(np.ceil((a[i + 1] - a[i]) / COMPARE_DT_S)) + 1))
            joints.append(evaluate(planned, dense).q)
        return PlannedPath(a, tuple(joints), tuple(fk_tcp(robot, q)[:, :3, 3] for q in joints))


def motion_difference(planned: Trajectory, rebuilt: Trajectory, robot: RobotModel,
                      reference: PlannedPath | None = None) -> MotionDifference:
    """How far a rebuilt motion is from the planned one (`MotionDifference`): the path, as the
    largest distance of the rebuilt motion's points from the planned path between the same weld
    boundaries (joint space and TCP), and the time, as the largest shift of those boundaries. A
    path compared at equal times would count a shift of a few ms as a joint difference.

    reference : `PlannedPath.of(planned, robot)`, when several rebuilt motions are compared.
    """
    if _same_samples(planned, rebuilt):
        return MotionDifference(0.0, 0.0, 0.0)
    ref = reference if reference is not None else PlannedPath.of(planned, robot)
    a, b = ref.anchors, _anchors(rebuilt)
    if len(a) != len(b):
        return MotionDifference(math.inf, math.inf, math.inf, float(planned.t[0]))
    u = np.linspace(0.0, 1.0, COMPARE_SAMPLES)
    worst_joint, worst_tcp, t_worst = 0.0, 0.0, float(b[0])
    for i in range(len(a) - 1):
        tb = b[i] + u * (b[i + 1] - b[i])
        points = evaluate(rebuilt, tb).q
        joint = _to_polyline(points, ref.joints[i])
        tcp = _to_polyline(fk_tcp(robot, points)[:, :3, 3], ref.tcp[i])
        k = int(np.argmax(joint))
        if joint[k] > worst_joint:
            worst_joint, t_worst = float(joint[k]), float(tb[k])
        worst_tcp = max(worst_tcp, float(tcp.max()))
    return MotionDifference(math.degrees(worst_joint), worst_tcp * 1000.0, float(np.abs(a - b).max()), t_worst)


def _same_samples(a: Trajectory, b: Trajectory) -> bool:
    """The same motion sample for sample (np.array_equal also compares the shapes)."""
    return bool(np.array_equal(a.t, b.t) and np.array_equal(a.q, b.q))


def _to_polyline(points: FloatArray, path: FloatArray) -> FloatArray:
    """Distance of each point (m, d) from the polyline through path (k, d)."""
    if len(path) < 2:
        ends: FloatArray = np.linalg.norm(points - path[:1], axis=1)
        return ends
    p0, p1 = path[:-1], path[1:]
    d = p1 - p0
    dd = np.maximum((d * d).sum(axis=1), 1e-30)
    rel = points[:, None, :] - p0[None, :, :]
    s = np.clip((rel * d[None]).sum(axis=2) / dd[None], 0.0, 1.0)
    closest = p0[None] + s[..., None] * d[None]
    nearest: FloatArray = np.linalg.norm(points[:, None, :] - closest, axis=2).min(axis=1)
    return nearest
