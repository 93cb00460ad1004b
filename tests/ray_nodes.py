"""Ray nodes started on this machine for the cluster test and the batch benchmark: `ray start --block`
in a session of its own, 1 CPU, a small object store, its own temporary folder and free ports, so that
nothing of another Ray running on the machine is shared. Never `ray stop` (it ends every Ray here)."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

HANG_S = 300.0                              # hang guard of every wait here


def free_ports(n: int) -> list[int]:
    """n TCP ports nothing listens on at 127.0.0.1 now."""
    socks = [socket.socket() for _ in range(n)]
    try:
        for s in socks:
            s.bind(("127.0.0.1", 0))
        return [int(s.getsockname()[1]) for s in socks]
    finally:
        for s in socks:
            s.close()


def processes(session: int) -> list[tuple[int, int, str, str]]:
    """(pid, parent pid, state, command line) of every process of a session (Linux /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()        # state, ppid, pgrp, session, ...
        if int(fields[3]) == session:
            found.append((int(entry.name), int(fields[1]), fields[0], cmdline))
    return found


def session_cpu_s(session: int) -> float:
    """CPU seconds of the session's processes and of the children they waited for (Linux /proc)."""
    ticks = os.sysconf("SC_CLK_TCK")
    total = 0.0
    for pid, *_ in processes(session):
        try:
            stat = Path(f"/proc/{pid}/stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()           # utime, stime, cutime, cstime: fields 11-14
        total += sum(int(v) for v in fields[11:15]) / ticks
    return total


def _signal_all(pids: list[int], signum: int) -> None:
    for pid in pids:
        try:
            os.kill(pid, signum)
        except ProcessLookupError:
            pass


@dataclass
class Node:
    """A `ray start --block` in a session of its own. Ray gives its worker processes process groups
    of their own inside that session, so the node is ended by signalling every process of the
    session (the processes this node started, found by session id, not by name)."""

    proc: subprocess.Popen[bytes]

    def kill(self) -> None:
        _signal_all([p for p, *_ in processes(self.proc.pid)], signal.SIGKILL)
        self.proc.wait(HANG_S)

    def stopped_while_planning(self) -> bool:
        """Stop the whole node (SIGSTOP) and say whether a cell's process (a child of a fork
        server) is alive in it, so that killing the node now loses a task in flight; else let it
        go on and say False."""
        pids = [p for p, *_ in processes(self.proc.pid)]
        _signal_all(pids, signal.SIGSTOP)
        procs = processes(self.proc.pid)
        servers = {p for p, _, _, cmd in procs if "multiprocessing.forkserver" in cmd}
        if any(parent in servers and state != "Z" for _, parent, state, _ in procs):
            return True
        _signal_all(pids, signal.SIGCONT)
        return False


@dataclass
class Cluster:
    address: str                             # host:port of the head's GCS
    nodes: list[Node]                        # the head first
    env: dict[str, str]                      # what the nodes run with; a driver runs with it too


def node_env(pythonpath: list[Path]) -> dict[str, str]:
    """This process's environment without Ray's settings or a robot library, for nodes and drivers:
    robomax_py imported from `pythonpath`, no token authentication (the nodes listen on this
    machine only), and a head that declares a node dead after ~3 s without an answer (default ~30 s)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("RAY_") and k != "ROBOMAX_ROBOTS"}
    env.update(PYTHONPATH=os.pathsep.join(str(p) for p in pythonpath), RAY_AUTH_MODE="disabled",
               RAY_health_check_initial_delay_ms="1000", RAY_health_check_period_ms="1000",
               RAY_health_check_timeout_ms="1000", RAY_health_check_failure_threshold="3")
    return env


# Ports one node takes (besides the head's own two): its managers, agents and 8 for worker processes.
NODE_PORTS = 14


def _start(args: list[str], ports: Iterator[int], temp: Path, env: dict[str, str], log: Path) -> Node:
    node_args = ["--block", "--num-cpus", "1", "--object-store-memory", str(100 * 2**20), "--temp-dir", str(temp),
                 "--disable-usage-stats", "--node-manager-port", str(next(ports)),
                 "--object-manager-port", str(next(ports)), "--dashboard-agent-listen-port", str(next(ports)),
                 "--dashboard-agent-grpc-port", str(next(ports)), "--runtime-env-agent-port", str(next(ports)),
                 "--metrics-export-port", str(next(ports)),
                 "--worker-port-list", ",".join(str(next(ports)) for _ in range(8))]
    ray = shutil.which("ray", path=str(Path(sys.executable).parent)) or "ray"
    with log.open("wb") as sink:
        proc = subprocess.Popen([ray, "start", *args, *node_args], env=env, stdout=sink, stderr=subprocess.STDOUT,
                                start_new_session=True)
    return Node(proc)


@contextmanager
def local_cluster(folder: Path, n_nodes: int, env: dict[str, str]) -> Iterator[Cluster]:
    """A head and n_nodes - 1 worker nodes, each with 1 CPU, all alive when the block starts; every
    process of every node killed when it ends. Logs in `folder`; each node's temporary folder is a
    short one of its own under the system's (Ray's sockets live there, and a socket's path may have
    at most 107 bytes), removed at the end, and so is every file they put in their temporary folder.
    The yielded Cluster's env has that folder as TMPDIR: a driver run with it keeps its files there too."""
    ports = iter(free_ports(2 + NODE_PORTS * n_nodes))       # all at once: no port given twice
    gcs, client = next(ports), next(ports)
    address = f"127.0.0.1:{gcs}"
    folder.mkdir(parents=True, exist_ok=True)
    temp = Path(tempfile.mkdtemp(prefix="rn"))
    # The nodes' own temporary files (the tasks' copies of their cells) go under it too: a task killed
    # with its node leaves its copies behind (`batch_ship.sweep_orphans` removes them only hours later).
    (temp / "t").mkdir()
    env = {**env, "TMPDIR": str(temp / "t")}
    nodes: list[Node] = []
    try:
        nodes.append(_start(["--head", "--port", str(gcs), "--ray-client-server-port", str(client),
                             "--include-dashboard", "false"], ports, temp / "h", env, folder / "head.log"))
        for k in range(1, n_nodes):
            nodes.append(_start(["--address", address], ports, temp / f"n{k}", env, folder / f"node{k}.log"))
        wait = ("import ray, sys, time\nray.init(address=sys.argv[1], log_to_driver=False)\n"
                "while sum(n['Alive'] for n in ray.nodes()) < int(sys.argv[2]): time.sleep(0.2)\n")
        waiting = subprocess.Popen([sys.executable, "-c", wait, address, str(n_nodes)], env=env,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + HANG_S
        while waiting.poll() is None:
            ended = [k for k, node in enumerate(nodes) if node.proc.poll() is not None]
            if ended or time.monotonic() > deadline:
                waiting.kill()
                waiting.wait()
                log = folder / ("head.log" if not ended or ended[0] == 0 else f"node{ended[0]}.log")
                raise RuntimeError(f"Ray nodes not up (see {log}): {log.read_text(errors='replace')[-2000:]}")
            time.sleep(0.2)
        if waiting.returncode != 0:
            raise RuntimeError(f"could not connect to the Ray cluster at {address} (see {folder}/head.log)")
        yield Cluster(address, nodes, env)
    finally:
        for node in reversed(nodes):
            node.kill()
        shutil.rmtree(temp, ignore_errors=True)
