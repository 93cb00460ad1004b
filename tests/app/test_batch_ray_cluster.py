"""`robomax batch --ray` on a real Ray cluster: a head node and a worker node started on this machine
with `ray start --block` (1 CPU each, their own temporary folders and ports, so that nothing of
another Ray on the machine is shared), planned through the command line as a user would.

The cells name a robot that only the driver's `--robots` folder holds (the nodes are given no robot
library); one cell's robot has a link mesh that is not a mesh, which only the worker finds. While
a cell is being planned on the worker node, the whole node is killed: every cell still ends
planned, or failed with its reason, and the lost one was submitted again. Then the driver itself is
killed mid-batch and `--resume` keeps what was written.

Timeouts here are hang guards only; nothing is asserted about how long anything takes."""

from __future__ import annotations

import csv
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import yaml
from ray_nodes import HANG_S, Cluster, local_cluster, node_env

from robomax_py.io.robot_paths import shipped_robots_dir

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(importlib.util.find_spec("ray") is None, reason="ray is not installed")]

REPO = Path(__file__).resolve().parents[2]
SmallCell = Callable[..., Path]


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cluster]:
    """A head and a worker node, importing robomax_py from this checkout, with no robot library."""
    with local_cluster(tmp_path_factory.mktemp("ray"), 2, node_env([REPO])) as started:
        yield started


def _cell(folder: Path, write_small_cell: SmallCell, stem: str, robot: str) -> str:
    path = write_small_cell(folder, stem)
    data = yaml.safe_load(path.read_text())
    data["robot"]["model"] = robot
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return str(path)


def _robot(library: Path, name: str) -> Path:
    folder = library / name
    shutil.copytree(shipped_robots_dir() / "kr125", folder)
    (folder / "robot.yaml").write_text((folder / "robot.yaml").read_text().replace("name: kr125", f"name: {name}"))
    return folder


def _driver(cluster: Cluster, library: Path, cells: list[str], out: Path, *args: str,
            env: dict[str, str] | None = None) -> subprocess.Popen[bytes]:
    command = [sys.executable, "-m", "robomax_py", "--robots", str(library), "batch", *cells, "-o", str(out), *args]
    return subprocess.Popen(command, env=env or cluster.env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            start_new_session=True)


def _rows(out: Path) -> dict[str, dict[str, str]]:
    with (out / "summary.csv").open(newline="") as fh:
        return {r["cell"]: r for r in csv.DictReader(fh)}


def _journal(out: Path) -> list[dict[str, object]]:
    rows = []
    for line in (out / "results.jsonl").read_text().splitlines():
        try:
            rows.append(json.loads(line))
        except ValueError:
            continue
    return rows


def _until(what: str, done: Callable[[], bool], driver: subprocess.Popen[bytes]) -> None:
    deadline = time.monotonic() + HANG_S
    while not done():
        if driver.poll() is not None:
            pytest.fail(f"the batch ended before {what} (exit {driver.returncode}): "
                        f"{driver.stderr.read().decode() if driver.stderr else ''}")
        if time.monotonic() > deadline:
            pytest.fail(f"hang guard: no {what} within {HANG_S:g} s")
        time.sleep(0.05)


def test_a_lost_node_and_a_killed_driver_lose_no_cell(cluster: Cluster, tmp_path: Path,
                                                      write_small_cell: SmallCell) -> None:
    library = tmp_path / "robots"
    _robot(library, "robo_x")
    bad = _robot(library, "robo_bad")
    (bad / "meshes" / "collision" / "link_2_0.stl").write_bytes(b"\x07 not a mesh " * 100)
    folder = tmp_path / "cells"
    cells = [_cell(folder, write_small_cell, f"c{k}", "robo_x") for k in range(1, 4)]
    cells.append(_cell(folder, write_small_cell, "bad", "robo_bad"))
    out = tmp_path / "out"

    # 1. The worker node is killed while it plans a cell; RAY_ADDRESS names the cluster, as Ray has it.
    driver = _driver(cluster, library, cells, out, "--ray", env={**cluster.env, "RAY_ADDRESS": cluster.address})
    _until("cell planned on the worker node", cluster.nodes[1].stopped_while_planning, driver)
    cluster.nodes[1].kill()
    _, stderr = driver.communicate(timeout=HANG_S)
    assert driver.returncode == 2, stderr.decode()              # the bad cell
    rows = _rows(out)
    assert {c: r["status"] for c, r in rows.items()} == {"c1": "planned", "c2": "planned", "c3": "planned",
                                                         "bad": "bad input"}
    # Found in the worker, named with the driver's paths (not those of the task's copies).
    assert str(bad / "meshes" / "collision" / "link_2_0.stl") in rows["bad"]["reasons"]
    assert "robomax-cell-" not in rows["bad"]["reasons"]
    retried = [r for r in rows.values() if int(r["attempts"]) > 1]
    assert retried and all(r["status"] == "planned" and "was lost" in r["notes"] for r in retried)
    planned_then = {c: json.loads((out / f"{c}.manifest.json").read_text())["plan"] for c in ("c1", "c2", "c3")}

    # 2. Two more cells, --resume; the driver is killed once one of them is written.
    more = cells + [_cell(folder, write_small_cell, f"c{k}", "robo_x") for k in (4, 5)]
    driver = _driver(cluster, library, more, out, "--ray-address", cluster.address, "--resume")
    _until("new cell written", lambda: any(r["cell"] in ("c4", "c5") for r in _journal(out)), driver)
    os.killpg(driver.pid, signal.SIGKILL)
    driver.wait(HANG_S)
    kept = {str(r["cell"]) for r in _journal(out) if r["status"] == "planned"}

    # 3. --resume again: what was written is kept, the rest planned.
    driver = _driver(cluster, library, more, out, "--ray-address", cluster.address, "--resume")
    _, stderr = driver.communicate(timeout=HANG_S)
    assert driver.returncode == 2, stderr.decode()
    rows = _rows(out)
    assert [rows[f"c{k}"]["status"] for k in range(1, 6)] == ["planned"] * 5 and rows["bad"]["status"] == "bad input"
    assert {c for c, r in rows.items() if r["resumed"] == "yes"} == kept
    assert {"c1", "c2", "c3"} < kept < {f"c{k}" for k in range(1, 6)}
    assert {c: json.loads((out / f"{c}.manifest.json").read_text())["plan"] for c in planned_then} == planned_then
