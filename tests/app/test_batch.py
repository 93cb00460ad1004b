"""`robomax batch`: statuses per cell, exit codes, summary files, timeouts, crashed workers, determinism."""

from __future__ import annotations

import csv
import json
import os
import signal
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robomax_py.app.batch import (
    BAD_INPUT,
    CRASHED,
    INFEASIBLE,
    PLANNED,
    TIMEOUT,
    BatchOptions,
    CellOutcome,
    PlanSettings,
    run_local,
    run_ray,
)
from robomax_py.app.cli import (
    EXIT_BAD_INPUT,
    EXIT_INFEASIBLE,
    EXIT_OK,
    _bare_ray_flag,
    app,
)

SmallCell = Callable[..., Path]   # conftest.write_small_cell
FORMATS = "srcl,krl"              # batch --format, as plan takes it
FAR_SPOT = {"name": "far", "xyz": [4.0, 0.0, 1.0], "normal": [-1, 0, 0], "direction": [0, 1, 0]}
runner = CliRunner()


@dataclass(frozen=True)
class Batch:
    cells: Path
    files: list[str]
    out: Path
    exit_code: int
    output: str


@pytest.fixture(scope="module")
def batch_run(tmp_path_factory: pytest.TempPathFactory, write_small_cell: SmallCell) -> Batch:
    """Two small cells, one infeasible, one bad file: planned by `robomax batch -j 2` once for the module."""
    cells = tmp_path_factory.mktemp("cells")
    a = write_small_cell(cells, "cell_a")
    b = write_small_cell(cells, "cell_b")
    far = write_small_cell(cells, "cell_far", [FAR_SPOT])
    bad = write_small_cell(cells, "cell_bad")
    bad.write_text(bad.read_text().replace("weld_time: 0.5", "weld_time: -1"))
    files = [str(p) for p in (a, far, bad, b)]
    out = cells / "out"
    result = runner.invoke(app, ["batch", *files, "-j", "2", "-o", str(out), "--format", FORMATS])
    return Batch(cells, files, out, result.exit_code, result.output)


def read_summary(out: Path) -> list[dict[str, str]]:
    with (out / "summary.csv").open(newline="") as fh:
        return list(csv.DictReader(fh))


def test_batch_statuses_in_argument_order_and_exit_2_for_a_bad_file(batch_run: Batch) -> None:
    assert batch_run.exit_code == EXIT_BAD_INPUT, batch_run.output
    rows = read_summary(batch_run.out)
    assert [r["file"] for r in rows] == batch_run.files
    assert [r["status"] for r in rows] == [PLANNED, INFEASIBLE, BAD_INPUT, PLANNED]
    a, far, bad, _b = rows
    assert float(a["cycle_time_s"]) > 0 and a["spots"] == "2" and a["detours"] != ""
    assert "flange/far: unreachable" in far["reasons"] and far["cycle_time_s"] == ""
    assert "cell_bad.yaml" in bad["reasons"] and "process.weld_time" in bad["reasons"]
    assert "Traceback" not in batch_run.output


def test_batch_writes_programs_of_planned_cells_only_and_a_markdown_table(batch_run: Batch) -> None:
    names = sorted(p.name for p in batch_run.out.iterdir() if not p.name.startswith("."))
    krl = ["{}.dat", "{}.src", "{}_frames.src"]
    assert names == sorted([*(f.format(c) for c in ("cell_a", "cell_b") for f in ["{}.json", "{}.manifest.json",
                                                                                  "{}.srcl", *krl]),
                            "results.jsonl", "summary.csv", "summary.md"])
    md = (batch_run.out / "summary.md").read_text().splitlines()
    table = [line for line in md if line.startswith("|")]
    assert table[0].split("|")[1:4] == [" cell ", " file ", " status "]
    assert len(table) == 2 + len(batch_run.files)
    assert "| cell_far |" in table[3] and f"| {INFEASIBLE} |" in table[3]


def _notices(file: str) -> list[str]:
    from robomax_py.io.cell import load_cell

    return [str(n) for n in load_cell(file).notices]


