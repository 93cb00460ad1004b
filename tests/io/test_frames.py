"""Named frames in cell files: poses in frames resolve to the world poses written by hand."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pydantic import ValidationError
from scipy.spatial.transform import Rotation

from robomax_py.errors import CellFileError
from robomax_py.io.cell import dump_cell_file, load_cell, read_cell_file
from robomax_py.io.cell_file import CellFile
from robomax_py.io.frames import resolve_frames
from tests.conftest import SmallCell

# Resolved world values against the same values transformed by hand (scipy, not the loader's own
# transforms): the sum of a few double-precision products of numbers below 10, so 1e-9 m and 1e-9
# of a unit vector leave orders of magnitude for rounding and none for a wrong transform.
TOL = 1e-9


def _T(xyz: list[float], rpy_deg: list[float]) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy_deg, degrees=True).as_matrix()
    T[:3, 3] = xyz
    return T


def _pose(T: np.ndarray) -> dict[str, list[float]]:
    return {"xyz": [float(v) for v in T[:3, 3]],
            "rpy": [float(v) for v in Rotation.from_matrix(T[:3, :3]).as_euler("xyz", degrees=True)]}


SPOTS = [
    {"name": "a", "xyz": [0.1, 0.0, 0.05], "normal": [0, 0, 1], "direction": [1, 0, 0]},
    {"name": "b", "xyz": [-0.2, 0.3, 0.0], "normal": [0, -1, 0], "direction": [0, 0, 1]},
]
BASE: dict[str, Any] = {"robomax": 1, "name": "f", "robot": {"model": "kr125", "home": [0, -90, 90, 0, 0, 0]},
                        "tool": "spot_gun_c"}


def _cell(**keys: Any) -> CellFile:
    return CellFile.model_validate({**BASE, **keys})


xyz_st = st.lists(st.floats(-3, 3), min_size=3, max_size=3)
rpy_st = st.lists(st.floats(-180, 180), min_size=3, max_size=3)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(xyz_st, rpy_st, xyz_st, rpy_st)
def test_a_fixture_moved_by_one_transform_moves_its_spots_and_parts(fx: list[float], fr: list[float],
                                                                    px: list[float], pr: list[float]) -> None:
    """Spots in a fixture's frame, a part on the fixture, a spot in the part's own frame: the world
    values are the fixture's transform applied by hand."""
    F, P = _T(fx, fr), _T(px, pr)
    cell = _cell(
        frames=[{"name": "fixture", "pose": {"xyz": fx, "rpy": fr}}],
        objects=[{"name": "part", "box": [0.1, 0.1, 0.1], "pose": {"xyz": px, "rpy": pr}, "frame": "fixture"}],
        seams=[{"name": "s", "frame": "fixture", "spots": [*SPOTS,
                {"name": "c", "xyz": [0, 0, 0.05], "normal": [0, 0, 1], "direction": [0, 1, 0], "frame": "part"}]}],
    )
    flat, tree = resolve_frames(cell, Path("f.yaml"))
    spots = flat.seams[0].spots
    for spot, given_spot, T in ((spots[0], SPOTS[0], F), (spots[1], SPOTS[1], F),
                                (spots[2], cell.seams[0].spots[2].model_dump(), F @ P)):
        assert spot.frame is None
        assert np.allclose(spot.xyz, (T @ np.r_[given_spot["xyz"], 1.0])[:3], atol=TOL, rtol=0)
        for k in ("normal", "direction"):
            assert np.allclose(getattr(spot, k), T[:3, :3] @ np.asarray(given_spot[k], float), atol=TOL, rtol=0)
    part = flat.objects[0]
    assert part.frame is None
    assert np.allclose(_T(part.pose.xyz, part.pose.rpy), F @ P, atol=TOL, rtol=0)
    assert [(n.name, n.kind, n.parent) for n in tree] == [("fixture", "frame", "world"), ("part", "object", "fixture")]
    assert np.allclose(tree[1].T_world, F @ P, atol=TOL, rtol=0)


def test_frames_nest_and_an_unplaced_cell_is_left_as_written() -> None:
    cell = _cell(frames=[{"name": "b", "parent": "a", "pose": {"xyz": [0, 1, 0]}},
                         {"name": "a", "pose": {"xyz": [1, 0, 0], "rpy": [0, 0, 90]}}],
                 seams=[{"name": "s", "spots": [{**SPOTS[0], "frame": "b"}, SPOTS[1]]}])
    flat, _ = resolve_frames(cell, Path("f.yaml"))
    assert np.allclose(flat.seams[0].spots[0].xyz, [1 - 1 - 0.0, 0.1, 0.05], atol=TOL)    # a: +x, turned; b: +y in a
    assert flat.seams[0].spots[1] == cell.seams[0].spots[1]
    plain = _cell(seams=[{"name": "s", "spots": SPOTS}])
    assert resolve_frames(plain, Path("f.yaml"))[0] is plain


