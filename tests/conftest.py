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


def place_cell(data: dict[str, Any], xyz: tuple[float, float, float], yaw_deg: float, roll_deg: float = 0.0) -> None:
    """Move a whole cell (its data as read from YAML) by one rigid transform, in place: the robot,
    every object and dynamic object, every spot with its normal and direction, as a station puts a
    cell wherever it stands. The cell plans the same motion: only the world moved."""
    from scipy.spatial.transform import Rotation

    R = Rotation.from_euler("xz", [roll_deg, yaw_deg], degrees=True)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R.as_matrix(), xyz

    def pose(p: dict[str, Any] | None) -> dict[str, Any]:
        p = p or {}
        M = np.eye(4)
        M[:3, :3] = Rotation.from_euler("xyz", p.get("rpy", [0, 0, 0]), degrees=True).as_matrix()
        M[:3, 3] = p.get("xyz", [0, 0, 0])
        N = T @ M
        rpy = Rotation.from_matrix(N[:3, :3]).as_euler("xyz", degrees=True)
        return {"xyz": [round(float(v), 9) for v in N[:3, 3]], "rpy": [round(float(v), 9) for v in rpy]}

    data["robot"]["base"] = pose(data["robot"].get("base"))
    for key in ("objects", "dynamic"):
        for obj in data.get(key, []):
            obj["pose"] = pose(obj.get("pose"))
    for seam in data.get("seams", []):
        for spot in seam["spots"]:
            spot["xyz"] = [round(float(v), 9) for v in (T @ np.r_[spot["xyz"], 1.0])[:3]]
            for k in ("normal", "direction"):
                spot[k] = [round(float(v), 12) for v in T[:3, :3] @ np.asarray(spot[k], dtype=float)]


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
