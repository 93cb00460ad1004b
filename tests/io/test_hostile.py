"""Hostile and broken input: a seeded generator of more than 1,000 mutants of the shipped
cells, robot folders and program files, each run through the command in-process with a time and
memory bound. The test fails on any traceback, any run past the bound, any refusal whose message
does not name a file, and any file written. A smaller sample runs through `plan` and `batch` (slow).

Classes: keys missing or misspelt at every level, wrong types, NaN / inf / zero / negative /
huge numbers, duplicate names, bad meshes (missing, empty, garbage, a folder, a symlink loop, a
device, a FIFO, a NUL byte, names too long), YAML hazards (alias bombs, recursive aliases, deep
nesting, complex and non-string keys, huge integers, non-UTF-8, BOM, empty, several documents, a
file over the size limit), odd names, robot.yaml and URDF mutants, and program-file mutants for
`verify` (truncated, non-UTF-8, gigantic, deeply nested, numbers out of range).
"""

from __future__ import annotations

import copy
import os
import resource
import shutil
import signal
import time
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import app

REPO = Path(__file__).resolve().parents[2]
# The shipped cells that stand in one file: a mutant is written alone into a temporary folder. A
# cell that includes files or reads a spot list (flanged_panel) is left to the tests of includes
# and spot lists, which mutate those files themselves.
CELLS = sorted(p for p in (REPO / "cells").glob("*.yaml")
               if not {"include", "spot_lists"} & set(yaml.safe_load(p.read_text(encoding="utf-8"))))
ROBOTS = REPO / "robomax_py" / "robots"
CPU_S_PER_FILE = 30.0            # a refusal takes well under a CPU second; a full check a few
# A run blocked without using CPU (a read from a FIFO) is caught by a wall-clock guard far above any
# run's time on a loaded machine: it stops a hang, it does not judge speed.
HANG_GUARD_S = 600.0
PEAK_RSS_MB = 3000               # the whole test process, after every mutant
runner = CliRunner()


@dataclass(frozen=True)
class Mutant:
    kind: str
    name: str
    build: Callable[[Path], Path]     # folder -> the file to run the command on


class Hang(Exception):
    pass


@contextmanager
def _bounded(cpu_s: float, guard_s: float = HANG_GUARD_S) -> Iterator[None]:
    """Hang raised once the process has used `cpu_s` CPU seconds (user + system, ITIMER_PROF: the
    same on a loaded machine as on a quiet one), or after `guard_s` seconds of blocking."""
    def stop(signum: int, frame: Any) -> None:
        what = f"{cpu_s} CPU s" if signum == signal.SIGPROF else f"{guard_s} s without ending"
        raise Hang(f"still running after {what}")

    old = {s: signal.signal(s, stop) for s in (signal.SIGPROF, signal.SIGALRM)}
    signal.setitimer(signal.ITIMER_PROF, cpu_s)
    signal.setitimer(signal.ITIMER_REAL, guard_s)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.setitimer(signal.ITIMER_REAL, 0)
        for s, handler in old.items():
            signal.signal(s, handler)


def _base(cell: Path) -> dict[str, Any]:
    """A shipped cell with its mesh paths made absolute, so a copy anywhere still finds them."""
    data = yaml.safe_load(cell.read_text())
    for o in data.get("objects", []) + data.get("dynamic", []):
        if "mesh" in o:
            o["mesh"] = str((cell.parent / o["mesh"]).resolve())
    return data


