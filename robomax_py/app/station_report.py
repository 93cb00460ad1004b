"""`robomax verify STATION ...`: the station replay's report as text or JSON, its exit code, and
the Gantt chart of the replay written beside the programs when asked (`--chart`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from robomax_py.app.commands.base import EXIT_OK, EXIT_VIOLATIONS, _print_json, out
from robomax_py.verify_station import StationReport


def station_payload(name: str, programs: dict[str, Path], report: StationReport) -> dict[str, Any]:
    """The report as plain data (`--json`)."""
    return {
        "station": name, "programs": {r: str(p) for r, p in programs.items()}, "clean": report.clean,
        "makespan": round(report.makespan, 4), "samples": report.samples, "deadlock": report.deadlock,
        "collisions": [{"robots": [c.robot_a, c.robot_b], "t": round(c.t_start, 4), "t_end": round(c.t_end, 4),
                        "pieces": [c.piece_a, c.piece_b]} for c in report.collisions],
        "waits_forever": [{"robot": s.robot, "signal": s.signal, "t": round(s.t, 4), "set_by": list(s.setters)}
                          for s in report.stuck],
        "unwelded": [f"{a}/{b}" for a, b in report.unwelded], "welded_twice": [f"{a}/{b}" for a, b in report.repeated],
        "robots": [{"name": m.name, "end": None if m.end is None else round(m.end, 4),
                    "idle_share": round(report.idle_share(m.name), 4), "clean": m.report.clean,
                    "violations": [{"kind": v.kind, "line": v.line, "t": v.t, "detail": v.detail}
                                   for v in m.report.violations],
                    "timeline": [{"kind": a.kind, "t": round(a.t_start, 4), "t_end": round(a.t_end, 4),
                                  "signal": a.signal, "of": a.other, "forever": a.forever} for a in m.timeline]}
                   for m in report.members],
    }


def print_station_verify(station_file: Path, given: list[Path], as_json: bool, chart: bool = False) -> int:
    """Verify every program set of the station found or named; exit 0 when all are clean, else 1."""
    from robomax_py.app.station_verify import verify_station_files
    from robomax_py.io.station import load_station

    results = [(programs, report) for programs, _, report in verify_station_files(station_file, given)]
    name = load_station(station_file).name
    clean = all(r.clean for _, r in results)
    if chart:
        _write_charts(name, results)
    if as_json:
        _print_json("verify", clean, {"station": name, "clean": clean,
                                      "sets": [station_payload(name, p, r) for p, r in results]})
        return EXIT_OK if clean else EXIT_VIOLATIONS
    for programs, report in results:
        _print_set(programs, report)
    return EXIT_OK if clean else EXIT_VIOLATIONS


def _print_set(programs: dict[str, Path], report: StationReport) -> None:
    out.print(f"{', '.join(p.name for p in programs.values())}: makespan {report.makespan:.3f} s, "
              f"{report.samples} station samples")
    for m in report.members:
        end = "waits forever" if m.end is None else f"ends {m.end:.3f} s"
        out.print(f"  {m.name}: {end}, idle {100 * report.idle_share(m.name):.1f} %, "
                  f"{len(m.report.violations)} violation(s) of its own")
        for v in m.report.violations:
            where = f"line {v.line}, " if v.line is not None else ""
            when = "" if v.t is None else f"t = {v.t:.3f} s"
            out.print(f"    [red]{v.kind}[/]: {(where + when).rstrip(', ')}: {v.detail}", soft_wrap=True)
    for c in report.collisions:
        out.print(f"  [red]collision[/]: {c.robot_a} and {c.robot_b} touch at t = {c.t_start:.3f}-{c.t_end:.3f} s "
                  f"({c.piece_a} / {c.piece_b})")
    if report.deadlock:
        held = ", ".join(f"{s.robot} waits for {s.signal}" for s in report.stuck if s.setters)
        out.print(f"  [red]deadlock[/]: {held}: each is set only by a robot that waits itself")
    for s in report.stuck:
        if not s.setters:
            out.print(f"  [red]waits forever[/]: {s.robot} waits for {s.signal} from t = {s.t:.3f} s; no robot sets it")
    for seam, spot in report.unwelded:
        out.print(f"  [red]spot[/]: {seam}/{spot} is welded by no robot")
    for seam, spot in report.repeated:
        out.print(f"  [red]spot[/]: {seam}/{spot} is welded by more than one robot")
    if report.clean:
        out.print("[green]clean[/]: no robot touches another, every program ends, each is clean alone")
    else:
        out.print("[red]violations[/]")


def replay_charts(station_file: Path, folder: Path) -> tuple[bool, list[Path]]:
    """The programs `plan` just wrote into `folder` replayed together as the controllers run them
    (`plan STATION --plot`): whether every set is clean, and the Gantt charts written of them."""
    from robomax_py.app.station_verify import verify_station_files
    from robomax_py.io.station import load_station

    results = [(programs, report) for programs, _, report in verify_station_files(station_file, [folder])]
    return all(r.clean for _, r in results), _write_charts(load_station(station_file).name, results)


def _write_charts(name: str, results: list[tuple[dict[str, Path], StationReport]]) -> list[Path]:
    """`<station>.gantt.png` (one per dialect set after the first: `<station>.<ext>.gantt.png`) beside the programs."""
    from robomax_py.app.station_chart import render_station_png, station_chart
    from robomax_py.io.atomic import write_atomic_bytes

    written = []
    for k, (programs, report) in enumerate(results):
        first = next(iter(programs.values()))
        stem = name if k == 0 else f"{name}.{first.suffix.lstrip('.')}"
        path = first.parent / f"{stem}.gantt.png"
        write_atomic_bytes(path, render_station_png(station_chart(name, report)))
        written.append(path)
    return written
