"""The `robomax` command: exit codes and messages per docs/cell-files.md, "Commands and exit codes".

A RobomaxError (a user's mistake) becomes one line on stderr and exit code 2, never a traceback.
Heavy modules are imported inside commands so `robomax --help` stays fast.

Every command takes --json: one JSON object on stdout instead of tables, its first keys `schema`
("robomax.cli.<command>/<version>", the version raised when a key changes meaning or goes) and `ok`
(true exactly when the exit code is 0). A bad input still exits non-zero: the object is then
{"schema", "ok": false, "error": {"file", "key", "message"}} and the human message goes to stderr
as without --json. Warnings and progress always go to stderr. A command line the parser rejects
(unknown option, missing argument) gets the usage message and exit 2 without JSON: the command
never ran.
"""

from __future__ import annotations

import re
import signal
import sys
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, TypeVar

import typer
from rich.console import Console
from rich.table import Table
from typer.core import TyperCommand, TyperGroup

from robomax_py._version import __version__
from robomax_py.errors import RobomaxError
from robomax_py.io.files import signals_held

if TYPE_CHECKING:                     # the commands import what they use when they run
    from robomax_py._typing import FloatArray
    from robomax_py.publish import CheckedProgram

EXIT_OK = 0
EXIT_VIOLATIONS = 1
EXIT_BAD_INPUT = 2
EXIT_INFEASIBLE = 3
EXIT_INTERRUPTED = 130                  # 128 + SIGINT
EXIT_TERMINATED = 143                   # 128 + SIGTERM

# The one table of exit codes, shown under every command's help.
EXIT_CODES = (
    (EXIT_OK, "done: valid, planned, clean"),
    (EXIT_VIOLATIONS, "verify found violations"),
    (EXIT_BAD_INPUT, "bad input: a file (named with its key) or the command line is wrong"),
    (EXIT_INFEASIBLE, "infeasible: a spot left unplanned (batch: or a cell timed out or crashed)"),
    (EXIT_INTERRUPTED, "interrupted (Ctrl-C)"),
    (EXIT_TERMINATED, "terminated (SIGTERM)"),
)
JSON_VERSION = 1
# "\b" keeps the lines as they are in the help (click's and typer's formatters rewrap otherwise).
EPILOG = "\b\nExit codes:\n" + "\n".join(f"  {code:>3}  {what}" for code, what in EXIT_CODES) + (
    f"\n\b\n--json: one object on stdout, {{\"schema\": \"robomax.cli.<command>/{JSON_VERSION}\", \"ok\": ...}}; "
    "on bad input {\"ok\": false, \"error\": {\"file\", \"key\", \"message\"}}")
HELP_OPTIONS = {"help_option_names": ["-h", "--help"]}


def json_schema(command: str) -> str:
    """The `schema` value of a command's --json output."""
    return f"robomax.cli.{command}/{JSON_VERSION}"


def _untyped_flags(params: list[Any]) -> list[Any]:
    """A flag takes no value: typer from 0.2x shows its type (`<bool>`) in the help unless it has a
    metavar, so flags get an empty one (no effect with older typer, which shows none)."""
    for param in params:
        if getattr(param, "is_flag", False) and param.metavar is None:
            param.metavar = ""
    return params