def test_batch_counts_each_cell_s_warnings_and_prints_them(batch_run: Batch) -> None:
    """The small cell keeps `clearance: 0` beside its workpiece (docs/cell_warnings.md): the summary
    and the printed table count each cell's warnings, as `check` finds them, and stderr gives each
    text as `check` prints it; a file that does not load has none to count."""
    a, far, _bad, b = batch_run.files
    warned = {f: _notices(f) for f in (a, far, b)}
    assert any("process.clearance" in line for line in warned[a])
    rows = read_summary(batch_run.out)
    assert [r["warnings"] for r in rows] == [str(len(warned[a])), str(len(warned[far])), "", str(len(warned[b]))]
    for lines in warned.values():
        for line in lines:
            assert f"warning: {line}" in batch_run.output
    md = [line.split("|") for line in (batch_run.out / "summary.md").read_text().splitlines() if line.startswith("|")]
    column = [c.strip() for c in md[0]].index("warnings")
    assert [row[column].strip() for row in md[2:]] == [r["warnings"] for r in rows]
    assert "warnings" in batch_run.output.split("batch:", 1)[1]          # the printed table's column


def test_batch_json_lists_each_cell_s_warnings(batch_run: Batch, tmp_path: Path) -> None:
    """--json gives each cell's warnings as `plan --json` does: file, key and message."""
    far = batch_run.files[1]
    result = runner.invoke(app, ["batch", far, "-o", str(tmp_path / "out"), "--json"])
    assert result.exit_code == EXIT_INFEASIBLE, result.output
    (cell,) = json.loads(result.stdout)["cells"]
    assert cell["status"] == INFEASIBLE
    assert [f"{w['file']}: {w['key']}: {w['message']}" for w in cell["warnings"]] == _notices(far) != []


def test_batch_programs_equal_plan_programs_byte_for_byte(batch_run: Batch, tmp_path: Path) -> None:
    result = runner.invoke(app, ["plan", batch_run.files[0], "-o", str(tmp_path), "--format", FORMATS])
    assert result.exit_code == EXIT_OK, result.output
    # The same set, written the same way: its manifest (the cell file's digest, each file's sha256) too.
    for ext in (".json", ".srcl", ".src", ".dat", "_frames.src", ".manifest.json"):
        assert (tmp_path / f"cell_a{ext}").read_bytes() == (batch_run.out / f"cell_a{ext}").read_bytes()
        assert (batch_run.out / f"cell_a{ext}").is_symlink()


def test_missing_cell_file_exits_2_up_front_and_plans_nothing(batch_run: Batch, tmp_path: Path) -> None:
    out = tmp_path / "out"
    missing = str(tmp_path / "nope.yaml")
    result = runner.invoke(app, ["batch", batch_run.files[0], missing, "-o", str(out)])
    assert result.exit_code == EXIT_BAD_INPUT
    assert "nope.yaml" in result.output and "not found" in result.output
    assert not out.exists()


