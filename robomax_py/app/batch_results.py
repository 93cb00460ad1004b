"""A batch's results, written as each cell finishes: its programs, its line in the journal, the summary.

`BatchWriter.add` is called in the driver's process as each cell finishes. A planned cell's
programs are written at once, as `robomax plan` writes them (one set with its manifest,
`io.files.commit_set`); its row is appended to the journal (`results.jsonl`, one JSON object a line,
synced); `summary.csv` and `summary.md` are written anew (atomically) with the rows of the cells
finished so far, in argument order. A driver killed at any moment leaves every finished cell's
programs and rows, and `--resume` (`resumable`) takes them up.

Two cells of one name would write the same program files: the first in argument order that is
planned writes them, a later one is `bad input` (as before results were written as they came, a
planned cell waits until the earlier cells of its name are done, so the outcome does not depend on
which finishes first).
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from robomax_py.app.batch_cell import (
    BAD_INPUT,
    PLANNED,
    STATUSES,
    CellOutcome,
    file_digests,
)

SUMMARY_COLUMNS = ("cell", "file", "status", "cycle_time_s", "planning_s", "spots", "detours", "reasons",
                   "warnings", "peak_rss_mb", "attempts", "node", "resumed", "notes")
JOURNAL_FORMAT = "robomax.batch.result/1"


def write_outcome_programs(out_dir: Path, outcome: CellOutcome, taken: dict[str, str]) -> CellOutcome:
    """Write a planned outcome's programs as `robomax plan` does (one set with its manifest,
    `io.files.commit_set`); the outcome without texts, with paths and the set's plan id.

    `taken` maps program file names already written in this batch to the cell file that wrote them:
    a second cell of the same name would overwrite them, so it becomes `bad input` and writes nothing.
    """
    from robomax_py.io.files import commit_set

    if outcome.status != PLANNED or outcome.resumed:
        return outcome
    from robomax_py.export import SHARED_FILES

    # Files every cell writes alike (FANUC's SPOT_WELD.ls) do not belong to one cell.
    own = [name for name, _ in outcome.programs if name not in SHARED_FILES]
    clash = next((taken[name] for name in own if name in taken), None)
    if clash is not None:
        return replace(outcome, status=BAD_INPUT, programs=(), cycle_time=None, detours=None,
                       reasons=f"{outcome.file}: name: cell name '{outcome.cell}' is also that of {clash}; "
                               "its programs would overwrite those")
    # The set is named as its trajectory file (publish renders it first): the cell, or <cell>_published / <cell>_teach_in.
    name = next((n.removesuffix(".json") for n, _ in outcome.programs if n.endswith(".json")), outcome.cell)
    committed = commit_set(out_dir, name, dict(outcome.programs), outcome.cell_sha256, SHARED_FILES)
    written = [*committed.paths, committed.manifest]
    for name in own:
        taken[name] = outcome.file
    return replace(outcome, programs=(), written=tuple(str(p) for p in written), plan=committed.plan)


# ------------------------------------------------------------------------------ summary tables


def summary_rows(outcomes: Sequence[CellOutcome]) -> list[dict[str, str]]:
    """One row per cell, columns SUMMARY_COLUMNS, fixed formats (s with 3 decimals)."""
    def num(v: float | None, fmt: str) -> str:
        return "" if v is None else format(v, fmt)

    return [
        {"cell": o.cell, "file": o.file, "status": o.status, "cycle_time_s": num(o.cycle_time, ".3f"),
         "planning_s": num(o.seconds, ".3f"), "spots": num(o.spots, "d"), "detours": num(o.detours, "d"),
         "reasons": o.reasons, "warnings": "" if o.spots is None else str(len(o.warnings)),
         "peak_rss_mb": num(o.peak_rss_mb, ".0f"), "attempts": str(o.attempts),
         "node": o.node, "resumed": "yes" if o.resumed else "", "notes": o.notes}
        for o in outcomes
    ]


def summary_csv(outcomes: Sequence[CellOutcome]) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=SUMMARY_COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(summary_rows(outcomes))
    return buf.getvalue()


def summary_markdown(outcomes: Sequence[CellOutcome], total: int | None = None) -> str:
    """The summary as a Markdown table; `total`: cells in the batch, when some are not done yet."""
    counts = {s: sum(1 for o in outcomes if o.status == s) for s in STATUSES}
    head = ", ".join(f"{n} {s}" for s, n in counts.items() if n)
    done = "" if total is None or total == len(outcomes) else f" ({total - len(outcomes)} not done yet)"
    lines = [f"# Batch summary: {len(outcomes)} cell(s), {head}{done}", "",
             "| " + " | ".join(SUMMARY_COLUMNS) + " |", "|" + "---|" * len(SUMMARY_COLUMNS)]
    for row in summary_rows(outcomes):
        cells = (row[c].replace("|", "\\|").replace("\n", " ") for c in SUMMARY_COLUMNS)
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_summary(out_dir: Path, outcomes: Sequence[CellOutcome], stem: str = "summary",
                  total: int | None = None) -> list[Path]:
    """DIR/<stem>.csv and DIR/<stem>.md, each written atomically."""
    from robomax_py.io.files import write_atomic

    paths = [out_dir / f"{stem}.csv", out_dir / f"{stem}.md"]
    write_atomic(paths[0], summary_csv(outcomes))
    write_atomic(paths[1], summary_markdown(outcomes, total))
    return paths


# ------------------------------------------------------------------------------ the journal


def journal_line(outcome: CellOutcome, options: Mapping[str, Any]) -> str:
    """One JSON object (one line) for the journal: the summary row's facts, the program files, the
    plan id, the inputs with their sha256 and the options the cell was planned with."""
    doc = {"format": JOURNAL_FORMAT, "file": outcome.file, "path": os.path.abspath(outcome.file),
           "cell": outcome.cell, "status": outcome.status, "cycle_time_s": outcome.cycle_time,
           "planning_s": round(outcome.seconds, 3), "spots": outcome.spots, "detours": outcome.detours,
           "reasons": outcome.reasons, "notes": outcome.notes,
           "warnings": [{"file": n.file, "key": n.key, "message": n.message} for n in outcome.warnings],
           "peak_rss_mb": None if outcome.peak_rss_mb is None else round(outcome.peak_rss_mb),
           "attempts": outcome.attempts, "node": outcome.node, "cell_sha256": outcome.cell_sha256,
           "plan": outcome.plan, "programs": [Path(p).name for p in outcome.written],
           "inputs": [list(pair) for pair in outcome.inputs], "options": dict(options)}
    return json.dumps(doc, separators=(",", ":")) + "\n"


def append_line(path: Path, line: str) -> None:
    """Append one line and sync it: a killed driver loses at most the line being written (which
    `read_journals` then skips; the next line starts on a line of its own)."""
    with open(path, "a+b") as fh:
        if fh.tell() > 0:
            fh.seek(-1, os.SEEK_END)
            if fh.read(1) != b"\n":
                line = "\n" + line
        fh.write(line.encode("utf-8"))
        fh.flush()
        os.fsync(fh.fileno())


def read_journals(out_dir: Path) -> list[dict[str, Any]]:
    """Every well-formed row of every journal in the folder (`results*.jsonl`: shards' too), in file
    and line order; a line cut short by a kill, or not a journal row, is skipped."""
    rows: list[dict[str, Any]] = []
    for path in sorted(out_dir.glob("results*.jsonl")):
        try:
            lines = path.read_text(encoding="utf-8").splitlines()
        except (OSError, UnicodeDecodeError):
            continue
        for line in lines:
            try:
                row = json.loads(line)
            except ValueError:
                continue
            if isinstance(row, dict) and row.get("format") == JOURNAL_FORMAT:
                rows.append(row)
    return rows


def resumable(out_dir: Path, options: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """Journal rows of cells planned with these options, by the cell file's absolute path (the last
    such row of each); `resumed_outcome` then checks that nothing changed since."""
    found: dict[str, dict[str, Any]] = {}
    for row in read_journals(out_dir):
        if row.get("status") == PLANNED and row.get("options") == dict(options) and isinstance(row.get("path"), str):
            found[row["path"]] = row
    return found


def resumed_outcome(row: Mapping[str, Any], file: str, out_dir: Path) -> CellOutcome | None:
    """The outcome of a cell planned by an earlier run (`resumable`), when its programs are still
    there whole and every file it read is unchanged (the cell file and its includes, so its digest,
    the robot, the tool, the meshes); None when it must be planned again."""
    from robomax_py.errors import RobomaxError
    from robomax_py.export import SHARED_FILES
    from robomax_py.io.files import MANIFEST_SUFFIX, check_set
    from robomax_py.spec import Notice

    try:
        inputs = [(str(p), str(h)) for p, h in row["inputs"]]
        programs = [str(n) for n in row["programs"]]
        if not inputs or not programs or list(file_digests([p for p, _ in inputs])) != inputs:
            return None
        read = [out_dir / n for n in programs if not n.endswith(MANIFEST_SUFFIX) and n not in SHARED_FILES]
        check = check_set(read[0], read)
        if not check.whole or check.cell_sha256 != row["cell_sha256"] or check.plan != row["plan"]:
            return None
        return CellOutcome(file, str(row["cell"]), PLANNED, float(row["planning_s"]), cycle_time=row["cycle_time_s"],
                           spots=row["spots"], detours=row["detours"], written=tuple(str(out_dir / n) for n in programs),
                           cell_sha256=str(row["cell_sha256"]), peak_rss_mb=row["peak_rss_mb"],
                           inputs=tuple(inputs), attempts=int(row["attempts"]), node=str(row["node"]),
                           notes=str(row["notes"]), plan=str(row["plan"]), resumed=True,
                           warnings=tuple(Notice(str(n["file"]), str(n["key"]), str(n["message"])) for n in row["warnings"]))
    except (KeyError, TypeError, ValueError, IndexError, RobomaxError):
        return None


# ------------------------------------------------------------------------------ the writer


def name_key(file: str) -> str:
    """What a cell's program files are named after, as far as it can be told without loading it:
    its `name` (else the file stem), lower case, other characters than letters and digits as `_`
    (FANUC names programs in capitals, with `_` for what it cannot hold)."""
    from robomax_py.errors import CellFileError, RobomaxError
    from robomax_py.io.yaml_files import read_yaml_mapping
    from robomax_py.safe_files import LIMITS

    name: object = None
    try:
        name = read_yaml_mapping(Path(file), CellFileError, "cell file", LIMITS.cell).get("name")
    except (RobomaxError, OSError, ValueError, TypeError, AttributeError):
        pass
    return re.sub(r"[^a-z0-9]", "_", (name if isinstance(name, str) else Path(file).stem).lower())


class BatchWriter:
    """Writes a batch's results into `out_dir` as its cells finish (module docstring).

    files : the batch's cell files, in argument order.
    options : what the cells are planned with, recorded in each journal row (`--resume` compares).
    stem : the summary files' and the journal's name: `summary` / `results`, or a shard's.
    fresh : start a new journal (else append to it: `--resume`).
    """

    def __init__(self, out_dir: Path, files: Sequence[str], options: Mapping[str, Any], *, journal: str = "results",
                 summary: str = "summary", fresh: bool = True) -> None:
        from robomax_py.io.files import write_atomic

        self.out_dir = out_dir
        self.files = list(files)
        self.options = dict(options)
        self.journal = out_dir / f"{journal}.jsonl"
        self.summary = summary
        self._keys = [name_key(f) for f in self.files]
        self._waiting: dict[int, CellOutcome] = {}
        self._kept: dict[int, CellOutcome] = {}
        self._taken: dict[str, str] = {}
        out_dir.mkdir(parents=True, exist_ok=True)
        if fresh or not self.journal.exists():
            write_atomic(self.journal, "")
        write_summary(out_dir, [], summary, len(self.files))

    def add(self, i: int, outcome: CellOutcome) -> CellOutcome:
        """Cell i is done: write what it gives once the earlier cells of its name are done; the
        outcome as it is now (its programs may not be written yet). A resumed cell's programs and
        journal row are there already: its file names are only taken."""
        self._waiting[i] = outcome
        for j in sorted(self._waiting):
            if all(k in self._kept for k in range(j) if self._keys[k] == self._keys[j]):
                self._keep(j, self._waiting.pop(j))
        return self._kept.get(i, outcome)

    def _keep(self, i: int, outcome: CellOutcome) -> None:
        if outcome.resumed:
            from robomax_py.export import SHARED_FILES

            self._taken.update({Path(p).name: outcome.file for p in outcome.written if Path(p).name not in SHARED_FILES})
            kept = outcome
        else:
            kept = write_outcome_programs(self.out_dir, outcome, self._taken)
            append_line(self.journal, journal_line(kept, self.options))
        self._kept[i] = kept
        write_summary(self.out_dir, [self._kept[k] for k in sorted(self._kept)], self.summary, len(self.files))

    def outcomes(self) -> tuple[CellOutcome, ...]:
        """Every cell's outcome in argument order, once all are added."""
        for j in sorted(self._waiting):            # none are left unless a cell was never added
            self._keep(j, self._waiting.pop(j))
        return tuple(self._kept[i] for i in range(len(self.files)))
