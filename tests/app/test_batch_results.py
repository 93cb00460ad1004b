"""`robomax batch` results as they come: programs, journal rows and the summary written as each cell
finishes; `--resume` keeps only what is unchanged; `--shard I/N`; cells of one name in argument order.

The cells are planned by a stand-in worker (in the local pool's processes, as the real one is): each
file holds `name` and optionally `sleep` (s) or `fail: true`."""

from __future__ import annotations

import csv
import hashlib
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.batch import (
    BAD_INPUT,
    INFEASIBLE,
    PLANNED,
    BatchOptions,
    CellOutcome,
    PlanSettings,
    Shard,
    run_batch,
)
from robomax_py.app.batch_cell import file_digests
from robomax_py.app.batch_results import read_journals
from robomax_py.app.cli import EXIT_BAD_INPUT, app


def stand_in_worker(file: str, settings: PlanSettings) -> CellOutcome:
    """Plans a file as its keys say: a trajectory and a program named after `name`, the file its input."""
    text = Path(file).read_text()
    data = yaml.safe_load(text)
    time.sleep(data.get("sleep", 0))
    name = data["name"]
    if data.get("fail"):
        return CellOutcome(file, name, INFEASIBLE, 0.01, spots=1, reasons="seam/s1: unreachable (stand-in)")
    programs = ((f"{name}.json", json.dumps({"cell": name, "method": settings.method})), (f"{name}.srcl", text))
    return CellOutcome(file, name, PLANNED, 0.01, cycle_time=1.0, spots=1, detours=0, programs=programs,
                       cell_sha256=hashlib.sha256(text.encode()).hexdigest(), inputs=file_digests([file]))


def write_cells(folder: Path, **cells: dict[str, object]) -> list[str]:
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for stem, data in cells.items():
        path = folder / f"{stem}.yaml"
        path.write_text(yaml.safe_dump({"name": stem, **data}))
        paths.append(str(path))
    return paths


def rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def journal(out: Path) -> list[dict[str, Any]]:
    return read_journals(out)


def test_each_cell_is_written_as_it_finishes(tmp_path: Path) -> None:
    files = write_cells(tmp_path / "cells", a={}, b={"fail": True}, c={})
    out = tmp_path / "out"
    seen: list[tuple[str, list[str], int, bool]] = []

    def done(k: int, o: CellOutcome) -> CellOutcome:
        # Called once the cell's results are written: its programs, its journal row, the summary.
        seen.append((o.cell, [r["cell"] for r in rows(out / "summary.csv")], len(journal(out)),
                     (out / f"{o.cell}.srcl").exists()))
        return o

    outcomes = run_batch(files, out, BatchOptions(jobs=1), on_done=done, worker=stand_in_worker)
    assert [o.status for o in outcomes] == [PLANNED, INFEASIBLE, PLANNED]
    assert seen == [("a", ["a"], 1, True), ("b", ["a", "b"], 2, False), ("c", ["a", "b", "c"], 3, True)]
    row = journal(out)[0]
    assert row["status"] == PLANNED and row["programs"] == ["a.json", "a.srcl", "a.manifest.json"]
    assert row["inputs"] == [[files[0], hashlib.sha256(Path(files[0]).read_bytes()).hexdigest()]]
    assert row["plan"] == json.loads((out / "a.manifest.json").read_text())["plan"]
    assert [r["attempts"] for r in rows(out / "summary.csv")] == ["1", "1", "1"]


def test_resume_keeps_unchanged_cells_and_plans_the_rest(tmp_path: Path) -> None:
    files = write_cells(tmp_path / "cells", a={}, b={}, c={}, d={"fail": True})
    out = tmp_path / "out"
    first = run_batch(files, out, BatchOptions(jobs=2), worker=stand_in_worker)
    kept_plan = first[0].plan
    Path(files[1]).write_text(Path(files[1]).read_text() + "# edited\n")   # an input changed
    (out / "c.srcl").write_text("edited by hand\n")                        # a program no longer the set's
    with (out / "results.jsonl").open("a") as fh:
        fh.write('{"format": "robomax.batch.result/1", "file": ')          # a line a killed driver cut short

    again = run_batch(files, out, BatchOptions(jobs=2), worker=stand_in_worker, resume=True)
    assert [o.resumed for o in again] == [True, False, False, False]
    assert [o.status for o in again] == [PLANNED, PLANNED, PLANNED, INFEASIBLE]
    assert again[0].plan == kept_plan and (out / "a.srcl").read_text() == Path(files[0]).read_text()
    assert (out / "c.srcl").read_text() == Path(files[2]).read_text()
    assert [r["resumed"] for r in rows(out / "summary.csv")] == ["yes", "", "", ""]
    # The journal keeps the first run's rows and gains one for each cell planned again (the cut line
    # skipped), in finishing order.
    cells = [str(r["cell"]) for r in journal(out)]
    assert sorted(cells[:4]) == ["a", "b", "c", "d"] and sorted(cells[4:]) == ["b", "c", "d"]

    # Other options (formats) are another plan: nothing is kept.
    other = run_batch(files, out, BatchOptions(jobs=2, formats="srcl,krl"), worker=stand_in_worker, resume=True)
    assert not any(o.resumed for o in other)


