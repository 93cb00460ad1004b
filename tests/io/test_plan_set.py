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

from robomax_py.io import plan_set
from robomax_py.io.files import TMP_SUFFIX, check_set, commit_set

# Two plans of one cell: "all" dialects, then srcl alone (large enough that writing takes a while).
# FANUC's files are named as its program (capitals); its routine is every plan's alike (shared).
OLD = {"c.json": "J" * 300_000, "c.srcl": "S" * 300_000, "c.src": "K" * 300_000, "c.dat": "D" * 300_000,
       "c_frames.src": "F" * 1000, "c.mod": "R" * 300_000, "C.ls": "T" * 300_000, "C_FRAMES.ls": "U" * 1000,
       "SPOT_WELD.ls": "W" * 100}
NEW = {"c.json": "j" * 300_000, "c.srcl": "s" * 300_000}
SHARED = frozenset({"SPOT_WELD.ls"})


def visible(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))


StateOf = Callable[[Path, str], "str | None"]


def test_a_new_set_replaces_the_old_one_whole_and_removes_what_it_lacks(tmp_path: Path, plan_set_state: StateOf) -> None:
    set_state = plan_set_state
    old = commit_set(tmp_path, "c", OLD, "cellsha", SHARED)
    assert set_state(tmp_path, "c") == old.plan
    new = commit_set(tmp_path, "c", NEW, "cellsha", SHARED)
    assert set_state(tmp_path, "c") == new.plan != old.plan
    assert new.removed == ("C.ls", "C_FRAMES.ls", "c.dat", "c.mod", "c.src", "c_frames.src")
    # FANUC's routine is every plan's: left, and said to be no plan's any more.
    assert new.unlisted == ("SPOT_WELD.ls",)
    assert visible(tmp_path) == ["SPOT_WELD.ls", "c.json", "c.manifest.json", "c.srcl"]
    hidden = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("."))
    assert len(hidden) == 2 and hidden[0] == ".c.robomax-set", hidden     # the pointer and one set folder


def test_the_same_files_give_the_same_manifest_bytes(tmp_path: Path) -> None:
    first = commit_set(tmp_path / "a", "c", NEW, "cellsha", SHARED)
    second = commit_set(tmp_path / "b", "c", NEW, "cellsha", SHARED)
    again = commit_set(tmp_path / "a", "c", NEW, "cellsha", SHARED)
    assert first.plan == second.plan == again.plan
    assert first.manifest.read_bytes() == second.manifest.read_bytes()
    doc = json.loads(first.manifest.read_text())
    assert doc["format"] == "robomax.manifest/1" and doc["cell_sha256"] == "cellsha"
    assert [f["name"] for f in doc["files"]] == ["c.json", "c.srcl"] and doc["shared"] == []
    shared = json.loads(commit_set(tmp_path / "s", "c", OLD, "cellsha", SHARED).manifest.read_text())
    assert [f["name"] for f in shared["shared"]] == ["SPOT_WELD.ls"]
    assert "SPOT_WELD.ls" not in [f["name"] for f in shared["files"]]
    assert commit_set(tmp_path / "a", "c", NEW, "other cell", SHARED).plan != first.plan


def test_an_older_robomax_set_of_plain_files_is_taken_over(tmp_path: Path) -> None:
    for name, text in OLD.items():
        (tmp_path / name).write_text(text.lower())
    commit_set(tmp_path, "c", NEW, "cellsha", SHARED)
    # The names of the new set are its links now; the older files it does not name stay, untouched.
    assert (tmp_path / "c.srcl").is_symlink() and (tmp_path / "c.srcl").read_text() == NEW["c.srcl"]
    assert not (tmp_path / "c.src").is_symlink() and (tmp_path / "c.src").read_text() == OLD["c.src"].lower()
    assert check_set(tmp_path / "c.srcl").whole


def test_check_set_tells_an_edited_or_foreign_file(tmp_path: Path) -> None:
    commit_set(tmp_path, "c", NEW, "cellsha", SHARED)
    assert check_set(tmp_path / "c.srcl").whole
    edited = tmp_path / "c.srcl"
    edited.unlink()
    edited.write_text("s" * 10)
    check = check_set(edited)
    assert check.manifest == tmp_path / "c.manifest.json" and not check.whole
    assert len(check.mismatched) == 1
    assert check.mismatched[0].startswith(f"c.srcl is not the file of plan {check.plan[:12]} that c.manifest.json "
                                          "lists (sha256 ")
    lone = tmp_path / "lone"
    lone.mkdir()
    (lone / "x.srcl").write_text("x")
    assert check_set(lone / "x.srcl").manifest is None


