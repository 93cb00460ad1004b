"""Shared fixtures: the repo's paths, the reference cell, a seeded rng, and --update-golden."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

REPO = Path(__file__).resolve().parents[1]
REFERENCE_CELL = REPO / "tests" / "data" / "reference" / "cabin_flange.yaml"
# The small test cell's source: a frozen copy of the reference cell (shipped cells may change).
SHIPPED_CELL = REPO / "tests" / "data" / "flange_cell" / "cabin_flange.yaml"

SmallCell = Callable[..., Path]


def _build_each_command_once() -> None:
    """`typer.testing.CliRunner.invoke` builds the click command from the Typer app on every call
    (~25 ms of signature inspection); the suite runs `robomax` in-process thousands of times (the
    hostile-file sweeps), so each app's command is built once here. A built click command keeps
    nothing of a run: each invocation makes its own context."""
    import typer.testing

    build = typer.testing._get_command
    built: dict[int, tuple[Any, Any]] = {}

    def get_command(app: Any) -> Any:
        if id(app) not in built:
            built[id(app)] = (app, build(app))      # the app kept alive, so its id is not reused
        return built[id(app)][1]

    typer.testing._get_command = get_command  # type: ignore[attr-defined]


_build_each_command_once()


def _write_small_cell(folder: Path, name: str = "small_cell", extra_spots: list[dict[str, Any]] | None = None) -> Path:
    """s7 and s8 of the shipped cell (no clamp between them), grid 3, gamma fixed: plans in ~2 s."""
    data = yaml.safe_load(SHIPPED_CELL.read_text())
    if not (folder / "parts").exists():
        shutil.copytree(SHIPPED_CELL.parent / "parts", folder / "parts")
    data["name"] = name
    seam = data["seams"][0]
    seam["spots"] = [s for s in seam["spots"] if s["name"] in ("s7", "s8")] + (extra_spots or [])
    seam["grid"] = 3
    seam["tolerance"]["gamma"] = [0, 0]
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def place_cell(data: dict[str, Any], xyz: tuple[float, float, float], yaw_deg: float, roll_deg: float = 0.0) -> None:
    """Move a whole cell (its data as read from YAML) by one rigid transform, in place: the robot,
    every object and dynamic object, every spot with its normal and direction, as a station puts a
    cell wherever it stands. The cell plans the same motion: only the world moved."""
    from scipy.spatial.transform import Rotation

    R = Rotation.from_euler("xz", [roll_deg, yaw_deg], degrees=True)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R.as_matrix(), xyz

    def pose(p: dict[str, Any] | None) -> dict[str, Any]:
        p = p or {}
        M = np.eye(4)
        M[:3, :3] = Rotation.from_euler("xyz", p.get("rpy", [0, 0, 0]), degrees=True).as_matrix()
        M[:3, 3] = p.get("xyz", [0, 0, 0])
        N = T @ M
        rpy = Rotation.from_matrix(N[:3, :3]).as_euler("xyz", degrees=True)
        return {"xyz": [round(float(v), 9) for v in N[:3, 3]], "rpy": [round(float(v), 9) for v in rpy]}

    data["robot"]["base"] = pose(data["robot"].get("base"))
    for key in ("objects", "dynamic"):
        for obj in data.get(key, []):
            obj["pose"] = pose(obj.get("pose"))
    for seam in data.get("seams", []):
        for spot in seam["spots"]:
            spot["xyz"] = [round(float(v), 9) for v in (T @ np.r_[spot["xyz"], 1.0])[:3]]
            for k in ("normal", "direction"):
                spot[k] = [round(float(v), 12) for v in T[:3, :3] @ np.asarray(spot[k], dtype=float)]


# Where the small cell's robot passes about 0.8 s into its first move (tests/plan/test_waiting.py
# derives it from the plan; frozen here so the process cell is a fixed file).
DOOR = {"name": "door", "box": [0.12, 0.12, 0.12], "pose": {"xyz": [1.4616, -0.0182, 1.2151]}, "present": [[0, 1.5]]}


def _write_process_cell(folder: Path, name: str = "process_cell") -> Path:
    """The small cell with a door to wait for, clamp 1 behind an input, gun 2 and s8 welded longer
    with its own schedule; placed as a station places it (1.6 m off the origin, turned 30 deg, on a
    0.45 m riser tilted 2 deg), with the integrator's numbers: tool 2, user frame 3 on the fixture
    plate, position registers 40 and 41 for the frames, the clamp on input 5, the door on 6."""
    path = _write_small_cell(folder, name=name)
    data = yaml.safe_load(path.read_text())
    data["dynamic"] = [dict(DOOR)]
    data["process"]["gun"] = 2
    data["process"]["schedule"] = 4
    for obj in data["objects"]:
        if obj["name"] == "clamp1_jaw":
            obj["signal"] = "clamp1_closed"
    for spot in data["seams"][0]["spots"]:
        if spot["name"] == "s8":
            spot.update(weld_time=0.8, schedule=7)
    place_cell(data, (1.2, -1.05, 0.45), 30.0, roll_deg=2.0)
    data["robot"]["controller"] = {
        "tool": {"number": 2, "name": "gun2"},
        "frame": {"number": 3, "object": "fixture_plate"},
        "registers": {"position": [40, 41]},
        "inputs": {"clamp1_closed": {"number": 5, "name": "diClamp1Closed"}, "door_clear": 6},
    }
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="session")
def write_process_cell() -> Callable[..., Path]:
    """Writes the process cell into a folder: write_process_cell(folder, name=...)."""
    return _write_process_cell


@pytest.fixture(scope="session")
def write_small_cell() -> SmallCell:
    """Writes the small test cell into a folder: write_small_cell(folder, name=..., extra_spots=...)."""
    return _write_small_cell


def _write_tool(folder: Path, shipped: str, load: Any) -> Path:
    """A copy of shipped tool `shipped` in `folder` (its meshes beside it), named after the folder,
    with tool.yaml `load` set to `load`; its tool.yaml."""
    from robomax_py.io.robot import shipped_robots_dir

    source = shipped_robots_dir() / "tools" / shipped
    folder.mkdir(parents=True, exist_ok=True)
    data = yaml.safe_load((source / "tool.yaml").read_text())
    for mesh in ("body", "tips"):
        shutil.copy(source / data[mesh], folder / data[mesh])
    data["name"] = folder.name
    data["load"] = load
    path = folder / "tool.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _write_small_cell_with_tool(folder: Path, tool: Path) -> Path:
    """The small test cell in `folder` with its tool the tool.yaml at `tool`."""
    path = _write_small_cell(folder)
    data = yaml.safe_load(path.read_text())
    data["tool"] = str(tool)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="session")
def write_tool() -> Callable[[Path, str, Any], Path]:
    """Writes a copy of a shipped tool with a load: write_tool(folder, shipped, load) -> its tool.yaml."""
    return _write_tool


@pytest.fixture(scope="session")
def write_small_cell_with_tool() -> Callable[[Path, Path], Path]:
    """Writes the small test cell using another tool: write_small_cell_with_tool(folder, tool_yaml)."""
    return _write_small_cell_with_tool


def _plan_set_state(folder: Path, name: str) -> str | None:
    """The plan id of the one consistent set of programs `name` in `folder` (None: no set, and no
    program file of the set's names readable): every file its manifest names has the manifest's
    sha256, and no other file named as the set's files are can be read. AssertionError otherwise."""
    import hashlib
    import json
    import re

    # The set's own names: the cell's, and FANUC's, named as its TP program (capitals; for short
    # names such as the tests', `export.fanuc.program_name` without importing the exporters).
    stems = {name, re.sub(r"[^A-Za-z0-9_]", "_", name).upper()}
    manifest = folder / f"{name}.manifest.json"
    readable = {p.name for p in folder.iterdir() if not p.name.startswith(".") and p.exists()
                and p.name.startswith(tuple(f"{stem}{sep}" for stem in stems for sep in "._"))}
    if not manifest.exists():
        assert not readable, f"program files without a manifest: {sorted(readable)}"
        return None
    doc = json.loads(manifest.read_text())
    listed = {f["name"]: f["sha256"] for f in doc["files"]}
    for file, sha in listed.items():
        assert hashlib.sha256((folder / file).read_bytes()).hexdigest() == sha, f"{file} is not the manifest's"
    others = readable - set(listed) - {manifest.name}
    assert not others, f"files not of the set: {sorted(others)}"
    return str(doc["plan"])


@pytest.fixture(scope="session")
def plan_set_state() -> Callable[[Path, str], str | None]:
    """plan_set_state(folder, name): the plan id of the one whole set of programs there (see
    `_plan_set_state`)."""
    return _plan_set_state


@pytest.fixture(scope="session")
def shared_once(tmp_path_factory: pytest.TempPathFactory, worker_id: str) -> Callable[[str, Callable[[], Any]], Any]:
    """shared_once(key, compute): `compute()` run once per test run, across the run's test workers
    (pytest-xdist gives each worker its own session fixtures: a plan that several test files use
    would otherwise be made once per worker). The first worker to ask computes under a file lock
    and pickles the answer into the run's temporary folder; the others read it. `key` names all
    the answer depends on (a cell file's bytes, the options): one key, one answer."""
    import hashlib
    import pickle

    from filelock import FileLock

    root = tmp_path_factory.getbasetemp()
    folder = (root.parent if worker_id != "master" else root) / "shared-once"
    folder.mkdir(exist_ok=True)

    def get(key: str, compute: Callable[[], Any]) -> Any:
        path = folder / f"{hashlib.sha256(key.encode()).hexdigest()[:32]}.pickle"
        with FileLock(str(path) + ".lock"):
            if path.exists():
                return pickle.loads(path.read_bytes())
            value = compute()
            path.write_bytes(pickle.dumps(value))
            return value

    return get


# The files that take longest, started first, so that test workers finish together (with
# `--dist loadfile` a file is one unit of work; the longest units first is the classic LPT rule).
LONGEST_FIRST = ("tests/test_shipped_cells.py", "tests/io/test_hostile.py", "tests/app/test_plan_files.py",
                 "tests/plan/test_tending_plan.py", "tests/controller_model/test_against_robomax.py",
                 "tests/plan/test_waiting.py", "tests/app/test_import_hostile.py", "tests/io/test_files.py")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    rank = {name: k for k, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(rank)))      # stable: the rest keep order


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--update-golden", action="store_true", help="rewrite tests/golden/* from current output")


@pytest.fixture
def update_golden(request: pytest.FixtureRequest) -> bool:
    return bool(request.config.getoption("--update-golden"))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


@pytest.fixture(scope="session")
def reference_cell_path() -> Path:
    """The contract's reference cell (a copy kept in tests/data/reference)."""
    assert REFERENCE_CELL.is_file(), f"{REFERENCE_CELL} is missing from the checkout"
    return REFERENCE_CELL


# Encoder pulses per degree stated for the test arms (KUKA kinematics) where a test writes Yaskawa
# INFORM, whose joint positions count pulses: a controller's pulse/degree parameters, as robot.yaml
# `controller.pulses_per_degree` states them for a Yaskawa arm.
TEST_PULSES_PER_DEGREE = (1194.7, 1194.7, 1194.7, 853.3, 853.3, 512.0)


def with_pulses(robot):  # type: ignore[no-untyped-def]
    """The robot with TEST_PULSES_PER_DEGREE stated on its controller (nothing else changes)."""
    import dataclasses

    return dataclasses.replace(robot, controller=dataclasses.replace(robot.controller,
                                                                      pulses_per_degree=TEST_PULSES_PER_DEGREE))


CROSSING_STATION = Path(__file__).resolve().parent / "data" / "station" / "crossing.yaml"


@pytest.fixture(scope="module")
def crossing_station_plan(shared_once: Callable[[str, Callable[[], Any]], Any],
                          tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """The files `robomax plan tests/data/station/crossing.yaml --format native,srcl --plot`
    writes, by name (the two-robot crossing station; planned once per test run, for the planner's tests and
    the station replay's)."""
    from typer.testing import CliRunner

    from robomax_py.app.cli import app

    def run() -> dict[str, str]:
        out = tmp_path_factory.mktemp("station")
        done = CliRunner().invoke(app, ["plan", str(CROSSING_STATION), "-o", str(out), "--format", "native,srcl",
                                        "--plot"])
        assert done.exit_code == 0, done.output
        # The Gantt charts of --plot are images: their first bytes stand for them (hex).
        return {p.name: p.read_bytes()[:8].hex() if p.suffix == ".png" else p.read_text()
                for p in out.iterdir() if p.is_file()}

    files: dict[str, str] = shared_once("station-crossing-cli:" + CROSSING_STATION.read_text(), run)
    return files
