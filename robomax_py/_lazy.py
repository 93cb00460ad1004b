"""A third-party module that a dependency imports at its top but robomax never calls, loaded on
its first use instead.

toppra imports matplotlib's pyplot (`toppra.algorithm`, `toppra.parametrizer`) for plots robomax
never draws; pyplot and what it pulls in (figures, backends, fonts, mplot3d) were about a fifth of
the import time of `robomax plan`. `importlib.util.LazyLoader` does not help here: on Python 3.11
an `import` statement that finds the module in `sys.modules` reads its `__spec__`, which runs it.
So `defer` puts a stand-in into `sys.modules`: the importing module binds it, and its first
attribute read imports the real module (replacing the stand-in) and answers from it, so a caller
that does use the module gets what it would have got.

A submodule's parent package gets a stand-in too: `import matplotlib.pyplot` runs the package
`matplotlib` (most of pyplot's import time) before it looks in `sys.modules` for the submodule. The
parent's stand-in answers a read of that submodule with the submodule's stand-in.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import Any


class _StandIn(types.ModuleType):
    """Forwards every attribute to the real module, imported on the first read."""

    def __getattr__(self, attr: str) -> Any:
        if attr == "__path__":                  # a submodule not deferred is being imported
            return _real(self.__name__).__path__
        if attr.startswith("__") and attr.endswith("__"):
            raise AttributeError(attr)          # import machinery probing (__file__...)
        child = sys.modules.get(f"{self.__name__}.{attr}")
        if isinstance(child, _StandIn):
            return child                        # `import a.b as c` reads b from a
        return getattr(_real(self.__name__), attr)


def _real(name: str) -> types.ModuleType:
    """Module `name` imported for real: the stand-ins for it and its parents give way first (the
    import machinery reads a parent's __path__, which a stand-in does not have)."""
    parts = name.split(".")
    for i in range(1, len(parts) + 1):
        prefix = ".".join(parts[:i])
        if isinstance(sys.modules.get(prefix), _StandIn):
            del sys.modules[prefix]
    return importlib.import_module(name)


def defer(name: str) -> None:
    """Import module `name` on the first attribute read instead of where it is imported, and its
    parent packages likewise; a module already imported is left alone."""
    parts = name.split(".")
    if name in sys.modules:
        return
    for i in range(1, len(parts) + 1):
        prefix = ".".join(parts[:i])
        if prefix not in sys.modules:
            stand_in = _StandIn(prefix)
            stand_in.__spec__ = None
            sys.modules[prefix] = stand_in
