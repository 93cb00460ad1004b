"""Shared fixtures: the repo's paths, the reference cell, a seeded rng, and --update-golden."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
REFERENCE_CELL = SHARED / "cells" / "reference" / "cabin_flange.yaml"
# The small test cell's source: a frozen copy of the reference cell (shipped cells may change).
SHIPPED_CELL = REPO / "tests" / "data" / "flange_cell" / "cabin_flange.yaml"

SmallCell = Callable[..., Path]


def _write_small_cell(folder: Path, name: str = "small_cell", extra_spots: list[dict[str, Any]] | None = None) -> Path:
    """s7 and s8 of the shipped cell (no clamp between them), grid 3, gamma fixed: plans in ~2 s."""
    data = yaml.safe_load(SHIPPED_CELL.read_text())
    if not (folder / "parts").exists():
        shutil.copytree(SHIPPED_CELL.parent / "parts", folder / "parts")
    data["name"] = name
    seam = data["seams"][0]
    seam["spots"] = [s for s in seam["spots"] if s["name"] in ("s7", "s8")] + (extra_spots or [])
    seam["grid"] = 3
    seam["tolerance"]["gamma"] = [0, 0]
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="session")
def write_small_cell() -> SmallCell:
    """Writes the small test cell into a folder: write_small_cell(folder, name=..., extra_spots=...)."""
    return _write_small_cell


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--update-golden", action="store_true", help="rewrite tests/golden/* from current output")


@pytest.fixture
def update_golden(request: pytest.FixtureRequest) -> bool:
    return bool(request.config.getoption("--update-golden"))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


@pytest.fixture(scope="session")
def reference_cell_path() -> Path:
    """The contract's reference cell (../shared beside the clone, as in CI)."""
    if not REFERENCE_CELL.is_file():
        pytest.skip(f"reference cell not found at {REFERENCE_CELL} (shared/ must sit beside the clone)")
    return REFERENCE_CELL
