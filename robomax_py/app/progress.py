"""Rich progress bars for the planner's stages (`plan.Progress`) and debug logging for `-v`."""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager

from rich.console import Console
from rich.logging import RichHandler
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TaskID,
    TextColumn,
    TimeElapsedColumn,
)

from robomax_py.plan import Progress as PlanProgress
from robomax_py.plan.results import STAGE_LABELS


@contextmanager
def stage_bars(console: Console, enabled: bool = True) -> Iterator[PlanProgress]:
    """A `plan.Progress` callback that draws one bar per stage on `console` (transient).

    Disabled (a no-op callback) when `enabled` is false or the console is not a terminal, so
    pipes and --json output stay clean.
    """
    if not enabled or not console.is_terminal:
        yield lambda stage, done, total: None
        return
    bars = Progress(TextColumn("{task.description:<36}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                    console=console, transient=True)
    tasks: dict[str, TaskID] = {}

    def update(stage: str, done: int, total: int) -> None:
        if stage not in tasks:
            tasks[stage] = bars.add_task(STAGE_LABELS.get(stage, stage), total=total)
        bars.update(tasks[stage], completed=done, total=total)

    with bars:
        yield update


def configure_logging(console: Console, verbose: bool) -> None:
    """-v: the package's debug log (stage sizes, counts, times) on the error console."""
    if not verbose:
        return
    handler = RichHandler(console=console, show_path=False, markup=False, rich_tracebacks=False)
    handler.setFormatter(logging.Formatter("%(name)s: %(message)s"))
    logger = logging.getLogger("robomax_py")
    logger.handlers[:] = [handler]
    logger.setLevel(logging.DEBUG)
    logger.propagate = False