class _Command(TyperCommand):
    """A command whose help shows no `<bool>` and names its arguments as the usage line does
    (CELL, [PROGRAM], CELLS...), not `{cell}`."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        for param in self.params:
            if param.param_type_name == "argument" and param.metavar is None and param.name:
                param.metavar = param.name.upper()

    def get_params(self, ctx: Any) -> list[Any]:
        return _untyped_flags(super().get_params(ctx))

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if param.param_type_name != "argument":
                pieces.extend(param.get_usage_pieces(ctx))
                continue
            name = str(param.metavar or param.name).upper()
            name = name if param.required else f"[{name}]"
            pieces.append(name + ("..." if param.nargs != 1 else ""))
        return pieces


class _Group(TyperGroup):
    def get_params(self, ctx: Any) -> list[Any]:
        return _untyped_flags(super().get_params(ctx))


app = typer.Typer(add_completion=False, no_args_is_help=True, cls=_Group, context_settings=HELP_OPTIONS,
                  epilog=EPILOG, help="Offline programming for spot-welding robot cells.")
out = Console(highlight=False)
err = Console(stderr=True, highlight=False)


def _command(name: str | None = None) -> Callable[[Callable[..., T]], Callable[..., T]]:
    """`app.command` with the conventions every command shares: -h, the exit-code epilog, clean help."""
    return app.command(name, cls=_Command, epilog=EPILOG)


JsonFlag = Annotated[bool, typer.Option("--json", help="print one JSON object on stdout instead of tables "
                                                       "(see below)")]


def _print_json(command: str, ok: bool, payload: dict[str, Any]) -> None:
    """A command's --json output: `schema` and `ok` first, then the command's own keys."""
    import json

    out.print_json(json.dumps({"schema": json_schema(command), "ok": ok, **payload}))


T = TypeVar("T")


def _print_version(wanted: bool) -> None:
    if wanted:
        out.print(f"robomax_py {__version__}", markup=False, highlight=False)
        raise typer.Exit(EXIT_OK)


@app.callback()
def _library(
    robots_dirs: Annotated[list[Path] | None, typer.Option(
        "--robots", metavar="DIR",
        help="a robot library folder searched before ROBOMAX_ROBOTS and the shipped library (repeatable; "
             "any command takes it, before or after the command name)")] = None,
    version: Annotated[bool, typer.Option("--version", is_eager=True, callback=_print_version,
                                          help="print the version and exit")] = False,
) -> None:
    """Offline programming for spot-welding robot cells."""
    if robots_dirs:
        _prepend_library([str(d) for d in robots_dirs])


def _prepend_library(dirs: list[str]) -> None:
    """Put folders in front of ROBOMAX_ROBOTS; batch workers and local Ray inherit the environment."""
    import os

    from robomax_py.io.robot import ROBOTS_ENV

    current = [p for p in os.environ.get(ROBOTS_ENV, "").split(os.pathsep) if p]
    wanted = [str(Path(d).resolve()) for d in dirs]
    os.environ[ROBOTS_ENV] = os.pathsep.join([*wanted, *[p for p in current if p not in wanted]])


def _warn(lines: tuple[str, ...] | list[str]) -> None:
    from rich.markup import escape

    for line in lines:
        err.print(f"[yellow]warning:[/] {escape(line)}", soft_wrap=True, highlight=False)


def _guarded(action: Callable[[], T], json_command: str | None = None) -> T:
    """Run a command body; a RobomaxError becomes one message on stderr and exit code 2 (with
    `json_command`, the --json error object on stdout as well)."""
    try:
        return action()
    except RobomaxError as exc:
        from rich.markup import escape

        err.print(f"[bold red]error:[/] {escape(str(exc))}", markup=True, soft_wrap=True)
        if json_command is not None:
            _print_json(json_command, False, {"error": {
                "file": getattr(exc, "file", None), "key": getattr(exc, "key", None), "message": str(exc)}})
        raise typer.Exit(EXIT_BAD_INPUT) from None


def _num(value: float | None) -> float | None:
    """A number for JSON (a numpy scalar as a float)."""
    return None if value is None else float(value)


def _json_failure(command: str, as_json: bool, file: str | None, message: str) -> int:
    """A bad input found by the command itself (not a RobomaxError): the message on stderr, the
    error object on stdout with --json; exit code 2."""
    from rich.markup import escape

    err.print(f"[bold red]error:[/] {escape(message)}", soft_wrap=True)
    if as_json:
        _print_json(command, False, {"error": {"file": file, "key": None, "message": message}})
    return EXIT_BAD_INPUT


@_command()
def robots(as_json: JsonFlag = False) -> None:
    """List the robot and tool library: axes, reach, IK solver, tool TCP."""

    def run() -> None:
        from robomax_py.app.library import list_robots, list_tools
        from robomax_py.io.robot import robot_library

        if as_json:
            found, tools_found = list_robots(), list_tools()
            _warn([f"robot {r.name}: {s} is hidden by {r.source}" for r in found for s in r.shadowed])
            _warn([f"tool {t.name}: {s} is hidden by {t.source}" for t in tools_found for s in t.shadowed])
            _print_json("robots", True, {
                "library": [str(d) for d in robot_library()],
                "robots": [{"name": r.name, "axes": r.axes, "reach_m": round(r.reach_m, 6), "payload_kg": r.payload_kg,
                            "ik": r.ik_solver, "controller": r.brand, "source": str(r.source),
                            "description": r.description} for r in found],
                "tools": [{"name": t.name, "tcp_xyz_m": [round(v, 6) for v in t.tcp_xyz_m],
                           "tcp_distance_m": round(t.tcp_distance_m, 6), "source": str(t.source)} for t in tools_found]})
            return
        out.print("library path: " + "  ".join(str(d) for d in robot_library()), soft_wrap=True)
        table = Table(title="Robots", title_justify="left")
        for col in ("name", "axes", "flange reach (m)", "payload (kg)", "IK", "controller", "from", "description"):
            table.add_column(col)
        for r in list_robots():
            payload = "-" if r.payload_kg is None else f"{r.payload_kg:g}"
            table.add_row(r.name, str(r.axes), f"{r.reach_m:.3f}", payload, r.ik_solver, r.brand,
                          str(r.source.parent.parent), r.description)
            _warn([f"robot {r.name}: {s} is hidden by {r.source}" for s in r.shadowed])
        out.print(table)
        tools = Table(title="Tools", title_justify="left")
        for col in ("name", "TCP offset from flange (m)", "TCP distance (m)", "from"):
            tools.add_column(col)
        for t in list_tools():
            xyz = ", ".join(f"{v:.3f}" for v in t.tcp_xyz_m)
            tools.add_row(t.name, f"[{xyz}]", f"{t.tcp_distance_m:.3f}", str(t.source.parent.parent.parent))
            _warn([f"tool {t.name}: {s} is hidden by {t.source}" for s in t.shadowed])
        out.print(tools)

    _guarded(run, "robots" if as_json else None)


@_command()
def check(cell: Annotated[Path, typer.Argument(help="cell file (YAML)")], as_json: JsonFlag = False) -> None:
    """Validate a cell (and its robot, tool and meshes) and print a summary."""

    def run() -> None:
        from robomax_py.app.summary import cell_summary
        from robomax_py.errors import CellFileError
        from robomax_py.io.cell import load_cell, load_cell_robot, read_cell_frames
        from robomax_py.io.frames import format_tree
        from robomax_py.plan.reach import reach_report, self_contacts

        spec = load_cell(cell)
        tree, included = read_cell_frames(cell)
        _warn([str(n) for n in spec.notices])   # probable mistakes: warnings, the cell is still valid
        robot = load_cell_robot(spec)
        _warn(robot.warnings)
        if not as_json:
            out.print(cell_summary(spec, robot))
            for file in included:
                out.print(f"includes {file}", markup=False, highlight=False, soft_wrap=True)
            if tree:
                out.print("frames:\n" + "\n".join(f"  {line}" for line in format_tree(tree)), markup=False,
                          highlight=False, soft_wrap=True)
        reach = reach_report(spec, robot)
        far = [r for r in reach if not r.reachable]
        stop = "station" if spec.tending else "spot"          # gripper actions (tending, pick and place)
        if far:
            worst = max(far, key=lambda r: r.out_by_m)
            others = f" ({len(far) - 1} more {stop}(s) out of reach)" if len(far) > 1 else ""
            raise CellFileError(cell, worst.key, f"{stop} {worst.seam}/{worst.name} is out of {robot.name}'s reach by "
                                f"{worst.out_by_m:.3f} m at every allowed orientation (shoulder to wrist "
                                f"{worst.distance_m:.3f} m, the arm reaches {worst.reach_m:.3f} m){others}")
        tight = min(reach, key=lambda r: -r.out_by_m) if reach else None
        if tight is not None and not as_json:
            out.print(f"reach: all {len(reach)} {stop}s within reach (least margin {-tight.out_by_m * 1000:.0f} mm "
                      f"at {tight.seam}/{tight.name})")
        at_home, always = self_contacts(robot, spec.home)
        _warn([f"{robot.name}: links {a} and {b} touch at home; if they touch by design, add "
               f"[{a}, {b}] to collision.disable in {robot.source}" for a, b in at_home])
        _warn([f"{robot.name}: links {a} and {b} touch in every sampled configuration; add [{a}, {b}] "
               f"to collision.disable in {robot.source} (or give its SRDF as srdf:)" for a, b in always])
        if as_json:
            _print_json("check", True, {
                "cell": str(cell), "name": spec.name, "robot": robot.name, "tool": spec.tool.name,
                "seams": [{"name": seam.name, "spots": len(seam.spots), "ordered": seam.ordered} for seam in spec.seams],
                "objects": [obj.name for obj in (*spec.objects, *spec.dynamic)],
                "reach": None if tight is None else {
                    stop + "s": len(reach), "least_margin_m": round(-tight.out_by_m, 6), "at": f"{tight.seam}/{tight.name}"},
                "self_contacts_at_home": [list(p) for p in at_home],
                "self_contacts_always": [list(p) for p in always],
                "frames": [node.as_dict() for node in tree], "includes": [str(file) for file in included]})
            return
        out.print(f"[green]ok[/]: {cell} is a valid cell")

    _guarded(run, "check" if as_json else None)


@_command()
def plan(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder")] = Path("programs"),
    baseline: Annotated[str | None, typer.Option("--baseline", metavar="published|teach-in", help="plan a baseline instead and write <name>_published.* or <name>_teach_in.*: published = the published method (paper 003: the cell's spot order, the DP over every orientation sample and IK branch, the same detours and timing), teach-in = the cell's order, nominal orientation, first branch")] = None,
    as_json: JsonFlag = False,
    speed: Annotated[float | None, typer.Option("--speed", min=0.01, max=1.0, help="override of every programmed speed, fraction in (0, 1] (default: the cell's planner.speed, else 1)")] = None,
    verbose: Annotated[bool, typer.Option("-v", "--verbose", help="debug logging: stage sizes, counts and times")] = False,
    plot: Annotated[bool, typer.Option("--plot", help="also write DIR/<name>.png: a cycle-time Gantt chart, one row per spot")] = False,
    formats: Annotated[str, typer.Option("--format", help="program dialects, comma-separated: srcl, krl, rapid, fanuc, urscript, inform, as, native (the robot's controller brand) or all (every dialect the robot file has the data for; the others are named in a warning)")] = "srcl",
    stamp: Annotated[bool, typer.Option("--stamp", help="write the date into each program's header (otherwise the same cell gives the same bytes)")] = False,
) -> None:
    """Plan a cell and write its program files (only when the plan is complete and every program proven)."""
    method = _method(baseline)

    def run() -> int:
        import datetime
        import time

        # SIGINT and SIGTERM held while the heavy modules are imported (a few seconds at most): an
        # import that catches BaseException would swallow the interrupt and leave half-imported
        # modules behind. A signal that arrived meanwhile is delivered when the imports are done.
        with signals_held():
            from robomax_py.app.progress import configure_logging, stage_bars
            from robomax_py.app.report import plan_report, report_tables
            from robomax_py.export import SHARED_FILES, choose_formats
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
        t0 = time.perf_counter()
        spec = load_cell(cell)
        _warn([str(n) for n in spec.notices])
        robot = load_cell_robot(spec)
        _honour_signals()
        _warn(robot.warnings)
        chosen = choose_formats(formats, robot)
        names = chosen.names
        _warn([s.message for s in chosen.skipped])
        set_name = spec.name + method_suffix(method)
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
            err.print(f"[bold red]infeasible:[/] {result.message}", soft_wrap=True)
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


def _method(baseline: str | None) -> str:
    """The planning method `--baseline` names (None: the optimiser); a usage error otherwise."""
    if baseline is None:
        return "optimised"
    if baseline not in ("published", "teach-in"):
        raise typer.BadParameter(f"expected published or teach-in, got {baseline!r}", param_hint="--baseline")
    return baseline


def _stale_programs(out_dir: Path, name: str, every: bool = False) -> list[str]:
    """Program files of the cell in the output folder that are not of its current set: regular
    files named as its programs (an older robomax's, or put there by hand; a plan writes its set
    as links into the set's folder). With `every`, the current set's files too."""
    from robomax_py.export import DIALECTS
    from robomax_py.export.plan_program import identifier
    from robomax_py.io.files import MANIFEST_SUFFIX

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
    program: Annotated[Path, typer.Argument(help="a program (.srcl, .src, .mod, .ls, .script: the motion rebuilt from its statements) or a trajectory file (.json)")],
    as_json: JsonFlag = False,
) -> None:
    """Re-simulate a program against the cell; report collisions, limit and tolerance violations."""

    def run() -> int:
        from robomax_py.io.cell import load_cell, load_cell_robot
        from robomax_py.verify import verify_program

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


@_command()
def bench(
    cell: Annotated[Path | None, typer.Argument(help="cell to plan (default: the cabin_flange example shipped "
                                                     "with the package)", show_default=False)] = None,
    runs: Annotated[int, typer.Option("--runs", min=1, help="planning runs (median)")] = 3,
    quick: Annotated[bool, typer.Option("--quick", help="smaller IK and collision batches")] = False,
    as_json: JsonFlag = False,
) -> None:
    """Measure this machine: IK/s, collision checks/s, planning time, cycle vs baseline vs lower bound."""

    def run() -> None:
        from rich.status import Status

        from robomax_py.app.bench import run_bench
        from robomax_py.app.examples import default_bench_cell
        from robomax_py.io.cell import load_cell, load_cell_robot

        path = default_bench_cell() if cell is None else cell
        spec = load_cell(path)
        robot = load_cell_robot(spec)
        with Status("", console=err) as status:
            rows = run_bench(spec, robot, runs=runs, quick=quick, on_step=lambda s: status.update(f"measuring {s}"))
        if as_json:
            _print_json("bench", True, {"cell": str(path), "name": spec.name, "robot": robot.name, "runs": runs,
                                        "quick": quick, "figures": [{"name": r.name, "value": float(r.value), "unit": r.unit,
                                                                     "note": r.note} for r in rows]})
            return
        table = Table(title=f"robomax bench: {spec.name} ({robot.name}), one process", title_justify="left")
        for col, justify in (("figure", "left"), ("value", "right"), ("unit", "left"), ("note", "left")):
            table.add_column(col, justify=justify)  # type: ignore[arg-type]
        for r in rows:
            value = f"{r.value:,.0f}" if r.value >= 1000 else f"{r.value:.3f}"
            table.add_row(r.name, value, r.unit, r.note)
        out.print(table)

    _guarded(run, "bench" if as_json else None)


@_command()
def cspace(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    wrist: Annotated[str, typer.Option("--wrist", help="A4-A6 held at home, or at a spot's nominal-orientation IK (spot or seam/spot)")] = "home",
    resolution: Annotated[int, typer.Option("--resolution", help="samples per axis of A1-A3 (4..400)")] = 50,
    plot: Annotated[Path | None, typer.Option("--plot", help="write a PNG of the blocked cells here")] = None,
    jobs: Annotated[int, typer.Option("-j", "--jobs", min=0, help="processes (0: the cores this process may use)")] = 0,
    as_json: JsonFlag = False,
    learned: Annotated[bool, typer.Option("--learned", help="also the map of the learned point model (trained once per robot, tool and wrist, then cached), compared with the exact one cell by cell")] = False,
    spacing: Annotated[float, typer.Option("--spacing", min=0.005, max=1.0, help="m between the object surface points of the learned map")] = 0.1,
    program: Annotated[Path | None, typer.Option("--program", help="with --plot: draw this trajectory file's A1-A3 path (a .json from plan) over the map")] = None,
    plot_model: Annotated[Path | None, typer.Option("--plot-model", help="with --learned: write a PNG of one point's C-obstacle at three distances")] = None,
    inflation: Annotated[float, typer.Option("--inflation", min=0.0, max=1.0, help="m added to the learned model's sphere radius (safety; 0.06 gave no wrongly free cell on the reference cell)")] = 0.06,
) -> None:
    """The A1-A3 configuration-space map of a cell with the wrist fixed, every cell checked exactly
    (and with --learned, from the learned point model too)."""

    def run() -> None:
        import numpy as np

        from robomax_py.app.cspace_view import map_png, map_summary, spot_wrist
        from robomax_py.cspace import build_map, check_arm, default_workers
        from robomax_py.io.cell import load_cell, load_cell_robot
        from robomax_py.io.files import write_atomic_bytes
        from robomax_py.world.collision import CollisionWorld
        from robomax_py.world.scene import build_scene

        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        check_arm(robot)
        scene = build_scene(spec, robot)             # one world for the wrist's IK check and the map
        world = CollisionWorld(robot, scene, spec.process.clearance)
        values: Literal["home"] | FloatArray = "home" if wrist == "home" else spot_wrist(spec, robot, wrist, world)
        m = build_map(spec, robot, values, resolution, jobs or default_workers(), world)
        path = None
        if program is not None:
            from robomax_py.export.trajectory_json import load_trajectory_file

            path = np.asarray(load_trajectory_file(program, robot)["q"], dtype=float)
        png = map_png(m, f"{spec.name} ({robot.name}): C-space, wrist {wrist}, {resolution}^3", path) if plot else None
        summary = {"cell": spec.name, "robot": robot.name, "wrist": wrist, **map_summary(m)}
        if learned:
            from robomax_py.app.cspace_view import learned_summary

            figures, model = learned_summary(spec, robot, scene, m, spacing, inflation)
            summary.update(figures)
            if plot_model is not None:
                from robomax_py.app.cspace_view import model_png

                reach = model.d_max
                write_atomic_bytes(plot_model, model_png(model, (0.3 * reach, 0.5 * reach, 0.7 * reach),
                                                         f"{robot.name} + {spec.tool.name}: a point's C-obstacle"))
                summary["plot_model"] = str(plot_model)
        if png is not None and plot is not None:
            write_atomic_bytes(plot, png)
            summary["plot"] = str(plot)
        if as_json:
            _print_json("cspace", True, summary)
            return
        table = Table(show_header=False, box=None)
        for key, value in summary.items():
            table.add_row(key, f"{value:,}" if isinstance(value, int) else str(value))
        out.print(table)

    _guarded(run, "cspace" if as_json else None)


@_command()
def preview(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    program: Annotated[Path | None, typer.Argument(help="program written by plan (.json or .srcl); without it the robot stands at home")] = None,
    html: Annotated[Path | None, typer.Option("--html", help="write one self-contained HTML page instead of serving")] = None,
    voxels: Annotated[float | None, typer.Option("--voxels", min=0.005, max=0.5, metavar="PRECISION",
                                                 help="also draw the voxel map of the static objects (blocked leaves) "
                                                      "at this precision limit, m")] = None,
    host: Annotated[str, typer.Option("--host", help="address to serve the page on (default: this machine only); "
                                                     "any other makes the cell visible to the network")] = "127.0.0.1",
    port: Annotated[int | None, typer.Option("--port", min=1, max=65535,
                                             help="web port (default: the first free one from 7000)")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="print one JSON object on stdout (see below): with --html "
                                                         "the page written, else the URL served, once it listens")] = False,
) -> None:
    """Show the cell in meshcat, animated along a program (serves until Ctrl-C, or writes --html)."""

    def run() -> None:
        from robomax_py.app.preview import serve, write_html
        from robomax_py.app.preview_program import home_program, load_program
        from robomax_py.app.preview_server import LOOPBACK, WILDCARDS, is_loopback
        from robomax_py.io.cell import load_cell, load_cell_robot

        if html is not None and (host != LOOPBACK or port is not None):
            raise typer.BadParameter("--html writes a file; --host and --port are for serving", param_hint="--host/--port")
        spec = load_cell(cell)
        robot = load_cell_robot(spec)
        shown = home_program(spec) if program is None else load_program(program, spec, robot)
        vmap = None
        if voxels is not None:
            from dataclasses import replace

            import numpy as np

            from robomax_py.plan.tcp_route import HALF_WIDTH_M
            from robomax_py.world.scene import build_scene
            from robomax_py.world.voxels import build_voxels

            lo = np.array([-HALF_WIDTH_M, -HALF_WIDTH_M, -0.5])
            vmap = build_voxels(build_scene(replace(spec, dynamic=()), robot), lo, lo + 2 * HALF_WIDTH_M, voxels)
        shown_files = {"cell": str(cell), "program": None if program is None else str(program)}
        if html is not None:
            content = write_html(html, spec, robot, shown, voxels=vmap)
            if as_json:
                _print_json("preview", True, {**shown_files, "url": None, "files": [str(html)],
                                              "frames": content.frames, "duration": round(content.duration, 4),
                                              "voxels": content.voxels if vmap is not None else None})
                return
            drawn = f", {content.voxels} blocked voxels" if vmap is not None else ""
            out.print(f"wrote {html} ({content.frames} animation frames, cycle {content.duration:.3f} s{drawn})")
            return

        def announce(url: str) -> None:
            # Said once the server listens, so a host it cannot bind gets only the error.
            if not is_loopback(host):
                where = "every interface of this machine" if host.strip("[]") in WILDCARDS else host
                _warn([(f"--host {host}: the preview listens on {where}; anyone who can reach it on the network "
                        "can open the page and see the cell (no password)")])
            if as_json:                         # one object, flushed now: the page is served until Ctrl-C
                _print_json("preview", True, {**shown_files, "url": url, "files": []})
                err.print("serving (Ctrl-C to stop)")
                return
            out.print(f"meshcat preview at {url}  (Ctrl-C to stop)", soft_wrap=True)

        serve(spec, robot, shown, announce, voxels=vmap, host=host, port=port)
        (err if as_json else out).print("preview stopped")

    _guarded(run, "preview" if as_json else None)


@_command()
def batch(
    cells: Annotated[list[Path], typer.Argument(help="cell files (YAML)")],
    jobs: Annotated[int | None, typer.Option("-j", "--jobs", min=1, help="cells planned at once (default: the number of CPUs)")] = None,
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder for programs and summary.csv / summary.md")] = Path("programs"),
    timeout: Annotated[float | None, typer.Option("--timeout", min=0.0, help="seconds per cell before its worker is killed")] = None,
    ray_address: Annotated[str | None, typer.Option("--ray", metavar="[ADDRESS]",
                                                    help="plan on Ray: a local Ray without ADDRESS (or with `local`), else the cluster at ADDRESS")] = None,
    baseline: Annotated[str | None, typer.Option("--baseline", metavar="published|teach-in", help="plan every cell by a baseline instead (see plan --baseline)")] = None,
    as_json: JsonFlag = False,
) -> None:
    """Plan many cells in parallel (one process per cell); write their programs and a summary table.

    Exit 0 all planned; 3 some infeasible, timed out or crashed; 2 a cell file is bad (reported in its
    row, the others still plan) or does not exist (nothing is planned).
    """
    method = _method(baseline)

    def run() -> int:
        import os

        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
        )

        from robomax_py.app.batch import (
            BAD_INPUT,
            PLANNED,
            BatchOptions,
            CellOutcome,
            run_batch,
        )

        files = [str(c) for c in cells]
        use_ray = ray_address is not None
        address = None if ray_address in (None, "", RAY_LOCAL) else ray_address
        missing = [f for f in files if not Path(f).is_file()]
        if missing:
            for f in missing:
                err.print(f"[bold red]error:[/] {f}: cell file not found", soft_wrap=True)
            if as_json:
                more = f" ({len(missing) - 1} more)" if len(missing) > 1 else ""
                _print_json("batch", False, {"error": {"file": missing[0], "key": None,
                                                       "message": f"{missing[0]}: cell file not found{more}"}})
            return EXIT_BAD_INPUT
        if use_ray:
            try:
                import ray  # noqa: F401
            except ImportError:
                return _json_failure("batch", as_json, None, "--ray needs Ray: pip install 'robomax-py[ray]'")
        options = BatchOptions(jobs=jobs or os.cpu_count() or 1, timeout=timeout, method=method)
        where = f"Ray ({address or 'local'})" if use_ray else f"{options.jobs} process(es)"
        with Progress(TextColumn("planning"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                      console=err, transient=False) as progress:
            task = progress.add_task("cells", total=len(files))
            progress.console.print(f"{len(files)} cell(s) on {where}")

            def done(i: int, o: CellOutcome) -> CellOutcome:
                style = "green" if o.status == PLANNED else "red"
                detail = f"cycle {o.cycle_time:.2f} s" if o.cycle_time is not None else o.reasons
                progress.console.print(f"[{style}]{o.status}[/]: {o.file} ({o.seconds:.1f} s) {detail}",
                                       soft_wrap=True, markup=True, highlight=False)
                progress.advance(task)
                return o

            outcomes = run_batch(files, out_dir, options, use_ray=use_ray, ray_address=address, on_done=done)
        code = (EXIT_OK if all(o.status == PLANNED for o in outcomes) else
                EXIT_BAD_INPUT if any(o.status == BAD_INPUT for o in outcomes) else EXIT_INFEASIBLE)
        if as_json:
            _print_json("batch", code == EXIT_OK, {
                "out": str(out_dir), "summary": [str(out_dir / "summary.csv"), str(out_dir / "summary.md")],
                "cells": [{"cell": o.cell, "file": o.file, "status": o.status, "cycle_time": _num(o.cycle_time),
                           "seconds": round(o.seconds, 3), "spots": o.spots, "detours": o.detours,
                           "reasons": o.reasons, "written": list(o.written)} for o in outcomes]})
            return code
        table = Table(title=f"batch: {out_dir / 'summary.md'}", title_justify="left")
        for col in ("cell", "status", "cycle (s)", "planning (s)", "spots", "detours"):
            table.add_column(col)
        for o in outcomes:
            table.add_row(o.cell, o.status, "" if o.cycle_time is None else f"{o.cycle_time:.2f}",
                          f"{o.seconds:.1f}", "" if o.spots is None else str(o.spots),
                          "" if o.detours is None else str(o.detours))
        out.print(table)
        return code

    code = _guarded(run, "batch" if as_json else None)
    raise typer.Exit(code)


@_command()
def variants(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    n: Annotated[int, typer.Option("--n", "-n", min=1, help="number of variants")] = 20,
    seed: Annotated[int, typer.Option("--seed", min=0, help="seed: the same seed writes the same files")] = 0,
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder")] = Path("variants"),
    as_json: JsonFlag = False,
) -> None:
    """Write seeded perturbed copies of a cell (clamps ±15 mm, part ±5 mm / ±1°, spot order of free seams)."""

    def run() -> None:
        from robomax_py.io.variants import write_variants

        made = write_variants(cell, n, seed, out_dir)
        if as_json:
            _print_json("variants", True, {"cell": str(cell), "seed": seed, "out": str(out_dir),
                                           "files": [str(v.path) for v in made]})
            return
        out.print(f"wrote {len(made)} variant(s) of {cell}: {made[0].path} ... {made[-1].path}")

    _guarded(run, "variants" if as_json else None)


@_command("import-urdf")
def import_urdf_command(
    source: Annotated[Path, typer.Argument(help=".urdf or .xacro file (xacro is expanded without ROS)")],
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="the robot folder to write, e.g. robots/irb2400")],
    packages: Annotated[list[Path] | None, typer.Option("--packages", metavar="DIR",
                        help="a ROS package folder or a folder holding packages (repeatable)")] = None,
    flange: Annotated[str, typer.Option("--flange", help="URDF frame the tool mounts on")] = "tool0",
    srdf: Annotated[Path | None, typer.Option("--srdf", help="MoveIt SRDF whose disable_collisions are kept")] = None,
    solver: Annotated[str | None, typer.Option("--solver", help="opw | ur | numeric (default: the first that fits)")] = None,
    brand: Annotated[str | None, typer.Option("--brand", help="kuka | abb | fanuc | ur | yaskawa | kawasaki | staubli | comau | nachi (default: guessed from the name)")] = None,
    name: Annotated[str | None, typer.Option("--name", help="robot name (default: the folder name)")] = None,
    force: Annotated[bool, typer.Option("--force", help="replace a folder that exists with other content")] = False,
    xacro_cpu_s: Annotated[float | None, typer.Option("--xacro-cpu-s", min=1, help="CPU seconds the xacro "
                                                      "expansion may take (default 30)")] = None,
    xacro_mb: Annotated[int | None, typer.Option("--xacro-mb", min=64, help="memory (MB) the xacro expansion may "
                                                 "use (default 1024)")] = None,
    xacro_arg: Annotated[list[str] | None, typer.Option("--xacro-arg", metavar="NAME:=VALUE",
                         help="a xacro argument (repeatable); unset ones take the value the package's "
                              "launch/load_<robot>.launch passes, else the file's default")] = None,
    as_json: JsonFlag = False,
) -> None:
    """Make a self-contained robot folder from a URDF or xacro: meshes copied, IK fitted and checked.

    The package is read as untrusted data: only files below --packages folders and the source's
    folder, xacro expanded without running Python, in a process bounded in CPU time and memory."""

    def run() -> None:
        import dataclasses

        from robomax_py.app.import_urdf import import_urdf
        from robomax_py.errors import RobotModelError

        if solver not in (None, "opw", "ur", "numeric"):
            raise RobotModelError(None, "--solver", f"expected opw, ur or numeric, got {solver!r}")
        from robomax_py.spec import BRANDS

        if brand is not None and brand not in BRANDS:
            raise RobotModelError(None, "--brand", f"expected one of {', '.join(BRANDS)}, got {brand!r}")
        from robomax_py.safe_files import LIMITS, MB

        limits = dataclasses.replace(LIMITS, xacro_cpu_s=xacro_cpu_s or LIMITS.xacro_cpu_s,
                                     xacro_memory=LIMITS.xacro_memory if xacro_mb is None else xacro_mb * MB)
        xacro_args: dict[str, str] = {}
        for given in xacro_arg or ():
            arg_name, sep, value = given.partition(":=")
            if not sep or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", arg_name):
                raise RobotModelError(None, "--xacro-arg", f"expected NAME:=VALUE, got {given!r}")
            xacro_args[arg_name] = value
        r = import_urdf(source, out_dir, packages or (), name=name, flange=flange, srdf=srdf, solver=solver,
                        brand=brand, force=force, limits=limits, xacro_args=xacro_args)
        _warn(r.warnings)
        if as_json:
            _print_json("import-urdf", True, {
                "folder": str(r.folder), "name": r.name, "solver": r.solver, "fk_error_m": float(r.fk_error_m),
                "brand": r.brand, "meshes": r.meshes, "disabled_pairs": r.disabled_pairs,
                "seconds": round(r.seconds, 3), "unchanged": r.unchanged, "warnings": list(r.warnings)})
            return
        what = "unchanged" if r.unchanged else "wrote"
        out.print(f"{what} {r.folder}: robot {r.name}, IK {r.solver} (FK agrees with the URDF within "
                  f"{r.fk_error_m:.1e} m), controller {r.brand}, {r.meshes} meshes, {r.disabled_pairs} disabled "
                  f"pairs from the SRDF ({r.seconds:.1f} s)")

    _guarded(run, "import-urdf" if as_json else None)


@_command("import-spots")
def import_spots_command(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML); it may have no seams yet")],
    spots: Annotated[Path, typer.Argument(help="CSV spot list: id, x, y, z, optional normal, group, weld time, schedule")],
    part: Annotated[str, typer.Option("--part", help="the object whose frame the list's coordinates are in")],
    out_file: Annotated[Path, typer.Option("-o", "--out", help="the new cell file, beside CELL")],
    units: Annotated[str | None, typer.Option("--units", help="m | mm, of the list's coordinates (default: m, "
                                                              "with a warning when they look like mm)")] = None,
    tolerance_mm: Annotated[float, typer.Option("--tolerance", min=0.001, max=1000,
                                                help="mm a spot may lie off the part's surface")] = 2.0,
    force: Annotated[bool, typer.Option("--force", help="replace the -o file if it exists")] = False,
    frame: Annotated[str | None, typer.Option("--frame", help="the frame the list's coordinates are in, when not "
                                                              "the part's: a frame of the cell, an object or world")] = None,
    as_json: JsonFlag = False,
) -> None:
    """Write a new cell with a spot list's spots added as seams (docs/spot-lists.md).

    Missing normals come from the part's surface, missing directions from the seam's course; without
    a group column, seams are formed from the part's geometry and listed on stderr to check."""

    def run() -> None:
        from robomax_py.app.import_spots import import_spots
        from robomax_py.errors import CellFileError

        if units not in (None, "m", "mm"):
            raise CellFileError(None, "--units", f"expected m or mm, got {units!r}")
        r = import_spots(cell, spots, part, out_file, units, tolerance_mm / 1000, force, frame)
        _warn([*r.warnings, *r.sides])
        for line in r.formed:
            err.print(line, markup=False, highlight=False, soft_wrap=True)
        if as_json:
            _print_json("import-spots", True, {
                "cell": str(r.cell), "seams": [{"name": n, "spots": k} for n, k in r.seams],
                "recovered_normals": r.recovered_normals, "recovered_directions": r.recovered_directions,
                "ambiguous": list(r.sides), "warnings": list(r.warnings), "cpu_s": round(r.cpu_s, 3)})
            return
        count = sum(k for _, k in r.seams)
        out.print(f"wrote {r.cell}: {count} spots in {len(r.seams)} seams, {r.recovered_normals} normals from the "
                  f"part's surface, {r.recovered_directions} directions from the seams' course ({r.cpu_s:.2f} s CPU)",
                  markup=False)

    _guarded(run, "import-spots" if as_json else None)


@_command()
def examples(
    folder: Annotated[Path, typer.Argument(help="folder to copy the example cells into (made if missing)")],
    force: Annotated[bool, typer.Option("--force", help="replace files there that hold something else")] = False,
    as_json: JsonFlag = False,
) -> None:
    """Copy the example cells shipped with the package (and the part meshes they name) into a folder."""

    def run() -> None:
        from robomax_py.app.examples import copy_examples

        done = copy_examples(folder, force=force)
        if as_json:
            _print_json("examples", True, {"folder": str(folder), "written": [str(p) for p in done.written],
                                           "unchanged": [str(p) for p in done.unchanged]})
            return
        cells = sorted(p.name for p in (*done.written, *done.unchanged) if p.suffix == ".yaml")
        same = f", {len(done.unchanged)} already there" if done.unchanged else ""
        out.print(f"wrote {len(done.written)} file(s) to {folder}{same}: {', '.join(cells)}", soft_wrap=True)
        if cells:
            out.print(f"try: robomax check {folder / cells[0]}", soft_wrap=True)

    _guarded(run, "examples" if as_json else None)


RAY_LOCAL = "local"


def _bare_ray_flag(argv: list[str]) -> list[str]:
    """`batch ... --ray` without an address (last, or before an option or a cell file) -> `--ray=local`.

    typer has no options with an optional value, so the console entry point spells the default out.
    """
    if "batch" not in argv:
        return argv
    args = list(argv)
    for k, arg in enumerate(args):
        nxt = args[k + 1] if k + 1 < len(args) else None
        if arg == "--ray" and (nxt is None or nxt.startswith("-") or nxt.endswith((".yaml", ".yml"))):
            args[k] = f"--ray={RAY_LOCAL}"
    return args


def _library_flags_first(argv: list[str]) -> list[str]:
    """`--robots DIR` anywhere -> in front of the command name, where the app callback reads it."""
    front: list[str] = []
    rest: list[str] = []
    k = 0
    while k < len(argv):
        arg = argv[k]
        if arg == "--robots" and k + 1 < len(argv):
            front += [arg, argv[k + 1]]
            k += 2
            continue
        if arg.startswith("--robots="):
            front.append(arg)
        else:
            rest.append(arg)
        k += 1
    return front + rest


class _Received:
    """The termination signal this process received (SIGINT or SIGTERM), for `_honour_signals`.
    Process state by nature: a signal handler has nowhere else to leave it."""

    signum: int | None = None


def _on_signal(signum: int, frame: object) -> None:
    # SIGTERM unwinds like Ctrl-C (KeyboardInterrupt, which the preview ends on), so a write in
    # progress removes its temporary files; the signal is also kept for `_honour_signals`, since a
    # dependency that catches BaseException (trimesh, on import and in some mesh functions) can
    # swallow the exception.
    _Received.signum = signum
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise SystemExit(128 + signum)


def _honour_signals() -> None:
    """End the run as an earlier SIGINT or SIGTERM asked, if its exception was swallowed: called
    between stages and before anything is written."""
    if _Received.signum == signal.SIGINT:
        raise KeyboardInterrupt
    if _Received.signum is not None:
        raise SystemExit(128 + _Received.signum)


def _unraisable(default: Callable[[Any], object]) -> Callable[[Any], None]:
    """sys.unraisablehook that keeps quiet about the interrupt raised where Python cannot pass it
    on (a finaliser, a weakref callback: it prints "Exception ignored" and a traceback, and the run
    goes on); `_honour_signals` ends the run at the next stage."""

    def hook(unraisable: Any) -> None:         # sys.UnraisableHookArgs
        if _Received.signum is not None and isinstance(getattr(unraisable, "exc_value", None),
                                                       (SystemExit, KeyboardInterrupt)):
            return
        default(unraisable)

    return hook


def main(restore_mask: Iterable[int] | None = None) -> None:
    """Console entry point. `restore_mask`: the signal mask to set once the handlers are installed
    (`python -m robomax_py` holds SIGINT and SIGTERM while it imports the command)."""
    signal.signal(signal.SIGTERM, _on_signal)
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:            # not when started ignoring it (nohup, &)
        signal.signal(signal.SIGINT, _on_signal)
    sys.unraisablehook = _unraisable(sys.unraisablehook)
    try:
        if restore_mask is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, restore_mask)     # a held signal is delivered here
        app(args=_bare_ray_flag(_library_flags_first(sys.argv[1:])))
    except KeyboardInterrupt:
        err.print("interrupted")
        sys.exit(130)
    except Exception:
        if _Received.signum is None:
            raise
        # The signal's exception raised inside compiled code comes out as another error: numba's
        # dispatcher reports a KeyboardInterrupt raised while its kernel ran as "SystemError: ...
        # returned a result with an exception set". The run ends as the signal asked all the same.
        err.print("interrupted" if _Received.signum == signal.SIGINT else "terminated")
        sys.exit(128 + _Received.signum)
    except SystemExit as exc:
        if _Received.signum == signal.SIGTERM and exc.code == 128 + signal.SIGTERM:
            err.print("terminated")
        raise


if __name__ == "__main__":
    main()
