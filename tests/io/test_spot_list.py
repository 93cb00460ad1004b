"""Spot lists: a 200-spot list on a known part, its normals dropped and recovered; bad rows; units."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from spot_list_case import (
    STATION,
    cell_data,
    known_spots,
    station_spots,
    world_normal,
    write_cell,
    write_csv,
)

from robomax_py.errors import CellFileError
from robomax_py.io.cell import load_cell, read_cell_file, spot_list_seams
from robomax_py.io.spot_list import read_spot_list

# A box's face normals are recovered exactly; this bounds rounding only.
NORMAL_TOLERANCE_DEG = 1e-4


def _import(tmp_path: Path, **csv: bool) -> tuple[list, object]:
    spots = known_spots()
    write_csv(tmp_path / "spots.csv", spots, mm=True, **csv)
    cell = write_cell(tmp_path / "cell.yaml", cell_data())
    return spot_list_seams(read_cell_file(cell), cell, "", tmp_path / "spots.csv", "plate", "mm", 0.002)


def test_recovered_normals_positions_and_seams(tmp_path: Path) -> None:
    seams, result = _import(tmp_path)
    spots = {s["id"]: s for s in known_spots()}
    got = {sp.name: sp for seam in seams for sp in seam.spots}
    assert len(got) == 200 and result.recovered_normals == 200 and not result.sides
    worst = max(math.degrees(math.acos(min(1.0, float(np.dot(got[i].normal, world_normal(s["normal"]))))))
                for i, s in spots.items())
    assert worst < NORMAL_TOLERANCE_DEG
    # Positions: the part's pose applied (a top spot at the plate's centre line).
    cell = load_cell(write_cell(tmp_path / "c.yaml", cell_data(spot_lists=[
        {"file": "spots.csv", "part": "plate", "units": "mm"}])))
    T = next(o for o in cell.objects if o.name == "plate").T_world_object
    for sp in (got["P001"], got["P150"]):
        local = np.asarray(spots[sp.name]["xyz"])
        assert np.allclose(sp.xyz, T[:3, :3] @ local + T[:3, 3], atol=1e-6)
    # Grouped by geometry: the four top lines, the front and the side, in list order.
    assert [(s.name, len(s.spots)) for s in seams] == [("seam1", 30), ("seam2", 30), ("seam3", 30), ("seam4", 30),
                                                        ("seam5", 40), ("seam6", 40)]
    by_seam = {s.name: {sp.name for sp in s.spots} for s in seams}
    truth: dict[str, set[str]] = {}
    for s in known_spots():
        truth.setdefault(s["seam"], set()).add(s["id"])
    assert sorted(map(sorted, by_seam.values())) == sorted(map(sorted, truth.values()))
    # Directions along the seam's course, perpendicular to the normal.
    top = seams[0].spots
    assert all(abs(float(np.dot(sp.direction, sp.normal))) < 1e-6 for sp in top)
    assert np.allclose(top[5].direction, world_normal([1, 0, 0]), atol=1e-6)


def test_two_close_rows_in_any_order_are_two_seams_along_their_rows(tmp_path: Path) -> None:
    """Two staggered rows 20 mm apart on the plate's top, 30 mm pitch, listed in a shuffled order:
    each spot's nearest neighbour is in the other row, yet the seams are the rows, their spots in
    order along them and their directions along the rows."""
    hz = 0.025                                                # the plate's top, in its frame
    rows = [[{"xyz": [-0.3 + 0.03 * k + 0.015 * r, 0.02 * r, hz], "normal": [0, 0, 1], "seam": f"row{r}",
              "id": f"R{r}_{k:02d}"} for k in range(15)] for r in (0, 1)]
    spots = rows[0] + rows[1]
    order = np.random.default_rng(3).permutation(len(spots))
    write_csv(tmp_path / "spots.csv", [spots[i] for i in order], mm=True)
    cell = write_cell(tmp_path / "cell.yaml", cell_data())
    seams, result = spot_list_seams(read_cell_file(cell), cell, "", tmp_path / "spots.csv", "plate", "mm", 0.002)
    assert result.by_geometry and len(seams) == 2
    got = sorted([sp.name for sp in s.spots] for s in seams)
    want = sorted([[sp["id"] for sp in row] for row in rows])
    assert [g if g[0] < g[-1] else g[::-1] for g in got] == want
    along = world_normal([1, 0, 0])
    for seam in seams:
        assert all(abs(abs(float(np.dot(sp.direction, along))) - 1) < 1e-6 for sp in seam.spots)


def test_group_column_and_given_normals(tmp_path: Path) -> None:
    seams, result = _import(tmp_path, normals=True, groups=True)
    assert [s.name for s in seams] == ["top1", "top2", "top3", "top4", "front", "side"]
    assert result.recovered_normals == 0 and not result.by_geometry


def test_cell_key_equals_import(tmp_path: Path) -> None:
    seams, _ = _import(tmp_path)
    cell = load_cell(write_cell(tmp_path / "c.yaml", cell_data(spot_lists=[
        {"file": "spots.csv", "part": "plate", "units": "mm"}])))
    assert [s.name for s in cell.seams] == [s.name for s in seams]
    for seam_file, seam in zip(seams, cell.seams, strict=True):
        for a, b in zip(seam_file.spots, seam.spots, strict=True):
            assert a.name == b.name and np.array_equal(np.asarray(a.xyz), b.xyz)
            assert np.allclose(a.normal, b.normal, atol=1e-12) and np.allclose(a.direction, b.direction, atol=1e-9)


def test_mm_and_m_give_the_same_spots(tmp_path: Path) -> None:
    spots = known_spots()[:40]
    write_csv(tmp_path / "mm.csv", spots, mm=True, delimiter=";")
    write_csv(tmp_path / "m.csv", spots, delimiter="\t")
    mm, m = read_spot_list(tmp_path / "mm.csv", "mm"), read_spot_list(tmp_path / "m.csv", "m")
    assert all(np.allclose(a.xyz, b.xyz, atol=1e-9) for a, b in zip(mm.rows, m.rows, strict=True))
    guessed = read_spot_list(tmp_path / "mm.csv", None)
    assert guessed.warnings and "units mm" in guessed.warnings[0]


def test_bad_rows_are_listed_together(tmp_path: Path) -> None:
    path = tmp_path / "bad.csv"
    path.write_text("id,x,y,z,nx,ny,nz\na,1,2,3,,,\nb,1,two,3,,,\nc,1,2,3,0,0,0\na,1,2,3,,,\nd,1,2,3,1,,\n")
    with pytest.raises(CellFileError) as info:
        read_spot_list(path, "mm")
    text = str(info.value)
    assert "4 problems" in text
    for where in ("row 3, column y", "row 4, column nx", "row 5, column id", "row 6, column ny"):
        assert where in text


def test_unknown_column_and_far_spot(tmp_path: Path) -> None:
    (tmp_path / "u.csv").write_text("id,x,y,z,colour\na,1,2,3,red\n")
    with pytest.raises(CellFileError, match="column 'colour': unknown column"):
        read_spot_list(tmp_path / "u.csv", "m")
    (tmp_path / "far.csv").write_text("id;x;y;z\nfar;0;0;50\n")          # 25 mm above the top (mm)
    cell = write_cell(tmp_path / "cell.yaml", cell_data())
    with pytest.raises(CellFileError, match=r"row 2, column x: spot 'far' is 25\.00 mm from"):
        spot_list_seams(read_cell_file(cell), cell, "", tmp_path / "far.csv", "plate", "mm", 0.002)


def test_open_sheet_is_ambiguous_toward_the_base(tmp_path: Path) -> None:
    import trimesh

    sheet = trimesh.Trimesh(vertices=[[-0.2, -0.2, 0], [0.2, -0.2, 0], [0.2, 0.2, 0], [-0.2, 0.2, 0]],
                            faces=[[0, 2, 1], [0, 3, 2]])          # faces point down, away from a robot above
    sheet.export(tmp_path / "sheet.stl")
    data = cell_data()
    data["objects"] = [{"name": "sheet", "mesh": "sheet.stl", "pose": {"xyz": [1.2, 0, 0.2]}}]
    data["robot"]["base"] = {"xyz": [0, 0, 1.0]}
    cell = write_cell(tmp_path / "cell.yaml", data)
    (tmp_path / "s.csv").write_text("id,x,y,z\nonly,0,0,0\n")
    seams, result = spot_list_seams(read_cell_file(cell), cell, "", tmp_path / "s.csv", "sheet", "m", 0.002)
    assert result.sides and "both sides" in result.sides[0]
    spot = seams[0].spots[0]
    assert np.allclose(spot.normal, [0, 0, 1]) and np.allclose(spot.direction, [1, 0, 0])


def test_spots_on_a_sheets_middle_plane_take_the_free_side_whatever_face_is_nearest(tmp_path: Path) -> None:
    """A 1.5 mm sheet with a block 10 mm under it (the approach is 30 mm), spots given on the sheet's
    middle plane as weld-spot exports place them: each is as near the top face as the bottom one.
    Every spot's normal points up, the one side free; the sheet itself does not block the line that
    starts at its lower face."""
    data = cell_data()
    data["objects"] = [{"name": "sheet", "box": [0.4, 0.3, 0.0015], "pose": {"xyz": [1.4, 0.0, 0.9]}, "workpiece": True},
                       {"name": "block", "box": [0.4, 0.3, 0.05], "pose": {"xyz": [1.4, 0.0, 0.864]}}]
    cell = write_cell(tmp_path / "cell.yaml", data)
    rows = "".join(f"m{i},{x:.3f},{y:.3f},0\n" for i, (x, y) in enumerate((x, y) for x in (-0.15, -0.05, 0.05, 0.15)
                                                                          for y in (-0.1, 0.0, 0.1)))
    (tmp_path / "s.csv").write_text("id,x,y,z\n" + rows)
    seams, result = spot_list_seams(read_cell_file(cell), cell, "", tmp_path / "s.csv", "sheet", "m", 0.002)
    normals = np.array([s.normal for seam in seams for s in seam.spots])
    assert len(normals) == 12 and not result.sides, result.sides
    np.testing.assert_allclose(normals, np.tile([0.0, 0.0, 1.0], (12, 1)), atol=1e-9)
    # With room under the sheet too (the block gone), both sides are free: reported, toward the base.
    data["objects"] = data["objects"][:1]
    cell = write_cell(tmp_path / "open.yaml", data)
    seams, result = spot_list_seams(read_cell_file(cell), cell, "", tmp_path / "s.csv", "sheet", "m", 0.002)
    assert len(result.sides) == 12 and all("both sides" in line for line in result.sides)
    assert all(s.normal[2] == -1.0 for seam in seams for s in seam.spots)      # the base is below the sheet
    # Where the seams' gun may stand on either side the planner chooses: nothing for a person to check.
    seams, result = spot_list_seams(read_cell_file(cell), cell, "", tmp_path / "s.csv", "sheet", "m", 0.002,
                                    {"tolerance": {"sides": "either"}})
    assert not result.sides and all(s.normal[2] == -1.0 for seam in seams for s in seam.spots)


def test_list_in_a_named_frame_equals_the_part_frame(tmp_path: Path) -> None:
    write_csv(tmp_path / "part.csv", known_spots()[:80], mm=True, groups=True)
    write_csv(tmp_path / "station.csv", station_spots(), mm=True, groups=True)
    part = load_cell(write_cell(tmp_path / "p.yaml", cell_data(frames=[STATION], spot_lists=[
        {"file": "part.csv", "part": "plate", "units": "mm"}])))
    framed = load_cell(write_cell(tmp_path / "f.yaml", cell_data(frames=[STATION], spot_lists=[
        {"file": "station.csv", "part": "plate", "units": "mm", "frame": "station"}])))
    assert [s.name for s in framed.seams] == [s.name for s in part.seams] == ["top1", "top2", "top3"]
    for a, b in zip(part.seams, framed.seams, strict=True):
        for p, q in zip(a.spots, b.spots, strict=True):
            assert np.allclose(p.xyz, q.xyz, atol=1e-6)
            assert np.allclose(p.normal, q.normal, atol=1e-9) and np.allclose(p.direction, q.direction, atol=1e-6)
    # The part's own name and the world are frames too.
    world = load_cell(write_cell(tmp_path / "w.yaml", cell_data(spot_lists=[
        {"file": "part.csv", "part": "plate", "units": "mm", "frame": "plate"}])))
    assert np.allclose(world.seams[0].spots[0].xyz, part.seams[0].spots[0].xyz, atol=1e-9)


def test_list_in_an_unknown_frame_is_refused(tmp_path: Path) -> None:
    write_csv(tmp_path / "part.csv", known_spots()[:10], mm=True)
    cell = write_cell(tmp_path / "c.yaml", cell_data(frames=[STATION], spot_lists=[
        {"file": "part.csv", "part": "plate", "units": "mm", "frame": "nowhere"}]))
    with pytest.raises(CellFileError, match=r"spot_lists\[0\]\.frame: unknown frame 'nowhere' \(frames: world, station"):
        load_cell(cell)
