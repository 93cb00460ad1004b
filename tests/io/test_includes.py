"""Included files: merged into the cell, each checked with its own file and key; the planned result
of a cell written with frames and includes is that of the same cell written flat."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

from robomax_py.app.cli import app
from robomax_py.errors import CellFileError
from robomax_py.io.cell import (
    dump_cell_file,
    load_cell,
    load_cell_robot,
    read_cell_file,
)
from robomax_py.plan import PlanOptions, plan_cell
from tests.conftest import SmallCell

FIXTURE_POSE = {"xyz": [1.8, 0.05, 0.62], "rpy": [0.0, 0.0, 3.0]}
# The fixture's parts, moved out of the cell into its include (the table stays in the cell).
ON_FIXTURE = ("fixture_plate", "cabin_panel", "clamp1_jaw", "clamp1_arm", "clamp1_post", "clamp2_jaw",
              "clamp2_arm", "clamp2_post")


def _T(pose: dict[str, Any]) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", pose.get("rpy", [0, 0, 0]), degrees=True).as_matrix()
    T[:3, 3] = pose.get("xyz", [0, 0, 0])
    return T


def _in_frame(F_inv: np.ndarray, pose: dict[str, Any]) -> dict[str, list[float]]:
    M = F_inv @ _T(pose)
    return {"xyz": [float(v) for v in M[:3, 3]],
            "rpy": [float(v) for v in Rotation.from_matrix(M[:3, :3]).as_euler("xyz", degrees=True)]}


def _split(flat: Path) -> Path:
    """The flat cell rewritten as a station integrator would: the fixture, its clamps, its part and
    its seam in fixture/fixture.yaml, in the fixture's frame (spots in part coordinates); the cell
    includes it."""
    data = yaml.safe_load(flat.read_text())
    F_inv = np.linalg.inv(_T(FIXTURE_POSE))
    objects = []
    for obj in data["objects"]:
        if obj["name"] in ON_FIXTURE:
            obj = {**obj, "pose": _in_frame(F_inv, obj.get("pose", {})), "frame": "fixture"}
            if "mesh" in obj:
                obj["mesh"] = "../" + obj["mesh"]          # relative to the included file
            objects.append(obj)
    spots = [{**s, "xyz": [float(v) for v in (F_inv @ np.r_[s["xyz"], 1.0])[:3]],
              "normal": [float(v) for v in F_inv[:3, :3] @ np.asarray(s["normal"], float)],
              "direction": [float(v) for v in F_inv[:3, :3] @ np.asarray(s["direction"], float)]}
             for s in data["seams"][0]["spots"]]
    (flat.parent / "fixture").mkdir(exist_ok=True)
    fixture = {"frames": [{"name": "fixture", "pose": FIXTURE_POSE}], "objects": objects,
               "seams": [{**data["seams"][0], "frame": "fixture", "spots": spots}]}
    (flat.parent / "fixture" / "fixture.yaml").write_text(yaml.safe_dump(fixture, sort_keys=False))
    cell = {k: v for k, v in data.items() if k != "seams"}
    cell["objects"] = [o for o in data["objects"] if o["name"] not in ON_FIXTURE]
    cell["include"] = ["fixture/fixture.yaml"]
    cell["name"] = data["name"] + "_framed"
    path = flat.parent / f"{cell['name']}.yaml"
    path.write_text(yaml.safe_dump(cell, sort_keys=False))
    return path


def test_a_cell_with_frames_and_includes_plans_as_the_same_cell_written_flat(
        tmp_path: Path, write_small_cell: SmallCell) -> None:
    framed = _split(write_small_cell(tmp_path))
    original = load_cell(tmp_path / "small_cell.yaml")
    cell = load_cell(framed)
    # The world spots and objects are the hand-written ones (1e-9: rounding of the two transforms).
    for a, b in zip(cell.seams[0].spots, original.seams[0].spots, strict=True):
        for k in ("xyz", "normal", "direction"):
            assert np.allclose(getattr(a, k), getattr(b, k), atol=1e-9, rtol=0)
    by_name = {o.name: o for o in original.objects}
    assert sorted(by_name) == sorted(o.name for o in cell.objects)
    for obj in cell.objects:
        assert np.allclose(obj.T_world_object, by_name[obj.name].T_world_object, atol=1e-9, rtol=0)
    # The same cell written flat (its resolved values, as `read_cell_file` gives them) plans the
    # same motion: the cycle time is equal to the last bit.
    flat = tmp_path / "written_flat.yaml"
    flat.write_text(dump_cell_file(read_cell_file(framed).model_copy(update={"name": "written_flat"})))
    assert "include" not in flat.read_text() and "frame" not in flat.read_text()
    flat_cell = load_cell(flat)
    assert [s.xyz.tolist() for s in flat_cell.seams[0].spots] == [s.xyz.tolist() for s in cell.seams[0].spots]
    results = [plan_cell(c, load_cell_robot(c), PlanOptions()) for c in (cell, flat_cell)]
    assert all(r.status == "planned" for r in results), [r.message for r in results]
    assert results[0].trajectory.duration == results[1].trajectory.duration
    assert np.array_equal(results[0].trajectory.q, results[1].trajectory.q)


def _write(folder: Path, name: str, data: dict[str, Any]) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _with_include(tmp_path: Path, write_small_cell: SmallCell, include: list[str]) -> Path:
    path = write_small_cell(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["include"] = include
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


BOX = {"name": "post", "box": [0.1, 0.1, 0.1], "pose": {"xyz": [0.5, 1.5, 0.05]}}


def test_the_same_file_included_twice_is_one_error_naming_both_places(tmp_path: Path,
                                                                      write_small_cell: SmallCell) -> None:
    _write(tmp_path, "a.yaml", {"include": ["post.yaml"]})
    _write(tmp_path, "post.yaml", {"objects": [BOX]})
    path = _with_include(tmp_path, write_small_cell, ["a.yaml", "./post.yaml"])
    with pytest.raises(CellFileError) as err:
        load_cell(path)
    assert err.value.file == str(path) and err.value.key == "include[1]"
    assert f"already included by {tmp_path / 'a.yaml'}: include[0]" in err.value.problem


def test_an_include_cycle_is_an_error_listing_the_chain(tmp_path: Path, write_small_cell: SmallCell) -> None:
    _write(tmp_path, "a.yaml", {"include": ["sub/b.yaml"]})
    _write(tmp_path, "sub/b.yaml", {"include": ["../a.yaml"]})
    path = _with_include(tmp_path, write_small_cell, ["a.yaml"])
    with pytest.raises(CellFileError) as err:
        load_cell(path)
    assert err.value.file == str(tmp_path / "sub" / "b.yaml") and err.value.key == "include[0]"
    a, b = (tmp_path / "a.yaml").resolve(), (tmp_path / "sub" / "b.yaml").resolve()
    assert f"include cycle: {a} -> {b} -> {a}" in err.value.problem
    _write(tmp_path, "a.yaml", {"include": ["small_cell.yaml"]})
    with pytest.raises(CellFileError, match="include cycle: .*small_cell.yaml -> .*a.yaml -> .*small_cell.yaml"):
        load_cell(path)


@pytest.mark.parametrize(("content", "key", "words"), [
    ({"objects": [{**BOX, "colour": "red"}]}, "objects[0].colour", "unknown key"),
    ({"objects": [BOX, {**BOX, "box": [0.1, 0.1, -1]}]}, "objects[1].box[2]", "greater than 0"),
    ({"seams": [{"name": "extra", "spots": [{"name": "x", "xyz": [1.3, 0, 0.9], "normal": [0, 0, 0],
                                             "direction": [0, 1, 0]}]}]}, "seams[0].spots[0].normal", "zero-length"),
    ({"objects": [BOX, {**BOX, "name": "table"}]}, "objects[1].name", "duplicate name 'table' (also objects[0] in "),
    ({"objects": [{**BOX, "frame": "nowhere"}]}, "objects[0].frame", "unknown frame 'nowhere'"),
    ({"objects": [{**BOX, "mesh": "missing.stl", "box": None}]}, "objects[0].mesh", "missing.stl"),
    ({"robot": {"model": "kr125", "home": [0, -90, 90, 0, 0, 0]}}, "robot", "also given in"),
    ({"process": {"weld_time": 1}}, "process", "unknown key"),
    ("just text", None, "expected a mapping"),
])
def test_an_error_inside_an_included_file_names_that_file_and_its_key(
        tmp_path: Path, write_small_cell: SmallCell, content: Any, key: str | None, words: str) -> None:
    if isinstance(content, dict):
        content = {k: [{kk: vv for kk, vv in o.items() if vv is not None} for o in v] if isinstance(v, list) else v
                   for k, v in content.items()}
    inc = _write(tmp_path, "inc/part.yaml", content) if isinstance(content, dict) else tmp_path / "inc" / "part.yaml"
    if not isinstance(content, dict):
        inc.parent.mkdir(exist_ok=True)
        inc.write_text(yaml.safe_dump(content))
    path = _with_include(tmp_path, write_small_cell, ["inc/part.yaml"])
    with pytest.raises(CellFileError) as err:
        load_cell(path)
    assert err.value.file == str(inc), str(err.value)
    assert err.value.key == key and words in err.value.problem, str(err.value)


def test_includes_are_relative_paths_and_read_only(tmp_path: Path, write_small_cell: SmallCell) -> None:
    post = _write(tmp_path, "post.yaml", {"objects": [BOX]})
    path = _with_include(tmp_path, write_small_cell, [str(post)])
    with pytest.raises(CellFileError, match="absolute path"):
        load_cell(path)
    path = _with_include(tmp_path, write_small_cell, ["nothere.yaml"])
    with pytest.raises(CellFileError) as err:
        load_cell(path)
    assert "nothere.yaml" in str(err.value)
    before = sorted(p.name for p in tmp_path.iterdir())
    path = _with_include(tmp_path, write_small_cell, ["post.yaml"])
    cell = load_cell(path)
    assert "post" in [o.name for o in cell.objects]
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_the_digest_covers_the_included_files(tmp_path: Path, write_small_cell: SmallCell) -> None:
    plain = write_small_cell(tmp_path)
    assert load_cell(plain).digest == hashlib.sha256(plain.read_bytes()).hexdigest()   # as before includes
    post = _write(tmp_path, "post.yaml", {"objects": [BOX]})
    path = _with_include(tmp_path, write_small_cell, ["post.yaml"])
    first = load_cell(path).digest
    assert first == load_cell(path).digest != hashlib.sha256(path.read_bytes()).hexdigest()
    post.write_text(post.read_text().replace("0.05", "0.06"))
    assert load_cell(path).digest != first


def test_check_prints_the_frame_tree_and_its_json_carries_it(tmp_path: Path, write_small_cell: SmallCell) -> None:
    framed = _split(write_small_cell(tmp_path))
    result = CliRunner().invoke(app, ["check", str(framed)])
    assert result.exit_code == 0, result.output
    assert "frames:" in result.output and "fixture (frame): xyz [1.8, 0.05, 0.62] m, rpy [0, 0, 3] deg in world" \
        in result.output
    assert "    cabin_panel (object)" in result.output and "includes " in result.output
    result = CliRunner().invoke(app, ["check", str(framed), "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["frames"][0] == {"name": "fixture", "kind": "frame", "parent": "world", "key": "frames[0]",
                                "pose": {"xyz": [1.8, 0.05, 0.62], "rpy": [0.0, 0.0, 3.0]},
                                "world": {"xyz": [1.8, 0.05, 0.62], "rpy": [0.0, 0.0, 3.0]}}
    assert {n["name"] for n in doc["frames"]} == {"fixture", *ON_FIXTURE}
    assert doc["includes"] == [str(framed.parent / "fixture" / "fixture.yaml")]
