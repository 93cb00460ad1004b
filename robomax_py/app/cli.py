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

import gc
import importlib._bootstrap
import importlib._bootstrap_external
import os
import signal
import sys
from collections.abc import Callable, Iterable
from pathlib import Path
from types import FrameType
from typing import Annotated, Any, NoReturn

import typer

# Importing the commands package registers every command on `app`, in the order the help lists them.
import robomax_py.app.commands  # noqa: F401
from robomax_py.app.commands.base import (
    EPILOG,
    EXIT_BAD_INPUT,
    EXIT_CODES,
    EXIT_INFEASIBLE,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_TERMINATED,
    EXIT_VIOLATIONS,
    JSON_VERSION,
    RAY_LOCAL,
    JsonFlag,
    _command,
    _guarded,
    _print_json,
    _Process,
    _Received,
    _warn,
    app,
    err,
    json_schema,
    out,
)

# What the app and tests take from here: the command's conventions live in commands.base.
__all__ = ["EPILOG", "EXIT_BAD_INPUT", "EXIT_CODES", "EXIT_INFEASIBLE", "EXIT_INTERNAL", "EXIT_INTERRUPTED", "EXIT_OK",
           "EXIT_TERMINATED", "EXIT_VIOLATIONS", "JSON_VERSION", "RAY_LOCAL", "_Received", "app", "err",
           "json_schema", "main", "out"]


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
    sides: Annotated[str, typer.Option("--sides", help="normal | either: the new seams' gun on the normal's side "
                                                       "of the sheet, or on either (tolerance.sides)")] = "normal",
    as_json: JsonFlag = False,
) -> None:
    """Write a new cell with a spot list's spots added as seams (docs/spot-lists.md).

    Missing normals come from the part's surface, missing directions from the seam's course; without
    a group column, seams are formed from the part's geometry (chains of spots on one face turning by
    at most 20 deg at each spot: parallel rows and corners split) and listed on stderr to check."""

    def run() -> None:
        from robomax_py.app.import_spots import import_spots
        from robomax_py.errors import CellFileError

        if units not in (None, "m", "mm"):
            raise CellFileError(None, "--units", f"expected m or mm, got {units!r}")
        if sides not in ("normal", "either"):
            raise CellFileError(None, "--sides", f"expected normal or either, got {sides!r}")
        r = import_spots(cell, spots, part, out_file, units, tolerance_mm / 1000, force, frame, sides == "either")
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


# The globals of Python's import machinery: a frame running in them means a module is being imported.
_IMPORT_MACHINERY = (vars(importlib._bootstrap), vars(importlib._bootstrap_external))
# Seconds between looks, after a signal that came during an import, at whether the import is done.
IMPORT_RETRY_S = 0.01


def _importing(frame: FrameType | None) -> bool:
    """Whether `frame` runs inside an import: the module's own code, an import it makes, or
    Python code an extension module's initialisation calls (nanobind builds enums with Python's
    `enum`), all below importlib's frames."""
    while frame is not None:
        if any(frame.f_globals is machinery for machinery in _IMPORT_MACHINERY):
            return True
        frame = frame.f_back
    return False


def _on_signal(signum: int, frame: FrameType | None) -> None:
    # SIGTERM unwinds like Ctrl-C (KeyboardInterrupt, which the preview ends on), so a write in
    # progress removes its temporary files; the signal is also kept for `_honour_signals`, since a
    # dependency that catches BaseException (trimesh, on import and in some mesh functions) can
    # swallow the exception.
    _Received.signum = signum
    if _importing(frame):
        # Not raised inside an import: an extension module whose initialisation meets the
        # exception ends the process (cascadio's nanobind init, which trimesh imports when it first
        # reads a mesh: SIGSEGV or an uncaught C++ exception), and a pure-Python one is left half
        # imported. The signal is delivered again once the import is done (or honoured at the
        # run's next stage, whichever comes first).
        _Received.deferred = True
        signal.signal(signal.SIGALRM, _deliver_deferred)
        signal.setitimer(signal.ITIMER_REAL, IMPORT_RETRY_S)
        return
    _Received.deferred = False
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise SystemExit(128 + signum)


