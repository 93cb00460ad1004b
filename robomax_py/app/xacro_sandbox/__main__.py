"""The expansion's child process, as `import_urdf.expand` starts it: `python -I <this file>`.

`python -I` puts no folder of ours on `sys.path`, and the child must not import robomax_py (see
the package's docstring), so this folder is loaded as a package of its own, `xacro_sandbox`,
from the files beside this one; its modules import each other relatively.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from types import ModuleType


def _package() -> ModuleType:
    """This folder as the package `xacro_sandbox`, its `__init__` run."""
    here = os.path.dirname(os.path.abspath(__file__))
    spec = importlib.util.spec_from_file_location("xacro_sandbox", os.path.join(here, "__init__.py"),
                                                  submodule_search_locations=[here])
    assert spec is not None and spec.loader is not None    # a file that exists beside this one
    package = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = package                       # before it runs: its relative imports find it
    spec.loader.exec_module(package)
    return package


if __name__ == "__main__":
    sys.exit(_package().main())
