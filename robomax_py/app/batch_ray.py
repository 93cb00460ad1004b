"""`robomax batch --ray`: each cell a Ray task, on a local Ray or on a cluster that shares nothing
with the machine the batch is started on.

Where: `--ray` joins the cluster at RAY_ADDRESS when it is set and otherwise starts a local Ray
(never a cluster that happens to run on this machine); `--ray ADDRESS` / `--ray-address ADDRESS`
joins that one (`auto`: Ray's own search, RAY_ADDRESS then the last `ray start` here).

What a task carries: the cell's files (`app.batch_ship`: the cell, its includes, meshes, robot and
tool folders, through the object store, each distinct file once per batch), so no node needs the
driver's folders. Each task declares 1 CPU and the memory its plan will take (`task_memory_mb`, a
measured model of a plan's peak by the cell's size, or `--task-memory`), so Ray runs as many at
once as the nodes hold; every cell is submitted (or `-j` at a time) and Ray queues the rest.

In the task, the cell is planned by the local pool (`app.batch_local`) in a process of its own: the
deadline counts from the task's start, and a cell that crashes its process is `crashed` like in the
local pool. A task whose worker process or node is lost (the Ray error of a lost worker, node or
result, not the cell's own failure) is submitted again, up to `retries` times; the outcome counts
its attempts and names what was lost.
"""

from __future__ import annotations

import os
import socket
import time
from collections import deque
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from robomax_py.app.batch_cell import (
    BAD_INPUT,
    CRASHED,
    BatchOptions,
    CellOutcome,
    PlanSettings,
    Worker,
    plan_cell_file,
)
from robomax_py.app.batch_local import OnDone
from robomax_py.app.batch_ship import ShippedCell, Survey, survey, unpacked

LOCAL = "local"
# How long a cluster's head may take to accept a connection before it counts as unreachable, s.
CONNECT_S = 10.0
# The driver's wait for finished tasks, s: how soon an interrupt is seen while tasks run.
WAIT_S = 1.0
# Peak resident memory of a plan (the worker process), MiB, from its size: TCP poses to solve, the
# cell's spots x orientation samples summed over its seams. An upper bound of the peaks measured by
# `tests/bench/bench_batch.py --memory` (docs/benchmarks.md, "Batch planning on Ray": 277-2,270 MiB
# for 18-24,000 poses, each under the bound, the closest 6 % below it).
PLAN_BASE_MB = 400.0
PLAN_MB_PER_POSE = 0.1
# What a task holds besides its plan's process, MiB: the Ray worker process (~90 MiB measured) and
# the fork server it starts (~280 MiB: the imported planner, whose pages the plan's process shares
# and counts in its own peak).
TASK_OVERHEAD_MB = 250.0
# Ray errors of a lost worker process, node or result object: the task is submitted again.
LOST = ("WorkerCrashedError", "NodeDiedError", "LocalRayletDiedError", "OutOfMemoryError", "ObjectLostError",
        "RaySystemError", "RpcError", "ObjectStoreFullError", "OutOfDiskError")


def task_memory_mb(poses: int) -> float:
    """The memory a cell's task declares to Ray, MiB: its plan's peak (the model) and the task's overhead."""
    return PLAN_BASE_MB + PLAN_MB_PER_POSE * poses + TASK_OVERHEAD_MB


def plan_shipped(cell: ShippedCell, settings: PlanSettings, timeout: float | None, worker: Worker,
                 *blobs: bytes) -> CellOutcome:
    """The Ray task (`plan_unpacked`), its outcome naming the node that planned it."""
    import socket

    import ray

    # The host, and Ray's id of the node (several nodes may share a host), as `ray status` shows it.
    node = f"{socket.gethostname()}/{ray.get_runtime_context().get_node_id()[:8]}"
    return replace(plan_unpacked(cell, settings, timeout, worker, blobs), node=node)


