"""`robomax robots` and `robomax check`: the robot library and a cell, looked at before planning."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from robomax_py.app.commands.base import (
    JsonFlag,
    _command,
    _guarded,
    _print_json,
    _warn,
    out,
)


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
        from robomax_py.io.station import is_station_file
        from robomax_py.plan.candidates import check_ik_work
        from robomax_py.plan.pipeline import home_collision
        from robomax_py.plan.reach import (
            always_touching_text,
            reach_report,
            self_contacts,
        )

        if is_station_file(cell):
            _check_station(cell, as_json)
            return
        spec = load_cell(cell)
        tree, included = read_cell_frames(cell)
        _warn([str(n) for n in spec.notices])   # probable mistakes: warnings, the cell is still valid
        robot = load_cell_robot(spec)
        _warn(robot.warnings)
        check_ik_work(spec, robot)             # what `plan` refuses before it plans
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
        # Where the robot cannot stand at home no program can start: `plan` refuses the cell; told here.
        home_blocked = home_collision(spec, robot)
        _warn([f"{home_blocked}; `plan` refuses this cell"] if home_blocked is not None else [])
        at_home, always = self_contacts(robot, spec.home)
        _warn([f"{robot.name}: links {a} and {b} touch at home; if they touch by design, add "
               f"[{a}, {b}] to collision.disable in {robot.source}" for a, b in at_home])
        _warn([f"{robot.name}: {always_touching_text(robot, a, b)} (or give its SRDF as srdf:)" for a, b in always])
        if as_json:
            _print_json("check", True, {
                "cell": str(cell), "name": spec.name, "robot": robot.name, "tool": spec.tool.name,
                "seams": [{"name": seam.name, "spots": len(seam.spots), "ordered": seam.ordered} for seam in spec.seams],
                "objects": [obj.name for obj in (*spec.objects, *spec.dynamic)],
                "reach": None if tight is None else {
                    stop + "s": len(reach), "least_margin_m": round(-tight.out_by_m, 6), "at": f"{tight.seam}/{tight.name}"},
                "home_collision": home_blocked,
                "self_contacts_at_home": [list(p) for p in at_home],
                "self_contacts_always": [list(p) for p in always],
                "frames": [node.as_dict() for node in tree], "includes": [str(file) for file in included]})
            return
        out.print(f"[green]ok[/]: {cell} is a valid cell")

    _guarded(run, "check" if as_json else None)


def _check_station(path: Path, as_json: bool) -> None:
    """`robomax check` of a station file: each robot read as its cell, its reach of the spots it may weld."""
    from robomax_py.errors import CellFileError
    from robomax_py.io.cell import load_cell_robot
    from robomax_py.io.station import load_station
    from robomax_py.plan.pipeline import home_collision
    from robomax_py.plan.reach import reach_report
    from robomax_py.station.homes import homes_touching
    from robomax_py.world.scene import build_scene

    station = load_station(path)
    _warn([str(n) for n in station.notices])
    rows = []
    reachable: dict[tuple[str, str], list[str]] = {}
    models = {}
    for r in station.robots:
        robot = models[r.name] = load_cell_robot(r.cell)
        _warn([f"{r.name}: {w}" for w in robot.warnings])
        allowed = set(station.allowed(r.name))
        reach = [x for x in reach_report(r.cell, robot) if (x.seam, x.name) in allowed]
        for x in reach:
            if x.reachable:
                reachable.setdefault((x.seam, x.name), []).append(r.name)
        rows.append({"name": r.name, "model": r.cell.robot.name, "tool": r.cell.tool.name,
                     "brand": r.cell.robot.controller.brand, "may_weld": len(allowed),
                     "within_reach": sum(x.reachable for x in reach),
                     "interlock_inputs": [r.interlock_inputs.first, r.interlock_inputs.last],
                     "interlock_outputs": [r.interlock_outputs.first, r.interlock_outputs.last]})
    orphan = [s for s in station.spots if s.key not in reachable]
    if orphan:
        more = f" ({len(orphan) - 1} more spot(s) out of every robot's reach)" if len(orphan) > 1 else ""
        raise CellFileError(path, "seams", f"spot {orphan[0].seam}/{orphan[0].spot} is out of the reach of every robot "
                            f"that may weld it ({', '.join(orphan[0].robots)}){more}")
    # A robot that cannot stand at home, or robots that touch there: `plan` refuses the station (no
    # program can start); told here first.
    blocked = {r.name: text for r in station.robots if (text := home_collision(r.cell, models[r.name])) is not None}
    _warn([f"{name}: {text}; `plan` refuses this station" for name, text in blocked.items()])
    touching = homes_touching(station, models, {r.name: build_scene(r.cell, models[r.name]) for r in station.robots})
    _warn([f"{touching.message()}; `plan` refuses this station"] if touching is not None else [])
    if as_json:
        _print_json("check", True, {"cell": str(path), "name": station.name, "station": True, "robots": rows,
                                    "spots": len(station.spots),
                                    "home_collisions": blocked,
                                    "homes_touching": None if touching is None else touching.message()})
        return
    out.print(f"station {station.name}: {len(station.robots)} robots, {len(station.spots)} spots", markup=False,
              highlight=False)
    for row in rows:
        out.print(f"  {row['name']}: {row['model']} with {row['tool']} ({row['brand']}), may weld {row['may_weld']} "
                  f"spots, {row['within_reach']} within reach; interlock inputs {row['interlock_inputs']}, outputs "
                  f"{row['interlock_outputs']}", markup=False, highlight=False, soft_wrap=True)
    out.print(f"[green]ok[/]: {path} is a valid station")
