"""A plan's files are committed as one set (`io.files.commit_set`): the old set or the new one,
never a mix, whatever instant a writer is killed at; files of the old set that the new one lacks
are removed; the manifest names every file with its sha256 and is the same bytes for the same files."""

from __future__ import annotations

import errno
import json
import multiprocessing
import os
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from robomax_py.io import files as files_module
from robomax_py.io.files import TMP_SUFFIX, check_set, commit_set

# Two plans of one cell: "all" dialects, then srcl alone (large enough that writing takes a while).
OLD = {"c.json": "J" * 300_000, "c.srcl": "S" * 300_000, "c.src": "K" * 300_000, "c.dat": "D" * 300_000,
       "c_frames.src": "F" * 1000, "c.mod": "R" * 300_000, "spot_weld.ls": "W" * 100}
NEW = {"c.json": "j" * 300_000, "c.srcl": "s" * 300_000}


def visible(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))


StateOf = Callable[[Path, str], "str | None"]


def test_a_new_set_replaces_the_old_one_whole_and_removes_what_it_lacks(tmp_path: Path, plan_set_state: StateOf) -> None:
    set_state = plan_set_state
    old = commit_set(tmp_path, "c", OLD, "cellsha")
    assert set_state(tmp_path, "c") == old.plan
    new = commit_set(tmp_path, "c", NEW, "cellsha")
    assert set_state(tmp_path, "c") == new.plan != old.plan
    assert new.removed == ("c.dat", "c.mod", "c.src", "c_frames.src")
    # FANUC's routine is every plan's: left, and said to be no plan's any more.
    assert new.unlisted == ("spot_weld.ls",)
    assert visible(tmp_path) == ["c.json", "c.manifest.json", "c.srcl", "spot_weld.ls"]
    hidden = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("."))
    assert len(hidden) == 2 and hidden[0] == ".c.robomax-set", hidden     # the pointer and one set folder


def test_the_same_files_give_the_same_manifest_bytes(tmp_path: Path) -> None:
    first = commit_set(tmp_path / "a", "c", NEW, "cellsha")
    second = commit_set(tmp_path / "b", "c", NEW, "cellsha")
    again = commit_set(tmp_path / "a", "c", NEW, "cellsha")
    assert first.plan == second.plan == again.plan
    assert first.manifest.read_bytes() == second.manifest.read_bytes()
    doc = json.loads(first.manifest.read_text())
    assert doc["format"] == "robomax.manifest/1" and doc["cell_sha256"] == "cellsha"
    assert [f["name"] for f in doc["files"]] == ["c.json", "c.srcl"]
    assert commit_set(tmp_path / "a", "c", NEW, "other cell").plan != first.plan


def test_an_older_robomax_set_of_plain_files_is_taken_over(tmp_path: Path) -> None:
    for name, text in OLD.items():
        (tmp_path / name).write_text(text.lower())
    commit_set(tmp_path, "c", NEW, "cellsha")
    # The names of the new set are its links now; the older files it does not name stay, untouched.
    assert (tmp_path / "c.srcl").is_symlink() and (tmp_path / "c.srcl").read_text() == NEW["c.srcl"]
    assert not (tmp_path / "c.src").is_symlink() and (tmp_path / "c.src").read_text() == OLD["c.src"].lower()
    assert check_set(tmp_path / "c.srcl").whole


def test_check_set_tells_an_edited_or_foreign_file(tmp_path: Path) -> None:
    commit_set(tmp_path, "c", NEW, "cellsha")
    assert check_set(tmp_path / "c.srcl").whole
    edited = tmp_path / "c.srcl"
    edited.unlink()
    edited.write_text("s" * 10)
    check = check_set(edited)
    assert check.manifest is not None and not check.whole
    assert "c.srcl has sha256" in check.mismatched[0]
    lone = tmp_path / "lone"
    lone.mkdir()
    (lone / "x.srcl").write_text("x")
    assert check_set(lone / "x.srcl").manifest is None


def test_without_symbolic_links_files_are_replaced_one_by_one_and_the_manifest_last(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, plan_set_state: StateOf) -> None:
    set_state = plan_set_state
    def refuse(*_: object, **__: object) -> None:
        raise OSError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(files_module.os, "symlink", refuse)
    done = commit_set(tmp_path, "c", NEW, "cellsha")
    assert not done.linked
    assert visible(tmp_path) == ["c.json", "c.manifest.json", "c.srcl"]
    assert not any(p.is_symlink() for p in tmp_path.iterdir())
    assert set_state(tmp_path, "c") == done.plan
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def _commit_forever(folder: str) -> None:
    # As `robomax` does: SIGTERM unwinds (temporary files and unfinished set folders removed).
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    k = 0
    while True:
        commit_set(Path(folder), "c", NEW if k % 2 == 0 else OLD, "cellsha")
        k += 1


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_a_writer_killed_at_any_instant_leaves_one_whole_set(tmp_path: Path, sig: signal.Signals,
                                                             plan_set_state: StateOf) -> None:
    """A process committing the two sets in turn, killed at seeded random instants: afterwards the
    folder holds one of them whole (by the manifest's sha256 sums), and the next commit cleans up."""
    old = commit_set(tmp_path, "c", OLD, "cellsha").plan
    new = commit_set(tmp_path / "ref", "c", NEW, "cellsha").plan
    rng = np.random.default_rng(20261203 + int(sig))
    ctx = multiprocessing.get_context("fork")
    for _ in range(12):
        proc = ctx.Process(target=_commit_forever, args=(str(tmp_path),))
        proc.start()
        time.sleep(float(rng.uniform(0.0, 0.4)))
        assert proc.pid is not None
        os.kill(proc.pid, sig)
        proc.join(30)
        state = plan_set_state(tmp_path, "c")
        assert state in (old, new), state
    commit_set(tmp_path, "c", NEW, "cellsha")
    assert plan_set_state(tmp_path, "c") == new
    # What the killed writers left (set folders, temporary links) is gone after the next commit.
    hidden = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".") and p.name != ".c.robomax-set")
    assert len(hidden) == 1 and not hidden[0].endswith(TMP_SUFFIX), hidden
