"""`robomax import-urdf`: a robot folder made from a URDF or xacro."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated

import typer

from robomax_py.app.commands.base import (
    JsonFlag,
    _command,
    _guarded,
    _print_json,
    _warn,
    out,
)


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
                "seconds": round(r.seconds, 3), "unchanged": r.unchanged, "warnings": list(r.warnings),
                "always_touching": {"pairs": [list(p) for p in r.always_touching.pairs],
                                    "samples": r.always_touching.samples}})
            return
        what = "unchanged" if r.unchanged else "wrote"
        pairs_from = (f"{r.disabled_pairs} disabled pairs from the SRDF" if srdf is not None
                      else "no SRDF given (--srdf keeps a MoveIt config's disabled pairs)")
        out.print(f"{what} {r.folder}: robot {r.name}, IK {r.solver} (FK agrees with the URDF within "
                  f"{r.fk_error_m:.1e} m), controller {r.brand}, {r.meshes} meshes, {pairs_from} "
                  f"({r.seconds:.1f} s)", markup=False, highlight=False, soft_wrap=True)
        if r.always_touching.pairs:
            pairs = ", ".join(f"[{a}, {b}]" for a, b in r.always_touching.pairs)
            out.print(f"collision.disable: {pairs} touch in every one of {r.always_touching.samples} sampled "
                      f"postures, so they are not checked (as MoveIt's Setup Assistant disables \"Always\" pairs); "
                      f"review them in {r.folder / 'robot.yaml'} and remove a pair that must stay checked",
                      markup=False, highlight=False, soft_wrap=True)

    _guarded(run, "import-urdf" if as_json else None)
