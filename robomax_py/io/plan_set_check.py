"""Whether a program file is one of the files of the plan's set beside it (`check_set`): the
manifest of its set found, and each file read compared with the sha256 the manifest lists (a mix
of two plans, an edited file, or one put there by hand)."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from robomax_py.errors import ProgramError
from robomax_py.io.plan_set import MANIFEST_FORMAT, MANIFEST_SUFFIX, _listed
from robomax_py.safe_files import LIMITS, read_text

# A set's own cell file (`robomax replan` writes the cell a continuation runs in beside its programs).
CELL_FILE_SUFFIX = ".cell.yaml"


@dataclass(frozen=True, slots=True)
class SetCheck:
    """Whether a program file is one of the files of the plan's set beside it.

    manifest : the manifest found (None: the file has none beside it; a lone program).
    mismatched : one line per file read that is not the file the manifest names (another plan's,
        an edited one, or one the manifest does not list), naming it.
    cell_sha256 : the cell digest the manifest names ("" without a manifest).
    plan : the plan id the manifest names ("" without a manifest).
    cell_file : the name of the cell file the set holds itself (`<name>.cell.yaml`: a
        continuation's, which runs in that cell), "" when it holds none.
    """

    manifest: Path | None
    mismatched: tuple[str, ...] = ()
    cell_sha256: str = ""
    plan: str = ""
    cell_file: str = ""          # the cell file the set holds (a continuation's, `robomax replan`), "" if none

    @property
    def whole(self) -> bool:
        return self.manifest is not None and not self.mismatched


def find_manifest(path: Path) -> Path | None:
    """The manifest of the set a program file belongs to: the one beside it, as the folder shows
    it (what a copy of the folder would hold), that lists its name; else one named as the program,
    case aside (FANUC's `SMALL_CELL.ls` is the set `small_cell`'s), which then does not list it;
    None for a lone program."""
    folder = path.parent
    try:
        manifests = sorted(p for p in folder.glob(f"*{MANIFEST_SUFFIX}") if p.is_file())
    except OSError:
        return None
    listing = next((m for m in manifests if path.name in _listed(m)), None)
    if listing is not None:
        return listing
    stem = path.name.split(".", 1)[0].lower()
    return next((m for m in manifests if m.name[: -len(MANIFEST_SUFFIX)].lower() == stem), None)


def check_set(path: Path, read: Sequence[Path] = ()) -> SetCheck:
    """Check a program file and the files read with it (its companions; default: the file alone)
    against the manifest of its set (`find_manifest`); ProgramError for a manifest that cannot be
    read."""
    manifest = find_manifest(path)
    if manifest is None:
        return SetCheck(None)
    text = read_text(manifest, LIMITS.program, ProgramError, "manifest")
    try:
        doc = json.loads(text)
        if doc.get("format") != MANIFEST_FORMAT:
            raise ValueError(f"format {doc.get('format')!r}")
        listed = {str(f["name"]): str(f["sha256"]) for f in doc["files"]}
        alike = {str(f["name"]) for f in doc.get("shared", [])}
        cell = str(doc.get("cell_sha256", ""))
        plan = str(doc.get("plan", ""))
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise ProgramError(manifest, None, f"not a robomax manifest ({exc})") from None
    bad = []
    for file in read or (path,):
        if file.name in alike:
            continue                 # every plan's of the folder, as the last one wrote it
        want = listed.get(file.name)
        try:
            got = hashlib.sha256(file.read_bytes()).hexdigest()
        except OSError as exc:
            bad.append(f"{file.name} cannot be read ({exc.strerror or exc})")
            continue
        if want is None:
            bad.append(f"{file.name} is not one of the files of plan {plan[:12]} that {manifest.name} lists "
                       "(another plan's, or put there by hand)")
        elif want != got:
            bad.append(f"{file.name} is not the file of plan {plan[:12]} that {manifest.name} lists (sha256 "
                       f"{got[:12]}..., the manifest's {want[:12]}...): another plan's, or edited")
    cell_file = next((n for n in listed if n.endswith(CELL_FILE_SUFFIX)), "")
    return SetCheck(manifest, tuple(bad), cell, plan, cell_file)
