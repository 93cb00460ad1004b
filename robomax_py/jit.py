"""The decorators every compiled loop of robomax_py is declared with (`kernel`, `helper`), and where
numba keeps what it compiled.

numba's own cache (`cache=True`) is keyed by the file a function is written in and nothing else: a
kernel that calls a compiled function of another file keeps that function's old machine code
after the other file changed. Upgrading with pip leaves numba's files beside the new sources (they
are not in the wheel's record), so a changed pre-filter helper would still run its old version
inside every kernel that calls it, without a word. Here the cache of a function is keyed by the
source of its file and of every robomax_py module that file imports, transitively (`source_digest`);
any change there compiles it again.

The cache lives in the cache folder (`$ROBOMAX_CACHE/numba`, else the XDG cache; `$NUMBA_CACHE_DIR`
when that is set, as numba's users expect), under the module's path inside the package, not the
path it is installed at: a new virtual environment or a reinstall of the same sources finds what an
earlier one compiled. numba's index still checks its own version, the signature, the bytecode and
the host CPU (`Cache._index_key`). Where the cache folder cannot be written the kernels are kept in
`__pycache__` beside the sources, with the same stamp; where neither can, every run compiles them.
"""

from __future__ import annotations

import functools
import hashlib
import os
import pickle
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import numba
from numba import njit
from numba.core import caching
from numba.core.dispatcher import Dispatcher
from numba.core.runtime.nrt import rtsys

from robomax_py.cache_files import cache_folder

_F = TypeVar("_F", bound=Callable[..., object])

_PACKAGE = Path(__file__).resolve().parent          # .../robomax_py
_NAME = _PACKAGE.name


def kernel(fn: _F) -> Dispatcher[_F]:
    """`njit(nogil=True)`, compiled once per source and machine (kept in the cache folder)."""
    return _cached(fn, {"nogil": True})


def helper(fn: _F) -> Dispatcher[_F]:
    """`kernel` for a function called only from other kernels: without a Python entry point (numba's
    CPython and C wrappers, lowered and optimised for every function, were about 0.7 s of a first
    plan's compile over the pre-filter's helpers, which Python never calls)."""
    return _cached(fn, {"nogil": True, "no_cpython_wrapper": True, "no_cfunc_wrapper": True})


def _cached(fn: _F, options: dict[str, Any]) -> Dispatcher[_F]:
    jit: Callable[[_F], Dispatcher[_F]] = njit(**options)      # Any: numba's stubs do not list these options
    dispatcher = jit(fn)
    if isinstance(dispatcher, Dispatcher):                     # not under NUMBA_DISABLE_JIT
        try:
            # What `Dispatcher.enable_caching` does, with this module's locator.
            dispatcher._cache = _PackageFunctionCache(fn)  # type: ignore[attr-defined]  # numba's slot
        except RuntimeError:
            pass                                               # no folder to write: compiled every run
    return dispatcher


def cache_root() -> Path:
    """Where compiled kernels are kept: `$NUMBA_CACHE_DIR/robomax_py` when set, else the cache folder's
    `numba/`."""
    numba_dir = os.environ.get("NUMBA_CACHE_DIR")
    return Path(numba_dir) / _NAME if numba_dir else cache_folder("numba")


def _module_file(name: str) -> Path | None:
    """The source file of robomax_py module `name` (dotted), None when it is not one."""
    parts = name.split(".")
    if parts[0] != _NAME:
        return None
    base = _PACKAGE.joinpath(*parts[1:])
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


# An import statement at the start of a line, in code or (harmlessly: one more file in a digest) in
# a docstring: `from <module> import <names>` (names in brackets may span lines) or `import <names>`.
# A regular expression, not `ast`: parsing the kernels' sources cost about 40 ms of every run.
_IMPORT = re.compile(rb"^[ \t]*(?:from[ \t]+(\.*[\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n#]*)|import[ \t]+([^\n#]*))",
                     re.MULTILINE)


@functools.cache
def _imported(path: Path) -> tuple[Path, ...]:
    """The robomax_py source files `path` imports anywhere in it (a function-level import included)."""
    package = path.relative_to(_PACKAGE.parent).parent.parts     # what a relative import starts from
    names: list[str] = []
    for found in _IMPORT.finditer(path.read_bytes()):
        source, listed, plain = (g.decode() if g is not None else None for g in found.groups())
        if plain is not None:
            names.extend(part.split()[0] for part in plain.split(",") if part.strip())
            continue
        assert source is not None and listed is not None
        level = len(source) - len(source.lstrip("."))
        stem = ".".join(package[:len(package) - level + 1]) if level else ""
        module = ".".join(p for p in (stem, source.lstrip(".")) if p)
        names.append(module)
        for part in re.sub(r"#[^\n]*", "", listed).strip("()").split(","):   # a submodule imported by name
            if part.split():
                names.append(f"{module}.{part.split()[0]}")
    found_files = {f for f in map(_module_file, names) if f is not None and f != path}
    return tuple(sorted(found_files))


@functools.cache
def source_digest(path: Path) -> str:
    """sha256 over the source of `path` and of every robomax_py module it imports, transitively: what
    a compiled function of that file can have taken into its machine code."""
    seen: set[Path] = set()
    todo = [path]
    while todo:
        file = todo.pop()
        if file not in seen:
            seen.add(file)
            todo.extend(_imported(file))
    digest = hashlib.sha256()
    for file in sorted(seen):
        digest.update(file.relative_to(_PACKAGE.parent).as_posix().encode() + b"\0")
        digest.update(file.read_bytes() + b"\0")
    return digest.hexdigest()


