"""A third-party module that a dependency imports at its top but robomax never calls, loaded on
its first use instead.

toppra imports matplotlib's pyplot (`toppra.algorithm`, `toppra.parametrizer`) for plots robomax
never draws; pyplot and what it pulls in (figures, backends, fonts, mplot3d) were about a fifth of
the import time of `robomax plan`. `importlib.util.LazyLoader` does not help here: on Python 3.11
an `import` statement that finds the module in `sys.modules` reads its `__spec__`, which runs it.
So `defer` puts a stand-in into `sys.modules`: the importing module binds it, and its first
attribute read imports the real module (replacing the stand-in) and answers from it, so a caller
that does use the module gets what it would have got.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import Any


class _StandIn(types.ModuleType):
    """Forwards every attribute to the real module, imported on the first read."""

    def __getattr__(self, attr: str) -> Any:
        if attr.startswith("__") and attr.endswith("__"):
            raise AttributeError(attr)          # import machinery probing (__path__, __file__...)
        if sys.modules.get(self.__name__) is self:
            del sys.modules[self.__name__]
        return getattr(importlib.import_module(self.__name__), attr)


def defer(name: str) -> None:
    """Import module `name` on the first attribute read instead of where it is imported; a module
    already imported is left alone."""
    if name not in sys.modules:
        stand_in = _StandIn(name)
        stand_in.__spec__ = None
        sys.modules[name] = stand_in