def plan_unpacked(cell: ShippedCell, settings: PlanSettings, timeout: float | None, worker: Worker,
                  blobs: Sequence[bytes]) -> CellOutcome:
    """Write the cell's files out, plan it in a process of its own (`batch_local.run_local`: its
    deadline from now, its crash its own outcome) and name the driver's paths in what it says."""
    from robomax_py.app.batch_local import run_local

    with unpacked(cell, blobs) as box:
        options = BatchOptions(jobs=1, timeout=timeout, method=settings.method, formats=settings.formats)
        (got,) = run_local([box.file], options, worker=worker, env=box.env)
        return replace(got, file=cell.file, reasons=box.outside(got.reasons), notes=box.outside(got.notes),
                       inputs=tuple((box.outside(p), h) for p, h in got.inputs),
                       warnings=tuple(replace(n, file=box.outside(n.file), message=box.outside(n.message))
                                      for n in got.warnings))


@dataclass(frozen=True, slots=True)
class _Task:
    index: int
    survey: Survey
    refs: tuple[Any, ...]            # the ObjectRefs of the cell's files
    memory_mb: float | None
    attempts: int = 1
    lost: tuple[str, ...] = ()       # what each lost attempt ended with
    submitted: float = 0.0           # time.monotonic() of this attempt's submission


def resolve_address(address: str | None) -> str:
    """The address ray.init is given: RAY_ADDRESS when no address is named (else a new local Ray),
    `local` for a new local Ray, otherwise the address named."""
    if address is None or address == "":
        return os.environ.get("RAY_ADDRESS") or LOCAL
    return address


def run_ray(
    files: Sequence[str], options: BatchOptions, address: str | None = None, on_done: OnDone | None = None,
    worker: Worker = plan_cell_file, init_kwargs: Mapping[str, Any] | None = None,
) -> tuple[CellOutcome, ...]:
    """Plan every file as a Ray task (module docstring); outcomes in argument order, as `run_local`
    gives them, `on_done` called as each cell finishes.

    When Ray is running in this process already, that connection is used (and kept); otherwise as
    `connected` says. Raises ImportError when ray is not installed, ConnectionError when the cluster
    cannot be reached.
    """
    import ray

    with connected(address, options.jobs, init_kwargs):
        return _run(ray, files, options, on_done, worker)


@contextmanager
def connected(address: str | None, jobs: int | None = None,
              init_kwargs: Mapping[str, Any] | None = None) -> Iterator[None]:
    """Ray connected in this process for the block (`resolve_address`; a local Ray started here gets
    `jobs` CPUs, default all, and is ended after); nothing is done when it is connected already.
    `init_kwargs` are passed on to `ray.init` (a runtime_env, for instance). ConnectionError, at
    once, when nothing answers at a `host:port` address (Ray itself would retry for minutes)."""
    import ray

    if ray.is_initialized():
        yield
        return
    where = resolve_address(address)
    _check_reachable(where)
    kwargs: dict[str, Any] = {"address": where, "log_to_driver": False}
    if where == LOCAL:
        kwargs["include_dashboard"] = False
        if jobs is not None:
            kwargs["num_cpus"] = jobs
    kwargs.update(init_kwargs or {})
    ray.init(**kwargs)
    try:
        yield
    finally:
        ray.shutdown()


def _check_reachable(address: str) -> None:
    """ConnectionError when a `host:port` address (not `local`, `auto` or a `ray://` one) refuses
    a TCP connection or does not answer within CONNECT_S."""
    host, sep, port = address.rpartition(":")
    if "://" in address or not sep or not port.isdigit():
        return
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=CONNECT_S).close()
    except OSError as exc:
        raise ConnectionError(f"nothing answers at {address} ({exc.strerror or exc})") from None


def _largest_node_mb(ray: Any) -> float | None:
    """The most memory one alive node offers tasks, MiB (None when no node states it)."""
    sizes = [n["Resources"].get("memory", 0) for n in ray.nodes() if n.get("Alive")]
    return max(sizes) / 2**20 if sizes and max(sizes) > 0 else None