class _PackageLocator(caching._CacheLocator):                 # numba's extension point for where caches go
    """A robomax_py function's cache: the folder of its module inside `cache_root()`, stamped with
    `source_digest` of its file."""

    def __init__(self, py_func: Callable[..., object], py_file: str) -> None:
        self._py_file = Path(py_file).resolve()
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = str(cache_root().joinpath(*self._py_file.relative_to(_PACKAGE.parent).parent.parts))

    def get_cache_path(self) -> str:
        return self._cache_path

    def get_source_stamp(self) -> str:
        return source_digest(self._py_file)

    def get_disambiguator(self) -> str:
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func: Callable[..., object], py_file: str) -> _PackageLocator | None:
        if not Path(py_file).resolve().is_relative_to(_PACKAGE):
            return None
        locator = cls(py_func, py_file)
        try:
            locator.ensure_cache_path()                        # type: ignore[no-untyped-call]
        except OSError:
            return None
        return locator


class _InTreeLocator(_PackageLocator):
    """`_PackageLocator` in `__pycache__` beside the source, for a cache folder that cannot be written."""

    def __init__(self, py_func: Callable[..., object], py_file: str) -> None:
        super().__init__(py_func, py_file)
        self._cache_path = str(self._py_file.parent / "__pycache__")


class _PackageCacheImpl(caching.CompileResultCacheImpl):
    _locator_classes = [_PackageLocator, _InTreeLocator]          # noqa: RUF012  # numba's own class attribute, read only


# What unpickling a damaged file raises (cut short: EOFError or UnpicklingError; other bytes: any).
_UNREADABLE = (pickle.UnpicklingError, EOFError, ValueError, TypeError, AttributeError, ImportError)


class _ReadableCacheFile(caching.IndexDataCacheFile):
    """numba's index and code files of a function, where a file that does not unpickle (cut short by
    a full disk or a crash, damaged) is read as missing: the function is compiled again and its
    files written anew. numba's own raises out of the first call, and a plan ended on a traceback."""

    def _load_index(self) -> dict[Any, str]:
        try:
            found: dict[Any, str] = super()._load_index()        # type: ignore[no-untyped-call]
        except _UNREADABLE:
            return {}
        return found

    def _load_data(self, name: str) -> Any:
        try:
            return super()._load_data(name)                      # type: ignore[no-untyped-call]
        except _UNREADABLE as exc:
            raise OSError(f"unreadable cache file {name}") from exc   # `load` reads an OSError as missing


# numba releases (major, minor) whose sources were read for where the symbols that machine code links
# against are registered (`_PackageFunctionCache.load_overload`): numba/__init__.py, core/base.py
# (`_load_global_helpers`, at a context's creation), core/cpu.py and core/externals.py (the CPU
# context's `init`), core/runtime/nrt.py (`rtsys.initialize`), cpython/hashing.py (at its import),
# np/ufunc/parallel.py (the parallel back end, which no kernel here uses) and misc/numba_sysinfo.py.
_READ_NUMBA = frozenset({(0, 68)})
_LEAN_LOAD = tuple(int(part) for part in numba.__version__.split(".")[:2]) in _READ_NUMBA


class _PackageFunctionCache(caching.FunctionCache):
    _impl_class = _PackageCacheImpl

    def __init__(self, py_func: Callable[..., object]) -> None:
        super().__init__(py_func)                                 # type: ignore[no-untyped-call]
        self._cache_file = _ReadableCacheFile(                    # type: ignore[no-untyped-call]
            self._cache_path, self._impl.filename_base, self._impl.locator.get_source_stamp())

    def load_overload(self, sig: Any, target_context: Any) -> Any:
        """numba's `load_overload` without its refresh of the CPU target, which imports some forty
        modules of lowering code and fills the typing and lowering tables: about 0.12 s of every
        process that loads a kernel (4 % of a warm plan of the reference cell), and loading machine
        code reads none of those tables. What loading needs is that every symbol the code links
        against is known to LLVM; numba registers them at its import and at the CPU context's
        creation (its C helpers, the math functions, the exception types), in `rtsys.initialize` (the
        NRT_ runtime) and at the import of `numba.cpython.hashing` (the hash secret), and nowhere
        else (`_READ_NUMBA`). A symbol left unknown would end the process in LLVM's fatal error, not
        in an exception, so on a numba release not read for this, numba's own load runs. A cache
        miss compiles, and every compile refreshes both tables first (`CompilerBase.__init__`)."""
        if not _LEAN_LOAD:
            return super().load_overload(sig, target_context)         # type: ignore[no-untyped-call]
        rtsys.initialize(target_context)
        import numba.cpython.hashing  # noqa: F401  # registers the hash secret's symbols
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)         # type: ignore[no-untyped-call]


def has_cache(fn: object) -> bool:
    """Whether `fn` is a compiled function whose machine code is kept in a folder (the cache folder,
    else beside the sources): not where neither can be written, nor under NUMBA_DISABLE_JIT."""
    return isinstance(getattr(fn, "_cache", None), _PackageFunctionCache)


def is_cached(dispatcher: Dispatcher[Any], args: tuple[Any, ...]) -> bool:
    """Whether the cache folder holds `dispatcher`'s machine code for argument types `args` (numba
    types), for this source and this machine: what its first call with those types would load
    instead of compiling. Reads the function's index only (`Cache.load_overload` reads the code
    too)."""
    cache = getattr(dispatcher, "_cache", None)
    if not isinstance(cache, _PackageFunctionCache):
        return False
    key = cache._index_key(args, dispatcher.targetctx.codegen())  # type: ignore[attr-defined,no-untyped-call]  # numba's own key
    return key in cache._cache_file._load_index()                  # type: ignore[no-untyped-call]
