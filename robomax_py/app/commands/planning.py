"""`robomax plan` and `robomax verify`: a cell's programs written, and a program checked against its cell."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from robomax_py.app.commands.base import (
    EXIT_INFEASIBLE,
    EXIT_OK,
    EXIT_VIOLATIONS,
    JsonFlag,
    _command,
    _compile_ahead,
    _guarded,
    _heavy_imports,
    _honour_signals,
    _method,
    _num,
    _print_json,
    _warn,
    err,
    out,
    output_folder,
)
from robomax_py.io.files import signals_held

if TYPE_CHECKING:                     # the commands import what they use when they run
    from robomax_py.publish import CheckedProgram


@_command()
def plan(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder", callback=output_folder)] = Path("programs"),
    baseline: Annotated[str | None, typer.Option("--baseline", metavar="published|teach-in", help="plan a baseline instead and write <name>_published.* or <name>_teach_in.*: published = the published method (paper 003: the cell's spot order, the DP over every orientation sample and IK branch, the same detours and timing), teach-in = the cell's order, nominal orientation, first branch")] = None,
    as_json: JsonFlag = False,
    speed: Annotated[float | None, typer.Option("--speed", min=0.01, max=1.0, help="override of every programmed speed, fraction in (0, 1] (default: the cell's planner.speed, else 1)")] = None,
    verbose: Annotated[bool, typer.Option("-v", "--verbose", help="debug logging: stage sizes, counts and times")] = False,
    plot: Annotated[bool, typer.Option("--plot", help="also write DIR/<name>.png: a cycle-time Gantt chart, one row per spot (a station: the programs replayed together, DIR/<station>.gantt.png, one row per robot)")] = False,
    formats: Annotated[str, typer.Option("--format", help="program dialects, comma-separated: srcl, krl, rapid, fanuc, urscript, inform, as, native (the robot's controller brand) or all (every dialect the robot file has the data for; the others are named in a warning)")] = "srcl",
    stamp: Annotated[bool, typer.Option("--stamp", help="write the date into each program's header (otherwise the same cell gives the same bytes)")] = False,
) -> None:
    """Plan a cell and write its program files (only when the plan is complete and every program proven).

    A station file (`robots:`, docs/stations.md) writes every robot's programs with their interlocks,
    their trajectory files and <station>.station.json."""
    method = _method(baseline)

    def run() -> int:
        import datetime
        import time

        # SIGINT and SIGTERM held while the heavy modules are imported (a few seconds at most): an
        # import that catches BaseException would swallow the interrupt and leave half-imported
        # modules behind. A signal that arrived meanwhile is delivered when the imports are done.
        with signals_held(), _heavy_imports():
            compiling = _compile_ahead()         # side by side with the imports and the files' reading
            from robomax_py.app.progress import configure_logging, stage_bars
            from robomax_py.app.report import plan_report, report_tables
            from robomax_py.export import SHARED_FILES, choose_formats, setup_signals
            from robomax_py.io.cell import load_cell, load_cell_robot
            from robomax_py.io.files import commit_set
            from robomax_py.plan import (
                PlanOptions,
                method_options,
                method_suffix,
                plan_cell,
            )
            from robomax_py.publish import publish
        _honour_signals()

        configure_logging(err, verbose)
        from robomax_py.io.station import is_station_file

        if is_station_file(cell):
            from robomax_py.app.station_command import plan_station_files

            if method != "optimised":
                from robomax_py.errors import CellFileError

                raise CellFileError(cell, "robots", "--baseline plans single-robot cells; a station "
                                    "compares its methods in tests/bench/bench_station.py")
            compiling.wait(_honour_signals)
            return plan_station_files(cell, out_dir, formats, speed, as_json,
                                      datetime.date.today().isoformat() if stamp else "", plot)
        t0 = time.perf_counter()
        spec = load_cell(cell)
        _warn([str(n) for n in spec.notices])
        robot = load_cell_robot(spec)
        _honour_signals()
        _warn(robot.warnings)
        chosen = choose_formats(formats, robot, setup_signals(spec.controller), spec.source)
        names = chosen.names
        _warn([s.message for s in chosen.skipped])
        set_name = spec.name + method_suffix(method)
        compiling.wait(_honour_signals)
        with stage_bars(err, enabled=not verbose) as bars:
            def progress(stage: str, done: int, total: int) -> None:
                _honour_signals()
                bars(stage, done, total)

            result = plan_cell(spec, robot, method_options(method, PlanOptions(speed=speed)), progress)
        _honour_signals()
        seconds = time.perf_counter() - t0
        written: list[Path] = []
        checked: list[CheckedProgram] = []
        removed: tuple[str, ...] = ()
        unlisted: tuple[str, ...] = ()
        if result.status == "planned":
            from robomax_py.app.chart import cycle_chart, render_png

            date = datetime.date.today().isoformat() if stamp else ""
            texts, checked = publish(result, spec, robot, names, stamp=date, method=method)  # all proven before any write
            files: dict[str, str | bytes] = dict(texts)
            if plot:
                files[f"{set_name}.png"] = render_png(cycle_chart(result))
            _honour_signals()                   # nothing is written after an interrupt
            committed = commit_set(out_dir, set_name, files, spec.digest, SHARED_FILES)
            _honour_signals()                   # one that came during the commit: the new set is whole
            written = [*committed.paths, committed.manifest]
            removed = committed.removed
            unlisted = committed.unlisted
        report = plan_report(result, seconds, written, robot.defaulted_limits, checked, chosen.skipped)
        report["warnings"] = [{"file": n.file, "key": n.key, "message": n.message} for n in spec.notices]
        if result.status == "planned":
            report["removed"] = [str(out_dir / n) for n in removed]
            report["not_of_this_plan"] = [str(out_dir / n) for n in _stale_programs(out_dir, set_name)]
            report["unlisted"] = [str(out_dir / n) for n in unlisted]
        if as_json:
            _print_json("plan", result.status == "planned", report)
        else:
            for renderable in report_tables(report):
                out.print(renderable)
        if result.status != "planned":
            from rich.markup import escape

            err.print(f"[bold red]infeasible:[/] {escape(result.message)}", soft_wrap=True)
            from robomax_py.plan.reach import reach_report

            reach = {(r.seam, r.name): r for r in reach_report(spec, robot)} if result.failures else {}
            for f in result.failures:
                r = reach.get((f.seam, f.name))
                far = f"; {r.out_by_m:.3f} m out of reach at the best orientation" if r and not r.reachable else ""
                err.print(f"  {f.seam}/{f.name}: {f.reason} ({f.detail}{far})", soft_wrap=True)
            stale = _stale_programs(out_dir, set_name, every=True)
            if stale:
                err.print(f"[yellow]note:[/] {', '.join(stale)} in {out_dir} are from an earlier plan, not this one "
                          "(nothing was written)", soft_wrap=True)
            return EXIT_INFEASIBLE
        if report["not_of_this_plan"]:
            err.print(f"[yellow]note:[/] {', '.join(Path(p).name for p in report['not_of_this_plan'])} in {out_dir} "
                      "are not of this plan (written by an older robomax or by hand; left as they are)", soft_wrap=True)
        if unlisted:
            err.print(f"[yellow]note:[/] {', '.join(unlisted)} in {out_dir}: no plan's set there names it any more "
                      "(left as it is: it may hold the integrator's routine)", soft_wrap=True)
        return EXIT_OK

    code = _guarded(run, "plan" if as_json else None)
    raise typer.Exit(code)


def _stale_programs(out_dir: Path, name: str, every: bool = False) -> list[str]:
    """Program files of the cell in the output folder that are not of its current set: regular
    files named as its programs (an older robomax's, or put there by hand; a plan writes its set
    as links into the set's folder). With `every`, the current set's files too."""
    from robomax_py.export import DIALECTS
    from robomax_py.io.files import MANIFEST_SUFFIX
    from robomax_py.program import identifier

    # FANUC's files are named as its TP program (capitals), the others' as the cell.
    stems = {name, *(d.program_name(identifier(name)) for d in DIALECTS.values() if d.program_name)}
    keys = (".json", ".png", MANIFEST_SUFFIX, *(k for d in DIALECTS.values() for k in (*d.extensions, *d.companions)))
    names = {f"{stem}{key}" for stem in stems for key in keys}
    try:
        return sorted(p.name for p in out_dir.iterdir()
                      if p.name in names and p.exists() and (every or not p.is_symlink()))
    except OSError:
        return []


@_command()
def verify(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    programs: Annotated[list[Path], typer.Argument(help="a program (.srcl, .src, .mod, .ls, .script: the motion rebuilt from its statements) or a trajectory file (.json); for a station, its output folder or one program per robot")],
    as_json: JsonFlag = False,
    chart: Annotated[bool, typer.Option("--chart", help="station: write the replay's Gantt chart <station>.gantt.png beside the programs")] = False,
) -> None:
    """Re-simulate a program against the cell; report collisions, limit and tolerance violations.
    A station's programs are replayed together on one clock: robot-robot contacts, each program's
    own violations, deadlocks and waits for signals no robot sets."""

    def run() -> int:
        from robomax_py.errors import ProgramError
        from robomax_py.export import dialect_for_file
        from robomax_py.io.cell import load_cell, load_cell_robot
        from robomax_py.io.station import is_station_file
        from robomax_py.verify import verify_program

        swapped = [p for p in programs if p.suffix.lower() in (".yaml", ".yml")]
        if swapped and (cell.suffix.lower() == ".json" or dialect_for_file(cell.suffix) is not None):
            # Read as a cell, a program fails as YAML on its first statement: name the mix-up instead.
            raise ProgramError(cell, None, f"a program where the cell is expected: `robomax verify` takes the cell "
                               f"first (robomax verify {swapped[0]} {cell})")
        if is_station_file(cell):
            from robomax_py.app.station_report import print_station_verify

            return print_station_verify(cell, programs, as_json, chart)
        if len(programs) != 1:
            raise ProgramError(cell, None, f"a cell's verify takes one program, got {len(programs)}")
        program = programs[0]
        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        report = verify_program(spec, robot, program)
        if as_json:
            c = report.clearance
            _print_json("verify", report.clean, {
                "cell": str(cell), "program": str(program), "clean": report.clean, "samples": report.samples,
                "cycle_time": round(report.cycle_time, 4), "collision_checks": report.collision_checks,
                "violations": [{"kind": v.kind, "line": v.line, "t": _num(v.t), "t_end": _num(v.t_end), "detail": v.detail}
                               for v in report.violations],
                "clearance": None if c is None else {"mm": round(c.distance_m * 1000, 3), "t": round(c.t, 4),
                                                     "between": c.between, "line": report.clearance_line},
                "ignored_statements": len(report.ignored), "notes": list(report.notes)})
            return EXIT_OK if report.clean else EXIT_VIOLATIONS
        out.print(f"{program}: {report.samples} samples, cycle {report.cycle_time:.3f} s, "
                  f"{report.collision_checks} collision checks")
        for v in report.violations:
            where = f"line {v.line}, " if v.line is not None else ""
            when = "" if v.t is None else (f"t = {v.t:.3f}-{v.t_end:.3f} s" if v.t_end is not None else f"t = {v.t:.3f} s")
            place = f"{where}{when}".rstrip(", ")
            out.print(f"  [red]{v.kind}[/]: {place + ': ' if place else ''}{v.detail}", soft_wrap=True)
        if report.clearance is not None:
            c = report.clearance
            at = f"line {report.clearance_line}, " if report.clearance_line is not None else ""
            out.print(f"  smallest clearance {c.distance_m * 1000:.1f} mm ({at}t = {c.t:.3f} s, {c.between})")
        if report.ignored:
            out.print(f"  {len(report.ignored)} statement(s) read but without effect on the motion (I/O, declarations ...)")
        for note in report.notes:
            out.print(f"  note: {note}", soft_wrap=True, markup=False)
        if report.clean:
            done = ("every station's gripper action at rest on its pose" if spec.tending
                    else "every spot welded within tolerance")
            out.print(f"[green]clean[/]: no collisions, limits kept, {done}")
            return EXIT_OK
        out.print(f"[red]{len(report.violations)} violation(s)[/]")
        return EXIT_VIOLATIONS

    code = _guarded(run, "verify" if as_json else None)
    raise typer.Exit(code)
