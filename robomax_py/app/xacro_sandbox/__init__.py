"""xacro expanded as untrusted data: no Python runs from the file, no file outside the allowed
folders is read, and the work is bounded.

xacro evaluates every `${...}` with Python's `eval` (xacro 2.1.1 `safe_eval`: builtins removed and
names starting with `__` refused, which attribute chains and `python.type` / `python.vars` still get
around), reads any file `xacro:include` or `xacro.load_yaml` names, and answers `$(env)` from the
environment. Here the installed xacro does the expansion (macros, blocks, scopes, namespaces, lazy
properties: its semantics, not a re-implementation), with five of its module functions replaced for
the one expansion this process runs:

- `safe_eval` (every `${...}`, and YAML unit tags): `evaluate`, which parses the expression with
  `ast` and evaluates only numbers, strings, booleans, lists, tuples and dicts, names of properties
  and macro parameters, arithmetic, comparison and boolean operators, conditional expressions, `**`
  with a bounded exponent, subscripts, calls of the functions in FUNCTIONS and of `xacro.*` helpers,
  and attribute access on xacro namespaces (`math.pi`, `xacro.load_yaml`, `ns.prop` of an include
  with `ns`) and on YAML data (`settings.arms.port`, xacro's dotted access). Anything else
  (attributes of other values, lambdas, comprehensions, dunder names, f-strings, keyword splats) is
  refused with the file and the expression named.
- `eval_extension` (`$(...)`): `$(find pkg)` answered from the allowed folders only, `$(arg x)`,
  `$(dirname)` (the folder of the file being read) and `$(eval ...)` through `evaluate`; `$(env)`,
  `$(optenv)` and `$(cwd)` are refused (a robot must not depend on the importing machine).
- `parse` (the source and every include) and `get_include_files` (glob patterns): only regular files
  whose real path lies inside an allowed folder, within the size limit.
- `load_yaml`: likewise, within the YAML size limit.
- the global symbol table: only FUNCTIONS, `True`/`False` and the `math` and `xacro` namespaces.

The expansion runs in its own process (`import_urdf.expand` starts this package's `__main__.py`
as a script with `python -I`), which first caps its own address space (RLIMIT_AS), CPU time (RLIMIT_CPU), file
writes (RLIMIT_FSIZE 0) and child processes (RLIMIT_NPROC 0), and dies with its parent: a macro that
expands 2^24 times or a string of a gigabyte ends that process, not the import. The request comes as
JSON on stdin, the answer goes as JSON to stdout: {"urdf": text} or {"file", "where", "problem",
"kind"}. This package imports nothing from robomax_py (the child must not import the package): its
modules import only the standard library and each other, relatively, and `__main__` loads the
folder as a package of its own.

The parts: `evaluator` (the `${...}` evaluator and its limits), `expansion` (xacro with the
replaced functions), `child` (the process: its limits, the request and the answer).
"""

from __future__ import annotations

from .child import MAX_LOG_CHARS, main, serve
from .evaluator import (
    FUNCTIONS,
    MAX_EXPRESSION_CHARS,
    MAX_POWER_BITS,
    MAX_SEQUENCE,
    Evaluator,
    Refused,
    shown,
)
from .expansion import Expansion

# What this module offered before its parts moved out stays importable from here.
__all__ = [
    "FUNCTIONS", "MAX_EXPRESSION_CHARS", "MAX_LOG_CHARS", "MAX_POWER_BITS", "MAX_SEQUENCE", "Evaluator", "Expansion",
    "Refused", "main", "serve", "shown",
]
