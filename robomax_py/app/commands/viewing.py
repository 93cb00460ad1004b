"""`robomax preview`: the cell in meshcat, served or written as one HTML page."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Annotated

import typer

from robomax_py.app.commands.base import (
    _command,
    _guarded,
    _print_json,
    _warn,
    err,
    out,
)


def _preview_station(station: Path, programs: Path | None, html: Path | None, as_json: bool,
                     announce: Callable[[str], None], host: str, port: int | None) -> None:
    """A station's robots on the clock of their replay (`app.preview_station`): one HTML page, or
    served until Ctrl-C."""
    from robomax_py.app.preview_station import (
        serve_station,
        shown_station,
        write_station_html,
    )
    from robomax_py.errors import ProgramError

    if programs is None:
        raise ProgramError(station, None, "a station's preview needs its output folder (or a program of it)")
    robots, zones = shown_station(station, programs)
    if html is None:
        serve_station(robots, zones, announce, host=host, port=port)
        (err if as_json else out).print("preview stopped")
        return
    content = write_station_html(html, robots, zones)
    if as_json:
        _print_json("preview", True, {"cell": str(station), "program": str(programs), "url": None, "files": [str(html)],
                                      "frames": content.frames, "duration": round(content.duration, 4),
                                      "robots": [r.name for r in robots], "zones": len(zones)})
        return
    out.print(f"wrote {html} ({len(robots)} robots, {len(zones)} interlock zones, {content.frames} animation frames, "
              f"{content.duration:.3f} s)")


@_command()
def preview(
    cell: Annotated[Path, typer.Argument(help="cell file (YAML)")],
    program: Annotated[Path | None, typer.Argument(help="program written by plan (.json, .srcl or a controller program: .src, .mod, .ls, .script ...); without it the robot stands at home; for a station, its output folder (with --html)")] = None,
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
        from robomax_py.io.station import is_station_file

        shown_files = {"cell": str(cell), "program": None if program is None else str(program)}

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

        if is_station_file(cell):
            _preview_station(cell, program, html, as_json, announce, host, port)
            return
        spec = load_cell(cell)
        _warn([str(n) for n in spec.notices])   # what is probably a mistake shows in the scene too
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

        serve(spec, robot, shown, announce, voxels=vmap, host=host, port=port)
        (err if as_json else out).print("preview stopped")

    _guarded(run, "preview" if as_json else None)
