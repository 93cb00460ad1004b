"""The compiled kernels' cache (`robomax_py.jit`): a kernel is compiled again when a function it
calls from another file changed (numba's own cache does not see that), and an install at another
path finds what an earlier one compiled."""

from __future__ import annotations

import ast
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import robomax_py
from robomax_py import jit

PACKAGE = Path(robomax_py.__file__).resolve().parent

# A helper in one file and a kernel calling it in another: the case numba's own cache gets wrong.
PROBE_A = "from robomax_py.jit import helper\n\n\n@helper\ndef lift(x):\n    return x + 1.0\n"
PROBE_B = ("from robomax_py._probe_a import lift\nfrom robomax_py.jit import kernel\n\n\n"
           "@kernel\ndef twice(x):\n    return lift(x) * 2.0\n")
SCRIPT = ("from robomax_py._probe_b import twice\n"
          "print(twice(1.0), sum(twice.stats.cache_hits.values()))\n")


def _ast_imports(path: Path) -> set[Path]:
    """What `path` imports of robomax_py, read with Python's own parser: the reference the regular
    expression of `jit._imported` is held to."""
    package = path.relative_to(PACKAGE.parent).parent.parts
    names: list[str] = []
    for node in ast.walk(ast.parse(path.read_bytes())):
        if isinstance(node, ast.Import):
            names.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            stem = ".".join(package[:len(package) - node.level + 1]) if node.level else ""
            module = ".".join(p for p in (stem, node.module or "") if p)
            names.append(module)
            names.extend(f"{module}.{alias.name}" for alias in node.names)
    found = set()
    for name in names:
        parts = name.split(".")
        if parts[0] != "robomax_py":
            continue
        base = PACKAGE.joinpath(*parts[1:])
        for candidate in (base.with_suffix(".py"), base / "__init__.py"):
            if candidate.is_file() and candidate != path:
                found.add(candidate)
                break
    return found


def test_the_import_scan_finds_every_module_python_would_import() -> None:
    """Every robomax_py file: the scan may add a module a docstring names (one more file in a
    digest), never miss one the code imports; on the kernels' own modules the two agree."""
    kernels = 0
    for path in sorted(PACKAGE.rglob("*.py")):
        scanned, parsed = set(jit._imported(path)), _ast_imports(path)
        assert parsed <= scanned, (path, parsed - scanned)
        if "robomax_py.jit import" in path.read_text():
            kernels += 1
            assert scanned == parsed, path
    assert kernels >= 7


def test_a_kernels_stamp_covers_the_files_it_calls_into() -> None:
    stamp = jit.source_digest((PACKAGE / "world/prefilter_kernels.py").resolve())
    assert {p.name for p in jit._imported((PACKAGE / "world/prefilter_kernels.py").resolve())} >= {
        "prefilter_reach.py", "box_separation.py", "jit.py"}
    assert stamp != jit.source_digest((PACKAGE / "world/box_separation.py").resolve())
    assert stamp == jit.source_digest((PACKAGE / "world/prefilter_kernels.py").resolve())


def _install(folder: Path) -> Path:
    """A package at `folder` of robomax_py's jit and cache_files, and the two probe modules."""
    package = folder / "robomax_py"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    for name in ("jit.py", "cache_files.py", "_typing.py"):
        shutil.copy(PACKAGE / name, package / name)
    (package / "_probe_a.py").write_text(PROBE_A)
    (package / "_probe_b.py").write_text(PROBE_B)
    return package


def _run(folder: Path, cache: Path) -> tuple[float, int]:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(PYTHONPATH=str(folder), ROBOMAX_CACHE=str(cache), PYTHONDONTWRITEBYTECODE="1")
    done = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, cwd=folder,
                          check=True, timeout=300)
    value, hits = done.stdout.split()
    return float(value), int(hits)


