"""A first plan's kernels compiled side by side: when the cache folder has not got the kernels every
plan calls (`kernel_table.PLAN_KERNELS`: after an install, an upgrade that changed them, a new
machine), they are compiled in processes of their own, one per CPU, the first while the command
imports and reads its files; the plan then loads them from the cache.

numba compiles a function at its first call, one at a time (its compiler holds a lock, and most
of the work is Python): on the reference cell about 6 s of a 9 s first plan, of which the
pre-filter's two kernels are 5 s. The helpers the two share are compiled first, in one process,
while the command imports and reads its files; then the kernels, shared out among one process per
CPU. With one CPU nothing is started: the kernels compile at their first call, as they would
anyway.

A process that fails or is killed costs nothing but its time: its kernels compile at their first
call. numba writes each cache file whole (a temporary file renamed), so a killed process leaves no
half-written entry.
"""

from __future__ import annotations

import gc
import importlib
import multiprocessing
import os
import signal
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from multiprocessing.context import ForkContext, SpawnContext
from multiprocessing.process import BaseProcess
from typing import Any

from numba.core.dispatcher import Dispatcher

from robomax_py.app.kernel_table import PLAN_KERNELS, SHARED_HELPERS, KernelEntry
from robomax_py.jit import has_cache, is_cached

# The longest a command waits for the compiling processes (a first plan's compile is about 3 s on
# two CPUs); past it they are stopped and what they did not finish compiles at its first call.
WAIT_S = 120.0
_POLL_S = 0.1


def usable_cpus() -> int:
    """The CPUs this process may run on (its affinity where the platform tells it)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:                      # not on Linux
        return os.cpu_count() or 1


def cold(kernels: Sequence[KernelEntry] = PLAN_KERNELS) -> list[KernelEntry]:
    """The kernels of `kernels` the cache has not got for this source and this machine. None where
    no folder keeps them (nor under NUMBA_DISABLE_JIT): what another process compiled would be
    lost, and the command would compile it again."""
    found = [(k, _dispatcher(k)) for k in kernels]
    if not all(has_cache(d) for _, d in found):
        return []
    return [k for k, d in found if not is_cached(d, k.args)]


def shares(kernels: Sequence[KernelEntry], count: int) -> list[list[KernelEntry]]:
    """`kernels` shared out into at most `count` non-empty groups of about equal cost: the dearest
    first, each to the group with the least so far (the longest-processing-time rule)."""
    groups: list[list[KernelEntry]] = [[] for _ in range(max(1, min(count, len(kernels))))]
    loads = [0.0] * len(groups)
    for k in sorted(kernels, key=lambda k: (-k.cost_s, k.module, k.name)):
        i = loads.index(min(loads))
        groups[i].append(k)
        loads[i] += k.cost_s
    return [g for g in groups if g]


@dataclass(frozen=True, slots=True)
class Compiling:
    """The compiling of one command: the processes under way and the kernels' groups still to start,
    each in a process of its own once those have ended (the helpers' process: the kernels then load
    the helpers from the cache). Empty when there is nothing to compile."""

    started: tuple[BaseProcess, ...] = ()
    groups: tuple[tuple[KernelEntry, ...], ...] = ()

    def wait(self, between: Callable[[], None] = lambda: None, limit_s: float = WAIT_S) -> int:
        """Wait until every process has ended, the groups' started in their turn (at most `limit_s`
        in all, then those left are stopped); `between` is called every tenth of a second meanwhile
        (a command's signal check). Returns how many processes ended without an error. Once per
        `start`: each call starts the groups' processes."""
        deadline = time.monotonic() + limit_s
        ended = _join(self.started, between, deadline)
        later = tuple(_launch(g) for g in self.groups)
        return ended + _join(later, between, deadline)


def start(kernels: Sequence[KernelEntry] = PLAN_KERNELS, helpers: Sequence[KernelEntry] = SHARED_HELPERS,
          cpus: int | None = None) -> Compiling:
    """Start compiling what the cache has not got: `helpers` in one process now, `kernels` shared
    out among one process per CPU (`cpus`, default `usable_cpus()`) once it has ended (at once when
    no helper is missing); nothing when every kernel is cached or only one CPU is there. The
    processes are daemons: a command that ends early stops them."""
    todo = cold(kernels)
    cpus = usable_cpus() if cpus is None else cpus
    if not todo or cpus < 2:
        return Compiling()
    if _context() == "fork":
        # numba's typing and target registries, filled here once rather than in every child (about
        # 0.15 s each), each of which compiles and so needs them. The command itself would not: it
        # loads the kernels without them (`jit._PackageFunctionCache.load_overload`).
        d = _dispatcher(todo[0])
        d.typingctx.refresh()                   # type: ignore[no-untyped-call]  # numba is untyped
        d.targetctx.refresh()                   # type: ignore[no-untyped-call]
    groups = tuple(tuple(g) for g in shares(todo, cpus))
    first = tuple(cold(helpers))
    if not first:
        return Compiling(tuple(_launch(g) for g in groups))
    # The helpers several kernels call, compiled once, while the command imports and reads its
    # files; each kernel's process would otherwise compile them again for itself.
    return Compiling((_launch(first),), groups)


def _context() -> str:
    """fork on Linux: the child has the parent's modules already (spawn would import numba and the
    kernels' modules again, about 0.5 s each); elsewhere the platform's safe default."""
    return "fork" if sys.platform.startswith("linux") else "spawn"


def _launch(group: Sequence[KernelEntry]) -> BaseProcess:
    ctx: ForkContext | SpawnContext = (multiprocessing.get_context("fork") if _context() == "fork"
                                       else multiprocessing.get_context("spawn"))
    p = ctx.Process(target=_compile, args=(tuple(group),), name="robomax-compile", daemon=True)
    p.start()
    return p


def _join(processes: Sequence[BaseProcess], between: Callable[[], None], deadline: float) -> int:
    """Join `processes` until `deadline` (time.monotonic), calling `between` every tenth of a second;
    those left then are stopped. How many ended without an error."""
    for p in processes:
        while p.is_alive() and time.monotonic() < deadline:
            p.join(_POLL_S)
            between()
        if p.is_alive():
            p.terminate()
            p.join()
    return sum(p.exitcode == 0 for p in processes)


def _compile(group: Sequence[KernelEntry]) -> None:
    """A compiling process: each kernel compiled for its argument types (numba saves it in the
    cache folder as it would at a first call)."""
    # Forked from a command that may hold SIGINT and SIGTERM (its imports) and handles them itself:
    # here SIGTERM (`wait`'s stop, or the command's exit stopping its daemons) ends the process at
    # once, and Ctrl-C, which the terminal sends to every process of the group, is the command's
    # to answer (it then stops this one).
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    gc.enable()                                 # a command disables it around its imports
    try:
        for k in group:
            _dispatcher(k).compile(k.args)
    except Exception:                           # noqa: BLE001  # any failure: the command compiles it itself
        # No traceback of this process on the command's terminal: the kernel compiles again at its
        # first call in the command, which reports a failure as it would have without this process.
        sys.exit(1)


def _dispatcher(k: KernelEntry) -> Dispatcher[Any]:
    found: Dispatcher[Any] = getattr(importlib.import_module(k.module), k.name)
    return found
