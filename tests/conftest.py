"""Shared fixtures: the repo's paths, the reference cell, a seeded rng, and --update-golden."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
REFERENCE_CELL = SHARED / "cells" / "reference" / "cabin_flange.yaml"


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