@pytest.mark.parametrize(("keys", "key", "words"), [
    ({"frames": [{"name": "a", "parent": "b"}, {"name": "b", "parent": "a"}]}, "frames[0].parent",
     "frames placed in each other: a -> b -> a"),
    ({"frames": [{"name": "a", "parent": "nowhere"}]}, "frames[0].parent", "unknown frame 'nowhere'"),
    ({"frames": [{"name": "a"}, {"name": "a"}]}, "frames[1].name", "duplicate frame name 'a' (also frames[0])"),
    ({"frames": [{"name": "world"}]}, "frames[0].name", "'world' is the frame"),
    ({"frames": [{"name": "part"}], "objects": [{"name": "part", "box": [1, 1, 1]}]}, "objects[0].name",
     "also the name of a frame"),
    ({"objects": [{"name": "p", "box": [1, 1, 1], "frame": "q"}, {"name": "q", "box": [1, 1, 1], "frame": "p"}]},
     "objects[0].frame", "p -> q -> p"),
    ({"seams": [{"name": "s", "spots": [{**SPOTS[0], "frame": "jig"}]}]}, "seams[0].spots[0].frame",
     "unknown frame 'jig'"),
    ({"robot": {**BASE["robot"], "frame": "jig"}}, "robot.frame", "unknown frame 'jig'"),
])
def test_frame_mistakes_name_the_key(keys: dict[str, Any], key: str, words: str) -> None:
    data = {"seams": [{"name": "s", "spots": SPOTS}], **keys}
    with pytest.raises(CellFileError) as err:
        resolve_frames(_cell(**data), Path("f.yaml"))
    assert err.value.key == key and words in err.value.problem and err.value.file == "f.yaml"


def test_a_robot_on_a_frame_and_an_error_names_the_cell_file(tmp_path: Path, write_small_cell: SmallCell) -> None:
    path = write_small_cell(tmp_path)
    flat = load_cell(path)
    data = yaml.safe_load(path.read_text())
    S = _T([0.5, -0.25, 0.1], [0, 0, 30])
    data["frames"] = [{"name": "station", "pose": _pose(S)}]
    data["robot"]["frame"] = "station"
    data["robot"]["base"] = {"xyz": [0.0, 0.0, 0.2]}
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    assert np.allclose(cell.T_world_base, S @ _T([0, 0, 0.2], [0, 0, 0]), atol=TOL, rtol=0)
    assert [s.xyz.tolist() for s in cell.seams[0].spots] == [s.xyz.tolist() for s in flat.seams[0].spots]
    data["robot"]["frame"] = "stations"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(CellFileError) as err:
        load_cell(path)
    assert err.value.file == str(path) and err.value.key == "robot.frame"


def test_a_part_placed_by_its_locations_takes_no_frame() -> None:
    with pytest.raises(ValidationError, match="no pose, frame"):
        CellFile.model_validate({**BASE, "pick_place": {
            "parts": [{"name": "p", "box": [0.1, 0.1, 0.1], "mass": 1, "frame": "x"}],
            "locations": [{"name": "a", "pose": {}}, {"name": "b", "pose": {}}],
            "transfers": [{"part": "p", "from": "a", "to": "b"}]}})


def test_read_cell_file_is_flat_so_a_rewritten_cell_stands_alone(tmp_path: Path, write_small_cell: SmallCell) -> None:
    path = write_small_cell(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["frames"] = [{"name": "jig", "pose": {"xyz": [0.1, 0, 0], "rpy": [0, 0, math.degrees(0.1)]}}]
    data["seams"][0]["frame"] = "jig"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    flat = tmp_path / "flat.yaml"
    flat.write_text(dump_cell_file(read_cell_file(path)))
    assert "frame" not in yaml.safe_load(flat.read_text())["seams"][0]
    a, b = load_cell(path), load_cell(flat)
    assert [s.xyz.tolist() for s in a.seams[0].spots] == [s.xyz.tolist() for s in b.seams[0].spots]


def test_stations_doors_locations_and_dynamic_objects_take_frames_too() -> None:
    M = {"xyz": [2.0, 1.0, 0.5], "rpy": [0.0, 0.0, 90.0]}
    T = _T(M["xyz"], M["rpy"])
    door = {"name": "door", "box": [0.1, 1, 1], "pose": {"xyz": [0.5, 0, 0]}, "frame": "machine"}
    cell = _cell(frames=[{"name": "machine", "pose": M}],
                 dynamic=[{"name": "cart", "box": [1, 1, 1], "frame": "machine", "present": [[0, 1]]}],
                 tending={"machines": [{"name": "m", "door": door, "schedule": {"machining": 5, "period": 10}}],
                          "stations": [{"name": "in", "xyz": [0.3, 0, 0.2], "rpy": [180, 0, 0], "action": "grip",
                                        "frame": "machine"}]})
    flat, _ = resolve_frames(cell, Path("f.yaml"))
    station = flat.tending.stations[0]
    assert station.frame is None
    assert np.allclose(_T(station.xyz, station.rpy), T @ _T([0.3, 0, 0.2], [180, 0, 0]), atol=TOL, rtol=0)
    assert np.allclose(flat.tending.machines[0].door.pose.xyz, (T @ np.r_[0.5, 0, 0, 1])[:3], atol=TOL, rtol=0)
    assert np.allclose(_T(flat.dynamic[0].pose.xyz, flat.dynamic[0].pose.rpy), T, atol=TOL, rtol=0)
    picks = _cell(frames=[{"name": "shelf", "pose": M}], pick_place={
        "parts": [{"name": "p", "box": [0.1, 0.1, 0.1], "mass": 1}],
        "locations": [{"name": "a", "pose": {}, "frame": "shelf"}, {"name": "b", "pose": {"xyz": [1, 0, 0]}}],
        "transfers": [{"part": "p", "from": "a", "to": "b"}]})
    flat, _ = resolve_frames(picks, Path("f.yaml"))
    assert np.allclose(_T(flat.pick_place.locations[0].pose.xyz, flat.pick_place.locations[0].pose.rpy), T, atol=TOL)
    assert flat.pick_place.locations[1] == picks.pick_place.locations[1]
