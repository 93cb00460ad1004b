"""A first plan's kernels compiled side by side: when the cache folder has not got the kernels every
plan calls (`kernel_table.PLAN_KERNELS`: after an install, an upgrade that changed them, a new
machine), they are compiled in processes of their own, one per CPU, while the command reads its
files; the plan then loads them from the cache.

numba compiles a function at its first call, one at a time (its compiler holds a lock, and most
of the work is Python): on the reference cell about 6 s of a 9 s first plan, of which the
pre-filter's two kernels are 5 s. Shared out among two processes the first plan ends about 2.5 s
sooner; it costs about 1 s more CPU, as each process compiles the helpers its kernels call. With
one CPU nothing is started: the kernels compile at their first call, as they would anyway.

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
from robomax_py.jit import is_cached

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
    """The kernels of `kernels` the cache has not got for this source and this machine."""
    return [k for k in kernels if not is_cached(_dispatcher(k), k.args)]


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
    """The compiling processes of one command (none when there was nothing to share out)."""

    processes: tuple[BaseProcess, ...]

    def wait(self, between: Callable[[], None] = lambda: None, limit_s: float = WAIT_S) -> int:
        """Wait until every process has ended (at most `limit_s`, then stop those left); `between`
        is called every tenth of a second meanwhile (a command's signal check). Returns how many
        ended without an error."""
        deadline = time.monotonic() + limit_s
        for p in self.processes:
            while p.is_alive() and time.monotonic() < deadline:
                p.join(_POLL_S)
                between()
            if p.is_alive():
                p.terminate()
                p.join()
        return sum(p.exitcode == 0 for p in self.processes)


def start(kernels: Sequence[KernelEntry] = PLAN_KERNELS, helpers: Sequence[KernelEntry] = SHARED_HELPERS,
          cpus: int | None = None) -> Compiling:
    """Start compiling the kernels of `kernels` that the cache has not got, shared out among one
    process per CPU (`cpus`, default `usable_cpus()`), after `helpers` (those the cache has not
    got) are compiled here; nothing when all kernels are cached or only one CPU is there. The
    processes are daemons: a command that ends early stops them."""
    todo = cold(kernels)
    cpus = usable_cpus() if cpus is None else cpus
    if not todo or cpus < 2:
        return Compiling(())
    # fork on Linux: the child has the parent's modules already (spawn would import numba and the
    # kernels' modules again, about 0.5 s each); elsewhere the platform's safe default.
    fork = sys.platform.startswith("linux")
    if fork:
        # numba's typing and target registries, filled here once rather than in every child (about
        # 0.15 s each); the command needs them anyway to load the kernels.
        d = _dispatcher(todo[0])
        d.typingctx.refresh()                   # type: ignore[no-untyped-call]  # numba is untyped
        d.targetctx.refresh()                   # type: ignore[no-untyped-call]
    # The helpers several kernels call, compiled once here: each child has them from the fork (or
    # the cache) instead of compiling them for its own kernels.
    _compile_all(cold(helpers))
    ctx: ForkContext | SpawnContext = (multiprocessing.get_context("fork") if fork
                                       else multiprocessing.get_context("spawn"))
    processes = []
    for i, group in enumerate(shares(todo, cpus)):
        p = ctx.Process(target=_compile, args=(group,), name=f"robomax-compile-{i}", daemon=True)
        p.start()
        processes.append(p)
    return Compiling(tuple(processes))


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
    _compile_all(group)


def _compile_all(entries: Sequence[KernelEntry]) -> None:
    for k in entries:
        _dispatcher(k).compile(k.args)


def _dispatcher(k: KernelEntry) -> Dispatcher[Any]:
    found: Dispatcher[Any] = getattr(importlib.import_module(k.module), k.name)
    return found