def _paths(data: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = []
    if isinstance(data, dict):
        for k, v in data.items():
            out.append((*prefix, k))
            out.extend(_paths(v, (*prefix, k)))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            out.append((*prefix, i))
            out.extend(_paths(v, (*prefix, i)))
    return out


def _get(data: Any, path: tuple[Any, ...]) -> Any:
    for p in path:
        data = data[p]
    return data


def _write(folder: Path, data: Any, name: str = "cell.yaml") -> Path:
    path = folder / name
    path.write_text(yaml.safe_dump(data, sort_keys=False, allow_unicode=True))
    return path


def _raw(text: str | bytes, name: str = "cell.yaml") -> Callable[[Path], Path]:
    def build(folder: Path) -> Path:
        path = folder / name
        path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
        return path
    return build


def _tree_mutants(rng: np.random.Generator, base: dict[str, Any], cell: str, n: int) -> list[Mutant]:
    paths = _paths(base)
    dict_keys = [p for p in paths if isinstance(p[-1], str)]
    leaves = [p for p in paths if not isinstance(_get(base, p), (dict, list))]
    values: list[Any] = [float("nan"), float("inf"), -float("inf"), 0, -1, -1e-9, 1e308, -1e308, 1e-320, True,
                         None, "", "x", "1.5", [], {}, [1, 2], {"a": 1}, 10**18, "\u202e\u0000", "𝔁" * 50]
    out = []
    for k in range(n):
        kind = ("drop_key", "typo_key", "wrong_value", "wrong_value", "duplicate_name")[k % 5]
        data = copy.deepcopy(base)
        if kind == "drop_key":
            p = dict_keys[int(rng.integers(len(dict_keys)))]
            del _get(data, p[:-1])[p[-1]]
            label = ".".join(map(str, p))
        elif kind == "typo_key":
            p = dict_keys[int(rng.integers(len(dict_keys)))]
            parent = _get(data, p[:-1])
            word = str(p[-1])
            i = int(rng.integers(len(word)))
            typo = word[:i] + word[i + 1:] + ("e" if i == len(word) - 1 else "")
            parent[typo or "x"] = parent.pop(p[-1])
            label = f"{'.'.join(map(str, p))}->{typo}"
        elif kind == "wrong_value":
            p = (leaves + dict_keys)[int(rng.integers(len(leaves) + len(dict_keys)))]
            v = values[int(rng.integers(len(values)))]
            _get(data, p[:-1])[p[-1]] = copy.deepcopy(v)
            label = f"{'.'.join(map(str, p))}={v!r}"[:60]
        else:
            lists: list[tuple[Any, str]] = [(("objects",), "name")]
            if "seams" in data:
                lists += [(("seams",), "name")] + [(("seams", i, "spots"), "name") for i in range(len(data["seams"]))]
            if "tending" in data:
                lists += [(("tending", "stations"), "name")]
                lists += [(("tending", "machines"), "name")] if data["tending"].get("machines") else []
            if "pick_place" in data:
                lists += [(("pick_place", "parts"), "name"), (("pick_place", "locations"), "name")]
            where, key = lists[int(rng.integers(len(lists)))]
            items = _get(data, where)
            if len(items) >= 2:
                items[1][key] = items[0][key]
            label = f"{where}"
        out.append(Mutant(kind, f"{cell}:{label}", lambda folder, d=data: _write(folder, d)))
    return out


def _mesh_mutants(base: dict[str, Any], cell: str) -> list[Mutant]:
    idx = next((i for i, o in enumerate(base["objects"]) if "mesh" in o), None)
    if idx is None:
        return []

    def with_mesh(make: Callable[[Path], str]) -> Callable[[Path], Path]:
        def build(folder: Path) -> Path:
            data = copy.deepcopy(base)
            data["objects"][idx]["mesh"] = make(folder)
            return _write(folder, data)
        return build

    def loop(folder: Path) -> str:
        (folder / "a.stl").symlink_to(folder / "b.stl")
        (folder / "b.stl").symlink_to(folder / "a.stl")
        return "a.stl"

    def fifo(folder: Path) -> str:
        os.mkfifo(folder / "pipe.stl")
        return "pipe.stl"

    def file_with(data: bytes, name: str = "m.stl") -> Callable[[Path], str]:
        def make(folder: Path) -> str:
            (folder / name).write_bytes(data)
            return name
        return make

    def folder_named(folder: Path) -> str:
        (folder / "dir.stl").mkdir()
        return "dir.stl"

    cases = {
        "missing": lambda f: "nope.stl", "empty": file_with(b""), "garbage": file_with(os.urandom(4096)),
        "text": file_with(b"solid x\nendsolid\n"), "folder": folder_named, "symlink_loop": loop, "fifo": fifo,
        "device": lambda f: "/dev/zero", "nul": lambda f: "a\x00b.stl", "long_name": lambda f: "m" * 300 + ".stl",
        "long_path": lambda f: "/".join(["d" * 200] * 30) + "/m.stl", "no_suffix": file_with(b"abc", "mesh"),
        "obj_garbage": file_with(b"v 1 2\nf 1 2 3 4 5\n", "m.obj"), "dae_garbage": file_with(b"<COLLADA>", "m.dae"),
        "one_triangle": file_with(b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                  b"vertex 0 1 0\nendloop\nendfacet\nendsolid t\n"),
    }
    return [Mutant("bad_mesh", f"{cell}:mesh={k}", with_mesh(v)) for k, v in cases.items()]


def _yaml_mutants(base: dict[str, Any], cell: str) -> list[Mutant]:
    text = yaml.safe_dump(base, sort_keys=False)
    bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{chr(98 + i)}: &{chr(98 + i)} [*{chr(97 + i)}, *{chr(97 + i)}, *{chr(97 + i)}, *{chr(97 + i)}, *{chr(97 + i)}, "
        f"*{chr(97 + i)}, *{chr(97 + i)}, *{chr(97 + i)}, *{chr(97 + i)}, *{chr(97 + i)}]\n" for i in range(9))
    out = {
        "bomb_in_spots": bomb + text.replace("spots:\n", "spots: *j\n  _old_spots:\n", 1),
        "bomb_in_home": bomb + text.replace("home:", "home: *j\n  _home:", 1),
        "bomb_in_name": bomb + "name: *j\n" + text,
        "recursive_alias": "x: &x [*x]\n" + text,
        "recursive_map": "x: &x {y: *x}\n" + text,
        "deep_list": "deep: " + "[" * 100_000 + "]" * 100_000 + "\n" + text,
        "deep_map": "deep: " + "{a: " * 5000 + "1" + "}" * 5000 + "\n" + text,
        "complex_key_list": "? [a, b]\n: x\n" + text,
        "complex_key_map": "? {a: 1}\n: x\n" + text,
        "int_key": "1: x\n" + text,
        "bool_key": "on: x\n" + text,
        "null_key": "~: x\n" + text,
        "huge_int": text.replace("robomax: 1", "robomax: " + "9" * 5000, 1),
        "huge_int_value": text.replace("weld_time:", "weld_time: " + "1" * 5000 + "\n  _w:", 1),
        "huge_float": text.replace("weld_time:", "weld_time: 1" + "0" * 400 + ".0\n  _w:", 1),
        "bom": "\ufeff" + text,
        "empty": "",
        "only_comment": "# nothing\n",
        "two_documents": text + "---\n" + text,
        "tabs": text.replace("  ", "\t"),
        "binary_tag": "x: !!binary AAAA\n" + text,
        "python_tag": "x: !!python/object/apply:os.system ['true']\n" + text,
        "merge_key": "base: &b {w: 1}\nm: {<<: *b}\n" + text,
        "anchor_unused": "u: &u 1\n" + text,
        "unclosed_quote": text + "bad: 'unclosed\n",
        "list_at_top": "- 1\n- 2\n",
        "scalar_at_top": "hello\n",
        "very_long_line": "x: " + "a" * 2_000_000 + "\n" + text,
    }
    mutants = [Mutant("yaml", f"{cell}:{k}", _raw(v)) for k, v in out.items()]
    mutants.append(Mutant("yaml", f"{cell}:latin1", _raw(text.encode("utf-8") + b"\nname: caf\xe9\n")))
    mutants.append(Mutant("yaml", f"{cell}:nul_byte", _raw(text.encode("utf-8") + b"\x00\n")))
    mutants.append(Mutant("yaml", f"{cell}:over_size_limit", _raw(text + "#" + "x" * (11 * 1024 * 1024) + "\n")))
    return mutants


def _name_mutants(base: dict[str, Any], cell: str) -> list[Mutant]:
    names = {"long": "n" * 300, "slash": "a/b", "dotdot": "..", "nul": "a\x00b", "control": "a\x07b",
             "unicode": "zelle_ß_✓", "empty": "", "spaces": "   ", "backslash": "a\\b", "newline": "a\nb",
             "hidden": ".hidden", "device": "con", "colon": "a:b", "trailing_dot": "x."}
    out = []
    for k, v in names.items():
        for field in ("name", "robot.model", "tool"):
            data = copy.deepcopy(base)
            if field == "robot.model":
                data["robot"]["model"] = v
            else:
                data[field] = v
            out.append(Mutant("odd_name", f"{cell}:{field}={k}", lambda folder, d=data: _write(folder, d)))
    for k, v in (("long_object", "o" * 5000), ("nul_seam", "s\x00"), ("unicode_spot", "spot_✓")):
        data = copy.deepcopy(base)
        data["objects"][0]["name"] = v if k == "long_object" else data["objects"][0]["name"]
        if k == "nul_seam":
            if "seams" in data:
                data["seams"][0]["name"] = v
            elif "tending" in data:
                data["tending"]["machines" if data["tending"].get("machines") else "stations"][0]["name"] = v
            else:
                data["pick_place"]["parts"][0]["name"] = v
        if k == "unicode_spot":
            if "seams" in data:
                data["seams"][0]["spots"][0]["name"] = v
            elif "tending" in data:
                data["tending"]["stations"][0]["name"] = v
            else:
                data["pick_place"]["locations"][0]["name"] = v
        out.append(Mutant("odd_name", f"{cell}:{k}", lambda folder, d=data: _write(folder, d)))
    data = copy.deepcopy(base)
    data.setdefault("dynamic", []).append({"name": "door", "box": [0.1, 0.1, 0.1], "pose": {"xyz": [3, 3, 3]},
                                           "present": [[0, 1e308]]})
    out.append(Mutant("odd_value", f"{cell}:window_1e308", lambda folder, d=data: _write(folder, d)))
    return out


def _robot_mutants(rng: np.random.Generator, n: int) -> list[Mutant]:
    """A copy of the kr16 folder with robot.yaml or its URDF broken; the cell names it by path."""
    src = ROBOTS / "kr16"
    spec = yaml.safe_load((src / "robot.yaml").read_text())
    urdf = (src / "kr16.urdf").read_text()
    cell = _base(REPO / "cells" / "cabin_flange.yaml")

    def folder_with(robot_yaml: Any = None, urdf_text: str | bytes | None = None,
                    extra: Callable[[Path], None] | None = None) -> Callable[[Path], Path]:
        def build(folder: Path) -> Path:
            dst = folder / "robots" / "kr16"
            shutil.copytree(src, dst)
            if robot_yaml is not None:
                text = robot_yaml if isinstance(robot_yaml, str) else yaml.safe_dump(robot_yaml, sort_keys=False)
                (dst / "robot.yaml").write_text(text)
            if urdf_text is not None:
                (dst / "kr16.urdf").write_bytes(urdf_text if isinstance(urdf_text, bytes) else urdf_text.encode())
            if extra is not None:
                extra(dst)
            data = copy.deepcopy(cell)
            data["robot"]["model"] = "robots/kr16/robot.yaml"
            return _write(folder, data)
        return build

    fixed: dict[str, Callable[[Path], Path]] = {
        "urdf_truncated": folder_with(urdf_text=urdf[: len(urdf) // 2]),
        "urdf_not_xml": folder_with(urdf_text="this is not xml"),
        "urdf_empty": folder_with(urdf_text=""),
        "urdf_binary": folder_with(urdf_text=os.urandom(2000)),
        "urdf_no_joints": folder_with(urdf_text='<robot name="r"><link name="tool0"/></robot>'),
        "urdf_no_limits": folder_with(urdf_text=urdf.replace("<limit", "<nolimit")),
        "urdf_mesh_missing": folder_with(extra=lambda d: shutil.rmtree(d / "meshes" / "collision")),
        "urdf_entity_bomb": folder_with(urdf_text='<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">'
                                        + "".join(f'<!ENTITY {chr(98 + i)} "&{chr(97 + i)};&{chr(97 + i)};&{chr(97 + i)};'
                                                  f'&{chr(97 + i)};&{chr(97 + i)};&{chr(97 + i)};&{chr(97 + i)};'
                                                  f'&{chr(97 + i)};&{chr(97 + i)};&{chr(97 + i)};">' for i in range(8))
                                        + ']><robot name="&i;"/>'),
        "flange_missing": folder_with({**spec, "flange": "nope"}),
        "srdf_missing": folder_with({**spec, "srdf": "nope.srdf"}),
        "srdf_garbage": folder_with({**spec, "srdf": "x.srdf"}, extra=lambda d: (d / "x.srdf").write_text("<robot><disable_collisions/>")),
        "disable_unknown_link": folder_with({**spec, "collision": {"disable": [["link_1", "nope"]]}}),
        "disable_three": folder_with({**spec, "collision": {"disable": [["a", "b", "c"]]}}),
        "limits_short": folder_with({**spec, "limits": {"acceleration": [1, 2], "jerk": [1, 2]}}),
        "limits_negative": folder_with({**spec, "limits": {"acceleration": [-1] * 6}}),
        "ik_a2_flipped": folder_with({**spec, "ik": {**spec["ik"], "params": {**spec["ik"]["params"], "a2": -spec["ik"]["params"]["a2"]}}}),
        "ik_unknown_solver": folder_with({**spec, "ik": {"solver": "magic"}}),
        "ik_ur_on_kuka": folder_with({**spec, "ik": {"solver": "ur"}}),
        "ik_fitted": folder_with({**spec, "ik": {"solver": "opw"}}),
        "name_mismatch": folder_with({**spec, "name": "other"}),
        "urdf_is_folder": folder_with({**spec, "urdf": "meshes"}),
        "urdf_package_missing": folder_with({**spec, "urdf": "package://nope/robot.urdf"}),
        "controller_brand": folder_with({**spec, "controller": {"brand": "yaskawa"}}),
        "robot_yaml_bomb": folder_with("a: &a [x,x,x,x,x,x,x,x,x,x]\n" + "".join(
            f"{chr(98 + i)}: &{chr(98 + i)} [*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},"
            f"*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)},*{chr(97 + i)}]\n" for i in range(9))
            + yaml.safe_dump(spec)),
    }
    out = [Mutant("robot", k, v) for k, v in fixed.items()]
    keys = [p for p in _paths(spec) if isinstance(p[-1], str)]
    for k in range(n):
        data = copy.deepcopy(spec)
        p = keys[int(rng.integers(len(keys)))]
        if k % 2:
            del _get(data, p[:-1])[p[-1]]
        else:
            _get(data, p[:-1])[p[-1]] = [None, "x", -1, 0, float("nan"), [], {}][k % 7]
        out.append(Mutant("robot", f"robot.yaml:{'.'.join(map(str, p))}:{k % 7}", folder_with(data)))
    return out


# Random tree edits per shipped cell: with the fixed classes, just over a thousand mutants. Most tree
# edits leave a valid cell whose full check costs seconds, so this count sets the test's cost; a
# wider sweep is `all_mutants(tree_per_cell=N)`.
TREE_PER_CELL = 120


def all_mutants(seed: int = 0, tree_per_cell: int = TREE_PER_CELL) -> list[Mutant]:
    rng = np.random.default_rng(seed)
    out: list[Mutant] = []
    for cell in CELLS:
        base = _base(cell)
        out += _tree_mutants(rng, base, cell.stem, tree_per_cell)
        out += _mesh_mutants(base, cell.stem)
        out += _yaml_mutants(base, cell.stem)
        out += _name_mutants(base, cell.stem)
    out += _robot_mutants(rng, 60)
    return out


def _files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*")} if folder.exists() else set()


def _run(command: list[str], folder: Path) -> tuple[int, str, float]:
    """Exit code, output and CPU seconds of one in-process run; AssertionError on a traceback, Hang
    past the CPU bound."""
    t0 = time.process_time()
    with _bounded(CPU_S_PER_FILE):
        result = runner.invoke(app, command)
    seconds = time.process_time() - t0
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise AssertionError(f"traceback: {type(result.exception).__name__}: {result.exception}\n{result.output}")
    return result.exit_code, result.output, seconds


def test_generator_makes_more_than_a_thousand_mutants() -> None:
    mutants = all_mutants()
    assert len(mutants) >= 1000
    assert len({m.kind for m in mutants}) >= 8
    assert [m.name for m in all_mutants()] == [m.name for m in mutants]      # seeded: the same every time


CHUNKS = 4       # the mutants in four interleaved runs, so that test workers share them


@pytest.mark.slow
@pytest.mark.parametrize("chunk", range(CHUNKS))
def test_every_mutant_is_refused_cleanly_by_check(tmp_path: Path, chunk: int) -> None:
    codes: Counter[int] = Counter()
    slowest = (0.0, "")
    slowest_refusal = (0.0, "")
    failures = []
    for k, m in enumerate(all_mutants()):
        if k % CHUNKS != chunk:
            continue
        folder = tmp_path / f"m{k}"
        folder.mkdir()
        try:
            target = m.build(folder)
        except OSError:                  # the file system refused to make the mutant (e.g. a name too long)
            codes[-1] += 1
            continue
        before = _files(folder)
        try:
            code, output, seconds = _run(["check", str(target)], folder)
        except (AssertionError, Hang) as exc:
            failures.append(f"{m.name}: {exc}")
            continue
        codes[code] += 1
        slowest = max(slowest, (seconds, m.name))
        if code == 2:
            slowest_refusal = max(slowest_refusal, (seconds, m.name))
        if code not in (0, 2):
            failures.append(f"{m.name}: exit {code}\n{output}")
        elif code == 2 and not any(s in output for s in (str(folder), "cells/", str(REPO))):
            failures.append(f"{m.name}: the message names no file:\n{output}")
        if _files(folder) != before:
            failures.append(f"{m.name}: files written: {sorted(_files(folder) - before)}")
        rss_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        if rss_mb > PEAK_RSS_MB:
            failures.append(f"{m.name}: peak memory {rss_mb:.0f} MB")
            break
        shutil.rmtree(folder, ignore_errors=True)
    print(f"\nmutants by exit code: {dict(codes)}; slowest {slowest[0]:.2f} CPU s ({slowest[1]}); slowest refusal "
          f"{slowest_refusal[0]:.2f} CPU s ({slowest_refusal[1]}); "
          f"peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")
    assert not failures, f"{len(failures)} failures:\n" + "\n".join(failures[:20])


# --------------------------------------------------------------------------------- program files

GOLDEN = REPO / "tests" / "golden"


def _program_mutants(rng: np.random.Generator) -> list[tuple[str, str, bytes]]:
    """(name, suffix, content) of broken programs for `verify`, from the small cell's golden files."""
    srcl = (GOLDEN / "small_cell" / "small_cell.srcl").read_bytes()
    js = (GOLDEN / "small_cell" / "small_cell.json").read_bytes()
    out: list[tuple[str, str, bytes]] = []
    for text, suffix in ((srcl, ".srcl"), (js, ".json")):
        for k in range(8):
            cut = int(rng.integers(1, len(text)))
            out.append((f"truncated_{k}", suffix, text[:cut]))
        out += [
            ("latin1", suffix, text + b"\n\xe9\xff"), ("nul", suffix, text.replace(b"\n", b"\x00\n", 1)),
            ("empty", suffix, b""), ("gigantic", suffix, text + b" " * (51 * 1024 * 1024)),
            ("bom", suffix, b"\xef\xbb\xbf" + text),
        ]
    lines = srcl.split(b"\n")
    for k in range(12):
        i = int(rng.integers(len(lines)))
        mutated = list(lines)
        del mutated[i]
        out.append((f"srcl_drop_line_{k}", ".srcl", b"\n".join(mutated)))
    numbers = [b"1e999", b"-1e999", b"nan", b"9" * 5000, b"0.0", b"-0.000", b"1" + b"0" * 400 + b".0", b"x"]
    for k in range(16):
        i = int(rng.integers(len(lines)))
        words = lines[i].split(b" ")
        j = int(rng.integers(len(words)))
        words[j] = numbers[k % len(numbers)] + (b";" if words[j].endswith(b";") else b"")
        mutated = list(lines)
        mutated[i] = b" ".join(words)
        out.append((f"srcl_number_{k}", ".srcl", b"\n".join(mutated)))
    out += [
        ("srcl_nested_comment", ".srcl", srcl.replace(b"BEGIN", b"BEGIN\n" + b"{" * 100_000 + b"}" * 100_000, 1)),
        ("srcl_long_line", ".srcl", srcl.replace(b"BEGIN", b"BEGIN\n{ " + b"x" * 5_000_000 + b" }", 1)),
        ("srcl_many_statements", ".srcl", srcl.replace(b"BEGIN", b"BEGIN\n" + b"  WAIT 0.000 SEC;\n" * 200_000, 1)),
        ("srcl_config_flipped", ".srcl", srcl.replace(b"CONFIG 'S", b"CONFIG 'X", 1)),
    ]
    data = __import__("json").loads(js)
    def dump(d: Any) -> bytes:
        return __import__("json").dumps(d).encode()
    for key, value in (("t", "x"), ("q", [[1e308] * 6] * 3), ("spots", [{"seam": 1}]), ("spots", "x"),
                       ("joints", ["a"]), ("format", 5), ("t", list(reversed(data["t"]))), ("q", [[0] * 5] * len(data["t"]))):
        out.append((f"json_{key}_{str(value)[:10]}", ".json", dump({**data, key: value})))
    spots = copy.deepcopy(data["spots"])
    spots[0]["t_arrive"] = "soon"
    out.append(("json_spot_time_text", ".json", dump({**data, "spots": spots})))
    spots = copy.deepcopy(data["spots"])
    spots[0]["alpha"] = [1, 2]
    out.append(("json_spot_angle_list", ".json", dump({**data, "spots": spots})))
    out += [
        ("json_nested", ".json", b"[" * 100_000 + b"]" * 100_000),
        ("json_huge_int", ".json", js.replace(b'"t": [', b'"t": [' + b"9" * 5000 + b", ", 1)),
        ("json_big_int", ".json", js.replace(b'"t": [', b'"t": [' + b"9" * 400 + b", ", 1)),
        ("json_nan", ".json", js.replace(b'"t": [', b'"t": [NaN, ', 1)),
        ("json_list", ".json", b"[1, 2, 3]"),
    ]
    return out


@pytest.mark.slow
@pytest.mark.parametrize("chunk", range(2))
def test_broken_programs_are_refused_cleanly_by_verify(tmp_path: Path, write_small_cell: Any, chunk: int) -> None:
    cell = write_small_cell(tmp_path)
    for suffix in (".srcl", ".json"):
        golden = tmp_path / f"golden{suffix}"
        golden.write_bytes((GOLDEN / "small_cell" / f"small_cell{suffix}").read_bytes())
        code, output, _ = _run(["verify", str(cell), str(golden)], tmp_path)
        assert code == 0, output            # the unbroken program verifies
    codes: Counter[int] = Counter()
    failures = []
    for k, (name, suffix, content) in enumerate(_program_mutants(np.random.default_rng(1))):
        if k % 2 != chunk:
            continue
        program = tmp_path / f"{name}{suffix}"
        program.write_bytes(content)
        try:
            code, output, _ = _run(["verify", str(cell), str(program)], tmp_path)
        except (AssertionError, Hang) as exc:
            failures.append(f"{name}{suffix}: {exc}")
            continue
        codes[code] += 1
        # 0 is right for a mutant that changed nothing that matters (a comment, a BOM)
        if code not in (0, 1, 2):
            failures.append(f"{name}{suffix}: exit {code}\n{output[-500:]}")
        elif code == 2 and program.name not in output:
            failures.append(f"{name}{suffix}: the message names no file:\n{output[-500:]}")
        program.unlink()
    print(f"\nprogram mutants by exit code: {dict(codes)}")
    assert not failures, f"{len(failures)} failures:\n" + "\n".join(failures[:20])


DIALECT_FILES = {".src": ".dat", ".mod": None, ".ls": None, ".script": None}


def _golden_name(suffix: str) -> str:
    """The small cell's program file of one suffix: FANUC names a .ls as its program, in capitals."""
    return "SMALL_CELL.ls" if suffix == ".ls" else f"small_cell{suffix}"


def _dialect_mutants(rng: np.random.Generator) -> list[tuple[str, str, bytes]]:
    """(name, file suffix, content) of broken controller programs, from the small cell's
    golden files: truncated, lines dropped or doubled, numbers replaced, bytes that are not text."""
    out: list[tuple[str, str, bytes]] = []
    numbers = [b"1e999", b"nan", b"9" * 400, b"-", b"1.2.3", b"0x10"]
    for suffix in (*DIALECT_FILES, ".dat"):
        text = (GOLDEN / "small_cell" / _golden_name(suffix)).read_bytes()
        lines = text.split(b"\n")
        for k in range(3):
            out.append((f"truncated_{k}", suffix, text[: int(rng.integers(1, len(text)))]))
        for k in range(3):
            i = int(rng.integers(len(lines)))
            out.append((f"drop_{k}", suffix, b"\n".join(lines[:i] + lines[i + 1:])))
        i = int(rng.integers(len(lines)))
        out.append(("double", suffix, b"\n".join(lines[:i] + [lines[i]] * 2 + lines[i + 1:])))
        for k in range(4):
            i = int(rng.integers(len(lines)))
            digits = [m.span() for m in __import__("re").finditer(rb"-?[0-9]+\.[0-9]+", lines[i])]
            if not digits:
                continue
            a, b = digits[int(rng.integers(len(digits)))]
            mutated = list(lines)
            mutated[i] = lines[i][:a] + numbers[k % len(numbers)] + lines[i][b:]
            out.append((f"number_{k}", suffix, b"\n".join(mutated)))
        out += [("latin1", suffix, text + b"\n\xe9\xff"), ("empty", suffix, b""),
                ("nul", suffix, text.replace(b"\n", b"\x00\n", 1))]
    return out


@pytest.mark.slow
def test_broken_controller_programs_are_refused_cleanly_by_verify(tmp_path: Path, write_small_cell: Any) -> None:
    from robomax_py.errors import RobomaxError
    from robomax_py.io.cell import load_cell, load_cell_robot
    from robomax_py.verify import verify_program

    cell = load_cell(write_small_cell(tmp_path))
    robot = load_cell_robot(cell)
    outcomes: Counter[str] = Counter()
    failures = []
    for k, (name, suffix, content) in enumerate(_dialect_mutants(np.random.default_rng(3))):
        folder = tmp_path / f"m{k}"
        folder.mkdir()
        main = ".src" if suffix == ".dat" else suffix
        for ext in (main, DIALECT_FILES.get(main)):
            if ext:
                (folder / _golden_name(ext)).write_bytes((GOLDEN / "small_cell" / _golden_name(ext)).read_bytes())
        (folder / _golden_name(suffix)).write_bytes(content)
        try:
            with _bounded(60.0):
                report = verify_program(cell, robot, folder / _golden_name(main))
            outcomes["clean" if report.clean else "violations"] += 1
        except RobomaxError as exc:
            outcomes["bad input"] += 1
            if "small_cell" not in str(exc).lower():
                failures.append(f"{name}{suffix}: the message names no file: {exc}")
        except Exception as exc:  # noqa: BLE001 - a traceback for a user's file is the failure
            failures.append(f"{name}{suffix}: {type(exc).__name__}: {exc}")
    print(f"\ncontroller program mutants: {dict(outcomes)}")
    assert sum(outcomes.values()) >= 50
    assert not failures, f"{len(failures)} failures:\n" + "\n".join(failures[:20])


# The classes that used to end in a traceback, a hang or a crashed batch row.
ONCE_FATAL = ("mesh=symlink_loop", "mesh=long_name", "mesh=nul", "mesh=fifo", "mesh=device", "bomb_in_spots",
              "bomb_in_home", "recursive_alias", "deep_list", "complex_key_list", "complex_key_map", "huge_int",
              "name=long", "robot.model=long", "tool=long", "name=nul", "window_1e308", "nul_byte",
              "over_size_limit", "latin1")


@pytest.mark.slow
def test_once_fatal_cells_are_bad_input_for_plan_and_batch(tmp_path: Path) -> None:
    from robomax_py.app.batch import BAD_INPUT, BatchOptions, run_batch

    chosen = [m for m in all_mutants() if m.name.startswith("cabin_flange:") and m.name.split(":", 1)[1] in ONCE_FATAL]
    assert len(chosen) == len(ONCE_FATAL)
    files, messages = [], []
    for k, m in enumerate(chosen):
        folder = tmp_path / f"m{k}"
        folder.mkdir()
        target = m.build(folder)
        out = folder / "programs"
        code, output, _ = _run(["check", str(target)], folder)
        assert code == 2, f"{m.name}: check exit {code}\n{output}"
        messages.append(" ".join(output.split("error:", 1)[1].split()))
        code, output, _ = _run(["plan", str(target), "-o", str(out)], folder)
        assert code == 2, f"{m.name}: plan exit {code}\n{output}"
        assert not out.exists(), f"{m.name}: plan wrote {sorted(p.name for p in out.iterdir())}"
        files.append(str(target))
    outcomes = run_batch(files, tmp_path / "batch", BatchOptions(jobs=2, timeout=120))
    for m, o, message in zip(chosen, outcomes, messages):
        assert o.status == BAD_INPUT, f"{m.name}: batch says {o.status}: {o.reasons}"
        assert " ".join(o.reasons.split()) == message, f"{m.name}: batch {o.reasons!r} vs check {message!r}"
