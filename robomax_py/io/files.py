"""Atomic output: a file appears whole or not at all, and a plan's files are committed as one set.

Each file is written to a temporary file in the same folder and renamed over the target
(`io.atomic`). A plan's files and its manifest are switched in as a whole through one symbolic
link, so a reader or a killed run sees the old set or the new one, never a mix (`io.plan_set`, whose
docstring tells how, also where a folder holds no symbolic links); a program file is checked
against its set's manifest by `io.plan_set_check`. Everything is done under an exclusive lock on
the folder, and the next writer removes what a killed writer left.
"""

from __future__ import annotations

from robomax_py.io.atomic import (
    TMP_SUFFIX,
    folder_lock,
    signals_held,
    write_atomic,
    write_atomic_bytes,
)
from robomax_py.io.plan_set import (
    MANIFEST_FORMAT,
    MANIFEST_SUFFIX,
    SET_POINTER,
    CommittedSet,
    commit_set,
    manifest_text,
    write_programs,
)
from robomax_py.io.plan_set_check import SetCheck, check_set, find_manifest

# What this module offered before its parts moved out stays importable from here.
__all__ = [
    "MANIFEST_FORMAT", "MANIFEST_SUFFIX", "SET_POINTER", "TMP_SUFFIX", "CommittedSet", "SetCheck", "check_set",
    "commit_set", "find_manifest", "folder_lock", "manifest_text", "signals_held", "write_atomic",
    "write_atomic_bytes", "write_programs",
]