def test_a_killed_drivers_last_line_is_skipped(tmp_path: Path) -> None:
    files = write_cells(tmp_path / "cells", a={})
    out = tmp_path / "out"
    run_batch(files, out, BatchOptions(jobs=1), worker=stand_in_worker)
    text = (out / "results.jsonl").read_text()
    (out / "results.jsonl").write_text(text + text[: len(text) // 2])     # killed while appending a row
    (kept,) = run_batch(files, out, BatchOptions(jobs=1), worker=stand_in_worker, resume=True)
    assert kept.resumed


def test_cells_of_one_name_resolve_in_argument_order_whichever_finishes_first(tmp_path: Path) -> None:
    folder = tmp_path / "cells"
    folder.mkdir()
    first, second = folder / "first.yaml", folder / "second.yaml"
    first.write_text(yaml.safe_dump({"name": "same", "sleep": 1.0}))     # finishes after the second
    second.write_text(yaml.safe_dump({"name": "same"}))
    out = tmp_path / "out"
    a, b = run_batch([str(first), str(second)], out, BatchOptions(jobs=2), worker=stand_in_worker)
    assert a.status == PLANNED and b.status == BAD_INPUT
    assert "also that of" in b.reasons and str(first) in b.reasons
    assert (out / "same.srcl").read_text() == first.read_text()


def test_shard_plans_every_nth_cell_and_writes_its_own_summary(tmp_path: Path) -> None:
    assert Shard.parse("2/3").picks(7) == [1, 4]
    assert Shard.parse(" 1 / 1 ").picks(2) == [0, 1]
    for bad in ("0/2", "3/2", "1", "a/b", "1/0"):
        with pytest.raises(ValueError, match="expected"):
            Shard.parse(bad)
    files = write_cells(tmp_path / "cells", a={}, b={}, c={})
    out = tmp_path / "out"
    (b,) = run_batch(files, out, BatchOptions(jobs=1), worker=stand_in_worker, shard=Shard(2, 2))
    assert b.cell == "b"
    assert sorted(p.name for p in out.glob("*.shard-*")) == ["results.shard-2-of-2.jsonl", "summary.shard-2-of-2.csv",
                                                            "summary.shard-2-of-2.md"]
    # A shard resumes from every journal of the folder: shard 1 of 1 keeps b, plans a and c.
    every = run_batch(files, out, BatchOptions(jobs=1), worker=stand_in_worker, resume=True, shard=Shard(1, 1))
    assert [o.resumed for o in every] == [False, True, False]


runner = CliRunner()


@pytest.mark.parametrize(("args", "message"), [
    (["--format", "srcl,nope"], "unknown program format 'nope'"),
    (["--shard", "3/2"], "expected 1 <= I <= N"),
])
def test_bad_batch_options_exit_2_before_anything_is_written(tmp_path: Path, args: list[str], message: str) -> None:
    (cell,) = write_cells(tmp_path / "cells", a={})
    out = tmp_path / "out"
    result = runner.invoke(app, ["batch", cell, "-o", str(out), *args])
    assert result.exit_code == EXIT_BAD_INPUT
    assert message in " ".join(result.output.split())
    assert not out.exists()


def test_an_unreachable_cluster_exits_2_before_anything_is_written(tmp_path: Path,
                                                                   free_port: Callable[..., int]) -> None:
    pytest.importorskip("ray")
    (cell,) = write_cells(tmp_path / "cells", a={})
    out = tmp_path / "out"
    address = f"127.0.0.1:{free_port()}"
    result = runner.invoke(app, ["batch", cell, "-o", str(out), "--ray-address", address])
    assert result.exit_code == EXIT_BAD_INPUT
    assert f"cannot reach the Ray cluster at {address}: nothing answers" in " ".join(result.output.split())
    assert not out.exists()
