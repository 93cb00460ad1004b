"""`robomax replan`: a running program's continuation after the cell changed."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robomax_py.app.commands.base import (
    EXIT_INFEASIBLE,
    EXIT_OK,
    EXIT_VIOLATIONS,
    JsonFlag,
    _command,
    _compile_ahead,
    _guarded,
    _honour_signals,
    _print_json,
    _warn,
    err,
    out,
    output_folder,
)
from robomax_py.errors import CellFileError, RobotModelError
from robomax_py.io.files import signals_held

EVENT_HELP = ("what changed (repeatable; times in s from the program's start, m, deg): "
              "window:NAME=A-B[,C-D...] (a door's closed windows, or a dynamic object's), window:NAME=none, "
              "late:NAME=S (its next opening S s late; NAME a machine or its door), remove:NAME, "
              "appear:NAME box=X,Y,Z|sphere=R|cylinder=R,L xyz=X,Y,Z [rpy=R,P,Y] [from=T1] [until=T2]")


@_command()
def replan(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    program: Annotated[Path, typer.Argument(help="the program running: its trajectory file (.json) or a program of any dialect robomax writes")],
    at: Annotated[float, typer.Option("--at", min=0.0, max=86_400.0, help="when the change is known, s from the program's start")],
    events: Annotated[list[str], typer.Option("--event", help=EVENT_HELP)],
    out_dir: Annotated[Path, typer.Option("-o", "--out", help="output folder", callback=output_folder)] = Path("programs"),
    formats: Annotated[str, typer.Option("--format", help="program dialects, comma-separated (as `robomax plan --format`)")] = "srcl",
    as_json: JsonFlag = False,
) -> None:
    """Plan the rest of a running program after its cell changed: the robot stops on its planned
    path (an action in progress completed), and the work left is planned from there with the
    events applied; writes DIR/<name>_from_<T>.* (only when planned and proven), among them
    <name>_from_<T>.cell.yaml, the cell the continuation runs in: verify its programs against it."""

    def run() -> int:
        with signals_held():
            compiling = _compile_ahead()         # side by side with the imports and the files' reading
            from robomax_py.app.replan import continuation_file, summary
            from robomax_py.app.replan import replan as replan_program
            from robomax_py.export import SHARED_FILES, choose_formats, setup_signals
            from robomax_py.io.cell import cell_from_mapping, load_cell, load_cell_robot
            from robomax_py.io.files import commit_set
            from robomax_py.io.plan_set_check import CELL_FILE_SUFFIX
            from robomax_py.publish import publish
            from robomax_py.verify import verify_program
        _honour_signals()
        from robomax_py.io.station import is_station_file

        if is_station_file(cell):
            # A station's robots wait on each other's signals: one robot's rest planned alone would
            # leave the others' interlocks waiting for it, so a station is planned again whole.
            raise CellFileError(cell, "robots", "a station file: replan takes one robot's cell; plan the station "
                                "again with `robomax plan` after the change")
        spec = load_cell(cell)
        _warn([str(n) for n in spec.notices])
        robot = load_cell_robot(spec)
        chosen = choose_formats(formats, robot, setup_signals(spec.controller), spec.source)
        _warn([s.message for s in chosen.skipped])
        compiling.wait(_honour_signals)
        outcome = replan_program(spec, robot, program, at, tuple(events))
        _honour_signals()
        report = summary(outcome)
        written: list[str] = []
        if outcome.status == "planned":
            assert outcome.result is not None and outcome.cell is not None
            texts, _ = publish(outcome.result, outcome.cell, robot, chosen.names)   # all proven before any write
            files, digest = dict(texts), spec.digest
            # The cell the continuation runs in, as a file beside its programs (one set with them),
            # so that `robomax verify` checks them against it: it must load from there first.
            cell_file = out_dir / f"{outcome.name}{CELL_FILE_SUFFIX}"
            written_cell = continuation_file(cell, out_dir, spec, robot, outcome)
            if written_cell.text is not None:
                import hashlib

                import yaml

                out_dir.mkdir(parents=True, exist_ok=True)      # its relative paths resolve from there
                try:
                    cell_from_mapping(yaml.safe_load(written_cell.text), out_dir)
                except (CellFileError, RobotModelError) as exc:  # named as the file it would be
                    raise type(exc)(cell_file, exc.key, exc.problem) from None
                files[cell_file.name] = written_cell.text
                digest = hashlib.sha256(written_cell.text.encode("utf-8")).hexdigest()   # as load_cell takes it
            _honour_signals()
            committed = commit_set(out_dir, outcome.name, files, digest, SHARED_FILES)
            written = [str(p) for p in (*committed.paths, committed.manifest)]
            against = load_cell(cell_file) if written_cell.text is not None else outcome.cell
            check = verify_program(against, robot, out_dir / f"{outcome.name}.json")
            report["verify"] = {"clean": check.clean, "violations": [f"{v.kind}: {v.detail}" for v in check.violations],
                                "cell": str(cell_file) if written_cell.text is not None else None}
            if written_cell.text is None:
                report["verify"]["no_cell_file"] = written_cell.reason
        report["written"] = written
        if as_json:
            _print_json("replan", outcome.status == "planned", report)
        else:
            s = outcome.stop
            for e in outcome.events:
                out.print(f"event: {e.text}", markup=False)
            out.print(f"stop: asked at {s.t_request:.3f} s, at rest at {s.t_stop:.3f} s ({s.how}; on the planned "
                      f"path at its t = {s.t_path:.3f} s)", markup=False)
            out.print(f"done: {len(s.done)}; left: {len(outcome.left)} ({', '.join(outcome.left)})", markup=False,
                      soft_wrap=True)
            new = "—" if outcome.new_finish is None else f"{outcome.new_finish:.3f} s"
            out.print(f"finish: {new} (planned: {outcome.old_finish:.3f} s); replanning {outcome.seconds:.1f} s CPU",
                      markup=False)
            if outcome.as_it_stands is not None:
                clean, finish, first = outcome.as_it_stands
                out.print(f"the program as it stands (its waits holding for the changed doors): finish {finish:.3f} s, "
                          + ("clean in the changed cell" + (": it finishes no later, it may run on as it is"
                                                            if outcome.new_finish is not None
                                                            and finish <= outcome.new_finish else "")
                             if clean else f"not safe in the changed cell ({first})"), markup=False, soft_wrap=True)
            for path in written:
                out.print(f"wrote {path}", markup=False)
            if "verify" in report:
                v = report["verify"]
                said = (f"against {v['cell']}, the cell it runs in" if v["cell"] else
                        f"against the changed cell, from the stop; no cell file written: {v['no_cell_file']}")
                out.print(f"verify: clean ({said})" if v["clean"] else f"verify ({said}): {v['violations']}",
                          markup=False, soft_wrap=True)
        if outcome.status != "planned":
            from rich.markup import escape

            err.print(f"[bold red]infeasible:[/] {escape(outcome.message)} (nothing was written)", soft_wrap=True)
            return EXIT_INFEASIBLE
        return EXIT_OK if report["verify"]["clean"] else EXIT_VIOLATIONS

    code = _guarded(run, "replan" if as_json else None)
    raise typer.Exit(code)
