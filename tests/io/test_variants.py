"""`robomax variants`: seeded, byte-identical per seed, valid cells, perturbations within their bounds."""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from robomax_py.app.cli import EXIT_OK, app
from robomax_py.io.cell import load_cell, read_cell_file
from robomax_py.io.variants import VariantBounds, clamp_group, write_variants

SmallCell = Callable[..., Path]   # conftest.write_small_cell
VALUE_TOL = 2e-6                  # values are written rounded to 1e-6
runner = CliRunner()


@pytest.fixture
def cell(tmp_path: Path, write_small_cell: SmallCell) -> Path:
    """The small cell plus an ordered seam (never reordered); its mesh sits outside the cell's folder."""
    folder = tmp_path / "cells"
    folder.mkdir()
    path = write_small_cell(folder, "small")
    shutil.move(folder / "parts", tmp_path / "meshes")
    data = yaml.safe_load(path.read_text())
    for obj in data["objects"]:
        if "mesh" in obj:
            obj["mesh"] = "../meshes/" + Path(obj["mesh"]).name
    spots = [{"name": f"o{k}", "xyz": [1.3, -0.1 + 0.05 * k, 0.9], "normal": [-1, 0, 0], "direction": [0, 1, 0]}
             for k in range(4)]
    data["seams"].append({"name": "in_order", "ordered": True, "spots": spots})
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_same_seed_same_bytes_other_seed_other_files(cell: Path, tmp_path: Path) -> None:
    runs = []
    for k, seed in enumerate((3, 3, 4)):
        out = tmp_path / f"out{k}"
        result = runner.invoke(app, ["variants", str(cell), "--n", "4", "--seed", str(seed), "-o", str(out)])
        assert result.exit_code == EXIT_OK, result.output
        runs.append({p.name: p.read_bytes() for p in sorted(out.iterdir())})
    assert list(runs[0]) == [f"small_v{k:02d}.yaml" for k in range(4)]
    assert runs[0] == runs[1]
    assert runs[0] != runs[2]
    assert len(set(runs[0].values())) == 4


def test_variants_are_valid_cells(cell: Path, tmp_path: Path) -> None:
    made = write_variants(cell, 3, 0, tmp_path / "elsewhere" / "out")
    for v in made:
        spec = load_cell(v.path)
        assert spec.name == v.name
    result = runner.invoke(app, ["check", str(made[0].path)])
    assert result.exit_code == EXIT_OK, result.output


def test_perturbations_stay_within_their_bounds(cell: Path, tmp_path: Path) -> None:
    bounds = VariantBounds()
    original = read_cell_file(cell)
    made = write_variants(cell, 6, 1, tmp_path / "out")
    for v in made:
        p = v.perturbation
        changed = read_cell_file(v.path)
        assert abs(p.part_offset[0]) <= bounds.part and abs(p.part_offset[1]) <= bounds.part
        assert abs(p.part_yaw) <= bounds.part_yaw
        c, s = math.cos(p.part_yaw), math.sin(p.part_yaw)
        R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        centre = np.array([*p.centre, 0.0])
        shift = np.array([*p.part_offset, 0.0])
        moves = {g: (dx, dy) for g, dx, dy in p.clamps}
        assert {clamp_group(o.name) for o in original.objects if clamp_group(o.name)} == set(moves)
        for before, after in zip(original.objects, changed.objects, strict=True):
            assert after.name == before.name and after.box == before.box
            group = clamp_group(before.name)
            if before.workpiece:
                want = centre + R @ (np.array(before.pose.xyz) - centre) + shift
                np.testing.assert_allclose(after.pose.xyz, want, atol=VALUE_TOL)
                assert after.pose.rpy[2] - before.pose.rpy[2] == pytest.approx(math.degrees(p.part_yaw), abs=VALUE_TOL)
            elif group is not None:
                dx, dy = moves[group]
                assert abs(dx) <= bounds.clamp and abs(dy) <= bounds.clamp
                delta = np.array(after.pose.xyz) - np.array(before.pose.xyz)
                np.testing.assert_allclose(delta, [dx, dy, 0.0], atol=VALUE_TOL)
                assert after.pose.rpy == before.pose.rpy
            else:
                assert after == before
        for seam_before, seam_after in zip(original.seams, changed.seams, strict=True):
            by_name = {sp.name: sp for sp in seam_before.spots}
            names = [sp.name for sp in seam_after.spots]
            assert sorted(names) == sorted(by_name)
            if seam_before.ordered:
                assert names == [sp.name for sp in seam_before.spots]
            for sp in seam_after.spots:
                old = by_name[sp.name]
                want = centre + R @ (np.array(old.xyz) - centre) + shift
                np.testing.assert_allclose(sp.xyz, want, atol=VALUE_TOL)
                np.testing.assert_allclose(sp.normal, R @ np.array(old.normal), atol=VALUE_TOL)
                np.testing.assert_allclose(sp.direction, R @ np.array(old.direction), atol=VALUE_TOL)
    # over several variants the free seam's order does change
    assert len({tuple(o for _, o in v.perturbation.orders) for v in made}) > 1
