"""What every `robomax` command shares (robomax_py.app.cli describes it): the exit codes, the
--json envelope, the app object the commands register on, the consoles and the error guard."""

from __future__ import annotations

import gc
import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, TypeVar

import typer
from rich.console import Console
from typer.core import TyperCommand, TyperGroup

from robomax_py._version import __version__
from robomax_py.errors import RobomaxError

if TYPE_CHECKING:
    from robomax_py.app.compile_ahead import Compiling

EXIT_OK = 0
EXIT_VIOLATIONS = 1
EXIT_BAD_INPUT = 2
EXIT_INFEASIBLE = 3
EXIT_INTERNAL = 70                      # sysexits.h EX_SOFTWARE: an internal software error
EXIT_INTERRUPTED = 130                  # 128 + SIGINT
EXIT_TERMINATED = 143                   # 128 + SIGTERM

# The one table of exit codes, shown under every command's help.
EXIT_CODES = (
    (EXIT_OK, "done: valid, planned, clean"),
    (EXIT_VIOLATIONS, "verify found violations"),
    (EXIT_BAD_INPUT, "bad input: a file (named with its key) or the command line is wrong"),
    (EXIT_INFEASIBLE, "infeasible: a spot left unplanned (batch: or a cell timed out or crashed)"),
    (EXIT_INTERNAL, "internal fault: a bug in robomax_py, not in the files (ROBOMAX_TRACEBACK=1 shows where)"),
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


# Set (to anything but empty) to see an internal fault's traceback instead of its one line.
TRACEBACK_ENV = "ROBOMAX_TRACEBACK"
# What ends a command or reports a usage error through typer: its to handle, never a fault. click's
# ClickException is found through typer's own BadParameter: newer typer carries click inside (no
# click distribution is installed with it), older typer used the separate one.
_CLI_ENDINGS: tuple[type[BaseException], ...] = (
    typer.Exit, typer.Abort, *(c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException"))


def _guarded(action: Callable[[], T], json_command: str | None = None) -> T:
    """Run a command body; a RobomaxError becomes one message on stderr and exit code 2 (with
    `json_command`, the --json error object on stdout as well). Any other error, in a command's
    own process, is a fault of this program: one line naming it and exit code 70, no traceback
    (unless ROBOMAX_TRACEBACK is set). A caller's process (tests, scripts) gets the exception."""
    try:
        return action()
    except _CLI_ENDINGS:
        raise
    except RobomaxError as exc:
        from rich.markup import escape

        err.print(f"[bold red]error:[/] {escape(str(exc))}", markup=True, soft_wrap=True)
        if json_command is not None:
            _print_json(json_command, False, {"error": {
                "file": getattr(exc, "file", None), "key": getattr(exc, "key", None), "message": str(exc)}})
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except Exception as exc:
        import os

        if not _Process.own or _Received.signum is not None or os.environ.get(TRACEBACK_ENV):
            raise                               # a signal's exception ends the run in `cli.main`
        _internal_fault(exc, json_command)
        raise typer.Exit(EXIT_INTERNAL) from None


def _internal_fault(exc: Exception, json_command: str | None) -> None:
    """Say that the run met a fault of this program, not of its input, and how to report it."""
    from rich.markup import escape

    first = next((line.strip() for line in str(exc).splitlines() if line.strip()), "")
    message = (f"internal fault in robomax_py, not in your files: {type(exc).__name__}"
               + (f": {first}" if first else "") + f". Run again with {TRACEBACK_ENV}=1 "
               "for the traceback, and report it with the command and the files it read")
    err.print(f"[bold red]error:[/] {escape(message)}", markup=True, soft_wrap=True)
    if json_command is not None:
        _print_json(json_command, False, {"error": {"file": None, "key": None, "message": message}})


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


def output_folder(value: Path) -> Path:
    """An `-o/--out` folder, refused before any work when it, or the nearest folder above it that
    exists, is a file: the command would otherwise plan to its end and fail on writing."""
    for at in (value, *value.parents):
        if at.is_symlink() or at.exists():
            if not at.is_dir():
                where = "" if at == value else f" (above {value})"
                raise typer.BadParameter(f"{at}{where} is a file, not a folder", param_hint="'-o' / '--out'")
            break
    return value


def _method(baseline: str | None) -> str:
    """The planning method `--baseline` names (None: the optimiser); a usage error otherwise."""
    if baseline is None:
        return "optimised"
    if baseline not in ("published", "teach-in"):
        raise typer.BadParameter(f"expected published or teach-in, got {baseline!r}", param_hint="--baseline")
    return baseline


RAY_LOCAL = "local"


class _Received:
    """The termination signal this process received (SIGINT or SIGTERM), for `_honour_signals`.
    Process state by nature: a signal handler has nowhere else to leave it."""

    signum: int | None = None
    # The signal came while a module was being imported and is to be delivered again once that
    # import is done (cli._on_signal); cleared when the run ends on it another way.
    deferred: bool = False


class _Process:
    """Whether this process is the command's own (started by `cli.main`, which ends it), rather
    than a caller's that runs the app in-process (tests, scripts). Process state by nature."""

    own: bool = False


# Allocations between two collections of the youngest generation in a command's own process
# (Python's default: 700). The planner makes and drops arrays and small objects by the hundred
# thousand, few of them in cycles; a tenth as many collections halve their cost (~0.06 s of CPU in
# a plan) and leave at most a few thousand objects' garbage waiting a little longer.
YOUNG_COLLECTION_THRESHOLD = 7000


def _compile_ahead() -> Compiling:
    """The kernels every plan calls, compiled side by side where the cache has not got them
    (`app.compile_ahead`); only in a command's own process (a caller's process, tests among them,
    compiles at the first call as before)."""
    from robomax_py.app.compile_ahead import Compiling, start

    return start() if _Process.own else Compiling()


@contextmanager
def _heavy_imports() -> Iterator[None]:
    """Around a command's heavy imports, in a process of its own: nothing those imports make is
    garbage (collecting during them only walks them, ~0.07 s of CPU before a plan), and all of it
    lives to the exit, where every full collection of the run would walk it again (~0.15 s);
    frozen once they are done, the collections see only what the command makes. Not in a caller's
    process, where objects alive now may later become garbage that frozen would never be freed."""
    if not _Process.own:
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        gc.set_threshold(YOUNG_COLLECTION_THRESHOLD, *gc.get_threshold()[1:])
        gc.enable()


def _honour_signals() -> None:
    """End the run as an earlier SIGINT or SIGTERM asked, if its exception was swallowed: called
    between stages and before anything is written."""
    if _Received.signum is not None:
        _Received.deferred = False              # the run ends here: no second delivery during its cleanup
    if _Received.signum == signal.SIGINT:
        raise KeyboardInterrupt
    if _Received.signum is not None:
        raise SystemExit(128 + _Received.signum)