def _run(ray: Any, files: Sequence[str], options: BatchOptions, on_done: OnDone | None,
         worker: Worker) -> tuple[CellOutcome, ...]:
    remote = ray.remote(num_cpus=1, max_retries=0)(plan_shipped)
    lost_kinds = tuple(getattr(ray.exceptions, n) for n in LOST if hasattr(ray.exceptions, n))
    largest = _largest_node_mb(ray)
    blobs: dict[str, Any] = {}               # a file's path -> its ObjectRef, each file put once
    pending = deque(range(len(files)))
    running: dict[Any, _Task] = {}           # ObjectRef of the outcome -> its task
    outcomes: dict[int, CellOutcome] = {}
    settings = options.settings

    def finish(i: int, outcome: CellOutcome) -> None:
        outcomes[i] = outcome if on_done is None else on_done(i, outcome)

    def submit(task: _Task) -> None:
        memory = {} if task.memory_mb is None else {"memory": int(task.memory_mb * 2**20)}
        ref = remote.options(**memory).remote(task.survey.shipped, settings, options.timeout, worker, *task.refs)
        running[ref] = replace(task, submitted=time.monotonic())

    def prepare(i: int) -> _Task | CellOutcome:
        from robomax_py.errors import RobomaxError

        t0 = time.perf_counter()
        try:
            cell = survey(files[i])
            refs = tuple(blobs[p] if p in blobs else blobs.setdefault(p, ray.put(Path(p).read_bytes()))
                         for p in cell.shipped.paths)
        except RobomaxError as exc:
            return CellOutcome(files[i], Path(files[i]).stem, BAD_INPUT, time.perf_counter() - t0, reasons=str(exc))
        except OSError as exc:
            return CellOutcome(files[i], Path(files[i]).stem, BAD_INPUT, time.perf_counter() - t0,
                               reasons=f"{files[i]}: a file it reads cannot be read: {exc}")
        want = options.task_memory_mb or task_memory_mb(cell.poses)
        return _Task(i, cell, refs, want if largest is None else min(want, largest))

    try:
        while pending or running:
            while pending and (options.jobs is None or len(running) < options.jobs):
                i = pending.popleft()
                made = prepare(i)
                if isinstance(made, CellOutcome):
                    finish(i, made)
                else:
                    submit(made)
                if running and ray.wait(list(running), num_returns=1, timeout=0)[0]:
                    break                    # write what is done before preparing more
            if not running:
                continue
            ready, _ = ray.wait(list(running), num_returns=1, timeout=WAIT_S)
            for ref in ready:
                task = running.pop(ref)
                got = _received(ray, ref, task, files[task.index], options, lost_kinds)
                if isinstance(got, _Task):
                    submit(got)
                else:
                    finish(task.index, got)
    finally:
        for ref in running:                  # interrupted: no task is left running
            ray.cancel(ref, force=True)
    return tuple(outcomes[i] for i in range(len(files)))


def _received(ray: Any, ref: Any, task: _Task, file: str, options: BatchOptions,
              lost_kinds: tuple[type[BaseException], ...]) -> CellOutcome | _Task:
    """A finished task's outcome, or the task to submit again after a lost worker, node or result."""
    def failed(reason: str) -> CellOutcome:
        return CellOutcome(file, Path(file).stem, CRASHED, time.monotonic() - task.submitted, reasons=reason,
                           attempts=task.attempts, notes=_retried(task))

    try:
        got: CellOutcome = ray.get(ref)
    except ray.exceptions.RayTaskError as exc:        # the task's own code raised (a bug): no retry
        return failed(f"Ray task failed: {type(exc).__name__}: {_first_line(exc)}")
    except lost_kinds as exc:
        lost = f"{type(exc).__name__}: {_first_line(exc)}"
        if task.attempts <= options.retries:
            return replace(task, attempts=task.attempts + 1, lost=(*task.lost, lost))
        return failed(f"worker or node lost on each of {task.attempts} attempt(s); the last: {lost}")
    except ray.exceptions.RayError as exc:
        return failed(f"Ray task failed: {type(exc).__name__}: {_first_line(exc)}")
    notes = "; ".join(n for n in (_retried(task), _as_given(got.notes, file)) if n)
    warnings = tuple(replace(n, file=_as_given(n.file, file), message=_as_given(n.message, file)) for n in got.warnings)
    return replace(got, file=file, reasons=_as_given(got.reasons, file), notes=notes, attempts=task.attempts,
                   warnings=warnings)


def _retried(task: _Task) -> str:
    if not task.lost:
        return ""
    return "submitted again after " + "; ".join(f"attempt {k + 1} was lost ({why})" for k, why in enumerate(task.lost))


def _as_given(text: str, file: str) -> str:
    """Paths in a task's message as the local pool names them: relative to the working folder when
    the cell file was given relative to it."""
    return text if os.path.isabs(file) else text.replace(os.getcwd() + os.sep, "")


def _first_line(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return lines[0] if lines else ""