def test_check_set_finds_the_manifest_of_a_program_named_apart_and_tells_a_file_it_does_not_list(
        tmp_path: Path) -> None:
    old = commit_set(tmp_path, "c", OLD, "cellsha", SHARED)
    # FANUC's C.ls is the set c's: found by the manifest that lists it, through the link.
    assert check_set(tmp_path / "C.ls", [tmp_path / "C.ls", tmp_path / "C_FRAMES.ls"]).whole
    commit_set(tmp_path, "c", NEW, "cellsha", SHARED)
    # The old plan's C.ls put back by hand beside the new set: its manifest (named as it, case
    # aside) does not list it.
    (tmp_path / "C.ls").write_text(OLD["C.ls"])
    check = check_set(tmp_path / "C.ls")
    assert check.manifest == tmp_path / "c.manifest.json" and check.plan != old.plan
    assert check.mismatched == ((f"C.ls is not one of the files of plan {check.plan[:12]} that c.manifest.json "
                                 "lists (another plan's, or put there by hand)"),)


def test_without_symbolic_links_files_are_replaced_one_by_one_and_the_manifest_last(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, plan_set_state: StateOf) -> None:
    set_state = plan_set_state
    def refuse(*_: object, **__: object) -> None:
        raise OSError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(plan_set.os, "symlink", refuse)
    old = commit_set(tmp_path, "c", OLD, "cellsha", SHARED)
    assert not old.linked and set_state(tmp_path, "c") == old.plan
    done = commit_set(tmp_path, "c", NEW, "cellsha", SHARED)
    assert not done.linked
    # The old set's own files removed after the new manifest; the shared routine left and named.
    assert done.removed == ("C.ls", "C_FRAMES.ls", "c.dat", "c.mod", "c.src", "c_frames.src")
    assert done.unlisted == ("SPOT_WELD.ls",)
    assert visible(tmp_path) == ["SPOT_WELD.ls", "c.json", "c.manifest.json", "c.srcl"]
    assert not any(p.is_symlink() for p in tmp_path.iterdir())
    assert set_state(tmp_path, "c") == done.plan
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def _commit_forever(folder: str) -> None:
    # As `robomax` does: SIGTERM unwinds (temporary files and unfinished set folders removed), and
    # the signal is also kept and honoured between steps, since Python drops the exception a
    # handler raises while a finaliser runs (`app.commands.base._honour_signals` does this there).
    received: list[int] = []

    def on_term(signum: int, frame: object) -> None:
        received.append(signum)
        sys.exit(128 + signum)

    signal.signal(signal.SIGTERM, on_term)
    k = 0
    while not received:
        commit_set(Path(folder), "c", NEW if k % 2 == 0 else OLD, "cellsha", SHARED)
        k += 1
    sys.exit(128 + received[0])


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_a_writer_killed_at_any_instant_leaves_one_whole_set(tmp_path: Path, sig: signal.Signals,
                                                             plan_set_state: StateOf) -> None:
    """A process committing the two sets in turn, killed at seeded random instants: afterwards the
    folder holds one of them whole (by the manifest's sha256 sums), and the next commit cleans up."""
    old = commit_set(tmp_path, "c", OLD, "cellsha", SHARED).plan
    new = commit_set(tmp_path / "ref", "c", NEW, "cellsha", SHARED).plan
    rng = np.random.default_rng(20261203 + int(sig))
    ctx = multiprocessing.get_context("fork")
    for _ in range(12):
        proc = ctx.Process(target=_commit_forever, args=(str(tmp_path),))
        proc.start()
        time.sleep(float(rng.uniform(0.0, 0.4)))
        assert proc.pid is not None
        os.kill(proc.pid, sig)
        proc.join(120)                          # a hang guard only: it ends in milliseconds
        if proc.exitcode is None:               # never read the folder beside a live writer
            proc.kill()
            proc.join()
            pytest.fail(f"the writer still ran 120 s after {sig.name}")
        state = plan_set_state(tmp_path, "c")
        assert state in (old, new), state
    commit_set(tmp_path, "c", NEW, "cellsha", SHARED)
    assert plan_set_state(tmp_path, "c") == new
    # What the killed writers left (set folders, temporary links) is gone after the next commit.
    hidden = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".") and p.name != ".c.robomax-set")
    assert len(hidden) == 1 and not hidden[0].endswith(TMP_SUFFIX), hidden
