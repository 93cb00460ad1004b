"""`robomax plan STATION`: every robot's programs, trajectory files and the station's summary,
written as one set, only when every robot is planned, the robots are coordinated and every program
is proven."""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

from robomax_py.app.commands.base import (
    EXIT_INFEASIBLE,
    EXIT_OK,
    EXIT_VIOLATIONS,
    _print_json,
    _warn,
    err,
    out,
)


def plan_station_files(path: Path, out_dir: Path, formats: str, speed: float | None, as_json: bool,
                       stamp: str, plot: bool = False) -> int:
    from robomax_py.app.station_files import (
        allocate,
        interlock_edit,
        station_block,
        station_signals,
        station_summary,
        with_interlock_io,
        with_station_block,
    )
    from robomax_py.export import SHARED_FILES, choose_formats, render_trajectory
    from robomax_py.io.cell import load_cell_robot
    from robomax_py.io.files import commit_set
    from robomax_py.io.station import load_station
    from robomax_py.plan import PlanOptions
    from robomax_py.publish import publish
    from robomax_py.station.pipeline import StationOptions, plan_station

    t0 = time.process_time()
    station = load_station(path)
    _warn([str(n) for n in station.notices])
    models = {r.name: load_cell_robot(r.cell) for r in station.robots}
    chosen = {r.name: choose_formats(formats, models[r.name], station_signals(i, r), station.source)
              for i, r in enumerate(station.robots)}
    _warn([f"{name}: {s.message}" for name, c in chosen.items() for s in c.skipped])
    plan = plan_station(station, models, StationOptions(plan=PlanOptions(speed=speed)))
    if plan.status != "planned" or plan.coordination is None:
        if as_json:
            _print_json("plan", False, {"station": station.name, "status": plan.status, "message": plan.message})
        from rich.markup import escape

        err.print(f"[bold red]infeasible:[/] {escape(plan.message)}", soft_wrap=True)
        return EXIT_INFEASIBLE
    interlocks = allocate(station, plan.coordination.interlocks)
    signals = frozenset(x.signal for x in interlocks)
    files: dict[str, str | bytes] = {}
    for p in plan.robots:
        if p.result is None or p.result.trajectory is None:
            continue                         # a robot with nothing to weld stays home: no program
        setup = with_interlock_io(p.cell.controller, p.robot, interlocks)
        result = dataclasses.replace(p.result, controller=setup)
        cell = dataclasses.replace(p.cell, controller=setup)
        texts, _ = publish(result, cell, p.model, chosen[p.robot].names, stamp=stamp,
                           edit=interlock_edit(p.robot, result, interlocks), station=signals)
        json_name = f"{result.cell}.json"
        texts[json_name] = with_station_block(render_trajectory(result), station_block(plan, p.robot))
        files.update(texts)
    files[f"{station.name}.station.json"] = station_summary(plan, interlocks)
    committed = commit_set(out_dir, station.name, files, station.digest, SHARED_FILES)
    cpu = time.process_time() - t0
    # --plot: the written programs replayed together as the controllers run them (as `verify
    # STATION DIR` does), each set's Gantt chart beside them; a replay that is not clean fails the
    # command, never a chart of a station that would not run as planned.
    replay_clean, charts = True, list[Path]()
    if plot:
        from robomax_py.app.station_report import replay_charts

        replay_clean, charts = replay_charts(path, out_dir)
    code = EXIT_OK if replay_clean else EXIT_VIOLATIONS
    schedule = plan.coordination.schedule
    gap = (plan.makespan - plan.bound.value) / plan.makespan if plan.makespan > 0 else 0.0
    if as_json:
        _print_json("plan", True, {"station": station.name, "makespan": round(plan.makespan, 4),
                                   "lower_bound": round(plan.bound.value, 4), "gap": round(gap, 4),
                                   "interlocks": len(interlocks), "cpu_s": round(cpu, 2),
                                   "files": [str(f) for f in (*committed.paths, committed.manifest)],
                                   "skipped_formats": [{"robot": name, "format": k.format, "robot_file": k.robot_file,
                                                        "key": k.key, "why": k.why, "message": k.message}
                                                       for name, c in chosen.items() for k in c.skipped],
                                   **({"replay_clean": replay_clean, "charts": [str(c) for c in charts]}
                                      if plot else {})})
        return code
    out.print(f"station {station.name}: makespan {plan.makespan:.3f} s, lower bound {plan.bound.value:.3f} s "
              f"(gap {gap:.1%}), {len(interlocks)} interlock(s), {cpu:.1f} s CPU", markup=False, highlight=False)
    for p in plan.robots:
        n = 0 if p.result is None else len(p.result.spots)
        out.print(f"  {p.robot}: {n} spots, own cycle {p.own_cycle:.3f} s, waits {schedule.waited(p.robot):.3f} s, "
                  f"done at {schedule.ends[p.robot]:.3f} s", markup=False, highlight=False)
    for x in interlocks:
        out.print(f"  {x.zone}: {x.leader} first (output {x.output} {x.signal}), {x.waiter} waits (input {x.input})",
                  markup=False, highlight=False)
    for f in (*committed.paths, committed.manifest):
        out.print(f"  wrote {f}", markup=False, highlight=False, soft_wrap=True)
    for c in charts:
        out.print(f"  wrote {c} (the programs replayed together)", markup=False, highlight=False, soft_wrap=True)
    if not replay_clean:
        err.print(f"[bold red]violations:[/] the programs replayed together are not clean: robomax verify {path} {out_dir}",
                  soft_wrap=True)
    return code