def _deliver_deferred(signum: int, frame: FrameType | None) -> None:
    """SIGALRM after a signal was deferred: the signal raised again, so that `_on_signal` sees
    where the run is now (and a block that holds SIGINT and SIGTERM still holds it)."""
    if _Received.deferred and _Received.signum is not None:
        signal.raise_signal(_Received.signum)


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


def _end_on_signal(signum: int) -> NoReturn:
    """Exit as the received signal asked: 128 + its number, saying so."""
    err.print("interrupted" if signum == signal.SIGINT else "terminated")
    sys.exit(128 + signum)


# The thread pools of the linear algebra libraries (OpenBLAS in numpy's and scipy's wheels, OpenMP,
# MKL), started when numpy loads.
_POOL_SIZES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def _one_thread_per_library() -> None:
    """One thread for each linear algebra library, where the user set no number, before numpy loads
    (a command imports it lazily): the planner's matrices are 3x3 to 8x8, far below what a pool
    splits, and its threads spin between calls: a warm plan of the reference cell took 2.65 s of
    CPU with them and 2.39 s without (medians of 3 alternating runs), at about the same wall time.
    The processes a batch starts inherit it (a plan per CPU, no pools on top)."""
    if "numpy" in sys.modules:
        return                                  # too late: the pools exist
    for name in _POOL_SIZES:
        os.environ.setdefault(name, "1")


def main(restore_mask: Iterable[int] | None = None) -> None:
    """Console entry point. `restore_mask`: the signal mask to set once the handlers are installed
    (`python -m robomax_py` holds SIGINT and SIGTERM while it imports the command)."""
    signal.signal(signal.SIGTERM, _on_signal)
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:            # not when started ignoring it (nohup, &)
        signal.signal(signal.SIGINT, _on_signal)
    sys.unraisablehook = _unraisable(sys.unraisablehook)
    _Process.own = True
    _one_thread_per_library()
    try:
        if restore_mask is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, restore_mask)     # a held signal is delivered here
        app(args=_bare_ray_flag(_library_flags_first(sys.argv[1:])))
    except KeyboardInterrupt:
        _end_on_signal(signal.SIGINT)
    except Exception:
        if _Received.signum is None:
            raise
        # The signal's exception raised inside compiled code comes out as another error: numba's
        # dispatcher reports a KeyboardInterrupt raised while its kernel ran as "SystemError: ...
        # returned a result with an exception set". The run ends as the signal asked all the same.
        _end_on_signal(_Received.signum)
    except SystemExit as exc:
        if _Received.deferred and _Received.signum is not None:
            # The command ended before a signal that came during an import was delivered again.
            _Received.deferred = False
            _end_on_signal(_Received.signum)
        if _Received.signum == signal.SIGTERM and exc.code == 128 + signal.SIGTERM:
            err.print("terminated")
        raise
    finally:
        if signal.getsignal(signal.SIGALRM) is _deliver_deferred:
            # No delivery again while the interpreter shuts down, which puts SIGALRM's default
            # action (ending the process) back.
            _Received.deferred = False
            signal.setitimer(signal.ITIMER_REAL, 0)
        # The process ends here: the interpreter's last collection would walk every object the
        # command and its ~2000 imported modules made (~0.3 s of CPU after a plan) only to free
        # memory the exit returns anyway. Frozen objects are left out of it; exit handlers, open
        # files and the streams are closed as before. Not once OMPL was used (a detour's last
        # resort, a replan): its bindings (nanobind) print every object of theirs still alive at
        # shutdown as a leak, types and functions by the thousand, so that run's last collection
        # walks everything, the objects the heavy imports froze included.
        if "ompl" in sys.modules:
            gc.unfreeze()
        else:
            gc.freeze()


if __name__ == "__main__":
    main()