@pytest.mark.slow
def test_a_changed_helper_is_compiled_again_and_another_install_finds_the_cache(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first, second = _install(tmp_path / "first"), _install(tmp_path / "second")
    assert _run(first.parent, cache) == (4.0, 0)               # compiled and kept
    assert _run(first.parent, cache) == (4.0, 1)               # found
    assert _run(second.parent, cache) == (4.0, 1)              # another install of the same sources
    assert not list(first.rglob("*.nbi")), "the kernels belong in the cache folder"
    # The helper's file changes, the kernel's does not: numba's own cache would still print 4.0.
    (second / "_probe_a.py").write_text(PROBE_A.replace("x + 1.0", "x + 100.0"))
    assert _run(second.parent, cache) == (202.0, 0)
    assert _run(second.parent, cache) == (202.0, 1)
    assert _run(first.parent, cache) == (4.0, 0)               # one entry per function: compiled again


@pytest.mark.slow
def test_an_unwritable_cache_folder_keeps_the_kernels_beside_the_sources(tmp_path: Path) -> None:
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("")
    package = _install(tmp_path / "site")
    assert _run(package.parent, blocker) == (4.0, 0)
    assert list((package / "__pycache__").glob("_probe_b.twice-*.nbi"))
    assert _run(package.parent, blocker) == (4.0, 1)


def test_a_damaged_cache_file_is_read_as_missing_and_written_anew(tmp_path: Path) -> None:
    """A file cut short or damaged (a full disk, a crash) is a cache miss: the function compiles
    again and the file is written anew, where numba's own reading raises out of the first call."""
    from numba.core.caching import IndexDataCacheFile

    files = jit._ReadableCacheFile(str(tmp_path), "f", "stamp")
    files.save(("sig",), ("code", 1))
    assert files.load(("sig",)) == ("code", 1)
    index = tmp_path / "f.nbi"
    data = next(tmp_path.glob("f.*.nbc"))
    for damaged in (index, data):
        whole = damaged.read_bytes()
        damaged.write_bytes(whole[:len(whole) // 2])            # cut short
        with pytest.raises(Exception):                          # noqa: B017  # numba's own: any unpickling error
            IndexDataCacheFile(str(tmp_path), "f", "stamp").load(("sig",))
        assert files.load(("sig",)) is None
        files.save(("sig",), ("code", 2))                       # compiled again: written anew
        assert files.load(("sig",)) == ("code", 2)
    index.write_bytes(b"garbage")
    assert files.load(("sig",)) is None


# Where numba registers the symbols machine code links against, as read for `jit._READ_NUMBA`
# (`_PackageFunctionCache.load_overload`): a release that adds a place is to be read again.
SYMBOL_SOURCES = {"__init__.py", "core/base.py", "core/cpu.py", "core/externals.py", "core/runtime/nrt.py",
                  "cpython/hashing.py", "misc/numba_sysinfo.py", "np/ufunc/parallel.py"}
# A kernel whose code links against numba's runtime (the array) and the hash secret (a string's hash).
PROBE_LINKED = ("import numpy as np\n\nfrom robomax_py.jit import kernel\n\n\n@kernel\ndef filled(n, word):\n"
                "    out = np.empty(n)\n    for i in range(n):\n        out[i] = i + (hash(word) == hash(word))\n"
                "    return out.sum()\n")
LOAD_SCRIPT = ("from robomax_py._probe_linked import filled\n"
               "from numba.core.registry import cpu_target\n"
               "print(filled(3, 'ab'), sum(filled.stats.cache_hits.values()), len(cpu_target.target_context._registries))\n")


def test_numba_registers_link_symbols_only_where_the_lean_load_was_read_for() -> None:
    import numba

    release = tuple(int(part) for part in numba.__version__.split(".")[:2])
    if release not in jit._READ_NUMBA:
        assert not jit._LEAN_LOAD                   # numba's own load, refresh and all
        return
    assert jit._LEAN_LOAD
    root = Path(numba.__file__).parent
    found = {path.relative_to(root).as_posix() for path in root.rglob("*.py")
             if "tests" not in path.relative_to(root).parts
             and re.search(r"add_symbol\(|load_library_permanently\(", path.read_text(encoding="utf-8"))}
    assert found == SYMBOL_SOURCES


def test_numbas_own_load_runs_on_a_release_not_read(monkeypatch: pytest.MonkeyPatch) -> None:
    from numba.core.runtime.nrt import rtsys

    from robomax_py.world.prefilter_kernels import _placements

    calls: list[str] = []

    class Target:
        def refresh(self) -> None:
            calls.append("refresh")

    cache = jit._PackageFunctionCache(_placements.py_func)
    monkeypatch.setattr(cache, "_load_overload", lambda sig, target: "code")
    monkeypatch.setattr(rtsys, "initialize", lambda target: calls.append("runtime"))
    monkeypatch.setattr(jit, "_LEAN_LOAD", False)
    assert cache.load_overload((), Target()) == "code"
    assert calls == ["refresh"]
    calls.clear()
    monkeypatch.setattr(jit, "_LEAN_LOAD", True)
    assert cache.load_overload((), Target()) == "code"
    assert calls == ["runtime"]


@pytest.mark.slow
def test_a_cached_kernel_loads_without_numbas_tables_and_gives_the_same(tmp_path: Path) -> None:
    """The second process loads the kernel (and the helper inside its code) without filling numba's
    lowering tables; the first compiled it, which fills them."""
    package = _install(tmp_path / "site")
    (package / "_probe_linked.py").write_text(PROBE_LINKED)
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(PYTHONPATH=str(package.parent), ROBOMAX_CACHE=str(tmp_path / "cache"), PYTHONDONTWRITEBYTECODE="1")
    runs = [subprocess.run([sys.executable, "-c", LOAD_SCRIPT], capture_output=True, text=True, env=env,
                           cwd=package.parent, check=True, timeout=300).stdout.split() for _ in range(2)]
    (value, hits, tables), (value_again, hits_again, tables_again) = runs
    assert (value, hits, value_again, hits_again) == ("6.0", "0", "6.0", "1")
    assert int(tables) > 0
    assert int(tables_again) == (0 if jit._LEAN_LOAD else int(tables))