def test_timeout_is_reported_the_worker_killed_and_exit_3(batch_run: Batch, tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = runner.invoke(app, ["batch", batch_run.files[0], "-o", str(out), "--timeout", "0.2"])
    assert result.exit_code == EXIT_INFEASIBLE, result.output
    (row,) = read_summary(out)
    assert row["status"] == TIMEOUT and "0.2 s" in row["reasons"]
    assert sorted(p.name for p in out.iterdir()) == ["results.jsonl", "summary.csv", "summary.md"]


DEADLINE_S = 60.0      # a cell's deadline in the tests where one must time out (it sleeps far longer)


def fake_worker(file: str, settings: PlanSettings) -> CellOutcome:
    """Test worker (imported by name in each cell's process): dies as the file's stem says, else 'plans'."""
    stem = Path(file).stem
    if stem == "exits":
        os._exit(7)
    if stem == "killed":
        os.kill(os.getpid(), signal.SIGKILL)
    if stem == "raises":
        raise ValueError("a bug")
    if stem == "sleeps":
        time.sleep(600)
    return CellOutcome(file, stem, PLANNED, 0.0, cycle_time=1.0, spots=1, detours=0)


def test_crashed_workers_are_reported_and_the_others_finish() -> None:
    files = ["ok1.yaml", "exits.yaml", "killed.yaml", "raises.yaml", "ok2.yaml"]
    seen: list[int] = []

    def done(i: int, o: CellOutcome) -> CellOutcome:
        seen.append(i)
        return o

    outcomes = run_local(files, BatchOptions(jobs=2), done, worker=fake_worker)
    assert [o.file for o in outcomes] == files
    assert [o.status for o in outcomes] == [PLANNED, CRASHED, CRASHED, CRASHED, PLANNED]
    assert "exited with code 7" in outcomes[1].reasons
    assert "SIGKILL" in outcomes[2].reasons
    assert "ValueError: a bug" in outcomes[3].reasons
    assert sorted(seen) == list(range(len(files)))


def test_bare_ray_flag_means_a_local_ray() -> None:
    assert _bare_ray_flag(["batch", "a.yaml", "--ray"]) == ["batch", "a.yaml", "--ray=local"]
    assert _bare_ray_flag(["batch", "--ray", "a.yaml"]) == ["batch", "--ray=local", "a.yaml"]
    assert _bare_ray_flag(["batch", "--ray", "-j", "2", "a.yaml"]) == ["batch", "--ray=local", "-j", "2", "a.yaml"]
    assert _bare_ray_flag(["batch", "a.yaml", "--ray", "ray://head:10001"]) == \
        ["batch", "a.yaml", "--ray", "ray://head:10001"]


@pytest.mark.slow
def test_ray_batch_gives_the_same_bytes_as_the_local_pool(batch_run: Batch, tmp_path: Path) -> None:
    pytest.importorskip("ray")
    out = tmp_path / "out"
    result = runner.invoke(app, ["batch", *batch_run.files, "-j", "2", "-o", str(out), "--format", FORMATS,
                                 "--ray=local"])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    assert [r["status"] for r in read_summary(out)] == [PLANNED, INFEASIBLE, BAD_INPUT, PLANNED]
    for name in ("cell_a.json", "cell_a.srcl", "cell_a.src", "cell_b.json", "cell_b.srcl", "cell_b.dat"):
        assert (out / name).read_bytes() == (batch_run.out / name).read_bytes()
    # The same reasons and warnings, naming the cell files as given (not the task's copies of them).
    for key in ("reasons", "warnings"):
        assert [r[key] for r in read_summary(out)] == [r[key] for r in read_summary(batch_run.out)]
    for line in (line for line in batch_run.output.splitlines() if line.startswith("warning:")):
        assert line in result.output


@pytest.mark.slow
def test_ray_reports_crashed_and_timed_out_tasks_and_finishes_the_others(tmp_path: Path,
                                                                         write_small_cell: SmallCell) -> None:
    pytest.importorskip("ray")
    import sys

    # Real cell files (the driver loads each to ship its files), planned by the fake worker.
    files = [str(write_small_cell(tmp_path, stem)) for stem in ("ok1", "exits", "sleeps", "ok2")]
    path = os.pathsep.join([str(Path(__file__).parent), *sys.path])   # Ray workers import this module
    # The deadline covers starting a cell's process too: about 20 s was seen on a loaded 2-core
    # machine, where a deadline of 20 s timed out a cell that plans at once.
    outcomes = run_ray(files, BatchOptions(jobs=2, timeout=DEADLINE_S), worker=fake_worker,
                       init_kwargs={"runtime_env": {"env_vars": {"PYTHONPATH": path}}})
    assert [o.status for o in outcomes] == [PLANNED, CRASHED, TIMEOUT, PLANNED]
    # A cell's own crash and deadline are found in the task, as in the local pool: not retried.
    assert "exited with code 7" in outcomes[1].reasons and f"{DEADLINE_S:g} s" in outcomes[2].reasons
    assert [o.attempts for o in outcomes] == [1, 1, 1, 1]      # (the sleeping cell would be planned, not timed out,
                                                               # had its worker not been killed)


def test_batch_counts_and_prints_the_robot_file_s_warnings(tmp_path: Path, write_small_cell: SmallCell) -> None:
    """A robot file without accelerations and jerks (as `import-urdf` writes one where the URDF has
    none): `check` and `plan` warn that they are derived; the batch counts that warning with the
    cell file's and prints the same line."""
    import shutil

    import yaml

    from robomax_py.io.robot_paths import shipped_robots_dir

    robot_dir = tmp_path / "kr125_derived"
    shutil.copytree(shipped_robots_dir() / "kr125", robot_dir)
    data = yaml.safe_load((robot_dir / "robot.yaml").read_text())
    del data["limits"]
    data["name"] = robot_dir.name
    (robot_dir / "robot.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    cell = write_small_cell(tmp_path, "derived")
    cell_data = yaml.safe_load(cell.read_text())
    cell_data["robot"]["model"] = str(robot_dir)
    cell.write_text(yaml.safe_dump(cell_data, sort_keys=False))
    checked = " ".join(runner.invoke(app, ["check", str(cell)]).output.split())
    warning = f"warning: {robot_dir / 'robot.yaml'}: limits.acceleration and limits.jerk not given; derived"
    assert warning in checked
    out = tmp_path / "out"
    result = runner.invoke(app, ["batch", str(cell), "-j", "1", "-o", str(out), "--format", "srcl"])
    assert result.exit_code == EXIT_OK, result.output
    assert warning in " ".join(result.output.split())
    (row,) = read_summary(out)
    assert row["warnings"] == str(len(_notices(str(cell))) + 1)
