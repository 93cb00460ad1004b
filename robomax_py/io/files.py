"""Atomic output: a file appears whole or not at all, and a plan's files are committed as one set.

Each file is written to a temporary file in the same folder and renamed over the target
(`io.atomic`).

A plan's files (`commit_set`, `io.plan_set`: the trajectory file, each dialect's files, the chart, and
`<name>.manifest.json`) are switched in as a whole: they are written into a fresh hidden folder
beside them, `.<name>.robomax-set-<plan>-<random>/`, and each `DIR/<file>` is a relative symbolic
link `.<name>.robomax-set/<file>` through one pointer, `DIR/.<name>.robomax-set`, a symbolic link
to the current set's folder. Renaming a new pointer over the old one (one `rename`) is the commit:
a reader, or a run killed at any instant (SIGKILL included), sees the old set or the new one,
never a mix. A file of the old set that the new one lacks (a dialect not written this time) then
names nothing and is removed; a regular file of the set's names that robomax did not write as
part of a set (an older robomax's, or one a user put there) is replaced when the new set has that
name and otherwise left alone (`robomax plan` names it). Files every plan of the folder
writes alike (`shared`: FANUC's `SPOT_WELD.ls`) are not the cell's: they are plain files, each
replaced atomically before the switch, and listed in the manifest apart from the set's own files
(`shared`), outside its sums, since any later plan of the folder may replace them.

Where the folder cannot hold symbolic links (a FAT-formatted stick), the files are replaced one by
one, the manifest last, and then the old set's files the new one lacks are removed: a kill can
leave a mix, which the manifest's sha256 sums expose (`check_set`, `io.plan_set_check`, which `robomax verify` uses).

Everything is done under an exclusive lock on the folder (flock on its directory descriptor: no
lock file is left), so two plans writing one folder at once end with one plan's complete set. The
next writer of a folder removes what a killed writer left: temporary files, unfinished set
folders and links that name nothing.
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
