"""Every module the package imports comes with `pip install robomax_py`: from the distributions
pyproject's `dependencies` names and what they require in turn, or, for the few imported only where
an extra is asked for, from that extra. The test environment has more (the test and ray extras
bring click, for one), so a module imported from there works in the tests and fails after a plain
install: `import click` did, on every command's first line."""

from __future__ import annotations

import ast
import importlib.metadata as md
import re
import sys
import tomllib
from pathlib import Path

from packaging.requirements import Requirement

REPO = Path(__file__).resolve().parents[1]
# Modules imported only by the features of an extra (their import names an install hint there).
EXTRA_ONLY = {"ray": "ray", "cascadio": "cad"}
# Binary wheels that tell no top-level module (importlib's packages_distributions misses them).
MODULE_DISTRIBUTION = {"coal": "coal", "pinocchio": "pin", "ruckig": "ruckig"}


def _name(dist: str) -> str:
    return re.sub(r"[-_.]+", "-", dist).lower()


def _base_closure() -> set[str]:
    """The base dependencies and everything they require (markers evaluated here, no extras)."""
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    todo = [Requirement(r) for r in project["dependencies"]]
    seen: set[str] = set()
    while todo:
        req = todo.pop()
        if req.marker is not None and not req.marker.evaluate({"extra": ""}):
            continue
        name = _name(req.name)
        if name in seen:
            continue
        seen.add(name)
        try:
            todo += [Requirement(r) for r in md.requires(req.name) or []]
        except md.PackageNotFoundError:
            pass
    return seen


def _imported_modules() -> set[str]:
    found = set()
    for path in (REPO / "robomax_py").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                found |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                found.add(node.module.split(".")[0])
    return {m for m in found if m not in sys.stdlib_module_names and m != "robomax_py"}


def test_every_imported_module_comes_with_the_install() -> None:
    closure = _base_closure()
    providers = md.packages_distributions()
    missing = []
    for module in sorted(_imported_modules()):
        if module in EXTRA_ONLY:
            continue
        dists = {_name(d) for d in providers.get(module, [])} | {_name(MODULE_DISTRIBUTION.get(module, module))}
        if not dists & closure:
            missing.append(f"{module} (from {', '.join(sorted(dists))})")
    assert not missing, f"imported but not installed by `pip install robomax_py`: {missing}"
